"""``pipeline run``: records in, column designs checked under the full records out, for one record or a whole database."""
from __future__ import annotations

import argparse

from ..batch import peer_inputs, risk, site, vertical
from ..args import (ArgumentError, ShapeNames, add_record_options, add_restitution_option, add_weighting_option,
                   jobs_count, parse_column_block, parse_column_height, parse_friction, parse_limit,
                   parse_restitution, parse_shapes,
                   record_options)

DEFAULT_OUT = "pipeline-output"

#: what ``--plots`` may be given: figures of each pair's governing direction, or of every one
PLOT_SCOPES = ("governing", "all")


def add_common(parser: argparse.ArgumentParser, default_out: str) -> None:
    """Options shared by ``run`` and ``demo``."""
    parser.add_argument("--out", metavar="DIR", default=default_out,
                        help=f"folder for the reports (default ./{default_out}); re-running into it "
                             "gives identical files")
    parser.add_argument("--jobs", "-j", metavar="N", default=None,
                        help="number of worker processes (default 1, or one per CPU with --dask "
                             "local; 0 = one per CPU); the output does not depend on it")
    parser.add_argument("--dask", metavar="SCHEDULER",
                        help="distribute records over a dask.distributed cluster: a scheduler "
                             "address (tcp://host:8786) or 'local' for a local cluster of --jobs "
                             "workers; needs the [dask] extra")
    parser.add_argument("--plots", nargs="?", const="governing", default="governing",
                        choices=PLOT_SCOPES,
                        help="write plots/<record>.png and plots/summary.png: for a pair designed in "
                             "several directions, the figures of its governing direction (default, "
                             "`governing`) or of every direction (`all`)")
    parser.add_argument("--no-plots", dest="plots", action="store_const", const="none",
                        help="write no figures")
    parser.add_argument("--quiet", "-q", action="store_true",
                        help="no progress bar and no messages (the exit status tells)")
    parser.add_argument("--limit", metavar="R", default=None,
                        help="performance level of the design width, the width quoted first: "
                             "max|theta|/alpha <= R, 0 < R <= 1 (default 0.5, the paper's "
                             "dependable design: peaks at or below alpha/2), at least the "
                             "overturning design width; that width, the verge (no margin), is "
                             "reported beside it (overturning_width_m). `none`: the verge alone, "
                             "as the design width. With --fragility and R given, critical scales "
                             "at which max|theta|/alpha first exceeds R (without --limit: collapse; "
                             "docs/design.md)")
    add_restitution_option(parser)


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "run", help="records in, column designs checked under the full records out",
        description="For every record: read it, fit its pulse (every shape), size each column by "
                    "Eq. 31, the envelope rule and the exact criterion, and verify the designs with "
                    "time histories under the full record. Prints the answer (a table per record and "
                    "column) and writes design.csv (the same), report.html (the batch to review in a "
                    "browser), <record>.csv, summary.csv, "
                    "failures.csv, columns.md and plots into --out, and pipeline-manifest.txt, the "
                    "files it wrote: the only ones a later run replaces or removes; one run at a time in "
                    "one --out (another run into it meanwhile is refused). Exit status 0 when every record "
                    "was processed, 1 when some failed (listed in failures.csv), 2 for bad arguments, "
                    "130 (143) when stopped by Ctrl-C (SIGTERM).")
    p.add_argument("records", nargs="*", metavar="RECORD",
                   help="record files (any format pulses.read_record reads: SAC, AT2, MiniSEED, text "
                        "...), folders of them, or PEER NGA-West2 downloads (a .zip, or a folder "
                        "holding _SearchResults.csv; see docs/peer.md)")
    p.add_argument("--glob", metavar="PATTERN",
                   help="folders given: take exactly their files whose names match this shell pattern "
                        "(e.g. '*.AT2'); by default every file but those plainly not records "
                        "(README, documents, images), which are named in one line")
    p.add_argument("--block", action="append", default=[], metavar="HxW",
                   help="a column as it stands, full height x full width in m (e.g. 7.5x1.8); "
                        "cyl:HxD for a solid circular column of diameter D rocking in a plane "
                        "(e.g. cyl:7.5x1.8); repeatable")
    p.add_argument("--height", action="append", default=[], metavar="H",
                   help="only the width a column of this height (m) needs (cyl:H: the diameter "
                        "of a circular one); repeatable")
    p.add_argument("--friction", metavar="MU", default=None,
                   help="the base's friction coefficient: every response is judged against it "
                        "(a column needing more slides, outside the rocking model; a design width "
                        "is valid only where the column does not slide). Default: the friction "
                        "each response needs is reported, not judged")
    shapes = p.add_argument("--shapes", nargs="+", metavar="SHAPE",
                   help="pulse shapes to fit: %(shapes)s or all (default: "
                        "the fitter's default set)")
    shapes.shapes = ShapeNames()  # listed when the help is printed
    add_weighting_option(p)
    p.add_argument("--force", action="store_true",
                   help="compute every record again; by default a record whose report in --out was "
                        "made from the same file content, options and version is kept")
    p.add_argument("--log", metavar="FILE",
                   help="append one JSON line per record to FILE (record, status, seconds, model, "
                        "worker), to watch a long batch")
    p.add_argument("--thorough", action="store_true",
                   help="for pairs: the check above the search width (and with --plots, the "
                        "figures) in every direction; by default only where it can change the "
                        "pair's design width (the same answer, docs/slivers.md)")
    add_record_options(p)
    site.add_options(p)
    peer_inputs.add_options(p)
    vertical.add_options(p)
    risk.add_options(p)
    add_common(p, DEFAULT_OUT)
    p.set_defaults(func=main)


