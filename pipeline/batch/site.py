"""Design for a site in ``pipeline run``: the site's options and columns of a task's rows (pair,
direction, scale, velocity pulse), the task's ground motion, suite results and collapse fragility.

A *task* of ``pipeline run`` is one ground motion to design for: a single component file, or one
horizontal direction of a pair of components (:mod:`pipeline.batch.pairs` makes them; a direction and its
opposite give the same width: the column is symmetric).  The component at ``theta`` is
``pulses.component(a1, a2, theta)``.

After the run, the rows of every task are gathered here: ``pairs.csv`` (each pair's governing
direction: the widest design width), ``suite.csv`` (widths and survival shares over the records
of the suite) and, with ``--fragility``, ``fragility.csv`` and ``fragility_curve.csv``.  Nothing
here re-implements the library: pairing, rotation and classification come from :mod:`pulses`,
widths, simulations and critical scales from :mod:`rocking`.
"""
from __future__ import annotations

import math

from . import memo, peer_inputs
from .pairs import SiteError, directions  # noqa: F401 (tests import directions here)
from .peer_inputs import PEER_TP
from ..reports.pulse_row import NOT_PULSE_WARNING, RUN_PULSE_COLUMNS, classification_fields  # noqa: F401 (tests import them here)
from ..args import SCALE_RANGE, parse_cap_mass_ratio, parse_up_to
from ..reports.report import (FRAGILITY_CSV, FRAGILITY_CURVE_CSV, FRAGILITY_PLOT, PAIRS_CSV, SUITE_CSV, SUITE_PLOT,
                     Columns)




# -- report columns ----------------------------------------------------------------------------------
SITE_COLUMNS = Columns(
    ("pair", "-", "The record this row belongs to in the suite: for a pair of components "
                  "(`--pair`, `--pairs auto`) the pair's id (the first file's id, `+`, what differs "
                  "in the second's), one per direction row; for a single component its record id."),
    ("file2", "-", "The second component's path for a pair (the first is `file`); blank for a single "
                   "component."),
    ("direction_deg", "deg", "Direction of the ground motion designed for, from the first component "
                             "towards the second (0..180; the component at theta is "
                             "a1 cos(theta) + a2 sin(theta)); blank for a single component."),
    ("direction_kind", "-", "Why this direction: `component-1`, `component-2` (the recorded "
                            "components), `pulse` (the strongest velocity pulse's direction, "
                            "`orientation_deg`), `pulse-normal` (90 deg from it) or `even` "
                            "(`--directions N`); blank for a single component."),
    ("direction_azimuth_deg", "deg", "Azimuth of that direction, clockwise from north (0..180), where "
                                     "the files state the components' azimuths; else blank."),
    ("scale", "-", "Factor every sample of the record was multiplied by (`--scale`, `--scales`; 1 "
                   "otherwise). Every other column describes the scaled record."),
    ("cap_mass_ratio", "-", "Mass of the cap beam over the columns' total mass (`--cap-mass-ratio`): "
                            "0 for a lone column, above 0 for a rocking frame of such columns "
                            "(docs/theory.md section 8: the frame's p and restitution are used throughout)."),
    # the velocity-pulse columns (pipeline.reports.pulse_row), PEER's period beside the package's
    *RUN_PULSE_COLUMNS.around(
        "velocity_tp_s",
        (PEER_TP, "s", "PEER's pulse period of the record (`Tp-Pulse Period` of a PEER download's "
                       "`_SearchResults.csv`), to compare with `velocity_tp_s`; blank when PEER gives "
                       "none (`-`: not pulse-like in its search) or the record is not from a PEER download.")),
)

ENVELOPE_COLUMNS = Columns(
    ("envelope_width_m", "m", "Width a column of this height needs by the envelope rule "
                              "(`rocking.required_width`, rule envelope, with each fitting shape's "
                              "factor; fixed point in B): the widest over the shapes that fit."),
    ("envelope_width_overturns", "-", "The envelope design overturns under the full record."),
)

FRAGILITY_COLUMNS = Columns(
    ("critical_scale", "-", "`--fragility`: smallest factor k (on this row's record, already scaled "
                            "by `scale`) for which k times the record overturns the column as it "
                            "stands (with `--limit` R: makes max|theta|/alpha exceed R; `rocking.critical_scale`: "
                            "a scan that respects safe islands, refined to 1e-6); blank when no factor up to `fragility_up_to` does, or "
                            "without `--fragility`."),
    ("critical_pga_g", "g", "PGA of the record at its critical scale."),
    ("critical_islands", "-", "Factor ranges above `critical_scale` where the column survives again "
                              "(`a-b`, `;`-separated; the last may end at `fragility_up_to`)."),
    ("uplift_scale", "-", "Below this factor the column never uplifts (g tan(alpha) / PGA)."),
    ("fragility_up_to", "-", "Largest factor examined."),
)


