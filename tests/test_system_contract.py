"""A user's PiecewiseSystem that breaks the contract fails at once, naming the piece.

Each test builds a small planar system with one defect: exact flows without a
sample step, a piece that mishandles a batch of states, a non-finite field value,
a switch_grad that is not the gradient of switch, and sliding reached by a system
built without it (said in the system's words; the scene layer adds its own).
"""
import numpy as np
import pytest

from filippov import MINUS, PLUS, PiecewiseSystem, SimulationError, simulate
from filippov.models import planar_sketch, pseudo_equilibrium

ONES = lambda z: np.ones_like(z[0])
ZEROS = lambda z: np.zeros_like(z[0])


def rotation(z0, tau):
    """Exact flow of x1' = x2, x2' = -x1."""
    tau = np.asarray(tau, dtype=float)
    c, s = np.cos(tau), np.sin(tau)
    return np.stack([c * z0[0] + s * z0[1], -s * z0[0] + c * z0[1]])


def rotation_field(z):
    return np.stack([z[1], -z[0]])


def oscillator(**kw):
    """The harmonic oscillator split by H = x2: it crosses H_s twice per period."""
    args = dict(names=("x1", "x2"), field_minus=rotation_field, field_plus=rotation_field,
                switch=lambda z: z[1],
                switch_grad=lambda z: np.stack([np.zeros_like(z[0]), np.ones_like(z[1])]))
    args.update(kw)
    return PiecewiseSystem(**args)


def crossings(t_end):
    """Crossings of x2 = 0 by the oscillator from (1, 0.5) up to t_end: x2 = 0 at
    t = phi0 + k pi, phi0 = atan2(0.5, 1)."""
    return int(np.floor((t_end - np.arctan2(0.5, 1.0)) / np.pi)) + 1


# --------------------------------------------------------------------------- 1. sample_step
@pytest.mark.parametrize("step", [np.inf, np.nan, 0.0, -0.1])
def test_exact_flows_need_a_finite_positive_sample_step(step):
    # with sample_step = inf a span of 1000 was scanned with 64 samples: 175 of
    # the 318 crossings were found, silently
    system = oscillator(flows={PLUS: rotation, MINUS: rotation}, sample_step=step)
    with pytest.raises(ValueError, match=r"sample_step.*finite.*> 0"):
        simulate(system, [1.0, 0.5], 1000.0)


def test_sample_step_is_not_needed_without_flows_or_when_integrating():
    system = oscillator(flows={PLUS: rotation, MINUS: rotation})  # sample_step = inf
    traj = simulate(system, [1.0, 0.5], 10.0, method="integrate")
    assert len(traj.switches()) == crossings(10.0)
    traj = simulate(oscillator(), [1.0, 0.5], 10.0)
    assert len(traj.switches()) == crossings(10.0)


def test_exact_flows_with_a_sample_step_find_every_crossing():
    system = oscillator(flows={PLUS: rotation, MINUS: rotation}, sample_step=0.1)
    traj = simulate(system, [1.0, 0.5], 1000.0, dense=False)
    assert len(traj.switches()) == crossings(1000.0)


# --------------------------------------------------------------------------- 2. batch shapes
A = np.array([[0.0, 1.0], [-1.0, 0.0]])
B = np.array([0.5, -0.25])


def affine_unbatched(z):  # a constant vector of shape (n,) against z of shape (n, m)
    return A @ z - B


def affine_batched(z):
    return A @ z - B.reshape((-1,) + (1,) * (np.ndim(z) - 1))


def test_a_field_that_does_not_broadcast_over_samples_is_named():
    system = oscillator(field_plus=affine_unbatched)
    with pytest.raises(ValueError, match=r"field_plus.*\(n, m\)") as info:
        simulate(system, [1.0, 0.5], 1.0)
    msg = str(info.value)
    assert "B[:, None]" in msg and "shape" in msg


@pytest.mark.parametrize("samples_per_step", [1, 2, 4])
def test_a_field_that_mixes_samples_is_caught_whatever_the_sample_count(samples_per_step):
    # samples_per_step=1 hands the pieces batches of 2 samples: for n = 2 the
    # unbatched constant broadcasts along the wrong axis without an error
    system = oscillator(field_minus=affine_unbatched, field_plus=affine_unbatched)
    with pytest.raises(ValueError, match="field_minus"):
        simulate(system, [1.0, 0.5], 1.0, method="integrate", samples_per_step=samples_per_step)


def test_a_correctly_batched_affine_field_runs():
    system = oscillator(field_minus=affine_batched, field_plus=affine_batched)
    simulate(system, [1.0, 0.5], 1.0, method="integrate")


@pytest.mark.parametrize("piece,bad,match", [
    ("switch", lambda z: z[1:2], r"switch.*shape \(1, \d+\).*expected \(\d+,\)"),
    ("switch_grad", lambda z: np.array([0.0, 1.0]), r"switch_grad.*shape \(2,\).*expected \(2, \d+\)"),
    ("field_minus", lambda z: np.stack([z[1], -z[0]]).T, r"field_minus.*expected \(2, \d+\)"),
])
def test_each_piece_is_probed(piece, bad, match):
    system = oscillator(**{piece: bad})
    with pytest.raises(ValueError, match=match):
        simulate(system, [1.0, 0.5], 1.0, method="integrate")


