"""Sections on the switching surface, and start points on a section, on both engines.

Two ways a return map could come out silently wrong:

* a section on H (the same zero set as the switch function): the switch event at
  the same root used to win, the mode restarted past the root, and the section
  was never hit;
* a start point on its section up to rounding: the run used to "return" at
  t ~ 1e-17 with P(z) = z.
"""
import dataclasses

import numpy as np
import pytest

from filippov import MINUS, PLUS, PiecewiseSystem, Section, SimulationError, fastmap, simulate
from filippov.models import hopf
from filippov.poincare import first_returns
from filippov_paper.scenes.fig04_retmaps import section_L1

# --------------------------------------------------------------------------- a planar crossing
# Region + (x1 >= 0) turns about the origin, region - about (-C, 0); both fields
# have x1' = -x2 on H = {x1 = 0}, so every orbit crosses H transversally. From
# (0.5, 0) the orbit reaches H at (0, 0.5) at t = pi/2 (x1 decreasing), turns
# 3 pi/2 about (-C, 0) to (0, -0.5) at t = 2 pi (x1 increasing), and is back at
# (0.5, 0) after the period 5 pi/2.
C = 0.5
PERIOD = 2.5 * np.pi


def _rotation(c):
    def field(z):
        return np.stack([-z[1], z[0] + c])

    def flow(z0, tau):
        tau = np.asarray(tau, dtype=float)
        u, v = z0[0] + c, z0[1]
        return np.stack([np.cos(tau) * u - np.sin(tau) * v - c, np.sin(tau) * u + np.cos(tau) * v])

    return field, flow


def two_centres():
    fp, flow_p = _rotation(0.0)
    fm, flow_m = _rotation(C)
    return PiecewiseSystem(
        names=("x1", "x2"), field_minus=fm, field_plus=fp, switch=lambda z: z[0],
        switch_grad=lambda z: np.stack([np.ones_like(z[0]), np.zeros_like(z[1])]),
        flows={PLUS: flow_p, MINUS: flow_m}, sample_step=0.05)


# the same zero set as H: H itself, and a function that is not a multiple of it
ON_H = {"H": lambda z: z[0], "2H+H^3": lambda z: 2 * z[0] + z[0] ** 3}


@pytest.mark.parametrize("func", ON_H.values(), ids=ON_H.keys())
@pytest.mark.parametrize("direction,t_hit,x2_hit", [(-1, np.pi / 2, 0.5), (0, np.pi / 2, 0.5),
                                                    (+1, 2 * np.pi, -0.5)])
def test_section_on_the_switching_surface_is_hit_at_the_crossing(func, direction, t_hit,
                                                                  x2_hit):
    system = two_centres()
    sec = Section("H", func, direction=direction, terminal=1)
    traj = simulate(system, [0.5, 0.0], 10.0, sections=[sec])
    assert traj.status == "section:H"
    hit = traj.events[-1]
    assert hit.kind == "section" and hit.t == pytest.approx(t_hit, abs=1e-12)
    np.testing.assert_allclose(hit.state, [0.0, x2_hit], rtol=0, atol=1e-12)
    ret = first_returns(system, [[0.5, 0.0]], sec, 10.0)
    assert ret.time[0] == pytest.approx(t_hit, abs=1e-12)
    np.testing.assert_allclose(ret.state[0], [0.0, x2_hit], rtol=0, atol=1e-12)


def test_section_on_the_switching_surface_logs_every_crossing_and_still_switches():
    system = two_centres()
    sec = Section("H", lambda z: z[0])
    traj = simulate(system, [0.5, 0.0], 2 * PERIOD - 0.1, sections=[sec], max_steps=20_000)
    hits = traj.section_hits("H")
    expected = np.array([np.pi / 2, 2 * np.pi, np.pi / 2 + PERIOD, 2 * np.pi + PERIOD])
    np.testing.assert_allclose([e.t for e in hits], expected, rtol=0, atol=1e-11)
    switches = traj.switches()
    assert [e.kind for e in switches] == ["crossing"] * 4
    np.testing.assert_allclose([e.t for e in switches], expected, rtol=0, atol=1e-11)
    # each hit is logged at its crossing, before it
    kinds = [e.kind for e in traj.events[1:]]
    assert kinds == ["section", "crossing"] * 4
    # and the orbit is the same as without the section
    plain = simulate(system, [0.5, 0.0], 2 * PERIOD - 0.1)
    np.testing.assert_allclose(traj.z, plain.z, rtol=0, atol=1e-12)