def pair_of(task) -> str:
    """The pair a task's rows belong to (``pair`` in the reports): a single record is its own."""
    return task.pair or task.record_id


def site_fields(task, record, classification=None) -> tuple[dict, str | None]:
    """The :data:`SITE_COLUMNS` group of one task's rows, and the warning to add (or None);
    ``classification``: the record's :class:`pulses.PulseClassification` where already made."""
    cls, warning = classification_fields(record, pair_fields=dict(task.pair_fields) or None,
                                         result=classification)
    az = None
    if task.path2 is not None:
        az = record.metadata.get("azimuth")
        az = None if az is None else float(az) % 180.0
    fields = {"pair": pair_of(task), "file2": task.path2,
              "direction_deg": task.direction, "direction_kind": task.direction_kind or None,
              "direction_azimuth_deg": az, "scale": float(task.scale),
              "cap_mass_ratio": float(task.options.cap_mass_ratio)}
    fields.update(cls)
    fields[PEER_TP] = peer_inputs.tp(task)
    return SITE_COLUMNS.row(fields), warning


def read_task(task):
    """The ground motion of a task: one file, or the component of a pair in its direction; scaled."""
    import pulses

    if getattr(task, "peer", None) is not None:
        return peer_inputs.read_task(task)
    opts = task.options
    kw = dict(format=opts.format, units=opts.units, dt=opts.dt, column=opts.column, trace=opts.trace)
    if task.path2 is None:
        record = pulses.read_record(task.path, **kw)
    else:
        read = lambda: pulses.read_pair(task.path, task.path2, **kw)  # noqa: E731
        try:
            key = (memo.file_key(task.path), memo.file_key(task.path2), repr(sorted(kw.items())))
        except OSError:  # read_pair says what is wrong
            first, second = read()
        else:
            first, second = memo.remembered("pair", key, read)
        record = pulses.component(first, second, task.direction)
    return record.scaled(task.scale) if task.scale != 1.0 else record


def extra_fields(H, block, record, fitting, options, cache, body="rectangular") -> dict:
    """The envelope design and (``--fragility``) the critical scale of one row (a column of
    ``body``'s shape, rocking.bodies)."""
    import rocking

    from . import margin

    g = options.cap_mass_ratio
    key = ("envelope", H) if body == "rectangular" else ("envelope", H, body)
    if key not in cache:
        widths = [float(rocking.required_width(H, c.pulse, rule="envelope", shape=c.shape,
                                               cap_mass_ratio=g, body=body).width) for c in fitting]
        w = max(widths)
        res = margin.simulate(H, w, record, options, body=body)[1]
        cache[key] = ENVELOPE_COLUMNS.row({"envelope_width_m": w,
                                           "envelope_width_overturns": bool(res.overturned)})
    fields = dict(cache[key])
    if not options.fragility or block is None:
        fields.update(FRAGILITY_COLUMNS.blank())
        return fields
    from pulses import G

    # with a restitution band, the weakest of its values (the smallest critical scale)
    scales = [rocking.critical_scale(b, record, up_to=options.up_to, limit=options.fragility_limit)
              for b in margin.blocks(H, block.width, options)]
    cs = min(scales, key=lambda s: math.inf if s.scale is None else s.scale)
    fields.update(FRAGILITY_COLUMNS.row({
        "critical_scale": cs.scale,
        "critical_pga_g": None if cs.critical_pga is None else cs.critical_pga / G,
        "critical_islands": "; ".join(f"{a:.6g}-{b:.6g}" for a, b in cs.islands),
        "uplift_scale": float(cs.uplift_scale), "fragility_up_to": float(cs.up_to),
    }))
    return fields


# -- command line ----------------------------------------------------------------------------------
#: largest scale factor accepted (``--scale``, ``--scales``, ``--up-to``): :data:`pipeline.args.SCALE_RANGE`
MAX_SCALE = SCALE_RANGE[1]


def add_options(parser) -> None:
    """The site options of ``pipeline run``."""
    import argparse

    from ..args import add_pair_options

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


