"""The benchmarks run, keep failing methods in the table, and score errors right.

Speed is not asserted here (machines are shared and noisy): the numbers live in
`make bench`. What is asserted is what a timing run must never get wrong.
"""
import numpy as np
import pytest

from filippov_paper.benchmarks import effect_cost, work_precision as wp


def test_work_precision_smoke(tmp_path):
    probs = [wp.Problem(p.name, p.x2[[0, 5, -1]], p.model, p.scored[[0, 5, -1]])
             for p in wp.fig04_problems(every=97)]
    fams = [("project compiled exact", [1e-10]), ("solve_ivp RK45", [1e-5]),
            ("solve_ivp nonsense", [1e-6])]
    ds = wp.run(probs, fams, repeat=1, time_cap=60.0, log=lambda s: None)
    assert ds.sizes == {"problem": 2, "config": 3}
    assert list(ds.method.values) == [f for f, _ in fams]
    # the exact flows agree with the independent DOP853 check to the reference floor
    assert np.all(ds.reference_check.values < 1e-11)
    assert np.all(ds.error_map.values[:, 0] < 1e-11)
    assert np.all(ds.status.values[:, :2] == "ok")
    # a method that fails stays in the table, with its reason and no numbers
    assert all(s.startswith("failed:") for s in ds.status.values[:, 2])
    assert np.all(np.isnan(ds.wall_time.values[:, 2]))
    text = wp.table(ds)
    assert "solve_ivp nonsense" in text and "failed" in text


def test_work_precision_fig11_smoke():
    prob = wp.fig11_problems(every=1)[1]           # panel (b), eps = 0.01
    prob = prob.subset([0, 12, 24])                 # 3 start points (4.15, 4.375, 4.6)
    fams = [("project compiled exact", [1e-10]), ("project DOP853", [1e-8]),
            ("solve_ivp DOP853", [1e-8])]
    ds = wp.run([prob], fams, repeat=1, time_cap=120.0, log=lambda s: None)
    assert ds.sizes == {"problem": 1, "config": 3}
    assert "solve_ivp DOP853" in str(ds.reference_pair.values[0])
    # project driver and solve_ivp agree to the reference floor
    assert ds.reference_check.values[0] < 1e-9
    # exact flows do not exist for the dry-friction oscillator: listed, no numbers
    assert ds.status.values[0, 0] == "n/a" and np.isnan(ds.wall_time.values[0, 0])
    assert np.all(ds.status.values[0, 1:] == "ok")
    assert np.all(ds.error_map.values[0, 1:] < 1e-6)
    assert "n/a" in wp.table(ds)


def test_work_precision_interleaves_its_runs_and_times_the_compiled_engine_last(monkeypatch):
    """run() takes the runs of all configurations in passes: round k of every one before
    round k+1 of any, so that load falls on all alike. In each pass every configuration
    off the compiled engine comes before any on it (a cold build's work_precision job then
    runs while another job compiles the kernel); each is scored against its own
    problem's reference as before, and the dataset names the machine and its load."""
    calls = []

    def fake_runner(problem, family, tol, time_cap):   # P and switch times = (tol, k tol)
        def run():
            calls.append((problem.name, family, tol))
            return np.full(2, tol), np.full(2, (1 + problem.x2[0]) * tol)
        return run

    monkeypatch.setattr(wp, "runner", fake_runner)
    base = wp.fig04_problems(every=97)[0]
    probs = [wp.Problem(f"p{k}", np.array([x, x + 0.1]), base.model, np.ones(2, bool))
             for k, x in enumerate((0.5, 2.0))]
    fams = [("project compiled exact", [1e-10]), ("solve_ivp RK45", [1e-6]),
            ("project compiled DOP853", [1e-8]), ("project DOP853", [1e-8])]
    ds = wp.run(probs, fams, repeat=3, time_cap=60.0, log=lambda s: None, min_time=0.0)
    cells = [(p.name, *fams[j][:1], fams[j][1][0]) for compiled in (False, True)
             for p in probs for j in range(len(fams))
             if fams[j][0].startswith("project compiled") == compiled]
    # pass 1: the warm-up run and the first timed run of each; passes 2 and 3: one run each
    first = [c for cell in cells for c in (cell, cell)]
    assert calls[:len(first) + 2 * len(cells)] == first + cells + cells
    assert all(tol == 1e-13 for _, _, tol in calls[len(first) + 2 * len(cells):])
    assert np.all(ds.runs.values == 3) and ds.attrs["timing_passes"] == 3
    assert ds.attrs["timing_order"] == "interleaved"
    # references: compiled exact 1e-13, its check project DOP853 1e-13 (exact: the check)
    for i, x in enumerate((0.5, 2.0)):
        for j, (fam, (tol,)) in enumerate(fams):
            assert ds.error_map.values[i, j] == pytest.approx(tol - 1e-13, rel=1e-12)
            assert ds.error_switch.values[i, j] == pytest.approx((1 + x) * (tol - 1e-13),
                                                                 rel=1e-12)
    assert np.all(ds.status.values == "ok")
    # the spread of every cell is stored with its median, in order
    for lo, hi in (("wall_time_min", "wall_time_q1"), ("wall_time_q1", "wall_time"),
                   ("wall_time", "wall_time_q3"), ("wall_time_q3", "wall_time_max")):
        assert np.all(ds[lo].values <= ds[hi].values), (lo, hi)
    for key in ("machine_cpu", "cpus", "load_average_before", "load_average_after",
                "python_version", "numpy_version", "scipy_version", "numba_version"):
        assert key in ds.attrs, key


