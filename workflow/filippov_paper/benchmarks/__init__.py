"""Benchmarks: scripts that measure and print a table (``make bench``), never timed tests."""
from __future__ import annotations

import argparse


def command_line(doc: str, run, argv=None, **counts) -> None:
    """The command line of a benchmark that prints a table: ``--<name> N`` for each of
    ``counts`` (name=default, passed to ``run`` by name) and ``--out FILE`` to write the
    dataset ``run`` returns."""
    from filippov.io import write_dataset

    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    for name, default in counts.items():
        ap.add_argument(f"--{name}", type=int, default=default)
    ap.add_argument("--out", default=None, help="netCDF file for the table")
    args = vars(ap.parse_args(argv))
    out = args.pop("out")
    ds = run(**args)
    if out:
        write_dataset(ds, out)