def test_a_two_way_section_is_left_behind_after_each_hit():
    """direction 0, not terminal: each hit is stepped to the far side of its crossing,
    so the restart does not find it again (the run used to stick at the first hit
    that rounding left on the near side, until the step limit)."""
    sec = Section("x2=0.1", lambda z: z[1] - 0.1)
    traj = simulate(two_centres(), [0.5, 0.0], 20.0, sections=[sec], max_steps=20_000)
    assert traj.status == "t_end"
    t = np.array([e.t for e in traj.section_hits("x2=0.1")])
    assert t.size == 6 and np.all(np.diff(t) > 0.1)
    np.testing.assert_allclose([e.state[1] for e in traj.section_hits("x2=0.1")], 0.1,
                               rtol=0, atol=1e-14)


# --------------------------------------------------------------------------- sliding on H
# F_+ = (-1, 1/2), F_- = (1, 1/2): all of H = {x1 = 0} is attracting sliding, with
# the Filippov field (0, 1/2). From (0.3, 0) the orbit reaches H at t = 0.3.
def sliding_system():
    const = lambda v: (lambda z: np.stack([np.full_like(z[0], v[0]), np.full_like(z[1], v[1])]))
    return PiecewiseSystem(
        names=("x1", "x2"), field_minus=const((1.0, 0.5)), field_plus=const((-1.0, 0.5)),
        switch=lambda z: z[0],
        switch_grad=lambda z: np.stack([np.ones_like(z[0]), np.zeros_like(z[1])]))


def test_section_on_H_is_hit_where_the_orbit_arrives_to_slide():
    sec = Section("H", lambda z: z[0], direction=-1, terminal=1)
    traj = simulate(sliding_system(), [0.3, 0.0], 5.0, sections=[sec])
    assert traj.status == "section:H"
    assert traj.t == pytest.approx(0.3, abs=1e-14)
    np.testing.assert_allclose(traj.z, [0.0, 0.15], rtol=0, atol=1e-14)


@pytest.mark.parametrize("z0,terminal", [([0.3, 0.0], None), ([0.3, 0.0], 2),
                                         ([0.0, 0.0], 1)])
def test_sliding_inside_a_section_on_H_is_refused(z0, terminal):
    """While the orbit slides along H, a section on H has no crossings, only
    rounding noise: continuing into sliding (or starting there) is an error."""
    sec = Section("onH", lambda z: 2 * z[0] + z[0] ** 3, terminal=terminal)
    with pytest.raises(SimulationError, match=r"slides.*section 'onH'"):
        simulate(sliding_system(), z0, 5.0, sections=[sec])


def test_a_section_transverse_to_the_sliding_flow_is_still_hit():
    sec = Section("x2=1", lambda z: z[1] - 1.0, direction=1, terminal=1)
    traj = simulate(sliding_system(), [0.3, 0.0], 5.0, sections=[sec])
    assert traj.status == "section:x2=1" and traj.mode == 0
    assert traj.t == pytest.approx(2.0, abs=1e-12)


# --------------------------------------------------------------------------- start on a section
SEC_X2 = Section("x2=0", lambda z: z[1], direction=1, where=lambda z: z[0] > 0, terminal=1)


@pytest.mark.parametrize("x2", [0.0, -5e-324, -0.5 * np.cos(np.pi / 2), -1e-16])
def test_start_on_the_section_up_to_rounding_is_not_a_return(x2):
    """(0.5, x2) with x2 one rounding error below the section: the first return is a
    full period later, as from the point exactly on it -- not P(z) = z at t ~ 1e-17."""
    ret = first_returns(two_centres(), [[0.5, x2]], SEC_X2, 10.0)
    assert ret.time[0] == pytest.approx(PERIOD, abs=1e-11)
    np.testing.assert_allclose(ret.state[0], [0.5, 0.0], rtol=0, atol=1e-11)