def test_time_at_error_interpolates_log_log():
    errs, times = np.array([1e-4, 1e-6, 1e-10]), np.array([1.0, 2.0, 8.0])
    assert wp.time_at_error(errs, times, 1e-6) == 2.0
    assert np.isclose(wp.time_at_error(errs, times, 1e-8), 4.0)  # halfway in log
    assert np.isnan(wp.time_at_error(errs, times, 1e-12))          # never reached
    assert wp.time_at_error(np.array([1e-12, 1e-13]), np.array([3.0, 5.0]), 1e-8) == 3.0


def test_the_speedup_over_rk45_is_a_range_from_the_quartiles():
    # the fastest project configuration within the target (1e-3 s) against RK45 at the
    # target (halfway in log between 0.5 s and 2 s: 1 s); the range: RK45's first quartile
    # over the project's third, its third over the project's first; the medians' ratio in it
    fam = np.array(["project compiled exact"] * 2 + ["solve_ivp RK45"] * 2)
    err = np.array([[1e-12, 1e-12, 1e-6, 1e-10]])
    wall = np.array([[2e-3, 1e-3, 0.5, 2.0]])
    out = wp._at_target(fam, err, wall, 0.8 * wall, 1.5 * wall)
    assert out["ours"][0] == 1e-3 and out["rk45"][0] == pytest.approx(1.0)
    assert out["ratio"][0] == pytest.approx(1000.0)
    assert out["low"][0] == pytest.approx(0.8 / 1.5e-3)
    assert out["high"][0] == pytest.approx(1.5 / 0.8e-3)
    # no quartiles (a sweep of before): no range
    assert np.isnan(wp._at_target(fam, err, wall)["low"][0])


def test_max_dev_counts_one_sided_switches():
    a, b = np.array([1.0, np.nan, 2.0, np.nan]), np.array([1.5, 1.0, 2.0, np.nan])
    err, odd = wp.max_dev(a, b, np.ones(4, bool))
    assert err == 0.5 and odd == 1


def test_effect_variants_switch_one_ingredient_each():
    scene = {"id": "fig04_retmaps", "ingredients": {"system": "slow_fast", "flow": "exact",
                                                     "sliding": True},
             "solver": {"rtol": 1e-12, "engine": "compiled"}}
    labels = [label for label, _ in effect_cost.variants(scene)]
    assert labels == ["as declared", "system: slow_fast -> reduced", "flow: exact -> integrate",
                      "sliding: True -> False", "engine: compiled -> reference"]
    by = dict(effect_cost.variants(scene))
    # the same engine with the other flow: the cost of the ingredient alone
    assert by["flow: exact -> integrate"]["solver"]["engine"] == "compiled"
    assert by["engine: compiled -> reference"]["ingredients"]["flow"] == "exact"
    assert scene["ingredients"]["flow"] == "exact"                    # the original untouched


def test_effect_cost_reports_unsupported_variants(tmp_path):
    ds = effect_cost.measure(["fig08_s0theta"], cap=120.0, log=lambda s: None)
    assert ds.status.values[0] == "ok" and ds.relative.values[0] == 1.0
    assert ds.sizes["variant"] >= 1


