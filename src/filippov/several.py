"""A run on several switching surfaces (a :class:`~filippov.surfaces.SurfacesSystem`),
stay by stay, on the reference engine.

Each stay is a one-surface problem (:mod:`filippov.surfaces`): in region sigma the
region's boundary (:func:`~filippov.surfaces.region_view`), while sliding on surface k
that surface alone (:func:`~filippov.surfaces.slide_view`, the other surfaces watched as
terminal sections). The engine's run (``one_stay``: :func:`filippov.simulate.one_stay`)
follows a stay with every rule of the one-surface book -- its event search, grazes,
sliding, exits and their rounding bands -- up to its first switch, and decides it there
(cross, slide, leave the slide); this module takes the decision into the next stay's
view, keeping H the same function near the surface (the orientation ``s``), and keeps
what spans the whole run: the switches against max_events and the Zeno ring
(:mod:`filippov.loop.run_state`), the steps against max_steps, the sections' hits, and
one trajectory whose modes are the run's codes (:func:`~filippov.surfaces.mode_of`).

Where the next stay is not a one-surface problem the run is refused by name
(:class:`~filippov.errors.SurfacesError`): a start or an event at two surfaces at once
(a corner) unless every field there crosses them all
(:func:`filippov.rules.through_corner`: then straight through); a slide on one surface
that reaches another, unless it slides on across it
(:func:`filippov.rules.slide_crosses`).
"""
from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np

from . import checks, intersection, rules
from . import scale as scale_mod
from .errors import SurfacesError, accumulation_detail, run_error
from .loop.run_state import RING, Limits, count_switch, new_run_state
from .loop.status import GO_ON, ZENO
from .section import Section, hit_within, tied_hits
from .surfaces import SurfacesSystem, flip, mode_name, mode_of, regions
from .system import PLUS, SLIDING

#: the sections a slide's stay watches the other surfaces with, and a slide on an
#: intersection its ends (alpha or beta at 0 or 1: filippov.intersection) -- never a
#: user's name
_SURFACE, _END = "\x00surface ", "\x00end "


class Stay(NamedTuple):
    """Where a stay is: region ``sigma``, the surface slid on (-1: none), the side of H
    the region is on in its view (``s``), what the stay begins with (None: the run's
    start decides; else its mode in the view, shift, banded shift and band), the
    second surface of an intersection slid on (``pair``; -1: none), and the surface a
    slide left as it began at an intersection's end with the rounding band the guard
    allows it on the stay's first segment (``left``: rules.left_band; -1: none)."""
    sigma: tuple
    slide: int
    s: int
    begun: tuple | None
    pair: int = -1
    left: tuple = (-1, 0.0)


def check_surfaces(system: SurfacesSystem, z: np.ndarray, floor: float) -> None:
    """The several-surface pieces' shapes on a batch next to z, and each region's field
    (one region's view is checked as a one-surface system by the engine's checks)."""
    zs = checks.probe_states(z, system.dim + 2, floor)
    system.values(z), system.values(zs), system.grads(z), system.grads(zs)
    for sigma in regions(system.m):
        for zz in (z, zs):
            f = np.asarray(system.region_field(sigma, zz), dtype=float)
            if f.shape != zz.shape:
                raise ValueError(f"field: region {sigma} returned shape {f.shape} for a "
                                 f"state of shape {zz.shape}")