def test_start_on_a_section_on_H_up_to_rounding():
    """Both fixes at once: the start is a rounding error past H = x1 = 0, on the
    section; the crossing at once is no return, the next arrival is."""
    sec = Section("H", lambda z: z[0], direction=-1, terminal=1)
    # |x1| <= touch_tol starts in region - (both fields point there); 5e-15 in +,
    # where it switches at once
    for x1, n_switches in ((5e-15, 2), (1e-17, 1), (0.0, 1), (-1e-17, 1)):
        ret = first_returns(two_centres(), [[x1, 0.5]], sec, 10.0)
        assert ret.time[0] == pytest.approx(PERIOD, abs=1e-11)
        np.testing.assert_allclose(ret.state[0], [0.0, 0.5], rtol=0, atol=1e-11)
        assert ret.n_switches[0] == n_switches


def test_start_genuinely_before_the_section_still_hits_at_once():
    ret = first_returns(two_centres(), [[0.5, -1e-9]], SEC_X2, 10.0)
    assert ret.time[0] == pytest.approx(2e-9, rel=1e-6)
    np.testing.assert_allclose(ret.state[0], [0.5, 0.0], rtol=0, atol=1e-15)


def test_min_time_ignores_early_hits():
    sec = dataclasses.replace(SEC_X2, min_time=1.0, terminal=None)
    ret = first_returns(two_centres(), [[0.5, -1e-9]], sec, 10.0)
    assert ret.time[0] == pytest.approx(PERIOD, abs=1e-8)
    # the option survives first_returns' rebuilding of the section, and is checked
    for bad in (-1.0, np.nan, np.inf):
        with pytest.raises(ValueError, match="min_time"):
            Section("s", lambda z: z[0], min_time=bad)


# --------------------------------------------------------------------------- compiled engine
EPS, MU, OMEGA = 0.01, 1.0, 8 * np.pi
OPTS = {"rtol": 1e-12, "atol": 1e-14}
T_MAX = 4.0 * 2 * np.pi / OMEGA


@pytest.mark.parametrize("x1", [5e-324, 1e-17, 0.5 * np.cos(np.pi / 2)])
def test_compiled_start_on_the_section_up_to_rounding_is_not_a_return(x1):
    """L1 is x1 = 0 with x1 decreasing: a start at x1 = +rounding used to "return"
    at once; now it returns as the start exactly on L1 does, on both engines."""
    cm = hopf.compiled(EPS, -0.5, MU, OMEGA)
    z0 = [[x1, 1.02, 0.0]]
    exact = fastmap.compute_returns(cm, [[0.0, 1.02, 0.0]], T_MAX, **OPTS)
    out = fastmap.compute_returns(cm, z0, T_MAX, **OPTS)
    assert out.status[0] == fastmap.OK
    assert out.time[0] == pytest.approx(exact.time[0], abs=1e-13)
    np.testing.assert_allclose(out.state, exact.state, rtol=0, atol=1e-13)
    ref = first_returns(hopf.model(EPS, -0.5, MU, OMEGA).full(), z0, section_L1(), T_MAX,
                        **OPTS)
    np.testing.assert_allclose(ref.state, exact.state, rtol=0, atol=1e-11)


def test_compiled_min_time():
    cm = hopf.compiled(EPS, -0.5, MU, OMEGA)
    z0 = [[1e-9, 1.02, 1e-9]]  # genuinely before L1: the hit at once is a return
    at_once = fastmap.compute_returns(cm, z0, T_MAX, **OPTS)
    assert at_once.status[0] == fastmap.OK and 0 < at_once.time[0] < 1e-10
    later = fastmap.compute_returns(cm, z0, T_MAX, min_time=0.1, **OPTS)
    full = fastmap.compute_returns(cm, [[0.0, 1.02, 0.0]], T_MAX, **OPTS)
    assert later.status[0] == fastmap.OK
    assert later.time[0] == pytest.approx(full.time[0], abs=1e-8)
    with pytest.raises(ValueError, match="min_time"):
        fastmap.compute_returns(cm, z0, T_MAX, min_time=-1.0)


def _on_h(theta, direction):
    """The compiled Hopf model with its section moved onto the switching surface."""
    cm = hopf.compiled(EPS, theta, MU, OMEGA)
    return dataclasses.replace(cm, section=cm.switch, section_direction=direction)


X2 = np.array([1.005, 1.01, 1.0125, 1.0175, 1.02])