def test_chunked_benchmark_parts_merge_in_order():
    probs = [wp.Problem(p.name, p.x2[[0, -1]], p.model, p.scored[[0, -1]])
             for p in wp.fig04_problems(every=97)]
    fams = [("project compiled exact", [1e-10])]
    parts = [wp.run([p], fams, repeat=1, time_cap=60.0, log=lambda s: None) for p in probs]
    # each part measured the machine's load at its own time (CI failed on the two parts'
    # load averages differing): the merged dataset states the largest
    for i, part in enumerate(parts):
        part.attrs["load_average_after"] = 2.0 - i
    merged = wp.merge(parts)
    assert merged.attrs["load_average_after"] == 2.0
    assert list(merged.problem.values) == [p.name for p in probs]
    assert merged.sizes == {"problem": 2, "config": 1}
    for i, part in enumerate(parts):
        np.testing.assert_array_equal(merged.error_map.values[i], part.error_map.values[0])
    with pytest.raises(ValueError, match="more than one part"):
        wp.merge([parts[0], parts[0]])
    other = wp.run([probs[1]], [("project compiled exact", [1e-8])], repeat=1, time_cap=60.0,
                   log=lambda s: None)
    with pytest.raises(ValueError, match="method/tolerance"):
        wp.merge([parts[0], other])


def test_compile_cost_times_a_cold_and_a_warm_process():
    # one pair of fresh processes (the first compiles the kernel on empty caches, ~20 s)
    from filippov_paper.benchmarks import compile_cost
    lines = []
    ds = compile_cost.run(repeat=1, log=lambda *a, **k: lines.append(" ".join(map(str, a))))
    assert list(ds.stage.values) == [s for s, _ in compile_cost.STAGES]
    for stage in ("kernel", "kernel_dpdz"):  # compiled, then loaded from numba's cache
        cold, warm = ds.cold.sel(stage=stage).item(), ds.warm.sel(stage=stage).item()
        assert cold > 10 * warm > 0, stage
    # (run() raises if returns without dP/dz compiled any of the dP/dz code)
    assert ds.cold.attrs["units"] == "s" and any(line.startswith("kernel") for line in lines)


def test_parallel_scaling_table(monkeypatch):
    # a small batch with 1..N workers: the table has a row per worker count, the results
    # were checked equal across them (run raises otherwise), and the CPU times are there
    from filippov_paper.benchmarks import parallel_scaling as ps
    monkeypatch.setattr(ps, "MIN_TIME", 0.0)
    monkeypatch.setattr(ps, "cores", lambda: 2)
    lines = []
    ds = ps.run(starts=40, returns=2, repeat=1, log=lines.append)
    assert list(ds.workers.values) == [1, 2]
    assert ds.returns_per_second.shape == (len(ps.CASES), 2)
    assert np.all(ds.returns_per_second.values > 0)
    assert np.all(ds.span.values <= ds.cpu_time.values * 1.05)  # one thread's share
    assert "load average" in lines[0] and ds.attrs["load_average_before"] >= 0


def test_sweep_cost_table(monkeypatch):
    # a small sweep three ways (a call per point, one call on 1 thread, on N): the
    # results were checked equal (run raises otherwise), a row per case and variant
    from filippov_paper.benchmarks import sweep_cost as sc
    monkeypatch.setattr(sc, "MIN_TIME", 0.0)
    lines = []
    ds = sc.run(points=6, returns=3, repeat=1, log=lines.append)
    assert list(ds.variant.values) == ["loop", "sweep 1", "sweep N"]
    assert ds.cpu_time.shape == (len(sc.CASES), 3) and np.all(ds.cpu_time.values > 0)
    assert ds.threads.values[0, 2] == sc.cores() and "load average" in lines[0]