def run(system: SurfacesSystem, z: np.ndarray, sections: list, opts: dict, one_stay,
        start_mode):
    """The run of :func:`filippov.simulate.simulate` on ``system`` from z (``opts``: its
    options by name): one trajectory, or the error that stopped it. The engine's
    ``one_stay`` (:func:`filippov.simulate.one_stay`) and ``start_mode``
    (:func:`filippov.simulate.initial_mode`)."""
    sigma = system.region(z)
    first = system.view(sigma, 1)
    sc = scale_mod.of_system(first, z, opts.get("scale"))
    given, system = system, _in_one_unit(system, sigma, z, opts.get("scale"), sc.switch)
    first = system.view(sigma, 1)
    check_surfaces(system, z, sc.state)
    for k in range(system.m):  # each surface's pieces, its gradient among them
        checks.check_system(system.view(sigma, 1, k), z, method="integrate",
                            floor=sc.state)
    o = scale_mod.tolerances(opts, sc, np.asarray(z).size)
    _refuse_corner_start(system, z, sigma, o)
    # a start on a surface (|h| <= touch_tol) is on its + side, as for one surface (where
    # the rules' ties, a repelling start among them, take region +): the first view is
    # oriented so that its + side is h >= 0 there, whatever sign rounding gave h
    h = system.values(z)
    sigma = tuple(1 if abs(h[k]) <= o["touch_tol"] else sigma[k] for k in range(system.m))
    first = system.view(sigma, 1)
    rs = new_run_state(Limits(o["t_end"], system.sliding, o["max_events"], o["zeno_count"],
                              o["zeno_span"], o["touch_tol"], o["state_scale"],
                              o["time_scale"], True, len(sections), o["max_steps"],
                              o["rtol"]))
    stay, t, z, traj, hits = (_first_stay(system, sigma, first, z, o, start_mode), o["t0"], z,
                              None, [0] * len(sections))
    while True:
        view = (system.intersection_view(stay.sigma, stay.slide, stay.pair)
                if stay.pair >= 0 else
                system.view(stay.sigma, stay.s, None if stay.slide < 0 else stay.slide))
        steps = 0 if traj is None else traj.n_steps
        mine = _stay_sections(system, stay, sections, hits, t - o["t0"])
        own = len(mine) - len(sections)   # the stay's own sections come first
        # the user's sections hit where the last stay ended: no second hit at this start
        starts = None if traj is None else {
            own + k for k, sec in enumerate(sections) for e in traj.events
            if e.kind == "section" and e.name == sec.name and e.t == t} | set(range(own))
        how, r = _guarded_stay(system, stay, one_stay, view, z, mine, starts, sc,
                               dict(o, t0=t, max_steps=max(o["max_steps"] - steps, 1),
                                    dense=True))
        surface = _event_surface(system, stay, r.z)
        traj = _merge(traj, r.traj, given, stay, surface, opts["dense"])
        t, z = r.t, r.z
        for k in range(len(sections)):
            hits[k] += r.hits[own + k]
        if how == "t_end":
            return _end(traj, "t_end", t, z, stay, surface, system)
        if how == "section":
            sec = mine[r.hit_section]
            if sec.name.startswith((_SURFACE, _END)):  # a slide reaches a surface, or ends
                if stay.pair >= 0 and sec.name.startswith(_SURFACE):
                    raise _intersection_meets(system, stay, int(sec.name[len(_SURFACE):]),
                                              t, z)
                done = _tied_hits(sections, hits, stay, r, o, traj)
                if done is not None:
                    return _end(traj, f"section:{done}", t, z, stay, surface, system)
                stay = (_slide_across(system, stay, int(sec.name[len(_SURFACE):]), t, z,
                                      traj, o) if sec.name.startswith(_SURFACE) else
                        _intersection_end(system, stay, sec.name[len(_END):], t, z, traj, o))
                status = count_switch(rs, t, True)
                if status != GO_ON:
                    raise _budget_error(status, rs, o, t, z)
                continue
            return _end(traj, f"section:{sec.name}", t, z, stay, surface, system)
        stay = _next_stay(system, stay, surface, r, o, traj)
        status = count_switch(rs, t, True)
        if status != GO_ON:
            raise _budget_error(status, rs, o, t, z)


def _in_one_unit(system, sigma, z, value, unit):
    """``system`` with each h_k (and its gradient) in the run's one unit of H, ``unit``:
    where the switch scale is measured (not declared by the run or the system), each
    surface's is measured on its own (filippov.scale, a power of two) and h_k multiplied
    by unit / its own -- exactly, a power of two -- so that touch_tol, the corner and
    hidden-crossing tests and the views' min hold every surface to its own size, not to
    the one nearest the start."""
    parts = scale_mod.declared(system.scale if value is None else value)
    if isinstance(parts, scale_mod.Scale) or "switch" in parts:
        return system
    own = np.array([scale_mod.of_system(system.view(sigma, 1, k), z, value).switch
                    for k in range(system.m)])
    c = unit / own
    if np.all(c == 1.0):
        return system

    def column(z):
        return c.reshape((-1,) + (1,) * (np.ndim(z) - 1))
    return dataclasses.replace(system, switches=lambda z: column(z) * system.switches(z),
                               switch_grads=lambda z: column(z)[:, None] * system.switch_grads(z)
                               if np.ndim(z) > 1 else c[:, None] * system.switch_grads(z))