def options_from_args(args) -> dict:
    """``cap_mass_ratio``, ``fragility``, ``up_to`` of :class:`pipeline.batch.tasks.Options`
    (the rules of :mod:`pipeline.args`, which ``pipeline.design()`` follows too; ``--limit`` and
    ``--restitution``: :func:`pipeline.commands.run.options_from`)."""
    return {"cap_mass_ratio": parse_cap_mass_ratio(args.cap_mass_ratio), "fragility": bool(args.fragility),
            "up_to": parse_up_to(args.up_to)}


# -- after the run: pairs, suite, fragility -----------------------------------------------------------
PAIR_COLUMNS = Columns(
    ("n_directions", "-", "Directions designed for (rows of this pair and column in `summary.csv`)."),
    ("n_directions_failed", "-", "Directions of this pair that failed (in `failures.csv`): where not "
                                 "0, the governing direction is the widest of the others only."),
    ("governing_direction_deg", "deg", "The direction whose design width is widest (the first such "
                                       "in angle order); blank for a single component."),
)


def _groups(rows):
    """``{(column label, pair): [rows]}`` in first-seen order."""
    out = {}
    for r in rows:
        out.setdefault((r["column"], r["pair"]), []).append(r)
    return out


def governing_rows(rows, failed=None) -> list[dict]:
    """One row per pair (or single record) and column: its direction with the widest design width.
    ``failed``: ``{pair: directions that failed}``."""
    out = []
    for (_, pair), group in _groups(rows).items():
        gov = max(group, key=lambda r: r["design_width_m"])  # first of equal widths
        row = PAIR_COLUMNS.row({"n_directions": len(group), "n_directions_failed": (failed or {}).get(pair, 0),
                                "governing_direction_deg": gov["direction_deg"]})
        row.update(gov)
        out.append(row)
    return out


SUITE_COLUMNS = Columns(
    ("column", "-", "The column as given (`HxW` or `H`)."),
    ("column_kind", "-", "`block` or `height` (as in `summary.csv`)."),
    ("height_m", "m", "Full height of the column."),
    ("width_m", "m", "Full width of the column as it stands (blank for `--height`)."),
    ("cap_mass_ratio", "-", "Cap beam mass over the columns' mass (0: a lone column)."),
    ("n_records", "-", "Records of the suite with results: a pair counts once, whatever its directions."),
    ("n_rows", "-", "Record directions with results (rows of `summary.csv` for this column)."),
    ("width_all_m", "m", "Width that survives every record in every direction: the largest design "
                         "width of the suite."),
    ("width_all_but_one_m", "m", "Width that survives all records but one (each record counted by its "
                                 "governing direction): the second largest governing design width "
                                 "(blank with fewer than two records)."),
    ("design_width_median_m", "m", "Median of the records' governing design widths."),
    ("design_width_p84_m", "m", "84th percentile of the records' governing design widths (linear "
                                  "interpolation between order statistics, numpy's default)."),
    ("eq31_width_max_m", "m", "Largest Eq. 31 width over the records and directions."),
    ("share_column_survives", "-", "Share of the records under which the column as it stands does not "
                                   "overturn, in any direction (blank for `--height`)."),
    ("share_column_adequate", "-", "Share of the records whose governing design width the column as it "
                                   "stands reaches (so it survives them with no safe island)."),
    ("share_column_checked", "-", "Share of the records whose governing design width the column as it "
                                  "stands reaches and that the check above the search width "
                                  "(`failing_share`, docs/slivers.md) found no failing width at or above "
                                  "the column's width, in any direction: judged with the same check as "
                                  "each record's `widest_failing_width_m` (blank for `--height`)."),
    ("share_eq31_survives", "-", "Share of the records under which the column's Eq. 31 design (for each "
                                 "direction, its own Eq. 31 width) does not overturn, in any direction."),
    ("share_envelope_survives", "-", "Same for the envelope-rule design (`envelope_width_m`)."),
)


def checked(row, width) -> bool:
    """A column ``width`` wide reaches the row's design width and is wider than every failing
    width the check above it found (docs/slivers.md)."""
    widest = row.get("widest_failing_width_m")
    return (width is not None and float(width) >= float(row["design_width_m"])
            and (widest is None or float(width) > float(widest)))


