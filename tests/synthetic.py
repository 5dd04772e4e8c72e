"""Small synthetic datasets with the contract's names, for plotting tests: each figure
module's own test knob ``synthetic_dataset`` (filippov_paper.product.FIGURE), so that a
new figure needs nothing here."""
from __future__ import annotations

import xarray as xr

from filippov_paper import plotting, product


def dataset(figure_id: str) -> xr.Dataset:
    """The stand-in dataset of figure ``figure_id`` (a scene id, or work_precision)."""
    return product.hook(plotting.module(figure_id), "synthetic_dataset")()