def _first_stay(system, sigma, first, z, o, start_mode) -> Stay:
    """The run's first stay: in the start's region, or -- a start on its nearest surface
    a, decided by the engine's start on the region's view -- sliding on a (the slide's
    own view: a region's view measures H on whichever surface is nearest, and a slide
    must stay on its own), or across it. The stay's own start decides again, from the
    same pieces."""
    mode, _ = start_mode(first, z, o["touch_tol"])
    a = _event_surface(system, Stay(sigma, -1, 1, None), z)
    if mode == SLIDING:
        return Stay(sigma, a, 1, None)
    if mode != 1:
        return Stay(flip(sigma, a), -1, -1, None)
    return Stay(sigma, -1, 1, None)


def _stay_sections(system, stay, sections, hits, elapsed):
    """The stay's own sections -- while sliding on k the other surfaces, terminal at their
    first crossing; on an intersection its ends -- first, so that they win a tie with a
    user's section crossed at the same instant (the engine takes the first of sections
    that cross at one time; a user's is then counted by the next stay, just after its
    start); then the user's sections as a stay that begins ``elapsed`` after the run sees
    them (min_time counted from the run's start, terminal hits from the run's)."""
    out = []
    if stay.slide >= 0:
        for j in range(system.m):
            if j != stay.slide and j != stay.pair:
                out.append(Section(f"{_SURFACE}{j}", _oriented(system, stay.sigma, j),
                                   direction=-1, terminal=1))
    if stay.pair >= 0:
        for name, func in _ends(system, stay).items():
            out.append(Section(f"{_END}{name}", func, direction=-1, terminal=1))
    for sec, n in zip(sections, hits):
        out.append(dataclasses.replace(
            sec, min_time=max(sec.min_time - elapsed, 0.0),
            terminal=None if sec.terminal is None else sec.terminal - n))
    return out


def _tied_hits(sections, hits, stay, r, o, traj):
    """The user's sections crossed at the instant a stay ended at one of its own (which
    win the engine's tie; :func:`filippov.section.tied_hits` on the stay's dense output),
    each a hit there, logged before the switch -- not one logged there already (the
    stay's engine logs those its own hit ties with); the name of the first terminal one
    whose hits are reached (the run ends there), else None."""
    _, te, _, Z = r.traj.segments[-1]
    z = np.asarray(r.z, dtype=float)
    mode = _code(stay, stay.slide, 1 if stay.pair >= 0 else SLIDING)
    logged = hit_within(sections, traj.events, te, o["event_xtol"])
    for k in tied_hits(sections, -1, te, z, Z, o["t0"], o["event_xtol"], skip=logged):
        hits[k] += 1
        traj.events.append(type(traj.events[0])(te, "section", z.copy(), mode, mode,
                                                sections[k].name))
    # the first whose hits are reached: tied here, or by the stay's own engine
    return next((sec.name for sec, n in zip(sections, hits)
                 if sec.terminal is not None and n >= sec.terminal), None)


def _ends(system, stay):
    """The ends of a slide on the intersection of h_j and h_k (j = stay.slide, k =
    stay.pair): alpha (h_j's + side's weight) or beta (h_k's) reaching 0 or 1."""
    j, k, sigma = stay.slide, stay.pair, stay.sigma

    def weight(z, i, one):
        zs = np.asarray(z, dtype=float)
        cols = zs[:, None] if zs.ndim == 1 else zs
        w = np.array([intersection.weights(system, sigma, j, k, cols[:, c])[i]
                      for c in range(cols.shape[1])])
        w = 1.0 - w if one else w
        return w[0] if zs.ndim == 1 else w
    return {"a0": lambda z: weight(z, 0, False), "a1": lambda z: weight(z, 0, True),
            "b0": lambda z: weight(z, 1, False), "b1": lambda z: weight(z, 1, True)}


def _oriented(system, sigma, j):
    """sigma_j h_j, >= 0 on region sigma's side of surface j."""
    return lambda z: sigma[j] * system.values(z)[j]


def _event_surface(system, stay, z):
    """The surface a stay's switch is at: the one slid on, or the region's nearest."""
    if stay.slide >= 0:
        return stay.slide
    g = np.asarray(stay.sigma, float) * system.values(np.asarray(z, float))
    return int(np.argmin(g))