def suite_rows(rows) -> list[dict]:
    """``suite.csv``: one row per column over every record of the suite."""
    import numpy as np

    by_column = {}
    for r in rows:
        by_column.setdefault(r["column"], []).append(r)
    out = []
    for label, crows in by_column.items():
        groups = _groups(crows)
        gov = np.array([max(r["design_width_m"] for r in g) for g in groups.values()])
        first = crows[0]
        is_block = first["column_kind"] == "block"

        def share(pred):
            return sum(all(pred(r) for r in g) for g in groups.values()) / len(groups)

        ranked = np.sort(gov)[::-1]
        out.append(SUITE_COLUMNS.row({
            "column": label, "column_kind": first["column_kind"], "height_m": first["height_m"],
            "width_m": first["width_m"], "cap_mass_ratio": first["cap_mass_ratio"],
            "n_records": len(groups), "n_rows": len(crows),
            "width_all_m": float(ranked[0]),
            "width_all_but_one_m": float(ranked[1]) if ranked.size > 1 else None,
            "design_width_median_m": float(np.median(gov)),
            "design_width_p84_m": float(np.percentile(gov, 84)),
            "eq31_width_max_m": max(float(r["eq31_width_m"]) for r in crows),
            "share_column_survives": share(lambda r: not r["overturns"]) if is_block else None,
            "share_column_adequate": share(lambda r: bool(r["design_adequate"])) if is_block else None,
            "share_column_checked": share(lambda r: checked(r, first["width_m"])) if is_block else None,
            "share_eq31_survives": share(lambda r: not r["eq31_width_overturns"]),
            "share_envelope_survives": share(lambda r: not r["envelope_width_overturns"]),
        }))
    return out


FRAGILITY_SUMMARY_COLUMNS = Columns(
    ("column", "-", "The column as it stands (`HxW`)."),
    ("n_records", "-", "Records fitted; each record counts by its weakest direction (the smallest "
                       "critical scale over its directions)."),
    ("n_overturned", "-", "Records that overturn the column at some factor up to `fragility_up_to` "
                          "(the others are right-censored there); blank with `--limit` (the critical "
                          "scales are then those of the level: `n_failed_at_level`)."),
    ("n_failed_at_level", "-", "With `--limit` R: records that make max|theta|/alpha exceed R (or "
                               "overturn the column) at some factor up to `fragility_up_to` (the "
                               "others are right-censored there); blank without `--limit`."),
    ("median_scale", "-", "Median critical scale factor (lognormal fit by maximum likelihood, "
                          "`rocking.fragility`)."),
    ("beta_scale", "-", "Lognormal dispersion of the critical scale factors."),
    ("median_pga_g", "g", "Median critical PGA (PGA of the critically scaled records)."),
    ("beta_pga", "-", "Lognormal dispersion of the critical PGAs."),
    ("error", "-", "Why no curve could be fitted (e.g. fewer than two records overturn, or exceed "
                   "the level); else blank."),
)
FRAGILITY_CURVE_COLUMNS = Columns(
    ("column", "-", "The column as it stands."),
    ("scale", "-", "Scale factor on the records."),
    ("p_overturn_scale", "-", "Fitted probability of overturning (with `--limit` R: of exceeding "
                              "max|theta|/alpha = R) at this scale factor."),
    ("pga_g", "g", "Scaled PGA."),
    ("p_overturn_pga", "-", "Fitted probability of overturning (with `--limit` R: of exceeding R) "
                            "at this PGA."),
)
#: points of each fragility curve in ``fragility_curve.csv``
CURVE_POINTS = 60


def _critical(group, limit=None):
    """The weakest direction of one record: a :class:`rocking.CriticalScale`-like entry for
    :func:`rocking.fragility` (scale, PGA and the largest factor examined; ``limit`` the level of
    the critical scales, None: overturning)."""
    from pulses import G
    from rocking.fragility import CriticalScale

    def key(r):
        return math.inf if r["critical_scale"] is None else r["critical_scale"]

    r = min(group, key=key)
    pga = r["pga_g"] * G
    return CriticalScale(scale=r["critical_scale"], islands=[], up_to=r["fragility_up_to"],
                         uplift_scale=r["uplift_scale"], pga=pga, n_scan=0, step=0.0, resolution=0.0,
                         near=0.0, rtol=0.0, runs=0, calls=0, limit=limit)


