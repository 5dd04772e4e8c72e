"""A section of the state space, where a run stops or logs a hit (user events, return
maps), and the first returns to one. The problem's definition, engine-free: both
engines and the front doors import it from here, and it imports nothing of theirs."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from . import options


@dataclass(frozen=True)
class Section:
    """A user event ``func(z) = 0``; ``direction`` -1 counts decreasing crossings
    only, +1 increasing, 0 both; ``where(z)`` must hold at the hit;
    ``terminal`` stops the run after that many hits (None: never); hits earlier
    than ``t0 + min_time`` are ignored.

    A start point on the section is not a hit, also when rounding puts it a hair
    before the section (a crossing in the run's first sample interval within
    ``rules.START_ULPS`` rounding errors of the start): a return map started on its
    section gives the next return, never ``P(z) = z`` at t ~ 1e-17. ``min_time``
    skips crossings that are genuinely close to the start.

    Sections crossed at one instant (the same surface written twice, two surfaces
    through one point of the orbit) are each hit there, in the order given
    (:func:`tied_hits`); a terminal one among them ends the run, the hits of those
    before it logged.

    A section may lie on the switching surface H: where the orbit crosses H, or
    arrives on it to slide, the hit is logged there, before the switch. Sliding
    along H inside the section (whatever ``where`` says) is an error, since its
    crossings there would be rounding noise: a terminal hit at the arrival ends
    the run first; else use a section transverse to the sliding flow.
    """

    name: str
    func: Callable[[np.ndarray], np.ndarray]
    direction: int = 0
    where: Optional[Callable[[np.ndarray], bool]] = None
    terminal: Optional[int] = None
    min_time: float = 0.0

    def __post_init__(self):
        if self.direction not in (-1, 0, 1):
            raise ValueError(f"Section {self.name!r}: direction must be -1, 0 or +1, got "
                             f"{self.direction!r}")
        if not callable(self.func):
            raise TypeError(f"Section {self.name!r}: func must be callable")
        if self.terminal is not None and (isinstance(self.terminal, bool)
                                          or not isinstance(self.terminal, (int, np.integer))
                                          or self.terminal < 1):
            raise ValueError(f"Section {self.name!r}: terminal must be None or an integer "
                             f">= 1, got {self.terminal!r}")
        m = self.min_time
        if not (options.finite(m) and m >= 0):
            raise ValueError(f"Section {self.name!r}: min_time must be a finite number >= 0, "
                             f"got {self.min_time!r}")


def tied_hits(sections, first: int, t: float, z, at, t0: float, xtol: float,
              skip=()) -> list:
    """The sections crossed at the instant ``t`` of a hit of section ``first`` (-1: of none
    of these, another event): the event search keeps the first of roots at one instant
    (``rules.section_first``), and the others' crossings lie behind the hit's state z,
    where the run goes on -- they are hits there too. A section is one whose value at
    ``at(t - d)`` (the run's dense output; d = ``rules.same_instant``) and at z holds its
    sign change, where ``where`` holds at z and ``min_time`` is past (from the run's start
    t0); not one of ``skip`` (logged there already), not within d of the run's start (a
    start on a section is no hit). One whose root rounding puts a hair beyond z is not:
    the search finds it next, just after t, so that no crossing is counted twice. Their
    indices, in order (docs/decisions.md#sections-at-one-instant)."""
    from . import rules

    d = rules.same_instant(xtol, t)
    if t - d <= t0:
        return []
    before = np.asarray(at(t - d), dtype=float).reshape(-1)
    z = np.asarray(z, dtype=float).reshape(-1)
    out = []
    for k, sec in enumerate(sections):
        if k == first or k in skip or t - t0 < sec.min_time:
            continue
        s0, s1 = (float(np.asarray(sec.func(v)).reshape(-1)[0]) for v in (before, z))
        if rules.crosses(rules.section_pred(sec.direction), s0, s1) and (
                sec.where is None or sec.where(z)):
            out.append(k)
    return out


def one_instant(t0: float, t: float, xtol: float) -> bool:
    """t is the instant t0 to the solver (``rules.same_instant``): a stay that begins a
    few ulps after a section hit -- at a switch the search refined just past it -- still
    begins on that section."""
    from . import rules

    return abs(t - t0) <= rules.same_instant(xtol, max(abs(t0), abs(t)))


def names_hit_within(events, t: float, xtol: float) -> list:
    """The names of the sections hit (the "section" events of ``events``) within
    ``rules.same_instant`` before t, once per hit, newest first."""
    from . import rules

    d, names = rules.same_instant(xtol, t), []
    for e in reversed(events):
        if e.t < t - d:
            break
        if e.kind == "section":
            names.append(e.name)
    return names


def hit_within(sections, events, t: float, xtol: float) -> set:
    """The indices of ``sections`` hit within ``rules.same_instant`` before t
    (:func:`names_hit_within`): a crossing counted there is not a tie of a hit at t
    (:func:`tied_hits`' ``skip``), so that roots rounding puts a hair apart are each
    counted once."""
    names = set(names_hit_within(events, t, xtol))
    return {k for k, sec in enumerate(sections) if sec.name in names}


@dataclass(frozen=True)
class Returns:
    """First returns of ``starts`` (shape ``(m, dim)``) to one section."""

    state: np.ndarray         # (m, dim) state at the return
    time: np.ndarray          # (m,) time of flight
    n_switches: np.ndarray    # (m,) changes of mode on the way
    sliding_time: np.ndarray  # (m,) time spent sliding on the way
    first_switch: np.ndarray  # (m,) time of the first change of mode (NaN: none)
