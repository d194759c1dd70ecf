"""The answer of ``pipeline run`` in view: ``design.csv`` and the table printed at the end of a run.

One row per record (a pair counts once, by its governing direction: the widest design width) and
column, with what an engineer decides on: is the record pulse-like, which pulse governs Eq. 31,
the width Eq. 31 asks for, the design width under the full record, and whether the column as it
stands survives.  Computed from the rows of ``summary.csv`` as written (so a resumed run prints and
writes the same), which stays complete.  The same rows in words, as the run prints them and
``report.html`` heads with them: :mod:`pipeline.reports.answer`.
"""
from __future__ import annotations

import math

from .columns import Columns, csv_text

DESIGN_COLUMNS = Columns(
    ("record", "-", "The record (for a pair of components: the pair, `pair` in `summary.csv`)."),
    ("column", "-", "The column as given: `HxW` for `--block`, `H` for `--height`."),
    ("direction_deg", "deg", "For a pair: the governing direction (the widest design width); blank "
                             "for a single component."),
    ("n_directions", "-", "Directions designed for (1 for a single component)."),
    ("n_directions_failed", "-", "Directions that failed (in `failures.csv`); where not 0, the row "
                                 "covers the others only."),
    ("scale", "-", "Factor the record was multiplied by (1 unless `--scale`, `--scales`)."),
    ("pulse_like", "-", "Pulse-like by Shahi & Baker's velocity-pulse classification (blank when "
                        "the classification failed)."),
    ("velocity_tp_s", "s", "Period of the extracted velocity pulse."),
    ("governing_shape", "-", "Shape of the acceleration pulse that governs Eq. 31 (see `columns.md`)."),
    ("governing_ap_g", "g", "Its amplitude ap, signed."),
    ("governing_tp_s", "s", "Its period Tp."),
    ("eq31_width_m", "m", "Width the column's height needs by Eq. 31 for the governing pulse."),
    ("eq31_width_overturns", "-", "That Eq. 31 design overturns under the full record."),
    ("design_width_m", "m", "Design width: the smallest width surviving the full record at it and at "
                              "every larger width examined, above every width the search and the check "
                              "found to fail, with the vertical where there is one (for a pair: the "
                              "widest over its directions; `--limit` R: max|theta|/alpha <= R)."),
    ("width_m", "m", "Width of the column as it stands (blank for `--height`)."),
    ("survives", "-", "The column as it stands does not overturn under the record (in any direction "
                      "of a pair); blank for `--height`."),
    ("design_adequate", "-", "The column as it stands is at least the design width (it survives "
                               "with no safe island); blank for `--height`."),
    ("max_theta_ratio", "-", "Largest max|theta|/alpha of the column as it stands over the directions."),
    ("widest_failing_width_m", "m", "Widest width found to overturn above the search width by the check "
                                    "after the search (over the directions; docs/slivers.md); blank where "
                                    "none was found, which does not prove there is none."),
    ("survives_vertical", "-", "The column as it stands does not overturn with the record's vertical "
                               "component too (in any direction of a pair); blank without a vertical. "
                               "False also where the block lifts off (`vertical_lift_off_s`): the "
                               "response stops there, and nothing shows that the column survives."),
    ("search_width_m", "m", "Diagnostic: the search's first transition in the governing direction, "
                            "before the check above it (docs/slivers.md); the design width is at least this."),
    ("design_governed_by", "-", "`horizontal` or `with vertical`: which motion sets the design width "
                                "(blank without a vertical)."),
    ("design_limit", "-", "`--limit` R (max|theta|/alpha <= R); blank: overturning."),
    ("overturning_width_m", "m", "With `--limit`: the overturning design width where it can change the "
                                 "level's, as in summary.csv (for a pair: the widest over its "
                                 "directions); the design width is at least it, and at least the "
                                 "overturning design width in full (a width that overturns fails "
                                 "every level). Blank without `--limit`."),
    ("eq31_below_design", "-", "The Eq. 31 width is below the design width (Eq. 31 is not conservative "
                               "for this record)."),
    ("verdict", "-", "The column as it stands: `survives` (under a level: and keeps max|theta|/alpha "
                     "<= R), `NO` (overturns), `NO: exceeds level` (under a level: it does not "
                     "overturn, but max|theta|/alpha exceeds R), `NO: safe island` (it survives but "
                     "is narrower than the design width: a wider column fails); blank for `--height`."),
    ("check_runs", "-", "Widths the check ran above the search width in the governing direction."),
    ("vertical_lift_off_s", "s", "Earliest time at which g + av < 0 before the response ended, over "
                                 "the directions: the block leaves the ground, which the rocking model "
                                 "does not describe (its own verdict, `lifts off at t s`); blank when "
                                 "it never does."),
    ("body", "-", "The body that rocks: `rectangular` or `cylinder (planar rocking)` (`cyl:`)."),
    ("friction_demand", "-", "The largest friction coefficient the rocking needs, over the "
                             "directions, of the column as it stands and at its design width "
                             "(max |F_x|/F_z, docs/theory.md \"Friction\")."),
    ("slides", "-", "With `--friction MU`: the column as it stands or at its design width needs more "
                    "than MU in some direction: it slides, outside the rocking model (`validity` "
                    "says where and when); blank without `--friction`."),
    ("validity", "-", "Which model answered and its checks in the governing direction (body, "
                      "restitution, friction, lift-off with the vertical; `summary.csv` has "
                      "every direction's)."),
)
#: with ``--hazard`` (pipeline.batch.risk): each column's answer at the site, in each of its rows
RISK_COLUMNS = Columns(
    ("site_rate_per_year", "1/yr", "`--hazard`: the column as it stands: annual rate of overturning "
                                   "at the site (the suite's fragility against the hazard curve; "
                                   "with `--limit`, of exceeding the level; `risk.csv`), the same in "
                                   "every row of the column."),
    ("target_width_m", "m", "`--target-rate`/`--target-poe`: the narrowest width whose rate at the "
                            "site meets the target (`risk.csv`), beside the record-by-record "
                            "`design_width_m`; the same in every row of the column (the target "
                            "is in `risk.csv`)."),
)
DESIGN_COLUMNS = Columns(*DESIGN_COLUMNS.columns, *RISK_COLUMNS.columns)
DESIGN_FIELDS = list(DESIGN_COLUMNS.names)