def _code(stay, surface, local):
    """A mode of a stay's view (``local``: its side s, the other side, or SLIDING) as
    the run's code."""
    if stay.pair >= 0:
        digits = list(stay.sigma)
        digits[stay.slide] = digits[stay.pair] = 0
        return mode_of(digits)
    if local == SLIDING:
        digits = list(stay.sigma)
        digits[surface] = 0
        return mode_of(digits)
    return mode_of(stay.sigma if local == stay.s else flip(stay.sigma, surface))


#: sample intervals per stored segment at which every other surface is checked after a
#: stay (:func:`_refuse_hidden_crossing`): twice the engine's own (samples_per_step = 4)
GUARD_SAMPLES = 8


#: how many times a stay is run again with shorter steps where the guard found a surface
#: crossed between the engine's samples, and the most steps those runs may take together:
#: GUARD_WORK times the first run's, or GUARD_FLOOR (:func:`_guarded_stay`)
GUARD_RETRIES, GUARD_WORK, GUARD_FLOOR = 4, 64, 20_000


def _guarded_stay(system, stay, one_stay, view, z, sections, starts, sc, o):
    """The engine's run of one stay, checked by :func:`_hidden_crossing`: where a surface
    was crossed between its samples, the stay is run again from its start with steps
    no longer than the guard's sample interval there (the engine then samples it four
    times finer than the guard did), GUARD_RETRIES times at most and within GUARD_WORK
    times the first run's steps (each run's steps out of the stay's one budget); then
    refused by name -- a bounded cost, never a run that only seems to hang."""
    first, spent = None, 0
    for _ in range(GUARD_RETRIES + 1):
        how, r = one_stay(view, z, sections, o, sc, stay.begun, starts)
        found = _hidden_crossing(system, stay, r.traj.segments, o)
        if found is None:
            return how, r
        j, tm, zm, span = found
        steps = max(r.traj.n_steps, 1)
        first, spent = first or steps, spent + steps
        ahead = steps * max(1.0, o["max_step"] / (span / GUARD_SAMPLES) if np.isfinite(
            o["max_step"]) else GUARD_SAMPLES)
        if spent + ahead > max(GUARD_WORK * first, GUARD_FLOOR):
            break
        o = dict(o, max_step=min(o["max_step"], span / GUARD_SAMPLES),
                 max_steps=max(o["max_steps"] - steps, 1))
    raise _hidden(system, stay, j, tm, zm)


def _hidden_crossing(system, stay, segments, o):
    """The view of a stay measures only the nearest surface (or the one slid on, the
    others at their samples as sections): a surface that another one's values hid --
    crossed and crossed back between samples, or where the nearest one's rate showed no
    extremum -- would be a silent wrong orbit. Each other surface is asked, on the
    stay's dense output, what the one-surface engine asks of its H: a sign change at a
    sample before the stay's event, or an extremum between samples toward it
    (rules.extremum_between, rules.graze) whose value crosses. The first found: (the
    surface, the time and state, the length of the segment it is in), or None."""
    sig = np.asarray(stay.sigma, dtype=float)[:, None]
    for n, (ta, tb, _, Z) in enumerate(segments):
        ts = np.linspace(ta, tb, GUARD_SAMPLES + 1)
        zs = np.asarray(Z(ts), dtype=float)
        f = np.asarray(view_field(system, stay, zs), dtype=float)
        g = sig * system.values(zs)
        rate = sig * np.einsum("knb,nb->kb", system.grads(zs), f)
        # the surface the stay began on measures from the exit's rounding band (the
        # engine's, rules.graze: a dip inside it is the exit's own tangency); the event
        # at the stay's end, its own
        band = stay.begun[3] if stay.begun is not None and n == 0 else 0.0
        entry = int(np.argmin(g[:, 0])) if stay.slide < 0 else -1
        at_end = ts >= segments[-1][1] - 4.0 * o["event_xtol"]
        if stay.pair >= 0 and system.intersection != "bilinear":
            for i in np.flatnonzero(~at_end):   # the choice settled at the entry, along
                _choice_settled(system, stay.sigma, stay.slide, stay.pair, ts[i], zs[:, i],
                                extend=True)
        for j in range(system.m):
            if j == stay.slide or j == stay.pair:
                continue
            tol = o["touch_tol"] + (band if j == entry else 0.0) + (
                stay.left[1] if n == 0 and j == stay.left[0] else 0.0)
            low = (g[j] < -tol) & ~at_end
            if np.any(low):
                i = int(np.flatnonzero(low)[0])
                return j, ts[i], zs[:, i], tb - ta
            dips = rules.extremum_between(PLUS, rate[j, :-1], rate[j, 1:]) & ~at_end[:-1]
            for i in np.flatnonzero(dips):
                tm, gm = _minimum(system, stay, j, Z, ts[i], ts[i + 1])
                if rules.graze(PLUS, gm, tol) == rules.GRAZE_CROSSES and not (
                        tm >= segments[-1][1] - 4.0 * o["event_xtol"]):
                    return j, tm, Z(tm), tb - ta
    return None


