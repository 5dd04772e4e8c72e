"""Figures from datasets: `draw(scene_id, ds)` and deterministic `save`.

Plotting reads results only (never calls the solver), one module per figure.
"""
from __future__ import annotations

import importlib

from ..io import atomic_output
from . import style

# scene id -> module in this package whose draw(ds) makes the figure
DRAW = {
    "fig01_slidesketch": "fig01_slidesketch",
    "fig02_cases": "fig02_cases",
    "fig03_grazingsketch": "fig03_grazingsketch",
    "fig04_retmaps": "fig04_retmaps",
    "fig05_thetalt0mfs": "fig05_thetalt0mfs",
    "fig06_sgraph": "fig06_sgraph",
    "fig07_pdm_theta_neg": "fig07_pdm_theta_neg",
    "fig08_s0theta": "fig08_s0theta",
    "fig09_pdm_theta_pos": "fig09_pdm_theta_pos",
    "bench_work_precision": "bench_work_precision",
    "work_precision": "bench_work_precision",
    "fig10_dfo": "fig10_dfo",
    "fig11_dfo_retmaps": "fig11_dfo_retmaps",
}

# No timestamps or tool versions in the files: same data -> same bytes.
PDF_METADATA = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}
PNG_METADATA = {"Software": None}
PNG_DPI = 200


def draw(scene_id: str, ds):
    try:
        module = importlib.import_module(f".{DRAW[scene_id]}", __name__)
    except KeyError:
        raise ValueError(f"no figure module for scene {scene_id!r}; known: {', '.join(sorted(DRAW))}") from None
    with style.context():
        return module.draw(ds)


def _atomic_savefig(fig, path, fmt: str, **kw) -> None:
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format=fmt, **kw)


def save(fig, pdf_path, png_path) -> None:
    """Vector PDF plus a 200-dpi PNG, byte-reproducible."""
    with style.context():
        _atomic_savefig(fig, pdf_path, "pdf", metadata=PDF_METADATA)
        _atomic_savefig(fig, png_path, "png", metadata=PNG_METADATA, dpi=PNG_DPI)