@pytest.mark.parametrize("theta,direction,n_switches", [(-0.5, -1, 0), (0.5, +1, 1)])
def test_compiled_section_on_the_switching_surface(theta, direction, n_switches):
    """From L1 the orbit first crosses H into region - (h decreasing); for theta > 0
    it comes back to slide (h increasing). The first arrival at H in the section's
    direction is the return, on both engines."""
    z0 = np.stack([0 * X2, X2, 0 * X2], axis=1)
    out = fastmap.first_returns_compiled(_on_h(theta, direction), z0, T_MAX, **OPTS)
    system = hopf.model(EPS, theta, MU, OMEGA).full()
    sec = Section("H", system.switch, direction=direction, where=lambda z: z[1] > 0,
                  terminal=1)
    ref = first_returns(system, z0, sec, T_MAX, **OPTS)
    assert np.all(out.n_switches == n_switches) and np.all(ref.n_switches == n_switches)
    assert np.all(np.abs(system.switch(out.state.T)) < 1e-13)
    assert np.all(out.time < 2 * np.pi / OMEGA)
    np.testing.assert_allclose(out.state, ref.state, rtol=0, atol=1e-11)
    np.testing.assert_allclose(out.time, ref.time, rtol=0, atol=1e-12)


@pytest.mark.parametrize("direction", [-1, 0, 1])
def test_compiled_start_sliding_inside_a_section_on_H_is_a_status(direction):
    system = hopf.model(EPS, 0.5, MU, OMEGA).full()
    events = simulate(system, [0.0, 1.02, 0.0], T_MAX, dense=False).events
    z0 = [next(e.state for e in events if e.kind == "slide_start")]  # on H, sliding
    out = fastmap.compute_returns(_on_h(0.5, direction), z0, T_MAX, **OPTS)
    assert out.status[0] == fastmap.SECTION_SLIDING
    with pytest.raises(SimulationError, match="slides"):
        fastmap.first_returns_compiled(_on_h(0.5, direction), z0, T_MAX, **OPTS)
    sec = Section("H", system.switch, direction=direction, terminal=1)
    with pytest.raises(SimulationError, match="slides"):
        first_returns(system, z0, sec, T_MAX, **OPTS)
    # a section across the sliding stretch is still fine from there
    assert fastmap.compute_returns(hopf.compiled(EPS, 0.5, MU, OMEGA), z0, T_MAX,
                                   **OPTS).status[0] == fastmap.OK


def test_an_arrival_that_would_slide_inside_a_section_is_refused_before_it_is_recorded():
    """An orbit that arrives on H and would slide there, inside a section on H whose hit
    does not count there (``where`` fails): both engines stop at the arrival with
    SECTION_SLIDING (the engine's record refuses it, the sections being the engine's:
    the seam's ``record``), the crossing before it counted and the arrival not."""
    from numba import njit

    from filippov.abi import WHERE_SIG

    @njit(WHERE_SIG)
    def far_below(z, p):
        return z[1] < -5.0

    cm = dataclasses.replace(_on_h(0.5, +1), section_where=far_below)
    z0 = np.array([[0.0, 1.02, 0.0]])
    out = fastmap.compute_returns(cm, z0, T_MAX, **OPTS)
    assert out.status[0] == fastmap.SECTION_SLIDING and out.n_switches[0] == 1
    system = hopf.model(EPS, 0.5, MU, OMEGA).full()
    sec = Section("H", system.switch, direction=+1, where=lambda z: z[1] < -5.0, terminal=1)
    with pytest.raises(SimulationError, match="slides along H inside the section"):
        first_returns(system, z0, sec, T_MAX, **OPTS)
    # where the compiled engine stopped: the reference's arrival into sliding (without
    # the section), after one crossing
    events = simulate(system, z0[0], T_MAX, dense=False, **OPTS).events
    kinds = [e.kind for e in events]
    arrival = events[kinds.index("slide_start")]
    assert kinds[:kinds.index("slide_start")].count("crossing") == 1
    assert abs(arrival.t - out.time[0]) < 1e-12