def test_return_floor_counts_without_changing_returns(monkeypatch):
    # the counting pieces give the same returns bit for bit (measure raises otherwise);
    # an exact-flow return evaluates each of flow, h, grad h, field and section at least
    # once per sample, and the floor is below the time of the return itself
    from filippov_paper.benchmarks import return_floor as rf
    monkeypatch.setattr(rf, "CASES", [(-0.5, 1e-2, 1.0)])
    lines = []
    ds = rf.run(returns=20, repeat=1, log=lines.append)
    assert ds.samples.values[0] > 16 and ds.calls_section_where.values[0] == 1.0
    flows = ds.calls_flow_plus.values[0] + ds.calls_flow_minus.values[0]
    assert flows == ds.samples.values[0] + ds.root_flows.values[0]
    assert 0 < ds.flow_floor.values[0] < ds.floor.values[0]
    assert ds.target.values[0] == 5e-6 and "floor" in lines[0]
    # the generated flow Jacobians are timed too (with an output of n*n: one of n was a
    # heap overflow that aborted a later test); a plain return never calls them
    for name in ("flow_jacobian_plus", "flow_jacobian_minus"):
        assert 0 < ds[f"cost_{name}"].values[0] < 1e-3
        assert ds[f"calls_{name}"].values[0] == 0.0
    # a CPU-time benchmark (min of the thread's clock), but it names the machine and its load
    for key in MACHINE:
        assert key in ds.attrs, key


def test_instruction_cost_reads_callgrind_s_dumps_in_order(tmp_path):
    """Per return: (I(2N) - I(N)) / N of each case and build, from the numbered dumps in
    their numeric order (10 after 9); a dump without its summary, a count of dumps that
    is not 3 per case and build, and no valgrind are refused by name."""
    from filippov_paper.benchmarks import instruction_cost as ic

    n, cases = 4, 2
    counts = []
    for case in range(cases):
        for build in range(len(ic.BUILDS)):
            per = 100 * (case + 1) + 10 * build
            counts += [7_000_000, 50 + n * per, 50 + 2 * n * per]
    for k, c in enumerate(counts, start=1):
        (tmp_path / f"cg.out.{k}").write_text(f"version: 1\nsummary: {c}\ntotals: {c}\n")
    (tmp_path / "cg.out").write_text("summary: 1\n")  # the part after the last dump
    read = ic.dump_counts(str(tmp_path / "cg.out"))
    assert read == counts
    assert ic.per_return(read, n, cases).tolist() == [[100.0, 110.0], [200.0, 210.0]]
    with pytest.raises(ValueError, match="expected 12 callgrind dumps"):
        ic.per_return(read[:-1], n, cases)
    (tmp_path / "cg.out.13").write_text("version: 1\n")
    with pytest.raises(ValueError, match="cg.out.13: no 'summary:'"):
        ic.dump_counts(str(tmp_path / "cg.out"))


def test_instruction_cost_names_valgrind_when_it_is_missing(monkeypatch):
    from filippov_paper.benchmarks import instruction_cost as ic

    monkeypatch.setattr(ic.shutil, "which", lambda name: None)
    with pytest.raises(RuntimeError, match="needs valgrind"):
        ic._valgrind()


def test_instruction_cost_s_probes_mark_their_phases_with_the_one_function_callgrind_dumps_at():
    """Every phase of both probes ends with a call of MARK and no other os call: a call of
    MARK is what makes a dump (--dump-before), so any other would move the phases' ends.
    The compile probe ends each of COMPILE_STAGES once; the per-return probe, per case and
    build, its warm-up and its N and 2N returns (one call in the loop over N, 2N)."""
    import re

    from filippov_paper.benchmarks import instruction_cost as ic

    for probe, marks in ((ic._COMPILE_PROBE, len(ic.COMPILE_STAGES)), (ic._PROBE, 2)):
        calls = re.findall(r"\bos\.(\w+)\(", probe)
        assert calls == [ic.MARK] * marks
    assert ic.MARK != "getppid"  # entered by the cold compile itself (see MARK)


# ----------------------------------------------------------------------------- the timing
# convention in every wall-clock benchmark (filippov_paper.benchmarks.timing): the things
# timed against each other get their rounds in passes, every time is stored with its
# spread and extremes in the work-precision dataset's naming, the dataset names the machine
# and its load, and whatever is printed shows the stored median with its quartiles and a
# ratio as a range.
MACHINE = ("machine_cpu", "cpus", "load_average_before", "load_average_after",
           "python_version", "numpy_version", "scipy_version", "numba_version")


def _passes(cells, repeat):
    """The order of calls of measure_interleaved with min_time 0: in pass 1 each cell's
    warm-up call and its first round, then one round of each per pass."""
    return [c for c in cells for _ in range(2)] + list(cells) * (repeat - 1)


