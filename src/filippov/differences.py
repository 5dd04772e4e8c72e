"""Central differences of a function of one state: the Jacobian checks of a system
defined once, Newton's Jacobians and the variational equations' fallback. Engine-free:
imported by both engines and by the system definitions below them."""
from __future__ import annotations

from typing import Callable

import numpy as np

from . import rules


def fd_jacobian(fun: Callable[[np.ndarray], np.ndarray], u: np.ndarray,
                step: float = 1e-7, floor: float = 1.0) -> np.ndarray:
    """Central differences; ``step`` is relative to ``max(floor, |u_i|)`` (``floor``: the
    state scale, filippov.scale, or each component's)."""
    u = np.asarray(u, dtype=float)
    floors = np.broadcast_to(np.asarray(floor, dtype=float), u.shape)
    cols = []
    for i in range(u.size):
        d = step * max(floors[i], abs(u[i]))
        up, um = u.copy(), u.copy()
        up[i] += d
        um[i] -= d
        cols.append((np.asarray(fun(up)) - np.asarray(fun(um))) / (2 * d))
    return np.stack(cols, axis=-1)


def richardson_jacobian(fun: Callable[[np.ndarray], np.ndarray], u: np.ndarray,
                        floor: float = 1.0) -> np.ndarray:
    """Richardson's extrapolation (4 D(d/2) - D(d)) / 3 of central differences, the
    step ``rules.richardson_step(max(floor, |u_k|))`` (``floor``: one, or each
    component's): the compiled engine's derivative of a closed-form flow without its
    Jacobian, here as an independent check of given or generated flow Jacobians."""
    u = np.asarray(u, dtype=float)
    floors = np.broadcast_to(np.asarray(floor, dtype=float), u.shape)

    def quotient(k, d):
        up, down = u.copy(), u.copy()
        up[k] += d
        down[k] -= d
        return (np.asarray(fun(up)) - np.asarray(fun(down))) / (up[k] - down[k])
    cols = []
    for k in range(u.size):
        d = rules.richardson_step(max(floors[k], abs(u[k])))
        cols.append((4 * quotient(k, d / 2) - quotient(k, d)) / 3)
    return np.stack(cols, axis=-1)
