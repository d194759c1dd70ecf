"""``pipeline demo``: the main job on the bundled example records, from any directory."""
from __future__ import annotations

import contextlib
import importlib.resources
import pathlib

from .run import add_common, options_from, parse_jobs

DEMO_BLOCK = "7.5x1.8"  #: the Temple of Apollo column at Corinth (paper, Section 6)
DEFAULT_OUT = "demo-output"


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "demo", help="run the pipeline on the bundled example records into ./demo-output",
        description=f"Runs 'pipeline run <bundled records> --block {DEMO_BLOCK}' on the example "
                    "records shipped with the package (near-fault-like records with known pulses, "
                    "made by data/make_examples.py), writing into ./demo-output.")
    add_common(p, DEFAULT_OUT)
    p.set_defaults(func=main)


@contextlib.contextmanager
def bundled_records():
    """Paths of the bundled example records (SAC), sorted by name: the installed package's
    ``pipeline.data``, or a source checkout's ``data/`` folder when the package is not installed."""
    try:
        root = importlib.resources.files("pipeline.data")
    except ModuleNotFoundError:  # run from a source checkout: pipeline.data is data/ once installed
        root = pathlib.Path(__file__).resolve().parents[1] / "data"
        if not root.is_dir():
            yield []
            return
    with importlib.resources.as_file(root) as folder:
        yield sorted(str(p) for p in folder.iterdir() if p.name.endswith(".sac"))


def main(args) -> int:
    from ..batch.tasks import Column
    from ..values import parse_block
    from ..batch.runner import run

    jobs = parse_jobs(args.jobs)
    with bundled_records() as paths:
        if not paths:
            print("pipeline demo: no bundled example records found (was the package installed "
                  "with its data?)")
            return 1
        summary = run(paths, (Column(*parse_block(DEMO_BLOCK)),), args.out,
                      options=options_from(args), jobs=jobs, dask=args.dask, quiet=args.quiet)
    return summary.exit_code