def _check_spread(ds, name, dims, units="s"):
    """``name`` stored with its spread and extremes (work_precision's naming: _q1, _q3,
    _min, _max; long_name, units, statistic), in order min <= q1 <= median <= q3 <= max."""
    from filippov_paper.benchmarks import timing

    for suffix, stat, _ in timing.STORED:
        var = ds[name + suffix]
        assert var.dims == dims and var.attrs["units"] == units, name + suffix
        assert var.attrs["statistic"] == stat and var.attrs["long_name"], name + suffix
    order = [ds[name + s].values for s in ("_min", "_q1", "", "_q3", "_max")]
    for lo, hi in zip(order, order[1:]):
        assert np.all((lo <= hi) | np.isnan(lo) & np.isnan(hi)), name


def _check_timed_dataset(ds, passes):
    assert ds.attrs["timing_order"] == "interleaved" and ds.attrs["timing_passes"] == passes
    assert ds.attrs["timing_statistic"] == "median"
    for key in MACHINE:
        assert key in ds.attrs, key


def test_attractor_cost_interleaves_plain_and_dpdz_and_prints_the_spread(monkeypatch):
    from filippov_paper import report
    from filippov_paper.benchmarks import attractor_cost as ac

    cases = [(-0.5, 1e-2, 1.0), (0.2, 1e-3, 2.0)]
    monkeypatch.setattr(ac, "CASES", cases)
    monkeypatch.setattr(ac, "MIN_TIME", 0.0)
    calls, real = [], ac.compute_returns

    def recording(cm, start, t_max, **kw):
        if kw.get("iterations", 1) > 1:  # a timed call (the switches are counted one by one)
            calls.append((float(start[0, 1]), kw["jacobian"]))
        return real(cm, start, t_max, **kw)

    monkeypatch.setattr(ac, "compute_returns", recording)
    lines = []
    ds = ac.run(returns=5, repeat=3, log=lines.append)
    starts = list(dict.fromkeys(x for x, _ in calls))   # the cases' start points, in order
    assert len(starts) == 2
    cells = [(x, jac) for x in starts for jac in (False, True)]
    assert calls == _passes(cells, 3)
    _check_timed_dataset(ds, 3)
    for name in ("time_per_return", "time_per_return_jacobian"):
        _check_spread(ds, name, ("case",))
    assert np.all(ds.runs.values == 3) and np.all(ds.runs_jacobian.values == 3)
    # the table: per case the stored medians, each with its first to third quartile
    m = report.Macros()
    rows = [r for r in ac.report(ds, m).splitlines() if r.startswith("$") and "theta" not in r]
    assert m.flags["rpHaveReturnCost"] and len(rows) == 2
    for k, row in enumerate(rows):
        cells = [c.strip() for c in row.removesuffix(r"\\").split("&")]
        for col, name in ((3, "time_per_return"), (5, "time_per_return_jacobian")):
            us = {q: 1e6 * float(ds[name + q].values[k]) for q in ("", "_q1", "_q3")}
            assert cells[col] == f"${report.num(us[''], 3)}$"
            assert cells[col + 1] == report.num_range(us["_q1"], us["_q3"], 3)
    # the printed log: the ratio with dP/dz as a range (low..high)
    assert "ratio (q1..q3)" in lines[1] and lines[2].count("..") == 3
    # a dataset of before (no spread): not quoted
    m = report.Macros()
    assert ac.report(ds.drop_vars("time_per_return_q1"), m) is None
    assert not m.flags["rpHaveReturnCost"]


# a variant's process for the test below: the protocol of effect_cost._CHILD (the scene on
# the first line, then a compute call per line), the scene telling it what to do; each call
# is written to the log file $EFFECT_LOG, and the seconds a call "took" grow by 10% a call
FAKE_VARIANT = r"""
import json, os, sys, time
scene = json.loads(sys.stdin.readline())
calls = 0
while sys.stdin.readline():
    calls += 1
    with open(os.environ["EFFECT_LOG"], "a") as f:
        f.write(scene["label"] + "\n")
    if scene.get("hang"):
        time.sleep(60)
    if scene.get("crash"):
        sys.stderr.write("boom\n")
        sys.exit(3)
    out = ({"error": "ValueError: needs sliding"} if scene.get("fail")
           else {"seconds": scene["seconds"] * (1 + 0.1 * calls)})
    sys.stdout.write(json.dumps(out) + "\n")
    sys.stdout.flush()
"""