def fragility_tables(rows, limit=None):
    """``(summary rows, curve rows, fits)`` of ``--fragility``; ``fits`` maps a column to
    ``(Fragility by scale, Fragility by PGA, critical entries)`` for the plot; ``limit``: the level
    of the critical scales (``Options.fragility_limit``; None: collapse, overturning)."""
    import numpy as np
    import rocking

    by_column = {}
    for r in rows:
        if r["column_kind"] == "block" and r["fragility_up_to"] is not None:
            by_column.setdefault(r["column"], []).append(r)
    summary, curve, fits = [], [], {}
    for label, crows in by_column.items():
        entries = [_critical(g, limit) for g in _groups(crows).values()]
        n_failed = sum(e.scale is not None for e in entries)
        level = entries[0].limit if entries else None
        # a critical scale under a level is where max|theta|/alpha first exceeds it: it does not
        # say whether the column overturns, so the count goes to its own column
        base = {"column": label, "n_records": len(entries),
                "n_overturned": n_failed if level is None else None,
                "n_failed_at_level": n_failed if level is not None else None}
        try:
            fs = rocking.fragility(entries, measure="scale", limit=level)
            fp = rocking.fragility(entries, measure="pga", limit=level)
        except ValueError as exc:
            summary.append(FRAGILITY_SUMMARY_COLUMNS.row({**base, "median_scale": None, "beta_scale": None,
                                                          "median_pga_g": None, "beta_pga": None,
                                                          "error": str(exc)}))
            continue
        summary.append(FRAGILITY_SUMMARY_COLUMNS.row({**base, "median_scale": fs.median, "beta_scale": fs.beta,
                                                      "median_pga_g": fp.median, "beta_pga": fp.beta,
                                                      "error": None}))
        fits[label] = (fs, fp, entries)
        zs = np.linspace(-2.5, 2.5, CURVE_POINTS)
        for z in zs:
            s, a = fs.median * math.exp(z * fs.beta), fp.median * math.exp(z * fp.beta)
            curve.append(FRAGILITY_CURVE_COLUMNS.row({"column": label, "scale": s,
                                                      "p_overturn_scale": fs.probability(s),
                                                      "pga_g": a, "p_overturn_pga": fp.probability(a)}))
    return summary, curve, fits


# -- files -----------------------------------------------------------------------------------------------


def write_outputs(outputs, rows, fields, options, failed=None, render=None) -> None:
    """Write ``pairs.csv``, ``suite.csv`` (and their plots) and, with ``--fragility``, the fragility
    files, from every row of the run (``failed``: ``{pair: directions that failed}``); ``render(fn,
    *args)`` draws a figure (default: here; pipeline.batch.executors.renderer)."""
    from ..reports import report
    from ..reports.figures import draw

    render = render or draw

    pair_fields = list(PAIR_COLUMNS.names) + list(fields)
    outputs.write(PAIRS_CSV, report.csv_text(pair_fields, governing_rows(rows, failed)))
    suite = suite_rows(rows) if rows else []
    outputs.write(SUITE_CSV, report.csv_text(list(SUITE_COLUMNS.names), suite))
    if options.plots and rows:
        outputs.write(SUITE_PLOT, render("plot_site:suite_figure_png", rows, suite))
    if options.fragility:
        summary, curve, fits = fragility_tables(rows, options.fragility_limit)
        outputs.write(FRAGILITY_CSV, report.csv_text(list(FRAGILITY_SUMMARY_COLUMNS.names), summary))
        outputs.write(FRAGILITY_CURVE_CSV, report.csv_text(list(FRAGILITY_CURVE_COLUMNS.names), curve))
        if options.plots and fits:
            outputs.write(FRAGILITY_PLOT, render("plot_site:fragility_figure_png", fits))


def columns_markdown() -> str:
    """The sections of ``columns.md`` for the site files."""
    cell = lambda text: text.replace("|", "\\|")

    def table(title, intro, columns):
        lines = ["", f"## {title}", "", intro, "", "| column | unit | meaning |", "|---|---|---|"]
        return lines + [f"| `{n}` | {u} | {cell(d)} |" for n, u, d in columns]

    lines = table("Columns of `pairs.csv`",
                  "One row per record of the suite (a pair, or a single component) and column: the "
                  "row of `summary.csv` of its governing direction (the widest design width), "
                  "after these two columns.", PAIR_COLUMNS.columns)
    lines += table("Columns of `suite.csv`",
                   "One row per column, over every record of the suite (failed records left out; "
                   "they are in `failures.csv`). A record's *governing* design width is the widest "
                   "over its directions. `plots/suite.png`: share of the records whose governing "
                   "design width is at most a given width, with the column's width and the Eq. 31 "
                   "widths marked.", SUITE_COLUMNS.columns)
    lines += table("Columns of `fragility.csv` (`--fragility`)",
                   "One row per column as it stands: the lognormal collapse fragility of the suite. "
                   "`fragility_curve.csv` gives the fitted curves point by point, and "
                   "`plots/fragility.png` draws them with the records' critical values.",
                   FRAGILITY_SUMMARY_COLUMNS.columns)
    lines += table("Columns of `fragility_curve.csv`", "The fitted curves, 60 points each "
                   "(median x exp(z beta), z from -2.5 to 2.5).", FRAGILITY_CURVE_COLUMNS.columns)
    return "\n".join(lines) + "\n"