def view_field(system, stay, zs):
    """The field of a stay: its region's, or the sliding field on its surface (or on its
    intersection)."""
    if stay.pair >= 0:
        return intersection.bilinear_field(system, stay.sigma, stay.slide, stay.pair, zs)
    if stay.slide < 0:
        return system.region_field(stay.sigma, zs)
    return system.view(stay.sigma, stay.s, stay.slide).sliding_field(zs)


def _minimum(system, stay, j, Z, lo, hi):
    """(t, value) of the minimum of sigma_j h_j along Z in [lo, hi], whose rate changes
    sign there from - to +: the lowest of a bounded minimisation (to a thousandth of
    [lo, hi]: it finds the deepest of several dips) and the roots of the rate (brentq, to
    the rounding of t) over [lo, hi] and about the minimisation's point -- a dip as
    narrow as its depth allows is seen below 0 there (the minimisation alone stopped up
    to 1e-4 from a dip 3e-5 wide, and a crossing of it was passed silently; the rate's
    root alone can be a shallow minimum beside a deep dip)."""
    from scipy.optimize import brentq, minimize_scalar

    def state(t):
        return np.asarray(Z(t), dtype=float).reshape(-1)

    def rate(t):
        z = state(t)
        f = np.asarray(view_field(system, stay, z), dtype=float).reshape(-1)
        return float(stay.sigma[j] * system.grads(z)[j] @ f)

    def g(t):
        return float(stay.sigma[j] * system.values(state(t))[j])
    res = minimize_scalar(g, bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-3 * (hi - lo)})
    found = [(float(res.x), float(res.fun))]
    near = 2e-3 * (hi - lo)
    eps = np.finfo(float).eps
    for a, b in ((lo, hi), (max(lo, res.x - near), min(hi, res.x + near))):
        ra, rb = rate(a), rate(b)
        if ra <= 0.0 <= rb:   # bracketed (a rate not finite inside: brentq refuses)
            try:
                tm = brentq(rate, a, b, xtol=4.0 * eps * max(abs(a), abs(b)), rtol=4.0 * eps)
            except ValueError:
                continue
            found.append((float(tm), g(tm)))
    return min(found, key=lambda tg: tg[1])


def _hidden(system, stay, j, t, z):
    mode = _code(stay, max(stay.slide, 0), stay.s if stay.slide < 0 else SLIDING)
    return SurfacesError(
        f"hidden crossing at t={float(t)!r}, state {np.asarray(z, float).reshape(-1).tolist()}:"
        f" h{j + 1} is crossed there while the stay in mode {mode_name(mode, system.m)}"
        " followed another surface nearer, and runs of the stay with ever shorter steps "
        f"(at most {GUARD_RETRIES}, {GUARD_WORK} times its steps) did not resolve it (a "
        "tangency of the two?)")


def _merge(traj, sub, system, stay, surface, dense=True):
    """The stay's trajectory appended to the run's, its modes as the run's codes."""
    events = [dataclasses.replace(e, mode_before=_code(stay, surface, e.mode_before),
                                  mode_after=_code(stay, surface, e.mode_after))
              for e in sub.events if not e.name.startswith((_SURFACE, _END))]
    segments = [(ta, tb, _code(stay, surface, mode), Z) for ta, tb, mode, Z in sub.segments
                if dense]
    here = mode_name(_code(stay, surface, stay.s if stay.slide < 0 else SLIDING), system.m)
    if traj is None:
        traj = dataclasses.replace(sub, system=system, events=[], segments=[], n_steps=0,
                                   n_windows=0, integrated_modes=set(), stiff_modes=set(),
                                   atol_raised={})
    traj.events += events
    traj.segments += segments
    traj.n_steps += sub.n_steps
    traj.n_windows += sub.n_windows
    if sub.integrated_modes:
        traj.integrated_modes.add(here)
    if sub.stiff_modes:
        traj.stiff_modes.add(here)
    for v in sub.atol_raised.values():
        traj.atol_raised[here] = max(traj.atol_raised.get(here, 0.0), v)
    return traj


