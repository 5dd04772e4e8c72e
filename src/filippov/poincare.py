"""Return maps: the first return of many start points to a section.

The return map is built from the event-driven solver alone: every start point is
one :func:`simulate` call that stops at its first section hit. Along with the
returned state, each return records the time taken, the number of switches and
the time spent sliding, so a figure can show where the map changes character.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from . import views
from .contracts import SectionView, provides
from .section import Returns  # noqa: F401  (re-exported: filippov.poincare.Returns)
from .errors import run_error
from .loop.status import NO_RETURN
from .progress import Progress
from .scale import of_batch
from .surfaces import SurfacesSystem, view_at
from .simulate import Section, simulate
from .system import SLIDING


def first_returns(system, starts, section, t_max: float, *, engine: str = "reference",
                  direction: int = 0, where=None, progress: Progress | None = None,
                  **options) -> Returns:
    """Follow each start point until it first hits ``section`` (within ``t_max``).

    ``system``: a :class:`~filippov.system.PiecewiseSystem` (reference engine), a system
    defined once (:class:`~filippov.FilippovSystem`, :class:`~filippov.SymbolicSystem`:
    either engine) or a :class:`~filippov.abi.CompiledModel` (compiled engine).
    ``section``: a :class:`~filippov.simulate.Section` (reference engine), or a function
    ``s(z, p) -> float`` of a system defined once, with ``direction`` (-1, 0, +1) and
    ``where(z, p) -> bool``; None: a CompiledModel's own section.
    ``engine``: "reference" (:func:`simulate` once per start) or "compiled" (one batch
    call of :func:`filippov.fastmap.compute_returns`), chosen by
    :func:`filippov.views.pick` from :data:`RUNS`.

    ``options`` go to the engine; ``atol``, ``touch_tol`` and ``event_xtol`` are in units
    of the batch's scale (:mod:`filippov.scale`: declared with ``scale=`` or by the
    system, else measured at the smallest and the largest start, the smaller taken). A
    start point that does not return within ``t_max`` is an error naming it: a return map
    with holes is not a return map.
    A start on the section (up to rounding) returns at its next crossing;
    ``min_time`` (a Section's, or an option) skips crossings closer to the start than
    that. ``progress`` is stepped once per start point.
    """
    return views.pick(RUNS, "first_returns", engine)(system, starts, section, t_max,
                                                     direction=direction, where=where,
                                                     progress=progress, **options)


def _reference_section(system, section, direction: int, where, options: dict) -> Section:
    """``section`` as the reference driver's terminal Section (a function s(z, p) of a
    system defined once compiled like its pieces; ``min_time`` taken from ``options``)."""
    if isinstance(section, Section):
        if direction != 0 or where is not None:
            raise ValueError("direction, where: a Section carries its own; give them to "
                             "the Section")
        return section if section.terminal == 1 else dataclasses.replace(section, terminal=1)
    if section is None or not provides(system, SectionView):   # filippov.contracts
        raise TypeError(f"section: first_returns(engine='reference') of a "
                        f"{type(system).__name__} expected a filippov.Section, got "
                        f"{type(section).__name__}")
    return system.python_section(section, direction=direction, where=where,
                                 min_time=options.pop("min_time", 0.0))


def _first_returns(system, starts, section, t_max: float, *, direction: int = 0,
                   where=None, progress: Progress | None = None, **options) -> Returns:
    """:func:`first_returns` on the reference driver."""
    python = views.reference_system(system, "first_returns", several=True)
    section = _reference_section(system, section, direction, where, options)
    system = python
    starts = np.atleast_2d(np.asarray(starts, dtype=float))
    # a several-surface system's modes are codes: it says which of them slide
    slid_on = system.slid_on if isinstance(system, SurfacesSystem) else None
    if starts.size and np.all(np.isfinite(starts)):   # one scale, as the compiled engine's
        measured = view_at(system, starts[0])
        options["scale"] = of_batch(system.scale if options.get("scale") is None
                                    else options["scale"], starts,
                                    lambda i: (measured.field_minus, measured.field_plus,
                                               measured.switch_grad))
        if slid_on is not None and options["scale"].how != "declared":
            # several surfaces: each one's switch scale measured by each run on its own
            # (filippov.several), the batch's state and time kept
            options["scale"] = {"state": options["scale"].state,
                                "time": options["scale"].time}
    m = starts.shape[0]
    state = np.empty_like(starts)
    time = np.empty(m)
    n_switches = np.empty(m, dtype=np.int64)
    sliding = np.empty(m)
    first = np.full(m, np.nan)
    for i, z0 in enumerate(starts):
        traj = simulate(system, z0, t_max, sections=[section], dense=False, **options)
        if traj.status != f"section:{section.name}":
            raise run_error(NO_RETURN, traj.t, traj.z, f": start point {z0.tolist()} did "
                            f"not return to section {section.name!r} within t_max={t_max!r} "
                            f"(status {traj.status})")
        hit = traj.events[-1]
        state[i], time[i] = hit.state, hit.t - traj.t0
        switches = traj.switches()
        n_switches[i] = len(switches)
        if switches:
            first[i] = switches[0].t - traj.t0
        sliding[i] = sliding_time(traj.events, None if slid_on is None else
                                  (lambda mode: slid_on(mode) >= 0))
        if progress is not None:
            progress.step()
    return Returns(state, time, n_switches, sliding, first)


def _first_returns_compiled(*args, **kwargs):
    """:func:`first_returns` on the compiled engine (:func:`filippov.fastmap._first_returns`,
    imported when first asked: the reference engine never imports numba)."""
    from .fastmap import _first_returns as run

    return run(*args, **kwargs)


#: what runs :func:`first_returns` on each engine
RUNS = {views.REFERENCE: _first_returns, views.COMPILED: _first_returns_compiled}


def sliding_time(events, slides=None) -> float:
    """Time spent sliding along an event log (a stretch open at the start -- a run that
    starts sliding -- or still open at the end counts), as the compiled engine counts.
    ``slides(mode)``: whether a mode slides (None: ``mode == SLIDING``, one surface)."""
    if slides is None:
        slides = (lambda mode: mode == SLIDING)
    total, since = 0.0, None
    for e in events:
        after, before = slides(e.mode_after), slides(e.mode_before)
        if after and (not before or e.kind == "start"):
            since = e.t
        elif before and not after and since is not None:
            total += e.t - since
            since = None
    if since is not None:
        total += events[-1].t - since
    return total


def fixed_points(grid: np.ndarray, values: np.ndarray, refine=None, xtol: float = 1e-14,
                 floor: float | None = None):
    """Fixed points of a 1-D map sampled as ``values = P(grid)``.

    Grid points where ``P(x) = x`` exactly are fixed points; a sign change of
    ``P(x) - x`` between neighbours is refined with Brent's method on
    ``refine(x) - x`` if given. A sign change across a jump of ``P`` is not a
    fixed point, so a refined root is kept only if ``|P(r) - r| <= 1e-9 max(floor,
    |r|)``; ``floor``: the map's state scale (None: the grid's largest value as
    :func:`filippov.scale.power_of_two` rounds it, at most 1: the test is relative
    beyond), and ``xtol`` is in its units.
    """
    from scipy.optimize import brentq

    from .scale import power_of_two

    grid, values = np.asarray(grid, dtype=float), np.asarray(values, dtype=float)
    if floor is None:
        finite = np.abs(grid[np.isfinite(grid)])
        floor = min(1.0, power_of_two(float(finite.max()))) if finite.size else 1.0

    d = values - grid
    out = list(grid[d == 0.0])
    for i in np.flatnonzero(d[:-1] * d[1:] < 0):
        a, b = grid[i], grid[i + 1]
        if refine is None:
            r = a - d[i] * (b - a) / (d[i + 1] - d[i])
            out.append(r)
            continue
        g = lambda x: float(refine(x)) - x
        r = brentq(g, a, b, xtol=xtol * floor)
        if abs(g(r)) <= 1e-9 * max(floor, abs(r)):
            out.append(r)
    return np.unique(np.asarray(out, dtype=float))
