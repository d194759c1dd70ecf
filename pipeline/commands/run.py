"""``pipeline run``: records in, column designs checked under the full records out, for one record or a whole database.

This module owns every option of ``pipeline run``: it declares them (:func:`add_parser`, the groups
shared with other commands from :mod:`pipeline.args`), reads their text by the rules of
:mod:`pipeline.values` into a :class:`pipeline.plan.Plan` of values (:func:`plan_of`), and runs it
as :func:`pipeline.design` does (:func:`pipeline.api.run_plan`): the batch takes values, never
the command line's text.
"""
from __future__ import annotations

import argparse

from ..args import (ShapeNames, add_pair_options, add_record_options, add_restitution_option,
                    add_weighting_option, record_options)
from ..values import (ArgumentError, jobs_count, parse_cap_mass_ratio, parse_column_block, parse_column_height,
                      parse_directions, parse_friction, parse_limit, parse_restitution, parse_scale,
                      parse_shapes, parse_up_to)

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
    add_site_options(p)
    p.add_argument("--peer-scales", action="store_true",
                   help="PEER downloads: multiply each record by the search's scale factor "
                        "(_SearchResults.csv); by default records are designed as recorded")
    p.add_argument("--vertical", choices=["auto", "none"], default="auto",
                   help="auto (default): where a record's vertical is known (PEER downloads, "
                        "--triplet, --pairs auto), add the response of each column as it stands "
                        "with it (vertical_* columns); none: horizontal motion only")
    p.add_argument("--triplet", nargs=3, action="append", default=[], metavar=("H1", "H2", "V"),
                   help="design H1 and H2 as a pair (as --pair) with V as their vertical; V must "
                        "state its polarity (UP or DWN in its name or header); repeatable")
    add_risk_options(p)
    add_common(p, DEFAULT_OUT)
    p.set_defaults(func=main)


def add_site_options(parser) -> None:
    """Pairs in several directions, scaled suites, frames and fragility."""
    add_pair_options(parser, default="none", action="design, in several directions, for")
    parser.add_argument("--directions", metavar="N", default="0",
                        help="for pairs, add N evenly spaced directions over 0-180 deg to the two "
                             "components, the velocity-pulse direction and its normal")
    parser.add_argument("--scale", metavar="K", default=None, help="multiply every record by K")
    parser.add_argument("--scales", metavar="FILE.csv",
                        help="scale factors per record: a CSV with columns record (or file) and scale")
    parser.add_argument("--cap-mass-ratio", metavar="G", default="0",
                        help="design rocking frames: cap beam mass over the columns' mass (default 0, "
                             "lone columns)")
    parser.add_argument("--fragility", action=argparse.BooleanOptionalAction, default=False,
                        help="collapse fragility of each --block column as it stands: the critical "
                             "scale factor per record and direction, the suite's lognormal curve "
                             "(with --limit R given, the fragility of exceeding max|theta|/alpha = R)")
    parser.add_argument("--up-to", metavar="K", default="10",
                        help="--fragility: largest scale factor examined (default 10)")


def add_risk_options(parser) -> None:
    """Risk at a site: the hazard curve and its options (:mod:`pipeline.batch.risk`)."""
    g = parser.add_argument_group("risk at a site (docs/risk.md)")
    g.add_argument("--hazard", metavar="FILE",
                   help="the site's hazard curve: an OpenQuake hazard_curve CSV, an nshmp-haz "
                        "curves/<IMT>/total.csv, a USGS hazard web service JSON, or a two-column CSV "
                        "(level, annual rate); gives each column's annual rate of overturning")
    g.add_argument("--site", metavar="LON,LAT", help="--hazard with several sites: the site's location")
    g.add_argument("--site-row", metavar="N", help="--hazard with several sites: the site's row (from 1)")
    g.add_argument("--imt", metavar="MEASURE",
                   help="--hazard: the measure (PGA, PGV, SA(T)) where the file does not say, or the "
                        "one to take from a file of several")
    g.add_argument("--hazard-units", metavar="UNITS",
                   help="--hazard: the levels' units where the file does not say (g, m/s2, cm/s2; "
                        "cm/s, m/s for PGV); --units is the records'")
    g.add_argument("--years", metavar="N", default="50",
                   help="--hazard: the probability of failure in N years (default 50)")
    g.add_argument("--age", metavar="A", help="--hazard: also the probability of having stood A years")
    target = g.add_mutually_exclusive_group()
    target.add_argument("--target-rate", metavar="X",
                        help="--hazard: the narrowest width whose annual rate of failure is at most X "
                             "(e.g. 1e-4)")
    target.add_argument("--target-poe", metavar="P%/N",
                        help="--hazard: the same for a probability P in N years (e.g. 2%%/50)")
    g.add_argument("--risk-seed", metavar="S", default="0",
                   help="--hazard: seed of the restitution drawn per record from its band (default 0)")


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
    """The batch's :class:`pipeline.batch.tasks.Options` of the options ``run`` and ``demo`` share
    (``overrides``: those of ``run`` alone)."""
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