def _end(traj, status, t, z, stay, surface, system):
    local = stay.s if stay.slide < 0 else SLIDING
    traj.status, traj.t, traj.z = status, t, np.array(z, dtype=float)
    traj.mode = _code(stay, surface, local)
    return traj


def _next_stay(system, stay, a, r, o, traj) -> Stay:
    """The stay after the switch the last one ended at, on surface a: its view's mode
    is the engine's decision (``r.mode``), and with it the shift and band it begins with."""
    begun = (r.mode, r.shift, r.banded, r.band)
    sigma, s = stay.sigma, stay.s
    if stay.slide >= 0:  # the slide's end: into its region, or across the surface
        if r.mode == s:
            return Stay(sigma, -1, s, begun)
        return Stay(flip(sigma, a), -1, -s, begun)
    corner = _corner(system, sigma, a, r.z, o)
    if corner:
        return _through(system, stay, [a] + corner, r, traj, o)
    if r.mode == SLIDING:
        return Stay(sigma, a, s, begun)
    return Stay(flip(sigma, a), -1, -s, begun)


def _corner(system, sigma, a, z, o, f=None):
    """The other surfaces the event on surface a is also at (rules.at_corner), the orbit
    moving along ``f`` (default: region sigma's field)."""
    z = np.asarray(z, dtype=float)
    h, G = system.values(z), system.grads(z)
    f = np.asarray(system.region_field(sigma, z) if f is None else f, dtype=float)
    return [j for j in range(system.m) if j != a and rules.at_corner(
        sigma[j] * h[j], sigma[j] * float(G[j] @ f), o["event_xtol"], o["touch_tol"])]


def _through(system, stay, at, r, traj, o) -> Stay:
    """A corner of the surfaces ``at``: straight through where rules.through_corner
    says so (the switch logged as a "corner" into the region across them all), else
    refused by name. The event's state is on the far side of the surface it was found
    on; another one it is at may be short of it by what rules.at_corner takes: the next
    stay measures H from there (rules.exit_shift), not a crossing back at once (which
    refused a corner passed 1e-15 from its point as one reached from the far region,
    or slid there for no time)."""
    z = np.asarray(r.z, dtype=float)
    G = system.grads(z)
    regions = _around(stay.sigma, at)
    speeds = np.array([[stay.sigma[k] * float(G[k] @ np.asarray(system.region_field(q, z),
                                                                  dtype=float))
                        for k in at] for q in regions])
    names = ", ".join(f"h{k + 1}" for k in sorted(at))
    if not rules.through_corner(speeds.ravel()):
        raise SurfacesError(
            f"corner at t={float(r.t)!r}, state {z.tolist()}: the orbit reaches {names} at once "
            f"from region {mode_name(mode_of(stay.sigma), system.m)}, and the fields there "
            "do not all cross them (normal speeds, a row per region meeting there: "
            f"{speeds.tolist()}); a corner where sliding or a choice of region may follow "
            "is not settled by filippov (rules.through_corner)")
    sigma = stay.sigma
    for k in at:
        sigma = flip(sigma, k)
    last = traj.events[-1]
    traj.events[-1] = dataclasses.replace(last, kind="corner", mode_after=mode_of(sigma),
                                          name=names)
    # a corner surface a rounding short of the state (within touch_tol): the next stay
    # measures H from there; farther short (rules.at_corner takes up to a few event
    # tolerances' worth of its rate), the view's H would read it as a switch at once --
    # a slide for no time, or a failed one: refused by name
    s = -stay.s
    short = float(np.min(np.asarray(sigma, dtype=float) * system.values(z)))
    if short < -o["touch_tol"]:
        raise SurfacesError(
            f"corner at t={float(r.t)!r}, state {z.tolist()}: the orbit passes {names} "
            f"at once from region {mode_name(mode_of(stay.sigma), system.m)}, but the "
            f"event's state is {-short!r} short of one of them (more than touch_tol "
            f"{o['touch_tol']!r}): where the passage lands is not settled (rules.at_corner)")
    shift = rules.exit_shift(s, s * short, o["touch_tol"], False)
    return Stay(sigma, -1, s, (s, shift, shift, 0.0))


