"""fig:slidesketch: one crossing and one sliding trajectory of concrete planar systems."""
from __future__ import annotations

from typing import Protocol
import numpy as np
import xarray as xr

from filippov import simulate
from filippov.io import finalize
from filippov.progress import Progress
from filippov_paper.scenes.common import registered_model, require, solver_options
from filippov_paper.report import Macros, tex_escape, var


class PlanarCases(Protocol):
    """What this scene uses of its model (``model:``): a planar system per case."""
    def system(self, case): ...


MODEL = PlanarCases

CASES = ("crossing", "sliding")

#: names and units of the variables built below (checked complete by filippov_paper.scenes)
VARIABLE_ATTRS = {
    "x1": ("x1 along the trajectory", "1"), "x2": ("x2 along the trajectory", "1"),
    "mode": ("field followed: -1 region -, 0 sliding, 1 region +", "1"),
    "hit_x1": ("x1 where the trajectory first meets H_s", "1"),
    "hit_x2": ("x2 where the trajectory first meets H_s", "1"),
    "arrow_x1": ("x1 of a field arrow", "1"), "arrow_x2": ("x2 of a field arrow", "1"),
    "arrow_u": ("x1 component of the field at the arrow", "1"),
    "arrow_v": ("x2 component of the field at the arrow", "1"),
    "case": ("trajectory shown: crossing or sliding", None), "t": ("time", "1"),
}


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    require(scene, "system", {"reduced"})
    p = scene["parameters"]
    opts = solver_options(scene)
    if not scene["ingredients"]["sliding"]:
        raise ValueError(f"{scene['id']}: ingredients.sliding must be true: panel (b) slides")
    t = np.linspace(0.0, p["t_end"], p["n_samples"])
    ax1 = np.linspace(-1.5, 1.5, 7)
    ax2 = np.array([-0.6, 0.6])
    g1, g2 = (a.ravel() for a in np.meshgrid(ax1, ax2))
    out = {k: [] for k in ("x1", "x2", "mode", "hit_x1", "hit_x2", "u", "v")}
    bar = Progress(scene["id"], len(CASES), progress)
    for case in CASES:
        sys_ = registered_model(scene).system(case)
        traj = simulate(sys_, p["start"], p["t_end"], **opts)
        _, z, mode = traj.sample(t, include_events=False)
        hit = next(e for e in traj.events if e.kind in ("crossing", "slide_start"))
        grid = np.stack([g1, g2])
        field = np.where(g2 < 0, sys_.field_minus(grid), sys_.field_plus(grid))
        for key, val in (("x1", z[0]), ("x2", z[1]), ("mode", mode), ("hit_x1", hit.state[0]),
                         ("hit_x2", hit.state[1]), ("u", field[0]), ("v", field[1])):
            out[key].append(val)
        bar.step(note=case)
    ds = xr.Dataset(
        {"x1": (("case", "t"), np.array(out["x1"]), {"units": "1"}),
         "x2": (("case", "t"), np.array(out["x2"]), {"units": "1"}),
         "mode": (("case", "t"), np.array(out["mode"], dtype=np.int8),
                  {"flag_values": np.array([-1, 0, 1], dtype=np.int8),
                   "flag_meanings": "minus sliding plus"}),
         "hit_x1": ("case", np.array(out["hit_x1"])), "hit_x2": ("case", np.array(out["hit_x2"])),
         "arrow_x1": (("case", "arrow"), np.array([g1, g1])),
         "arrow_x2": (("case", "arrow"), np.array([g2, g2])),
         "arrow_u": (("case", "arrow"), np.array(out["u"])),
         "arrow_v": (("case", "arrow"), np.array(out["v"]))},
        coords={"case": ("case", list(CASES)), "t": ("t", t, {"units": "1"})})
    return finalize(ds, scene, title="crossing and sliding at H_s = {x2 = 0}",
                    switching_function="h = x2",
                    crossing_fields="f_- = (1, 1 + x1/2), f_+ = (1, 1/2)",
                    sliding_fields="f_- = (1, 1), f_+ = (1, -1 - x1^2/4)")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    from filippov_paper.report import formulas_tex  # here: the module's imports are in its code hash

    sid = "fig01_slidesketch"
    for case, word in (("crossing", "Cross"), ("sliding", "Slide")):
        var(m, f"rpOneHit{word}A", ds, sid, "hit_x1", case=case)
        var(m, f"rpOneHit{word}B", ds, sid, "hit_x2", case=case)
    # the fields and the switching function as formulas in the paper's notation
    # ("$f_-(x)=(1,\,1+x_1/2)$ and ...", "$h(x)=x_2$"), from the dataset's plain text
    m.add("rpOneFieldsCross", None, f"{sid}:attrs.crossing_fields",
          text=formulas_tex(ds.attrs["crossing_fields"]))
    m.add("rpOneFieldsSlide", None, f"{sid}:attrs.sliding_fields",
          text=formulas_tex(ds.attrs["sliding_fields"]))
    m.add("rpOneSwitching", None, f"{sid}:attrs.switching_function",
          text=formulas_tex(ds.attrs["switching_function"]))
    return None


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "t_end"