def test_an_exact_flow_that_does_not_broadcast_over_times_is_named():
    v = np.array([1.0, 2.0])
    flows = {PLUS: lambda z0, tau: z0 + v * tau, MINUS: rotation}
    system = oscillator(flows=flows, sample_step=0.1)
    with pytest.raises(ValueError, match=r"flows\[PLUS\].*\(n, m\)"):
        simulate(system, [1.0, 0.5], 1.0)


def test_the_probe_changes_no_result():
    """The probes only evaluate the pieces: the trajectory is the unprobed one bit for bit."""
    from filippov import checks

    system = pseudo_equilibrium.model(0.05, 0.3).full()
    probed = simulate(system, [0.4, 0.7], 3.0)
    calls = []
    orig = checks.check_system
    try:
        checks.check_system = lambda *a, **k: calls.append(a)
        unprobed = simulate(system, [0.4, 0.7], 3.0)
    finally:
        checks.check_system = orig
    assert calls  # the replacement ran instead of the probes
    assert [(e.t, e.kind, e.state.tolist()) for e in probed.events] == \
        [(e.t, e.kind, e.state.tolist()) for e in unprobed.events]
    assert probed.z.tolist() == unprobed.z.tolist()


# --------------------------------------------------------------------------- 3. non-finite field
def test_non_finite_field_value_names_the_piece_and_state():
    # x1 grows at speed 1 in region +; field_plus has no value beyond x1 = 0.5
    fp = lambda z: np.stack([ONES(z), np.where(z[0] > 0.5, np.nan, 0.0)])
    system = oscillator(field_plus=fp, field_minus=lambda z: np.stack([ONES(z), ZEROS(z)]))
    with pytest.raises(SimulationError,
                       match=r"^non-finite state or value of a piece at t=0\.5\d*, state \[0\.5\d*, "
                             r"1\.0\] \(field_plus returned a non-finite value there"):
        simulate(system, [0.0, 1.0], 1.0, method="integrate")


def test_non_finite_field_at_the_start_names_the_piece():
    fm = lambda z: np.stack([np.full_like(z[0], np.inf), ZEROS(z)])
    system = oscillator(field_minus=fm)
    with pytest.raises(SimulationError, match=r"at t=0\.0, state \[0\.0, -1\.0\] "
                                              r"\(field_minus returned a non-finite value there"):
        simulate(system, [0.0, -1.0], 1.0, method="integrate")


# --------------------------------------------------------------------------- 4. switch_grad
@pytest.mark.parametrize("grad", [
    lambda z: np.stack([np.zeros_like(z[0]), -np.ones_like(z[1])]),   # sign flipped
    lambda z: np.stack([np.ones_like(z[0]), np.zeros_like(z[1])]),    # another function's
    lambda z: np.stack([np.zeros_like(z[0]), np.zeros_like(z[1])]),   # missing
])
def test_a_switch_grad_that_is_not_the_gradient_of_switch_is_named(grad):
    # the sliding sketch: with a flipped gradient sliding looked repelling and
    # the run ended in a Zeno error far from the cause
    base = planar_sketch.system("sliding")
    system = PiecewiseSystem(names=base.names, field_minus=base.field_minus,
                             field_plus=base.field_plus, switch=base.switch,
                             switch_grad=grad, flows=base.flows, sample_step=base.sample_step)
    with pytest.raises(ValueError, match=r"switch_grad.*finite difference of switch"):
        simulate(system, [-1.0, 0.5], 3.0)


def test_a_nonlinear_switch_with_its_true_gradient_passes_far_from_the_origin():
    # H = x2 - 100 sin(x1 / 100) at |z| ~ 1e4: the finite difference has
    # curvature and rounding to absorb
    H = lambda z: z[1] - 100 * np.sin(z[0] / 100)
    system = oscillator(switch=H,
                        switch_grad=lambda z: np.stack([-np.cos(z[0] / 100), np.ones_like(z[1])]))
    simulate(system, [1e3, 2e4], 0.01, method="integrate")
    bad = oscillator(switch=H,
                     switch_grad=lambda z: np.stack([np.cos(z[0] / 100), np.ones_like(z[1])]))
    with pytest.raises(ValueError, match="switch_grad"):
        simulate(bad, [1e3, 2e4], 0.01, method="integrate")


# --------------------------------------------------------------------------- 5. library words
def test_sliding_excluded_is_said_in_the_systems_words():
    system = pseudo_equilibrium.model(0.02, 0.4).full(sliding=False)
    with pytest.raises(SimulationError, match=r"built with sliding=False; build it with "
                                              r"sliding=True") as info:
        simulate(system, [0.2, 0.1], 2.0)
    assert "scene" not in str(info.value) and "ingredient" not in str(info.value)


def test_the_scene_layer_adds_its_own_words():
    from filippov_paper import scenes

    system = pseudo_equilibrium.model(0.02, 0.4).full(sliding=False)
    scene = {"id": "fig05_thetalt0mfs", "ingredients": {"sliding": False}}
    with pytest.raises(SimulationError, match=r"^fig05_thetalt0mfs: attracting sliding .*"
                                              r"built with sliding=False.*ingredients\.sliding: "
                                              r"false; set it to true"):
        with scenes._in_scene_terms(scene):
            simulate(system, [0.2, 0.1], 2.0)
