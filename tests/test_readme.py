"""The README's user example runs as written and computes what it says."""
import contextlib
import io
import re
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def _relay_example():
    """examples/relay_feedback.py (its closed form: period, start point, multipliers)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("relay", ROOT / "examples" / "relay_feedback.py")
    relay = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(relay)
    return relay


def _run_first_block(start: str, end: str):
    """(scope, stdout) of the first python block of the README section start..end."""
    text = (ROOT / "README.md").read_text()
    code = re.search(r"```python\n(.*?)```", text[text.index(start):text.index(end)],
                     re.S).group(1)
    out, scope = io.StringIO(), {"__code__": code}
    with contextlib.redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), scope)
    return scope, out.getvalue()


def test_the_readme_user_example_runs_and_finds_the_relay_orbit():
    scope, out = _run_first_block("## Your own system", "## A system written once in SymPy")
    assert len(scope["__code__"].strip().splitlines()) <= 30
    relay = _relay_example()
    want = relay.closed_form()
    assert abs(scope["orbit"].t - want["period"]) < 1e-10
    got = np.sort(np.abs(np.linalg.eigvals(
        scope["return_jacobian"](scope["relay"], scope["orbit"], scope["up"],
                                 jacobian=lambda mode, z: relay.A))))[::-1]
    # dP/dz has the nontrivial multipliers and a 0 (the section direction)
    np.testing.assert_allclose(got[:2], want["multipliers"][1:], rtol=1e-6)
    assert "Floquet multipliers" in out


def test_the_readme_compiled_engine_block_runs():
    text = (ROOT / "README.md").read_text()
    section = text[text.index("## Your own system"):text.index("## A system written once in SymPy")]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert len(blocks) == 2
    scope = {}
    with contextlib.redirect_stdout(io.StringIO()):
        for code in blocks:                       # the second uses the first's imports
            exec(compile(code, "README.md", "exec"), scope)
    ret = scope["returns"]
    assert ret.state.shape == (2, 3) and np.all(ret.time > 0)
    np.testing.assert_allclose(ret.state[:, 0], 0.0, atol=1e-14)   # on the section x1 = 0
    # the compiled engine's dP/dz at the fixed point is the reference driver's
    ref = scope["return_jacobian"](scope["relay"], scope["orbit"], scope["up"],
                                   jacobian=lambda mode, z: scope["A"])
    np.testing.assert_allclose(scope["J"], ref, rtol=0, atol=1e-8)


def test_the_readme_symbolic_block_finds_the_relay_orbit_on_both_engines():
    scope, out = _run_first_block("## A system written once in SymPy", "## Examples")
    relay = _relay_example()
    want = relay.closed_form()
    assert abs(scope["po"].period - want["period"]) < 1e-12       # the last engine: python
    np.testing.assert_allclose(scope["po"].multipliers, want["multipliers"], atol=1e-9)
    assert np.array_equal(np.asarray(scope["relay_sym"].jacobians["plus"], dtype=float), relay.A)
    assert "compiled 3.67975067086" in out
