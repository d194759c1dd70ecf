"""The suite's tables of ``pipeline run``, made from the rows of ``summary.csv`` (as written, so a
resumed run makes the same): ``pairs.csv`` (each pair's governing direction: the widest design
width), ``suite.csv`` (widths and survival shares over the records of the suite) and, with
``--fragility``, ``fragility.csv`` and ``fragility_curve.csv`` (the suite's lognormal collapse
fragility, :func:`rocking.fragility`, fitted to the records' critical scales).
"""
from __future__ import annotations

import math

from .columns import TEXT, WHOLE, Columns
from .outfiles import FRAGILITY_CSV, FRAGILITY_CURVE_CSV, FRAGILITY_PLOT, PAIRS_CSV, SUITE_CSV, SUITE_PLOT


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
    ("column", "-", "The column as given (`HxW` or `H`).", TEXT),
    ("column_kind", "-", "`block` or `height` (as in `summary.csv`).", TEXT),
    ("height_m", "m", "Full height of the column."),
    ("width_m", "m", "Full width of the column as it stands (blank for `--height`)."),
    ("cap_mass_ratio", "-", "Cap beam mass over the columns' mass (0: a lone column)."),
    ("n_records", "-", "Records of the suite with results: a pair counts once, whatever its directions.", WHOLE),
    ("n_rows", "-", "Record directions with results (rows of `summary.csv` for this column).", WHOLE),
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
    from rocking import CriticalScale

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
def write_tables(outputs, rows, fields, options, failed=None, render=None) -> None:
    """Write ``pairs.csv``, ``suite.csv`` (and their plots) and, with ``--fragility``, the fragility
    files, from every row of the run (``failed``: ``{pair: directions that failed}``); ``render(fn,
    *args)`` draws a figure (default: here; pipeline.batch.executors.renderer); ``options``: the
    run's (``plots``, ``fragility``, ``fragility_limit``)."""
    from . import columns
    from .figures import draw

    render = render or draw

    pair_fields = list(PAIR_COLUMNS.names) + list(fields)
    outputs.write(PAIRS_CSV, columns.csv_text(pair_fields, governing_rows(rows, failed)))
    suite = suite_rows(rows) if rows else []
    outputs.write(SUITE_CSV, columns.csv_text(list(SUITE_COLUMNS.names), suite))
    if options.plots and rows:
        outputs.write(SUITE_PLOT, render("site:suite_figure_png", rows, suite))
    if options.fragility:
        summary, curve, fits = fragility_tables(rows, options.fragility_limit)
        outputs.write(FRAGILITY_CSV, columns.csv_text(list(FRAGILITY_SUMMARY_COLUMNS.names), summary))
        outputs.write(FRAGILITY_CURVE_CSV, columns.csv_text(list(FRAGILITY_CURVE_COLUMNS.names), curve))
        if options.plots and fits:
            outputs.write(FRAGILITY_PLOT, render("site:fragility_figure_png", fits))