#: under a performance level (the default): max|theta|/alpha at the design width and at the verge
MARGIN_DESIGN_COLUMNS = Columns(
    ("design_max_theta_ratio", "-", "max|theta|/alpha of a column of the design width under the record "
                                    "(its governing direction; as in summary.csv): at most `design_limit`."),
    ("overturning_max_theta_ratio", "-", "max|theta|/alpha of a column of `overturning_width_m`, the verge "
                                         "(no margin), under the record (the direction it comes from): 1 or "
                                         "more where the column passes its slenderness angle there."),
)
#: with ``--restitution``: the restitution of the row's design
RESTITUTION_DESIGN_COLUMNS = Columns(
    ("restitution", "-", "`--restitution` as given (a factor of Eq. 5, `eta=V` or `r=V`; `LOW:HIGH` a band)."),
    ("restitution_values_run", "-", "Single values of the restitution run (a band: its values, ends included)."),
    ("restitution_governing", "-", "The value whose design width governs (the widest)."),
    ("design_eta", "-", "The velocity ratio eta at impact at the design width (the governing value)."),
    ("design_r", "-", "The energy ratio r = eta^2 at impact at the design width."),
)


def design_columns(margin: bool = False, restitution: bool = False) -> tuple:
    """The columns of ``design.csv``: :data:`DESIGN_COLUMNS`, with after ``overturning_width_m``
    the margin's (under a level) and the restitution's (with ``--restitution``)."""
    base = DESIGN_COLUMNS.columns
    k = DESIGN_COLUMNS.names.index("overturning_width_m") + 1
    extra = (MARGIN_DESIGN_COLUMNS.columns if margin else ()) + (
        RESTITUTION_DESIGN_COLUMNS.columns if restitution else ())
    return base[:k] + extra + base[k:]


def design_fields(rows) -> list:
    """The names of :func:`design_columns` for the rows of ``summary.csv`` (or of ``design.csv``)
    ``rows``: the extra groups where the rows have them."""
    first = rows[0] if rows else {}
    return [n for n, _, _ in design_columns("design_max_theta_ratio" in first, "restitution" in first)]


def _groups(rows):
    """``{(pair, column): [rows]}`` in first-seen order (pairs.csv groups the same way)."""
    out = {}
    for r in rows:
        out.setdefault((r.get("pair") or r.get("record"), r.get("column")), []).append(r)
    return out


def _bool_all(values):
    values = [v for v in values if v is not None]
    if not values:
        return None
    return all(bool(v) for v in values)


