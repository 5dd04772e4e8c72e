"""Thin: results/<id>.nc -> filippov.plotting -> figures/<id>.{pdf,png}.

filippov.plotting builds pyplot-free Figures, so no GUI backend is involved.
"""
from pathlib import Path

import xarray as xr

import filippov.plotting

with xr.open_dataset(snakemake.input.data) as ds:  # noqa: F821
    ds = ds.load()
# the figure's id is its file name: figures/<id>.pdf (scenes and benchmarks alike)
fig = filippov.plotting.draw(Path(snakemake.output.pdf).stem, ds)  # noqa: F821
filippov.plotting.save(fig, snakemake.output.pdf, snakemake.output.png)  # noqa: F821
