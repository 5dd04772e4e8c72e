"""A harsh user: oversized configs, extreme eps, unchecked options and malformed
settings each stop at once with one line naming the field (or t, state and mode),
in the library and in the workflow."""

import shutil
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from filippov import EventLimitError, SimulationError, SystemContractError, simulate
from filippov_paper import scenes
from filippov_paper.config import SceneError, check_limits, limits, load_scene
from filippov.models import hopf, pseudo_equilibrium
from filippov.simulate import Section

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "config" / "schema" / "scene.schema.json"
sys.path.insert(0, str(ROOT / "workflow" / "scripts"))
from verify import copy_project, run_snakemake  # noqa: E402


def _scene(sid):
    return load_scene(ROOT / "config" / "scenes" / f"{sid}.yaml", SCHEMA)


# ----------------------------------------------------------------------------- size limits
@pytest.mark.parametrize("sid,field,value,named", [
    ("fig04_retmaps", "n_uniform", 100_000_000, "parameters.n_uniform"),
    ("fig08_s0theta", "n_theta", 2_000_000_000, "parameters.n_theta"),
    ("fig02_cases", "t_end", 1.0e9, "parameters.t_end"),
    ("fig02_cases", "n_samples", 100_000_000, "parameters.n_samples"),
])
def test_oversized_scene_is_refused_naming_field_and_limit(sid, field, value, named):
    scene = _scene(sid)
    scene["parameters"][field] = value
    with pytest.raises(SceneError, match=rf"{named}: .*max_\w+ = .*--config max_\w+="):
        check_limits(scene)
    # an explicit, larger limit lets a real large run through
    check_limits(scene, limits({"max_points": 1e10, "max_samples": 1e10, "max_t_end": 1e10}))


def test_chunks_beyond_limit_or_grid_are_refused():
    scene = _scene("fig04_retmaps")
    scene["chunks"] = 100_000
    with pytest.raises(SceneError, match="chunks: 100000 jobs, over the limit max_chunks"):
        check_limits(scene)
    scene = _scene("fig09_pdm_theta_pos")
    scene["chunks"] = 500   # under max_chunks and the cheap estimate, over the real grid
    with pytest.raises(SceneError, match=r"chunks: 500 chunks for a grid of \d+ points"):
        scenes.check(scene)


def test_malformed_limit_override_is_named():
    with pytest.raises(SceneError, match="--config max_points: must be a positive number"):
        limits({"max_points": "lots"})


def test_engine_a_scene_does_not_offer_is_one_line():
    scene = _scene("fig02_cases")
    scene["solver"]["engine"] = "compiled"
    with pytest.raises(SceneError, match=r"solver.engine: 'compiled' not available"):
        scenes.check(scene)


def test_pdm_eps_below_the_resolution_of_x1_is_refused_before_computing():
    scene = _scene("fig07_pdm_theta_neg")
    scene["parameters"]["eps"] = [1.0e-2, 1.0e-12]
    with pytest.raises(SceneError, match=r"parameters.eps: 1e-12 .* below the resolution"):
        scenes.check(scene)


# ----------------------------------------------------------------------------- extreme eps
@pytest.mark.parametrize("eps", [1e-12, 1e6, 1e-300])
def test_extreme_eps_stops_at_once_with_context(eps):
    # either a clear refusal with t and state, or (eps = 1e-300, where y = x1 to the
    # last bit) the right answer: the reduced system's orbit, event for event
    t0 = time.perf_counter()
    model = hopf.model(eps, 0.5)
    try:
        traj = simulate(model.full(), [0.0, 1.2, 0.0], 1.0)
    except SimulationError as exc:
        assert "t=" in str(exc) and "state" in str(exc)
        assert "f(a) and f(b)" not in str(exc)
    except SystemContractError as exc:
        # eps = 1e6: the closed form leaves the start along (1, 0, 0), its field is
        # (1, 0, -30.2) (checks.flow_check): refused at the start, naming it
        assert eps == 1e6 and "start state" in str(exc), exc
    else:
        assert eps == 1e-300, "only the limit eps -> 0 may run through"
        reduced = simulate(model.reduced(), [0.0, 1.2], 1.0)
        assert [e.kind for e in traj.events] == [e.kind for e in reduced.events]
        np.testing.assert_allclose([e.t for e in traj.events], [e.t for e in reduced.events],
                                   rtol=0, atol=1e-12)
        np.testing.assert_allclose(traj.z[:2], reduced.z, rtol=0, atol=1e-12)
    assert time.perf_counter() - t0 < 20


