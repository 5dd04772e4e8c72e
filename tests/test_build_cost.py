"""The build-cost reader's projection of chunked scenes onto N cores."""
import pytest

from filippov_paper.benchmarks.build_cost import chunked_projection, makespan


def test_makespan_schedules_the_longest_first_on_the_core_that_frees_first():
    assert makespan([3.0, 3.0, 2.0, 2.0, 2.0], 2) == 7.0  # {3,2,2}, {3,2}
    assert makespan([5.0, 1.0, 1.0], 64) == 5.0  # more cores than jobs: the longest
    assert makespan([1.0] * 10, 1) == 10.0
    assert makespan([], 4) == 0.0
    for bad in (0, 2.5, None):
        with pytest.raises(ValueError, match="cores"):
            makespan([1.0], bad)


def _log(path, cpu):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"progress\njoblog: CPU {cpu:.3f} s (before the script: 0.100 s)\n")


def test_the_projection_reads_chunk_and_merge_logs(tmp_path):
    for i, cpu in enumerate([4.0, 4.0, 2.0]):
        _log(tmp_path / "compute_chunk" / "figA" / f"{i}.log", cpu)
    _log(tmp_path / "compute_chunk" / "figB" / "0.log", 6.0)
    _log(tmp_path / "merge_chunks" / "figA.log", 1.0)
    _log(tmp_path / "merge_chunks" / "figB.log", 0.5)
    wall, scenes = chunked_projection(tmp_path, 2)
    assert wall == 8.0 + 1.0  # {6, 2}, {4, 4}: figB done at 6, its merge to 6.5; figA at 8
    assert scenes == {"figA": (3, 10.0, 4.0, 1.0), "figB": (1, 6.0, 6.0, 0.5)}
    assert chunked_projection(tmp_path, 4)[0] == 6.5  # figA done at 4, merged by 5
    assert chunked_projection(tmp_path, 1)[0] == 16.0 + 1.5  # all in a row
    (tmp_path / "merge_chunks" / "figB.log").write_text("killed\n")
    with pytest.raises(ValueError, match=r"figB\.log: no .joblog: CPU"):
        chunked_projection(tmp_path, 2)