def parse_jobs(text) -> int | None:
    """``--jobs``: None when not given, else a positive count (0 means one per CPU)."""
    if text is None:
        return None
    try:
        jobs = int(str(text))
    except ValueError:
        raise ArgumentError(f"--jobs expects a whole number of processes, got {text!r}") from None
    try:
        return jobs_count(jobs, "--jobs")
    except ValueError as exc:
        raise ArgumentError(str(exc)) from None


def build_columns(blocks, heights):
    from ..batch.tasks import Column

    columns = [Column(*parse_column_block(b)) for b in blocks]
    columns += [Column(h, None, kind) for h, kind in map(parse_column_height, heights)]
    if not columns:
        raise ArgumentError("give at least one column: --block HxW (e.g. --block 7.5x1.8) or --height H")
    return tuple(dict.fromkeys(columns))


def options_from(args, **overrides):
    from ..batch.margin import DEFAULT_LIMIT
    from ..batch.tasks import Options

    limit = DEFAULT_LIMIT if args.limit is None else parse_limit(args.limit)
    # the fragility stays collapse unless a level is asked for by name (--limit R)
    kw = dict(plots=args.plots != "none", plots_all=args.plots == "all",
              thorough=bool(getattr(args, "thorough", False)), limit=limit,
              fragility_limit=None if args.limit is None else limit,
              restitution=parse_restitution(args.restitution))
    kw.update(overrides)
    return Options(**kw)


def main(args) -> int:
    """``pipeline run``: its arguments parsed into the values of :func:`pipeline.design`, which runs
    the batch (the same plan, so the same tasks and numbers)."""
    from .. import api

    columns = build_columns(args.block, args.height)
    jobs = parse_jobs(args.jobs)
    options = options_from(args, shapes=parse_shapes(args.shapes), weighting=args.weighting,
                           friction=parse_friction(getattr(args, "friction", None)),
                           vertical=args.vertical, **record_options(args), **site.options_from_args(args),
                           risk=risk.options_from_args(args, restitution=parse_restitution(args.restitution)))
    plan = api.Plan(records=list(args.records), columns=columns, options=options, record_opts=record_options(args),
                    pairs=args.pairs, pair=list(args.pair),
                    triplets={(str(a), str(b)): str(v) for a, b, v in args.triplet},
                    directions=args.directions, scale=args.scale, scales=args.scales,
                    peer_scales=args.peer_scales, jobs=jobs, out=args.out, force=args.force,
                    quiet=args.quiet, dask=args.dask, log=args.log, glob=args.glob)
    return api.run_plan(plan).exit_code