def test_chatter_faster_than_the_budget_allows_stops_at_once():
    t0 = time.perf_counter()
    with pytest.raises(EventLimitError, match=r"switching every .* exceed max_events"):
        simulate(pseudo_equilibrium.model(1e-12, -0.5).full(), [1e-11, 0.0], 1.0)
    assert time.perf_counter() - t0 < 20


def test_integrating_a_stiff_field_switches_to_radau_with_a_note():
    # method="integrate" at eps = 1e-12: the fast relaxation makes DOP853 crawl; the
    # driver notes the stiffness and finishes with Radau, agreeing with the exact flow
    system = hopf.model(1e-12, -0.5).full()
    t0 = time.perf_counter()
    traj = simulate(system, [0.0, 1.2, 0.3], 0.02, method="integrate")
    assert time.perf_counter() - t0 < 20
    assert traj.status == "t_end" and traj.stiff_modes == {"plus"}
    exact = simulate(system, [0.0, 1.2, 0.3], 0.02)
    np.testing.assert_allclose(traj.z, exact.z, rtol=0, atol=1e-10)


@pytest.mark.parametrize("eps", [1e-7, 1e-9])
def test_stiff_sliding_at_tiny_eps_is_cheap_and_leaves_at_its_tangential_exit(eps):
    # theta > 0: the orbit slides, x1 + 1 relaxing at rate 1/(theta eps) inside the
    # slide. Before: at eps = 1e-7 Radau chased the field's rounding noise (11072
    # steps, 11 s); at eps = 1e-9 the exit point, one rounding below H, read as a
    # crossing back and the driver cycled slide_end/slide_start into a ZenoError.
    from filippov_paper.scenes.fig04_retmaps import section_L1
    model = hopf.model(eps, 0.5)
    traj = simulate(model.full(), [0.0, 1.2, 0.0], 1.0, sections=[section_L1()], dense=False)
    reduced = simulate(model.reduced(), [0.0, 1.2], 1.0, sections=[section_L1()], dense=False)
    assert traj.status == "section:L1"
    # into region -, a fast approach to H, one slide, the tangential exit (a touch of
    # H right after it is recorded as such), the return
    assert [e.kind for e in traj.events if e.kind != "touch"] == [
        "start", "crossing", "slide_start", "slide_end", "section"]
    assert traj.n_steps < 1500
    # a and b of the slide carry the state's rounding times 1/eps: judged above it
    # (engines.py asymmetry 12), a step is searched in a few windows, not split down to
    # 1/4096 of it (628 windows for 89 steps at eps = 1e-7, 710 for 91 at 1e-9; 12496
    # for 91 at 1e-9, 15 times the time, when 64 ulps of a were taken for its rounding)
    assert traj.n_windows < 10 * traj.n_steps
    # the tolerance the noise allowed is reported, and it grows like 1/eps^2 at most
    # (noise ~ u/eps, steps of the slow scale): 1e-14 * (1e-4/eps)^2 bounds it
    assert atol_floor_bound(traj, eps)
    # the return differs from the reduced one (P = 1) by 163 eps^2 (the hard-case
    # sweep measures 1 - P = 1.63e-10 at eps = 1e-6): the raised tolerance does not
    # reach P, since the sliding flow contracts every error across the flow
    # (to a few rounding errors of P either way: observed 2 ulps at eps = 1e-9)
    ulp = np.finfo(float).eps
    assert -8 * ulp <= reduced.z[1] - traj.z[1] < 200 * eps ** 2 + 8 * ulp
    if eps >= 1e-7:  # the compiled engine (explicit DOP853 in sliding) agrees
        from filippov import fastmap
        ref = fastmap.compute_returns(hopf.compiled(eps, 0.5), [[0.0, 1.2, 0.0]], 1.0)
        assert ref.status[0] == 0
        assert abs(ref.state[0, 1] - traj.z[1]) < 1e-13