def _refuse_corner_start(system, z, sigma, o):
    g = np.asarray(sigma, float) * system.values(z)
    on = [k for k in range(system.m) if abs(g[k]) <= o["touch_tol"]]
    if len(on) > 1:
        raise SurfacesError(
            f"start at a corner: state {z.tolist()} is on "
            f"{', '.join(f'h{k + 1}' for k in on)} at once (|h| <= touch_tol); start "
            "off the corner, or on one surface")


def _slide_across(system, stay, j, t, z, traj, o) -> Stay:
    """A slide on k at surface j: on across it where rules.slide_crosses says so (a
    "crossing" of h_j logged while sliding), else refused by name."""
    k, s, z = stay.slide, stay.s, np.asarray(z, dtype=float)
    slide = system.view(stay.sigma, s, k).sliding_field(z)
    at = [i for i in _corner(system, stay.sigma, j, z, o, slide) if i != k]
    if at:
        raise SurfacesError(
            f"corner at t={float(t)!r}, state {z.tolist()}: the slide on h{k + 1} reaches "
            f"{', '.join(f'h{i + 1}' for i in sorted([j] + at))} at once; a slide into a "
            "corner is not settled by filippov")
    far = flip(stay.sigma, j)
    near_view, far_view = (system.view(q, s, k) for q in (stay.sigma, far))
    a_far, b_far = (float(v) for v in far_view.normal_speeds(z))
    normal = stay.sigma[j] * system.grads(z)[j]
    v_near, v_far = (float(normal @ np.asarray(v.sliding_field(z), dtype=float))
                     for v in (near_view, far_view))
    if rules.slides_into_intersection(v_near, v_far):
        return _intersection_start(system, stay, j, t, z, traj)
    if not rules.slide_crosses(a_far, b_far, v_near, v_far):
        raise _slide_meets(system, stay, j, t, z)
    before, after = (mode_of(q[:k] + (0,) + q[k + 1:]) for q in (stay.sigma, far))
    traj.events.append(type(traj.events[0])(t, "crossing", z.copy(), before, after,
                                            f"h{j + 1}"))
    return Stay(far, k, s, (SLIDING, 0.0, 0.0, 0.0))


def _slide_meets(system, stay, j, t, z):
    return SurfacesError(
        f"intersection at t={float(t)!r}, state {np.asarray(z, float).tolist()}: the slide on "
        f"h{stay.slide + 1} (mode {mode_name(_code(stay, stay.slide, SLIDING), system.m)}) "
        f"reaches h{j + 1}, where it neither crosses (rules.slide_crosses) nor slides on "
        "the intersection (rules.slides_into_intersection): it leaves the surface there, "
        "which filippov does not follow")


def _intersection_meets(system, stay, i, t, z):
    return SurfacesError(
        f"intersection at t={float(t)!r}, state {np.asarray(z, float).tolist()}: the slide on the "
        f"intersection of h{min(stay.slide, stay.pair) + 1} and "
        f"h{max(stay.slide, stay.pair) + 1} reaches h{i + 1}; what follows there (a slide on "
        "the intersection across it, or on three surfaces) is not built into filippov")


def _intersection_start(system, stay, j, t, z, traj) -> Stay:
    """A slide on k that reaches surface j, where the slides on either side of j push
    toward it: on along the intersection, with the bilinear field where the system
    settles the choice (:func:`_choice_settled`) or declares it, else refused by name."""
    k = stay.slide
    _choice_settled(system, stay.sigma, j, k, t, z)
    inner = Stay(stay.sigma, j, stay.s, (1, 0.0, 0.0, 0.0), pair=k)
    before = _code(stay, k, SLIDING)
    traj.events.append(type(traj.events[0])(t, "slide_start", np.asarray(z, float).copy(),
                                            before, _code(inner, j, 1), f"h{j + 1}"))
    return inner