# ------------------------------------------------------ two sections crossed at one instant
@pytest.mark.parametrize("method", ["exact", "integrate"])
def test_sections_crossed_at_one_instant_are_each_hit(method):
    # x2 = 0 upward (through (0.5, 0) at t = PERIOD), the same zero set written twice
    # (x2 and 2 x2 + x2^3) and a different surface through the same point (x1 + x2 =
    # 0.5, crossed there at the rate 0.5, its root 1e-18 from x2's): each a
    # hit at that instant, in the order given; the search keeps the first of tied roots,
    # and the others used to be lost (their crossing lies behind the far side of the first)
    up = Section("x2", lambda z: z[1], direction=1)
    twice = Section("2x2+x2^3", lambda z: 2 * z[1] + z[1] ** 3, direction=1)
    other = Section("x1+x2=0.5", lambda z: z[0] + z[1] - 0.5, direction=1)
    start = [0.5, -1e-9]
    tr = simulate(two_centres(), start, PERIOD + 0.5, sections=[up, twice, other],
                  method=method)
    hits = [(e.name, e.t) for e in tr.events if e.kind == "section"]
    assert [n for n, _ in hits][:3] == ["x2", "2x2+x2^3", "x1+x2=0.5"]
    assert hits[0][1] == hits[1][1] == hits[2][1] == pytest.approx(2e-9, rel=1e-6)
    # a terminal one among the tied ends the run there, named; the others before it logged
    stop = dataclasses.replace(twice, terminal=1)
    tr = simulate(two_centres(), start, PERIOD + 0.5, sections=[up, stop, other],
                  method=method)
    assert tr.status == "section:2x2+x2^3" and tr.t == pytest.approx(2e-9, rel=1e-6)
    assert [e.name for e in tr.events if e.kind == "section"] == ["x2", "2x2+x2^3", "x1+x2=0.5"]
    # what a hit must satisfy holds for a tied one too: its direction, where, min_time
    for tied in (dataclasses.replace(twice, direction=-1, terminal=1),
                 dataclasses.replace(twice, where=lambda z: z[0] < 0, terminal=1),
                 dataclasses.replace(twice, min_time=1.0, terminal=2)):
        tr = simulate(two_centres(), start, 3.0, sections=[up, tied], method=method)
        assert [e.t for e in tr.events if e.name == tied.name][:1] != [tr.events[1].t]


# A generated crossing (tests/generated_systems.py, n = 3, exact flows) whose section is
# H itself: the section's root is refined 3 ulps before the switch's, the stay after the
# hit begins on the section, and the switch a few ulps later began another stay whose
# exact flow rounded h back below 0 -- the one crossing logged twice, and terminal=2
# ending the run at it (found by a review). A stay begun at the instant of a hit
# (section.one_instant) begins on the sections hit there.
_ON_H_Z0 = [0.5258970501378047, 0.5633646867779194, 0.09671951379978269]
_ON_H_P = [-1.300930314488954, -0.8103100225202343, 0.3808851164732415, 0.25159340921751805, 0.3370655768973355, -0.7062627830383769, -0.691309376377082, 1.457001599417387, 0.775368712817658, -1.6710556806469135, -0.7434773240818368, 0.42636077825530366, 0.9811458608474195, -0.5393460874251095, 1.4417703540010979e-177, 0.0, 1.0, -6.103515625e-05, 0.34951555992841477, -0.4062774114347447, 1.5575070096246764, 1.0192087747726375, 0.5497150170038141, 2.154208086927612e-05, -1.3960039078050622e-05, 1.000008391928591, 3.9188053777928736e-05, -0.2287212802547814, 0.13749335803517698, 0.6420570730975844, -1.1652468447166164, 0.4883754099713282, 0.4883754099713282, 0.0, 1.1, -1.1, -1.6865829403201364, -0.16980054047829105, -1.7345447367744333, 0.9212158350637241, -0.30784431461077555, -0.017721698858204186, 1.1066353626835752, 0.5904223394499298, 0.2929721352328225, -0.41324437102353534, 0.1226014657623799, 0.2937238081353744, -1.2090814602366813, -1.2825049908003128, -0.23851986746011858, 0.9083703901347742, -1.5859241413906917e-27, -0.1682521255234254, 0.5493468601886463, 1.514614332772363, -0.38855768555000336, -0.5038457819189139, -0.15820558351432806, 1.0, 1.2047119093186345, 0.02206771739965316, 0.21126992058442517, -0.2931264525455987, 0.6827943896246345, 0.21598585905113676, 0.5606147724692138, 0.11914061115926865, 1.1406176271948352, 0.7448733362550107, 0.7448733362550107, 0.3156153101390069, 0.5102122928010393, -0.5102122928010393, 0.0, 1.0122029770986494, -1.0526049499354895, 2.6754996974846286, -0.8885930307949229, -0.456822106404832, -0.04142449423403339, -6.0528482444146294e-120, 0.0, 0.0, 0.0, 0.0, 0.6707180572122433]


