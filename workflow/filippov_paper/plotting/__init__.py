"""Figures from datasets: `draw(scene_id, ds)` and deterministic `save`.

Plotting reads results only (never calls the solver), one module per figure.
"""
from __future__ import annotations

import importlib
import pkgutil
import re

from filippov.io import atomic_output
from filippov_paper.plotting import style

# a figure's module is named like its dataset (figNN_name.py draws results/figNN_name.nc);
# only figures whose module has another name are listed
ALIASES = {"work_precision": "bench_work_precision"}


def _module_name(scene_id: str) -> str:
    name = ALIASES.get(scene_id, scene_id)
    # figure modules: figNN_name (a scene) or bench_name (a benchmark); the rest are helpers
    known = {m.name for m in pkgutil.iter_modules(__path__)
             if re.fullmatch(r"fig[0-9]{2}_[a-z0-9_]+|bench_[a-z0-9_]+", m.name)}
    if name not in known:
        raise ValueError(f"no figure module for scene {scene_id!r}; known: "
                         f"{', '.join(sorted(known | set(ALIASES)))}")
    return name


# No timestamps or tool versions in the files: same data -> same bytes.
PDF_METADATA = {"CreationDate": None, "ModDate": None, "Producer": None, "Creator": None}
PNG_METADATA = {"Software": None}
PNG_DPI = 200


def figure_ids() -> list[str]:
    """The ids of every figure: the scenes' and the aliased ones (work_precision)."""
    inverse = {v: k for k, v in ALIASES.items()}
    return sorted(inverse.get(m.name, m.name) for m in pkgutil.iter_modules(__path__)
                  if re.fullmatch(r"fig[0-9]{2}_[a-z0-9_]+|bench_[a-z0-9_]+", m.name))


def module(scene_id: str):
    """The figure module of dataset ``scene_id`` (hooks: filippov_paper.product.FIGURE)."""
    return importlib.import_module(f".{_module_name(scene_id)}", __name__)


def draw(scene_id: str, ds):
    with style.context():
        return module(scene_id).draw(ds)


def _atomic_savefig(fig, path, fmt: str, **kw) -> None:
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format=fmt, **kw)


def save(fig, pdf_path, png_path) -> None:
    """Vector PDF plus a 200-dpi PNG, byte-reproducible."""
    with style.context():
        _atomic_savefig(fig, pdf_path, "pdf", metadata=PDF_METADATA)
        _atomic_savefig(fig, png_path, "png", metadata=PNG_METADATA, dpi=PNG_DPI)
