"""``pipeline convert FILES... --to sac|mseed --out DIR``: rewrite records in a standard format.

SAC is written with ``idep = iacc`` and samples in nm/s^2 (the SAC standard), so ``pipeline run``
and :func:`pulses.read_record` read the files back without ``--units``.  MiniSEED has no field
for units: its samples are written in m/s^2 (float64) and must be read back with ``--units m/s2``.
"""
from __future__ import annotations

import pathlib
import sys

from ..args import add_record_options, record_options
from ..values import ArgumentError
from .fit import _with_path


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "convert", help="convert records (AT2, text, K-NET, ...) to SAC or MiniSEED",
        description="Read each record (units from the file or --units) and write it as SAC "
                    "(acceleration in nm/s^2, idep = iacc) or MiniSEED (m/s^2, no units stored) "
                    "into --out. Exit status 0 when every file was converted, 1 when some could not "
                    "be read, 2 for bad arguments.")
    p.add_argument("files", nargs="+", metavar="FILE", help="record files")
    p.add_argument("--to", required=True, choices=["sac", "mseed"], help="output format")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created if needed)")
    add_record_options(p)
    p.set_defaults(func=main)


def output_name(record, path, suffix: str) -> str:
    """``rinaldi.txt`` column 2 -> ``rinaldi.col2.sac``; ``Rinaldi228.AT2`` -> ``Rinaldi228.sac``."""
    stem = pathlib.Path(path).stem
    column = record.metadata.get("column")
    if record.metadata.get("columns", 1) > 1 and column:
        stem += f".col{column}"
    return stem + suffix


def write_mseed(record, path) -> str:
    """Write ``record`` as MiniSEED, float64 samples in m/s^2 (MiniSEED stores no units)."""
    import numpy as np
    from obspy import Trace, UTCDateTime

    tr = Trace(data=np.asarray(record.acc, dtype=np.float64))
    tr.stats.delta = record.dt
    tr.stats.starttime = UTCDateTime(0) + record.t_start
    meta = record.metadata or {}
    tr.stats.station = "".join(ch for ch in str(meta.get("station", "")) if ch.isalnum())[:5].upper()
    tr.stats.channel = "".join(ch for ch in str(meta.get("component", "")) if ch.isalnum())[:3]
    tr.write(str(path), format="MSEED", encoding="FLOAT64")
    return str(path)


def main(args) -> int:
    import pulses

    opts = record_options(args)
    from ..reports.outpaths import check_output_dir, check_output_file

    out = check_output_dir(args.out, "--out", inputs=args.files)
    failures = 0
    for path in args.files:
        try:
            record = pulses.read_record(path, **opts)
        except pulses.RecordError as exc:
            print(f"pipeline convert: {_with_path(path, exc)}", file=sys.stderr)
            failures += 1
            continue
        target = out / output_name(record, path, "." + args.to)
        try:  # never onto one of the inputs (pipeline.reports.outpaths)
            check_output_file(target, "--out: the file", "record", inputs=args.files, command="convert")
        except ArgumentError as exc:
            print(f"pipeline convert: {path}: {exc}", file=sys.stderr)
            failures += 1
            continue
        if args.to == "sac":
            pulses.write_sac(record, target)
            print(f"{path} -> {target} (SAC, acceleration in nm/s^2, idep = iacc)")
        else:
            write_mseed(record, target)
            print(f"{path} -> {target} (MiniSEED, m/s^2: read back with --units m/s2)")
        for w in record.metadata.get("warnings", []):
            print(f"  warning: {w}")
    return 1 if failures else 0
