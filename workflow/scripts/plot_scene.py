"""Thin: results/<id>.nc -> filippov_paper.plotting -> figures/<id>.{pdf,png}.

filippov_paper.plotting builds pyplot-free Figures, so no GUI backend is involved.
"""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import filippov.io  # noqa: E402
import filippov_paper.plotting  # noqa: E402

# the figure's id is its file name: figures/<id>.pdf (scenes and benchmarks alike)
fid = Path(snakemake.output.pdf).stem  # noqa: F821
try:
    # a damaged, truncated or foreign file is refused before anything is drawn
    ds = filippov.io.read_dataset(snakemake.input.data,  # noqa: F821
                                  scene_id=fid if fid.startswith("fig") else None)
except filippov.io.DatasetError as exc:
    sys.exit(f"error: {exc}")
fig = filippov_paper.plotting.draw(fid, ds)
filippov_paper.plotting.save(fig, snakemake.output.pdf, snakemake.output.png)  # noqa: F821