@pytest.mark.parametrize("method", ["exact", "integrate"])
def test_a_section_on_h_is_hit_once_where_the_switch_follows_a_few_ulps_later(method):
    import generated_systems as gs

    fs = gs.system(3, method == "exact")
    gs.load(fs, np.array(_ON_H_P))
    on_h = dataclasses.replace(fs.python_section(gs.switch, direction=0), terminal=None,
                               name="H")
    traj = simulate(fs.python(), np.array(_ON_H_Z0), 3.0, sections=[on_h], dense=False,
                    method=method)
    kinds = [(e.kind, e.name) for e in traj.events if e.kind != "start"]
    assert kinds[:2] == [("section", "H"), ("crossing", "")], kinds
    hits = [e.t for e in traj.events if e.kind == "section"]
    crossings = [e.t for e in traj.events if e.kind == "crossing"]
    assert len(hits) == len(crossings), (hits, crossings)   # one hit per crossing of H
    twice = dataclasses.replace(on_h, terminal=2)
    traj2 = simulate(fs.python(), np.array(_ON_H_Z0), 3.0, sections=[twice], dense=False,
                     method=method)
    assert traj2.status == ("t_end" if len(hits) < 2 else "section:H"), traj2.status
    if len(hits) >= 2:
        assert traj2.t == pytest.approx(hits[1], abs=1e-12)


def test_a_section_found_again_and_again_at_one_instant_is_refused():
    # defence in depth behind the start on a section after a hit (D25): section hits
    # count against no budget, so a run that found one crossing again an ulp later each
    # time, rounding the same state, crawled on an ulp per hit (a hang). The reference's
    # record of a hit refuses a section hit more than REHITS_AT_INSTANT times within one
    # instant, naming it; two hits there are an orbit's (next test)
    from types import SimpleNamespace

    from filippov.simulate import GO_ON, REHITS_AT_INSTANT, _section_hit

    traj = SimpleNamespace(events=[], t0=0.0)
    run = SimpleNamespace(sections=[Section("x=0", lambda z: z[0])], hit_section=0,
                          traj=traj, event_xtol=1e-15, z=np.array([0.0, 1.0]),
                          step_Z=None, hits=[0], start_instant=-1.0, start_sections=None)
    t = 1.2345
    for k in range(REHITS_AT_INSTANT):
        assert _section_hit(MINUS, t, run) == GO_ON and run.hits == [k + 1]
        t = np.nextafter(t, 2.0)
    with pytest.raises(SimulationError, match=f"section 'x=0' hit {REHITS_AT_INSTANT + 1} "
                                              "times within one instant"):
        _section_hit(MINUS, t, run)
    assert run.hits == [REHITS_AT_INSTANT] and len(traj.events) == REHITS_AT_INSTANT
    # a crossing of the same section past that instant is a hit
    assert _section_hit(MINUS, t + 1e-9, run) == GO_ON and run.hits == [REHITS_AT_INSTANT + 1]


@pytest.mark.parametrize("e", [0.0, 1e-16, 1e-15, 3e-15, 1e-14])
def test_an_orbit_through_a_corner_on_a_section_crosses_it_twice_or_once(e):
    # (a review of the refusal above, in its first form: any second hit within one
    # instant) H = {x = 0}, F_- = (1, -1), F_+ = (1, 1) from (-1, 1 - e): the orbit comes
    # down to y = -e at x = 0 and back up, crossing y = 0 at t = 1 -+ e -- twice (once
    # for e = 0: the corner on the section); it was refused for e = 1e-16 .. 3e-15
    from filippov import FilippovSystem

    fs = FilippovSystem(("x", "y"), lambda z, p: np.array([1.0, -1.0]),
                        lambda z, p: np.array([1.0, 1.0]), lambda z, p: z[0],
                        lambda z, p: np.array([1.0, 0.0])).python()
    tr = simulate(fs, [-1.0, 1.0 - e], 2.0, sections=[Section("y0", lambda z: z[1])])
    hits = [ev.t for ev in tr.events if ev.kind == "section"]
    assert len(hits) in (1, 2) and all(abs(h - 1.0) <= e + 1e-15 for h in hits), hits
    assert tr.z == pytest.approx([1.0, 1.0 - e], abs=1e-14)