def test_effect_cost_interleaves_the_variants_processes_and_prints_the_spread(monkeypatch,
                                                                               tmp_path):
    """A scene's variants each in a process of its own, kept for all its calls, their
    rounds interleaved in passes (a round: the seconds the process measured); a variant
    that fails, crashes or runs over the cap is listed with its status and dropped from
    the later passes."""
    from filippov_paper import report
    from filippov_paper.benchmarks import effect_cost as ec

    log = tmp_path / "calls.log"
    monkeypatch.setenv("EFFECT_LOG", str(log))
    monkeypatch.setattr(ec, "_CHILD", FAKE_VARIANT)
    monkeypatch.setattr(ec, "load_scene", lambda path, schema: {"id": path.stem})
    toy = [("as declared", {"label": "a", "seconds": 0.5}),
           ("flow: exact -> integrate", {"label": "b", "seconds": 1.0}),
           ("sliding: True -> False", {"label": "c", "fail": True}),
           ("engine: compiled -> reference", {"label": "d", "hang": True}),
           ("system: slow_fast -> reduced", {"label": "e", "crash": True})]
    monkeypatch.setattr(ec, "variants", lambda scene: toy)
    ds = ec.measure(["toy_scene"], cap=2.0, log=lambda s: None, repeat=3, min_time=0.0)
    assert log.read_text().split() == _passes("ab", 3)[:4] + ["c", "d", "e"] + ["a", "b"] * 2
    assert list(ds.status.values) == ["ok", "ok", "ValueError: needs sliding",
                                      "time cap (2 s)", "crashed: ['boom']"]
    _check_timed_dataset(ds, 3)
    _check_spread(ds, "seconds", ("variant",))
    # the rounds are the seconds the processes measured: calls 2..4 after the warm-up
    for k, base in enumerate((0.5, 1.0)):
        rounds = base * np.array([1.2, 1.3, 1.4])
        assert ds.seconds.values[k] == pytest.approx(np.median(rounds))
        assert ds.seconds_q1.values[k] == pytest.approx(np.percentile(rounds, 25))
        assert ds.seconds_q3.values[k] == pytest.approx(np.percentile(rounds, 75))
    assert list(ds.runs.values) == [3, 3, 0, 0, 0] and np.all(np.isnan(ds.seconds.values[2:]))
    # the ratio to the scene as declared: the medians', and its range from the quartiles
    assert ds.relative.values[:2] == pytest.approx([1.0, 2.0])
    assert ds.relative_low.values[1] == pytest.approx(ds.seconds_q1[1] / ds.seconds_q3[0])
    assert ds.relative_high.values[1] == pytest.approx(ds.seconds_q3[1] / ds.seconds_q1[0])
    m = report.Macros()
    rows = [r for r in ec.report(ds, m).splitlines() if r.startswith(r"\texttt")]
    assert m.flags["rpHaveEffects"] and len(rows) == len(toy)
    for k, row in enumerate(rows[:2]):
        cells = [c.strip() for c in row.removesuffix(r"\\").split("&")]
        assert cells[2] == f"${report.num(float(ds.seconds.values[k]), 3)}$"
        assert cells[3] == report.num_range(float(ds.seconds_q1.values[k]),
                                            float(ds.seconds_q3.values[k]), 3)
        assert cells[4] == report.num_range(float(ds.relative_low.values[k]),
                                            float(ds.relative_high.values[k]), 3)


def test_parallel_scaling_interleaves_the_worker_counts_and_keeps_the_spread(monkeypatch):
    from filippov_paper.benchmarks import parallel_scaling as ps

    monkeypatch.setattr(ps, "MIN_TIME", 0.0)
    monkeypatch.setattr(ps, "cores", lambda: 2)
    calls, real = [], ps.compute_returns

    def recording(cm, z0, t_max, **kw):
        calls.append((float(z0[0, 1]), kw["workers"]))
        return real(cm, z0, t_max, **kw)

    monkeypatch.setattr(ps, "compute_returns", recording)
    lines = []
    ds = ps.run(starts=40, returns=2, repeat=3, log=lines.append)
    starts = list(dict.fromkeys(x for x, _ in calls))
    assert calls == _passes([(x, n) for x in starts for n in (1, 2)], 3)
    _check_timed_dataset(ds, 3)
    for name in ("wall_time", "cpu_time", "span"):
        _check_spread(ds, name, ("case", "workers"))
    assert np.all(ds.runs.values == 3)
    # the speed-up over one worker: the medians' ratio inside its range from the quartiles
    assert np.all(ds.speedup_low.values <= ds.speedup.values)
    assert np.all(ds.speedup.values <= ds.speedup_high.values)
    assert ds.speedup_low.values[0, 1] == pytest.approx(
        float(ds.wall_time_q1[0, 0] / ds.wall_time_q3[0, 1]))
    # the printed table: the wall time's median (q1..q3) as stored, ratios as ranges
    row = lines[2].split()
    assert float(row[3]) == pytest.approx(1e3 * float(ds.wall_time[0, 0]), abs=0.006)
    assert "wall ms (q1..q3)" in lines[1] and lines[2].count("..") == 4