def number(value):
    """``value`` as a finite float, or None (blank cells, text, nan and inf read back from a report)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _widest(values, above=None):
    """The largest of ``values`` if it is above ``above`` (a failing width of one direction below the
    pair's design width is no failure of the design), else None."""
    values = [v for v in map(number, values) if v is not None]
    if not values or (above is not None and max(values) <= above):
        return None
    return max(values)


def _whole(value):
    """``15`` for the number 15.0 read back from a report (an RSN, a year), else the text."""
    v = number(value)
    return str(int(v)) if v is not None and v == int(v) else str(value)


def _at_widest(group, width, value):
    """``value`` of the row of ``group`` whose ``width`` is the widest (the first of equals)."""
    rows = [r for r in group if number(r.get(width)) is not None]
    return max(rows, key=lambda r: number(r[width])).get(value) if rows else None


def _extra(gov, group) -> dict:
    """The margin's and the restitution's cells of a design row, where the rows have them."""
    out = {}
    if "design_max_theta_ratio" in gov:
        out.update(MARGIN_DESIGN_COLUMNS.row({
            "design_max_theta_ratio": gov.get("design_max_theta_ratio"),
            "overturning_max_theta_ratio": _at_widest(group, "overturning_width_m", "overturning_max_theta_ratio")}))
    if "restitution" in gov:
        out.update(RESTITUTION_DESIGN_COLUMNS.row({k: gov.get(k) for k in RESTITUTION_DESIGN_COLUMNS.names}))
    return out


def _meets(r, limit):
    """The column as it stands survives the row's record (and keeps max|theta|/alpha <= limit)."""
    if r.get("overturns") is None:
        return None
    ratio = number(r.get("max_theta_ratio"))
    return (not r["overturns"]) and (limit is None or (ratio is not None and ratio <= limit))


def design_rows(rows, failed=None, risk=None) -> list[dict]:
    """The rows of ``design.csv`` from the rows of ``summary.csv`` (dicts of typed values) and
    ``failed`` (``{pair: directions that failed}``); ``risk``: ``{column: its answer at the site}``
    (pipeline.batch.risk.answer_fields), blank without."""
    out = []
    for (pair, column), group in _groups(rows).items():
        gov = max(group, key=lambda r: number(r.get("design_width_m")) or -math.inf)  # first of equals
        block = gov.get("column_kind") == "block"
        limit = number(gov.get("design_limit"))
        ratios = [number(r.get("max_theta_ratio")) for r in group]
        ratios = [v for v in ratios if v is not None]
        survives = _bool_all([_meets(r, limit) for r in group]) if block else None
        overturns = None if not block else any(bool(r.get("overturns")) for r in group)
        adequate = _bool_all([r.get("design_adequate") for r in group]) if block else None
        w31, wd = number(gov.get("eq31_width_m")), number(gov.get("design_width_m"))
        row = DESIGN_COLUMNS.row({
            "record": pair, "column": column,
            "direction_deg": gov.get("direction_deg"),
            "n_directions": len(group), "n_directions_failed": (failed or {}).get(pair, 0),
            "scale": gov.get("scale"),
            "pulse_like": gov.get("pulse_like"), "velocity_tp_s": gov.get("velocity_tp_s"),
            "governing_shape": gov.get("governing_shape"), "governing_ap_g": gov.get("governing_ap_g"),
            "governing_tp_s": gov.get("governing_tp_s"),
            "eq31_width_m": gov.get("eq31_width_m"), "eq31_width_overturns": gov.get("eq31_width_overturns"),
            "design_width_m": gov.get("design_width_m"),
            "width_m": gov.get("width_m") if block else None,
            "survives": survives, "design_adequate": adequate,
            "max_theta_ratio": max(ratios) if (block and ratios) else None,
            "widest_failing_width_m": _widest([r.get("widest_failing_width_m") for r in group],
                                              above=number(gov.get("search_width_m"))),
            "survives_vertical": (None if not block else _bool_all(
                [None if r.get("vertical_overturns") is None else not (r["vertical_overturns"] or r.get("vertical_lifts_off"))
                 for r in group])),
            "search_width_m": gov.get("search_width_m"), "design_governed_by": gov.get("design_governed_by"),
            "design_limit": limit,
            "overturning_width_m": _widest([r.get("overturning_width_m") for r in group]),
            "eq31_below_design": None if (w31 is None or wd is None) else w31 < wd,
            "check_runs": gov.get("check_runs"),
            "verdict": None if survives is None else verdict_text({"survives": survives,
                                                                   "design_adequate": adequate,
                                                                   "overturns": overturns,
                                                                   "design_limit": limit}),
            "vertical_lift_off_s": (None if not block else min(
                [t for t in (number(r.get("vertical_t_lift_off_s")) for r in group if r.get("vertical_lifts_off"))
                 if t is not None], default=None)),
            **{k: (risk or {}).get(column, {}).get(k) for k in RISK_COLUMNS.names},
            **_validity(group, gov),
        })
        row.update(_extra(gov, group))
        out.append(row)
    return out


def _validity(group, gov) -> dict:
    """The design row's ``body``, ``friction_demand``, ``slides`` and ``validity``."""
    demands = [number(r.get(k)) for r in group for k in ("friction_demand", "design_friction_demand")]
    demands = [d for d in demands if d is not None]
    judged = [r for r in group if number(r.get("friction_mu")) is not None]
    slides = None
    if judged:
        slides = any(bool(r.get("slides")) or bool(r.get("design_slides")) for r in judged)
    return {"body": gov.get("body"), "friction_demand": max(demands) if demands else None,
            "slides": slides, "validity": gov.get("validity")}


def verdict_text(row) -> str:
    """``survives``, ``NO`` (overturns), ``NO: exceeds level`` (under a level ``design_limit``: it
    does not overturn, but max|theta|/alpha exceeds the level), ``NO: safe island`` (survives,
    but narrower than the design width: a wider column fails) or ``-``."""
    s = row.get("survives")
    if s is None:
        return "-"
    if not s:
        level = number(row.get("design_limit")) is not None
        return "NO: exceeds level" if level and row.get("overturns") is False else "NO"
    return "survives" if row.get("design_adequate") else "NO: safe island"


def design_csv(rows, failed=None) -> str:
    """The text of ``design.csv``."""
    return csv_text(design_fields(rows), design_rows(rows, failed))