def atol_floor_bound(traj, eps):
    raised = traj.atol_raised.get("sliding", 0.0)
    return 1e-14 < raised < 1e-14 * (1e-4 / eps) ** 2


def test_field_noise_is_the_rounding_of_state_and_field():
    from filippov.simulate import field_noise
    jac = np.array([[-1e6, 2.0], [0.0, -3.0]])
    z = np.array([-1.0, 0.5])
    noise = field_noise(lambda t, zz: jac @ zz, 0.0, z)
    u = np.finfo(float).eps
    expected = np.abs(jac) @ (u * np.abs(z)) + u * np.abs(jac @ z)
    np.testing.assert_allclose(noise, expected, rtol=1e-6)


def test_without_the_stiff_switch_it_refuses_at_once_with_the_reason():
    t0 = time.perf_counter()
    with pytest.raises(EventLimitError, match=r"exceed max_steps.*stiff"):
        simulate(hopf.model(1e-12, -0.5).full(), [0.0, 1.2, 0.0], 1.0, method="integrate",
                 stiff=False)
    assert time.perf_counter() - t0 < 20


# ----------------------------------------------------------------------------- options
@pytest.mark.parametrize("option,value", [
    ("max_step", 0.0), ("max_step", np.nan), ("rtol", -1.0), ("atol", 0.0), ("rtol", np.inf),
    ("zeno_count", 0), ("zeno_count", 1), ("max_events", 0), ("max_steps", 2.5),
    ("event_xtol", -1e-15), ("touch_tol", np.nan), ("samples_per_step", 0),
    ("stiff", "yes")])
def test_every_option_is_checked_where_it_enters(option, value):
    system = pseudo_equilibrium.model(0.1, -0.5).full()
    with pytest.raises(ValueError, match=rf"^{option} must be"):
        simulate(system, [0.3, 0.0], 1.0, **{option: value})


def test_sections_are_checked():
    with pytest.raises(ValueError, match="direction must be -1, 0 or"):
        Section("L", lambda z: z[0], direction=5)
    with pytest.raises(ValueError, match="terminal must be None or an integer"):
        Section("L", lambda z: z[0], terminal=0)
    with pytest.raises(TypeError, match=r"sections\[0\]"):
        simulate(pseudo_equilibrium.model(0.1, -0.5).full(), [0.3, 0.0], 1.0,
                 sections=[lambda z: z[0]])


# ----------------------------------------------------------------------------- workflow
@pytest.fixture
def project(tmp_path):
    work = copy_project(tmp_path / "p")
    yield work
    shutil.rmtree(work, ignore_errors=True)


def _edit(path: Path, fn):
    data = yaml.safe_load(path.read_text())
    fn(data)
    path.write_text(yaml.safe_dump(data, sort_keys=False))


def _lines(run):
    return [line for line in (run.stdout + run.stderr).splitlines() if line.strip()]


def test_planning_an_oversized_scene_stops_in_seconds(project):
    _edit(project / "config/scenes/fig04_retmaps.yaml", lambda d: d.update(chunks=100_000))
    t0 = time.perf_counter()
    run = run_snakemake(project, "-n")
    assert run.returncode != 0 and time.perf_counter() - t0 < 30
    assert any(line.startswith("error: config/scenes/fig04_retmaps.yaml: chunks: 100000")
               for line in _lines(run)), run.stderr[-2000:]
    assert "Traceback" not in run.stdout + run.stderr
    # the limit is raised explicitly for a real large run (then the grid bound applies)
    run = run_snakemake(project, "-n", "--config", "max_chunks=1000000")
    assert "chunks for a sweep of at most 2202 points" in run.stdout + run.stderr


def test_malformed_config_names_file_line_and_column(project):
    cfg = project / "config/config.yaml"
    cfg.write_text(cfg.read_text().replace("schema: ", "schema: [", 1))
    run = run_snakemake(project, "-n")
    assert run.returncode != 0
    assert any(line.startswith("error: config/config.yaml: line ") and "column" in line
               for line in _lines(run)), run.stderr[-2000:]