def test_sweep_cost_interleaves_its_three_ways_and_keeps_the_spread(monkeypatch):
    from filippov_paper.benchmarks import sweep_cost as sc

    monkeypatch.setattr(sc, "MIN_TIME", 0.0)
    monkeypatch.setattr(sc, "cores", lambda: 2)
    calls = []
    loop, sweep = sc.compute_returns, sc.sweep_returns

    def loop_call(*a, **kw):
        calls.append("loop")
        return loop(*a, **kw)

    def sweep_call(*a, **kw):
        calls.append(f"sweep {kw['workers']}")
        return sweep(*a, **kw)

    monkeypatch.setattr(sc, "compute_returns", loop_call)
    monkeypatch.setattr(sc, "sweep_returns", sweep_call)
    points, lines = 4, []
    ds = sc.run(points=points, returns=2, repeat=3, log=lines.append)
    # a round of the loop is a call per point: one entry per round
    rounds, k = [], 0
    while k < len(calls):
        rounds.append(calls[k])
        k += points if calls[k] == "loop" else 1
    assert rounds == _passes(["loop", "sweep 1", "sweep 2"] * 2, 3)
    _check_timed_dataset(ds, 3)
    for name in ("wall_time", "cpu_time"):
        _check_spread(ds, name, ("case", "variant"))
    row = lines[2].split()   # theta eps loop  median (q1..q3) ...
    assert float(row[3]) == pytest.approx(float(ds.wall_time[0, 0]), abs=0.0006)
    assert "median (q1..q3)" in lines[0] and lines[2].count("..") == 4


def test_sliding_cost_interleaves_its_returns_and_keeps_the_spread(monkeypatch):
    from filippov_paper.benchmarks import sliding_cost as sl

    monkeypatch.setattr(sl, "EPS", [1e-2])
    monkeypatch.setattr(sl, "MIN_TIME", 0.0)
    stages, real = [], sl.driver.simulate

    def recording(*a, **kw):
        stages.append(sl.driver.STIFF_STAGES)
        return real(*a, **kw)

    monkeypatch.setattr(sl.driver, "simulate", recording)
    default = sl.driver.STIFF_STAGES
    lines = []
    ds = sl.run(repeat=3, log=lines.append)
    assert stages == _passes(sl.STAGES, 3) and sl.driver.STIFF_STAGES == default
    _check_timed_dataset(ds, 3)
    _check_spread(ds, "time", ("eps", "stages"))
    assert np.all(ds.runs.values == 3) and np.all(ds.steps.values > 0)
    # the printed table: the median (q1..q3) in ms as stored, the ratio as a range
    cells = lines[2].split()
    assert float(cells[2]) == pytest.approx(1e3 * float(ds.time[0, 0]), abs=0.06)
    assert "ms (q1..q3)" in lines[1] and lines[2].count("..") == 4


