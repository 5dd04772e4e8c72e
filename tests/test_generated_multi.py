"""The closed-form orbits of tests/generated_multi.py (several switching surfaces, issue
59) against an independent recomputation: scipy's solve_ivp (DOP853, rtol 1e-12, atol
1e-14) on the region's field, stopped by an event per surface and one for the section,
started again in the region beyond (a surface crossed is not watched again: the draws'
h_k rise along the whole orbit). The crossings (which surface, in which order), their
times, the return point and time agree to TOL (1e-10: the integration's global error at
rtol 1e-12 over t <= 10 on O(1) states, with solve_ivp's events refined to machine
precision; measured over 15 draws, 2.0e-12 at most); dP/dz0 against central differences
of that recomputed return map (step 1e-5: truncation ~1e-10, the integration's error
divided by the step ~1e-7) to TOL_DP (1e-5 times the factors' norms)."""
import numpy as np
from hypothesis import given, settings
from scipy.integrate import solve_ivp

from generated_multi import multi_crossings

TOL = 1e-10
TOL_DP = 1e-5


def _integrated(g, z0):
    """(surfaces crossed, their times, the return point, its time) by solve_ivp."""
    z, t, sig = np.asarray(z0, dtype=float), 0.0, g.region(z0)
    crossed, times = [], []
    for _ in range(g.m + 1):
        side = g.fields[sig]
        events, watched = [], [k for k in range(g.m) if sig[k] < 0]
        for k in watched:   # a surface crossed is not crossed again (h_k rises: the draw)
            ev = (lambda tt, x, k=k: g.h(x)[k])
            ev.terminal, ev.direction = True, 1
            events.append(ev)
        sec = (lambda tt, x: g.s(x))
        sec.terminal, sec.direction = True, 1
        events.append(sec)
        sol = solve_ivp(lambda tt, x: side.f(x), (0.0, 20.0), z, method="DOP853",
                        rtol=1e-12, atol=1e-14, events=events)
        hits = [(ts[0], j) for j, ts in enumerate(sol.t_events) if ts.size]
        assert hits, "no event"
        tau, j = min(hits)
        z = sol.y_events[j][0]
        t += tau
        if j == len(watched):
            return crossed, times, z, t
        j = watched[j]
        crossed.append(j)
        times.append(t)
        sig = tuple(1 if i == j else s for i, s in enumerate(sig))
    raise AssertionError("more crossings than surfaces")


@settings(max_examples=6, deadline=None)
@given(case=multi_crossings())
def test_the_closed_form_orbit_is_the_integrated_one(case):
    crossed, times, P, time = _integrated(case.g, case.z0)
    assert crossed == case.surfaces
    assert np.max(np.abs(np.subtract(times, case.times)), initial=0.0) <= TOL
    assert np.max(np.abs(P - case.P)) <= TOL * max(1.0, np.abs(case.P).max())
    assert abs(time - case.time) <= TOL
    # every crossing state lies on its surface, every region is the one beyond
    for k, zc, sig in zip(case.surfaces, case.states, case.regions[1:]):
        assert abs(case.g.h(zc)[k]) <= 1e-12 and sig[k] == 1


@settings(max_examples=4, deadline=None)
@given(case=multi_crossings())
def test_the_closed_form_dpdz_is_the_integrated_map_s(case):
    n, step = case.g.n, 1e-5
    fd = np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = step
        up, down = (_integrated(case.g, case.z0 + sgn * e) for sgn in (1, -1))
        assert up[0] == down[0] == case.surfaces   # the same crossings either side
        fd[:, k] = (up[2] - down[2]) / (2 * step)
    assert np.max(np.abs(fd - case.dP)) <= TOL_DP * max(1.0, case.scale)


@settings(max_examples=6, deadline=None)
@given(case=multi_crossings(counts=(3,)))
def test_the_draws_cross_several_surfaces(case):
    """The generator is worth its name: with three surfaces, at least two are crossed
    (before the section); the others lie beyond it."""
    assert len(case.surfaces) >= 2, case.surfaces
