"""Thin: results/<id>.nc -> filippov.plotting -> figures/<id>.{pdf,png}.

filippov.plotting builds pyplot-free Figures, so no GUI backend is involved.
"""
import xarray as xr

import filippov.plotting

with xr.open_dataset(snakemake.input.data) as ds:  # noqa: F821
    ds = ds.load()
fig = filippov.plotting.draw(snakemake.wildcards.scene, ds)  # noqa: F821
filippov.plotting.save(fig, snakemake.output.pdf, snakemake.output.png)  # noqa: F821