def test_fig04_speed_interleaves_the_methods_and_prints_the_spread(monkeypatch, capsys):
    from filippov_paper.benchmarks import fig04_speed as f4, timing, work_precision as wp

    calls = []

    def fake_runner(problem, family, tol, time_cap):   # P = tol everywhere
        def run():
            calls.append((problem.name, family, tol))
            return np.full(problem.x2.size, tol), None
        return run

    base = wp.fig04_problems(every=97)[0]
    probs = [wp.Problem(f"p{k}", np.array([0.5, 2.0]), base.model, np.ones(2, bool))
             for k in range(2)]
    monkeypatch.setattr(f4, "runner", fake_runner)
    monkeypatch.setattr(f4, "fig04_problems", lambda every: probs)
    monkeypatch.setattr(f4, "compile_kernel", lambda: None)
    f4.main(["--repeat", "3", "--min-time", "0"])
    out = capsys.readouterr().out
    for p in probs:   # its methods' runs interleaved, then the untimed reference check
        mine = [c[1:] for c in calls if c[0] == p.name]
        # one untimed run per family: the second RK45 tolerance has none
        first = [m for m in f4.METHODS for _ in range(1 if m == f4.METHODS[3] else 2)]
        assert mine == first + f4.METHODS * 2 + [("project DOP853", 1e-13)]
    assert "(q1..q3)" in out and "load average" in out and "machine:" in out
    # a row: median (first..third quartile) and the ratio to the project's as a range
    t = timing.of_rounds([1.0, 2.0, 3.0, 4.0])
    row = f4._row("p", "m", t, 1e-9, timing.ratio_range(t, timing.of_rounds([0.5, 1.0])))
    assert "2.500 (    1.750..    3.250)" in row and "2.0..     5.2" in row


def test_compile_cost_keeps_the_spread_of_its_pairs_of_processes(monkeypatch):
    """A cold process, then a warm one on the caches it wrote, pair after pair (the one
    order there is: no interleaving); per stage the median over the pairs, its quartiles
    and extremes; the report quotes the quartiles when there is more than one pair."""
    from filippov_paper import report
    from filippov_paper.benchmarks import compile_cost as cc

    caches, seconds = [], iter([3.0, 1.0, 2.0, 6.0, 4.0, 5.0])

    def fake_process(cache):
        warm = cache in caches
        caches.append(cache)
        t = next(seconds)
        return {**{s: (0.01 if warm else 1.0) * t for s, _ in cc.STAGES}, "loaded": warm,
                "dpdz_before": 0, "ok": 8}

    monkeypatch.setattr(cc, "_process", fake_process)
    ds = cc.run(repeat=3, log=lambda *a, **k: None)
    assert caches[0::2] == caches[1::2] and len(set(caches)) == 3   # a pair per cache
    for name in ("cold", "warm"):
        _check_spread(ds, name, ("stage",))
    assert ds.cold.sel(stage="kernel").item() == 3.0            # the cold ones: 3, 2, 4
    assert ds.cold_q1.sel(stage="kernel").item() == 2.5
    assert ds.cold_q3.sel(stage="kernel").item() == 3.5
    assert ds.warm_max.sel(stage="kernel").item() == pytest.approx(0.06)
    assert np.all(ds.runs.values == 3) and ds.attrs["timing_warmup"] == 0
    for key in MACHINE:
        assert key in ds.attrs, key
    m = report.Macros()
    cc.report(ds, m)
    got = report.read_macros(m.tex())
    assert m.flags["rpHaveCompileSpread"] and got["rpCompilePairs"][0] == \
        "three pairs of fresh processes"
    body, src = got["rpCompileKernelColdFirstQuartile"]
    assert report.parse_num(body) == 2.5 and src.startswith(
        "bench_compile_cost:cold_q1[stage='kernel']")
    assert report.parse_num(got["rpCompileModelWarmThirdQuartile"][0]) == pytest.approx(0.055)
    # one pair: no spread to quote
    m = report.Macros()
    cc.report(ds.assign(runs=("stage", np.ones(ds.sizes["stage"], int))), m)
    assert not m.flags["rpHaveCompileSpread"]
    assert "rpCompileKernelColdFirstQuartile" not in report.read_macros(m.tex())


def test_surfaces_cost_times_the_same_return_written_four_ways():
    """The four returns of the several-surfaces benchmark are the closed form's: y = -8
    at x = 5 after the slide's exit at x = 1 (y = -(x - 1)^2 / 2), for one surface
    however written and with a spectator surface (one more stay, one more event); 0 for
    the tutorial's system (across x = 2 at y = -1/2, y' = 1/4 to y = 0 at x = 4, slides)."""
    from filippov_paper.benchmarks import surfaces_cost

    ds = surfaces_cost.run(repeat=1, log=lambda s: None)
    assert list(ds.case.values) == surfaces_cost.CASES
    np.testing.assert_allclose(ds.return_y.values, [-8.0, -8.0, -8.0, 0.0], atol=1e-10)
    assert list(ds.events.values) == [4, 4, 5, 6]
    assert np.all(ds.time.values > 0) and ds.ratio.values[0] == 1.0