def risk_options(args, restitution=None):
    """The checked :class:`pipeline.batch.risk.RiskOptions` of ``--hazard`` and its options (None
    without ``--hazard``); ``restitution``: the run's (``--restitution``), sampled per record."""
    from ..batch import risk

    others = [o for o, v in (("--site", args.site), ("--site-row", args.site_row), ("--imt", args.imt),
                             ("--hazard-units", args.hazard_units), ("--age", args.age),
                             ("--target-rate", args.target_rate), ("--target-poe", args.target_poe))
              if v is not None]
    if args.hazard is None:
        if others:
            raise ArgumentError(f"{others[0]} needs --hazard FILE (the site's hazard curve)")
        return None
    return risk.risk_options(args.hazard, site=None if args.site is None else _site(args.site),
                             site_row=args.site_row, imt=args.imt, units=args.hazard_units, years=args.years,
                             age=args.age, target_rate=args.target_rate, target_poe=args.target_poe,
                             restitution=restitution, seed=args.risk_seed)


def _site(text):
    """``--site LON,LAT``: ``(lon, lat)`` in degrees."""
    parts = str(text).replace(" ", "").split(",")
    try:
        lon, lat = (float(p) for p in parts)
    except ValueError:
        raise ArgumentError(f"--site: expected LON,LAT in degrees (e.g. -118.25,34.05), got {text!r}") from None
    return lon, lat


def plan_of(args):
    """The :class:`pipeline.plan.Plan` of ``pipeline run``'s parsed arguments: every option read by
    its rule (:mod:`pipeline.values`), as :func:`pipeline.design` reads its arguments."""
    from ..batch.tasks import ReadOptions
    from ..plan import Plan

    columns = build_columns(args.block, args.height)
    jobs = parse_jobs(args.jobs)
    options = options_from(args, shapes=parse_shapes(args.shapes), weighting=args.weighting,
                           friction=parse_friction(args.friction), vertical=args.vertical,
                           read=ReadOptions(**record_options(args)),
                           cap_mass_ratio=parse_cap_mass_ratio(args.cap_mass_ratio),
                           fragility=bool(args.fragility), up_to=parse_up_to(args.up_to),
                           risk=risk_options(args, parse_restitution(args.restitution)))
    return Plan(records=list(args.records), columns=columns, options=options, pairs=args.pairs,
                pair=[tuple(ab) for ab in args.pair],
                triplets={(str(a), str(b)): str(v) for a, b, v in args.triplet},
                directions=parse_directions(args.directions),
                scale=None if args.scale is None else parse_scale(args.scale, "--scale"),
                scales=args.scales, peer_scales=args.peer_scales, jobs=jobs, out=args.out, force=args.force,
                quiet=args.quiet, dask=args.dask, log=args.log, glob=args.glob)


def main(args) -> int:
    """``pipeline run``: its arguments read into a plan of values (:func:`plan_of`), which runs as
    :func:`pipeline.design`'s does (the same plan, so the same tasks and numbers)."""
    from .. import api

    return api.run_plan(plan_of(args)).exit_code
