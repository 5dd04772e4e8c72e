"""Scene computations: a validated scene dict in, an xarray Dataset out.

One module per figure. Each reads only the ingredients its scene declares (the
system kind, exact or integrated flows, sliding) and builds nothing else.
"""
from __future__ import annotations

import importlib

SCENES = {
    "fig01_slidesketch": "fig01_slidesketch",
    "fig02_cases": "fig02_cases",
    "fig03_grazingsketch": "fig03_grazingsketch",
    "fig04_retmaps": "fig04_retmaps",
    "fig05_thetalt0mfs": "fig05_thetalt0mfs",
    "fig06_sgraph": "fig06_sgraph",
    "fig07_pdm_theta_neg": "fig07_pdm_theta_neg",
    "fig08_s0theta": "fig08_s0theta",
    "fig09_pdm_theta_pos": "fig09_pdm_theta_pos",
}


def compute(scene: dict, *, progress: bool = False):
    sid = scene.get("id")
    if sid not in SCENES:
        raise ValueError(f"id: unknown scene {sid!r}; known scenes: {', '.join(sorted(SCENES))}")
    module = importlib.import_module(f".{SCENES[sid]}", __name__)
    return module.compute(scene, progress=progress)