def _choice_settled(system, sigma, j, k, t, z, extend=False):
    """Refuse a slide on the intersection of h_j and h_k at z unless the bilinear field
    exists there and either agrees with both nested choices (rules.choices_agree: the
    system settles the field) or the system takes it (``intersection="bilinear"``).
    ``extend``: along the slide, its weights continued a hair past the square (the
    samples at its end)."""
    z = np.asarray(z, dtype=float)
    fb = intersection.bilinear_field(system, sigma, j, k, z, extend=extend)
    names = f"h{min(j, k) + 1} and h{max(j, k) + 1}"
    if not np.all(np.isfinite(fb)):
        raise SurfacesError(
            f"intersection at t={float(t)!r}, state {z.tolist()}: no bilinear sliding field on "
            f"{names} there (filippov.intersection: the intersection does not attract)")
    nested = [intersection.nested_field(system, sigma, a, b, z) for a, b in ((j, k), (k, j))]
    spread = max(float(np.abs(fb - f).max()) for f in nested)
    if system.intersection != "bilinear" and not rules.choices_agree(
            spread, float(np.abs(fb).max())):
        raise SurfacesError(
            f"intersection at t={float(t)!r}, state {z.tolist()}: the sliding field on {names} "
            f"depends on the choice there (bilinear {fb.tolist()}, nested "
            f"{[f.tolist() for f in nested]}): the system does not settle it; declare "
            "SurfacesSystem(..., intersection='bilinear') to take Dieci and Lopez's "
            "bilinear field (filippov.intersection)")


def _intersection_end(system, stay, end, t, z, traj, o) -> Stay:
    """The end of a slide on an intersection: alpha or beta at 0 or 1 (``end``), the
    slide going on on the other surface, on the side the weight left; refused by name
    where that slide does not attract. The surface left may lie a rounding behind the
    state, which the slide on the intersection kept from its start: the guard allows it
    that much at the next stay's start (rules.left_band), and refuses by name where it
    is more."""
    j, k = stay.slide, stay.pair
    gone, keep = (j, k) if end[0] == "a" else (k, j)
    side = 1 if end[1] == "1" else -1
    sigma = list(stay.sigma)
    sigma[gone], sigma[keep] = side, 1
    sigma, zf = tuple(sigma), np.asarray(z, dtype=float)
    a, b = (float(v) for v in system.view(sigma, 1, keep).normal_speeds(zf))
    if not a > 0.0 > b:
        raise SurfacesError(
            f"intersection end at t={float(t)!r}, state {zf.tolist()}: the slide "
            f"on h{j + 1} and h{k + 1} ends toward h{gone + 1}'s {'+-'[side < 0]} side, where "
            f"the slide on h{keep + 1} does not attract (a = {a:.3g}, b = {b:.3g}); what "
            "follows is not built into filippov")
    normal = system.grads(zf)[gone]
    speed = max(abs(float(normal @ np.asarray(system.region_field(q, zf), dtype=float)))
                for q in _around(sigma, (gone, keep)))
    g = side * float(system.values(zf)[gone])   # oriented to the side the orbit leaves to
    band = rules.left_band(g, speed, o["event_xtol"], o["touch_tol"])
    if band != band:
        raise SurfacesError(
            f"intersection end at t={float(t)!r}, state {zf.tolist()}: the slide on h{j + 1} "
            f"and h{k + 1} ends toward h{gone + 1}'s {'+-'[side < 0]} side, but the state is "
            f"{-g!r} short of h{gone + 1}: more than the rounding an event leaves "
            "(rules.left_band)")
    after = Stay(sigma, keep, 1, (SLIDING, 0.0, 0.0, 0.0), left=(gone, band))
    traj.events.append(type(traj.events[0])(t, "slide_end", zf.copy(),
                                            _code(stay, j, 1), _code(after, keep, SLIDING),
                                            f"h{gone + 1}"))
    return after


def _around(sigma, surfaces):
    """The regions that meet where the surfaces given are all 0, near region sigma."""
    regions = [tuple(sigma)]
    for k in surfaces:
        regions += [flip(q, k) for q in regions]
    return regions


def _budget_error(status, rs, o, t, z):
    if status == ZENO:
        ratio, t_star = rules.geometric_accumulation(rs.ring, rs.count[RING], o["zeno_count"])
        detail = (accumulation_detail(ratio, t_star) if ratio == ratio else
                  f": {o['zeno_count']} switches within the Zeno span")
        return run_error(ZENO, t, z, detail)
    return run_error(status, t, z, f": event limit {o['max_events']} hit (rapid switching "
                                   "between the surfaces)")