def test_the_scenes_are_the_scene_files(project):
    # no list to keep: every config/scenes/*.yaml is built; a list in config.yaml picks
    # some, and an id without its file is named
    from filippov_paper.config import load_workflow_config
    cfg = project / "config/config.yaml"
    schema = project / "config/schema/config.schema.json"
    every = sorted(p.stem for p in (project / "config/scenes").glob("*.yaml"))
    assert load_workflow_config(cfg, schema)["scenes"] == every and len(every) >= 14
    assert load_workflow_config(cfg, schema, {"scenes": every[:2]})["scenes"] == every[:2]
    cfg.write_text(cfg.read_text() + "scenes: [fig02_cases, fig99_nothing]\n")
    run = run_snakemake(project, "-n")
    assert run.returncode != 0
    assert any(line.startswith("error: config/config.yaml: scenes: no scene file") and
               "fig99_nothing.yaml" in line for line in _lines(run)), run.stderr[-2000:]


def test_unknown_top_level_setting_is_named(project):
    run = run_snakemake(project, "-n", "--config", "max_pionts=5")
    assert run.returncode != 0
    assert "'max_pionts' was unexpected" in run.stdout + run.stderr


def test_engine_error_from_the_compute_job_is_one_line(project):
    _edit(project / "config/scenes/fig02_cases.yaml",
          lambda d: d["solver"].update(engine="compiled"))
    run = run_snakemake(project, "results/fig02_cases.nc")
    assert run.returncode != 0
    assert "error: fig02_cases: solver.engine: 'compiled' not available" in run.stdout + run.stderr
    assert "Traceback" not in run.stdout + run.stderr
    assert not (project / "results/fig02_cases.nc").exists()


def test_manifest_check_defaults_to_the_working_directory(tmp_path, monkeypatch):
    from filippov_paper import manifest

    monkeypatch.chdir(tmp_path)
    (tmp_path / "results").mkdir()
    (tmp_path / "figures").mkdir()
    # no build here: every dataset and figure of the manifest is missing *here*
    assert manifest.main(["check"]) == 1


def test_verify_refuses_a_first_build_directory_that_is_not_empty(tmp_path, capsys):
    import verify
    (tmp_path / "kept.txt").write_text("a user's file")
    with pytest.raises(SystemExit) as stop:
        verify.main(["--first-build", str(tmp_path)])
    assert stop.value.code == 2
    assert "--first-build" in capsys.readouterr().err
    assert [p.name for p in tmp_path.iterdir()] == ["kept.txt"]  # nothing built, nothing removed


def test_the_suite_reuses_only_a_finished_build_of_this_tree(tmp_path):
    """FILIPPOV_TEST_BUILD (CI: verify's first build) is taken only when its copied files
    are this tree's (both ways; bytecode aside), every scene's figure is there and no
    dataset is older than src/; else each test needing it fails naming the variable."""
    import os

    import conftest
    from filippov_paper.config import scene_files
    from verify import copy_project

    work = copy_project(tmp_path / "build")
    with pytest.raises(pytest.UsageError, match="FILIPPOV_TEST_BUILD.*not a finished build"):
        conftest._reused_build(work)  # this tree's files, nothing built
    (work / "results").mkdir()
    (work / "figures").mkdir()
    for scene in scene_files(work / "config" / "scenes"):
        (work / "figures" / f"{scene}.pdf").write_bytes(b"")
    with pytest.raises(pytest.UsageError, match="no dataset"):
        conftest._reused_build(work)
    dataset = work / "results" / "fig02_chatter.nc"
    dataset.write_bytes(b"")
    (work / "workflow" / "__pycache__").mkdir(exist_ok=True)
    (work / "workflow" / "__pycache__" / "stray.cpython-311.pyc").write_bytes(b"")
    assert conftest._reused_build(work).returncode == 0  # bytecode is not the tree's
    os.utime(dataset, (0, 0))
    with pytest.raises(pytest.UsageError, match="older than the library's sources"):
        conftest._reused_build(work)
    os.utime(dataset)
    extra = work / "config" / "scenes" / "fig99_extra.yaml"
    extra.write_text("id: fig99_extra\n")
    with pytest.raises(pytest.UsageError, match="not a build of this tree"):
        conftest._reused_build(work)  # a file the tree does not have
    extra.unlink()
    config = work / "config" / "config.yaml"
    config.write_text(config.read_text() + "\n# edited\n")
    with pytest.raises(pytest.UsageError, match="not a build of this tree"):
        conftest._reused_build(work)
