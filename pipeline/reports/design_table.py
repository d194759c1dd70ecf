"""The answer of ``pipeline run`` in view: ``design.csv`` and the table printed at the end of a run.

One row per record (a pair counts once, by its governing direction: the widest design width) and
column, with what an engineer decides on: is the record pulse-like, which pulse governs Eq. 31,
the width Eq. 31 asks for, the design width under the full record, and whether the column as it
stands survives.  Computed from the rows of ``summary.csv`` as written (so a resumed run prints and
writes the same), which stays complete.
"""
from __future__ import annotations

import math

from .report import Columns, csv_text, display

#: the file in ``--out``
DESIGN_CSV = "design.csv"

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


def design_csv(rows, failed=None) -> str:
    """The text of ``design.csv``."""
    return csv_text(design_fields(rows), design_rows(rows, failed))


# -- the printed table -------------------------------------------------------------------------------
def _yes(value, yes="yes", no="no"):
    if value is None:
        return "-"
    return yes if value else no


def _m(value):
    v = number(value)
    return "-" if v is None else f"{v:.3f}"


def excess_text(value, reference) -> str | None:
    """``+2.5 %``: how far the width ``value`` lies above the ``reference`` width (the search
    width, in the reports), relative to it.

    Whole percent from 10 % (``+25 %``), tenths from 1 % (``+2.5 %``), hundredths below
    (``+0.25 %``, ``+0.02 %``) and ``<+0.01 %`` below 0.01 %, so that a failing width a hair above
    the reference never reads as ``+0.0 %``.  None when either is blank or ``value`` is not
    above ``reference``.
    """
    v, ref = number(value), number(reference)
    if v is None or ref is None or ref <= 0 or v <= ref:
        return None
    pct = 100.0 * (v - ref) / ref
    if pct < 0.01:
        return "<+0.01 %"
    return f"+{pct:.{0 if pct >= 10 else 1 if pct >= 1 else 2}f} %"


def failing_text(value, reference, unit=" m") -> str | None:
    """``0.608 m (+2.5 %)``: a failing width with how far it lies above ``reference``
    (:func:`excess_text`; metres only where that is blank); None where ``value`` is blank.
    ``unit=""`` gives ``0.608 (+2.5 %)`` for a column headed in metres."""
    v = number(value)
    if v is None:
        return None
    excess = excess_text(v, reference)
    return f"{v:.3f}{unit}" + (f" ({excess})" if excess else "")


def pulse_text(row) -> str:
    """``sine +0.71g 0.80s``: the governing pulse of a design row."""
    shape, ap, tp = row.get("governing_shape"), number(row.get("governing_ap_g")), number(row.get("governing_tp_s"))
    if not shape or ap is None or tp is None:
        return "-"
    return f"{shape} {ap:+.2f}g {tp:.2f}s"


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


def survives_text(row) -> str:
    """The printed verdict of the column as it stands (:func:`verdict_text`, ``yes`` for survives,
    the level's value for ``NO: exceeds level``), with ``passes alpha`` where the column does not
    overturn but its max|theta|/alpha reaches 1 (it passes its slenderness angle and comes
    back)."""
    text = row.get("verdict") or verdict_text(row)
    text = {"survives": "yes", "NO: exceeds level": f"NO: exceeds {number(row.get('design_limit')) or 0:g}"}.get(text, text)
    ratio = number(row.get("max_theta_ratio"))
    if text not in ("-", "NO") and ratio is not None and ratio >= 1.0:
        text = "NO: passes alpha" if text.startswith("NO: exceeds") else text + ", passes alpha"
    return text


def passes_text(ratio) -> str:
    """``, passes alpha`` where ``ratio`` (max|theta|/alpha of a column that does not overturn) is
    1 or more: the column passes its slenderness angle and comes back; else ``""``."""
    r = number(ratio)
    return ", passes alpha" if r is not None and r >= 1.0 else ""


def eq31_text(row) -> str:
    """``2.441 m``, or ``0.400 m BELOW`` where the Eq. 31 width is below the design width (``,
    overturns`` where its design overturns under the record; ``, passes alpha`` where it does not
    but passes its slenderness angle, ``eq31_width_max_theta_ratio`` where the row has it)."""
    text = _m(row.get("eq31_width_m"))
    if text == "-":
        return text
    text += " m"
    if row.get("eq31_below_design"):
        text += " BELOW" + (", overturns" if row.get("eq31_width_overturns") else "")
    if not row.get("eq31_width_overturns"):
        text += passes_text(row.get("eq31_width_max_theta_ratio"))
    return text


def design_text(row) -> str:
    """``1.907 m``: the design width (`` (vertical)`` where the vertical governs, ``, passes
    alpha`` where a column of it passes its slenderness angle)."""
    w = number(row.get("design_width_m"))
    if w is None:
        return "-"
    return (f"{w:.3f} m" + (" (vertical)" if row.get("design_governed_by") == "with vertical" else "")
            + passes_text(row.get("design_max_theta_ratio")))


def verge_text(row) -> str:
    """``1.683 m, passes alpha``: the verge beside a level's design width (the overturning design
    width, no margin), with whether a column of it passes its slenderness angle."""
    w = number(row.get("overturning_width_m"))
    if w is None:
        return "-"
    return f"{w:.3f} m" + passes_text(row.get("overturning_max_theta_ratio"))


HEADERS = ("record", "column", "pulse-like", "governing pulse", "Eq.31 width", "design width",
           "search width", "survives")
#: the heading of the column added under a performance level (the default): the verge beside the
#: design width
VERGE_HEADER = "verge (no margin)"
#: the heading of the column added where a run used vertical components
VERTICAL_HEADER = "with vertical"


def table_cells(row) -> tuple[str, ...]:
    """The printed cells of one design row (also the batch table of ``report.html``): those of
    :data:`HEADERS`, with the verge after the design width where the row has the margin's columns
    (a performance level)."""
    name = display(row["record"])
    d = number(row.get("direction_deg"))
    if d is not None and (row.get("n_directions") or 1) > 1:
        name += f" @{d:.0f}deg"
    verge = (verge_text(row),) if "overturning_max_theta_ratio" in row else ()
    return (name, display(row.get("column") or "-"), _yes(row.get("pulse_like")), pulse_text(row),
            eq31_text(row), design_text(row)) + verge + (search_text(row), survives_text(row))


def headers_for(rows) -> tuple[str, ...]:
    """The printed table's headings for ``rows`` (:data:`HEADERS`, with :data:`VERGE_HEADER` after
    the design width under a level)."""
    if rows and "overturning_max_theta_ratio" in rows[0]:
        k = HEADERS.index("design width") + 1
        return HEADERS[:k] + (VERGE_HEADER,) + HEADERS[k:]
    return HEADERS


def search_text(row) -> str:
    """``0.584 m (-9.2 %)``: the search's first transition, with how far the design width lies
    above it (``-`` where blank)."""
    w = number(row.get("search_width_m"))
    if w is None:
        return "-"
    excess = excess_text(row.get("design_width_m"), w)
    return f"{w:.3f} m" + (f" ({excess})" if excess else "")


def vertical_text(row) -> str:
    """The verdict with the vertical: ``yes``, ``NO``, ``lifts off at 2.31 s`` (never ``yes``: the
    rocking model stops where the block leaves the ground) or ``-``."""
    t = number(row.get("vertical_lift_off_s"))
    if t is not None:
        return f"lifts off at {t:.2f} s"
    return _yes(row.get("survives_vertical"), no="NO")


def metadata_text(row) -> str | None:
    """``RSN77 San Fernando 1971, Pacoima Dam: M6.61 Reverse, Rrup 1.8 km, Vs30 2016 m/s; Tp 1.64 s
    (PEER), 1.64 s (here)`` for a row of a PEER download (``summary.csv``'s ``peer_*``); None otherwise."""
    if not row.get("peer_rsn"):
        return None
    year = _whole(row["peer_year"]) if row.get("peer_year") is not None else ""
    parts = [f"RSN{_whole(row['peer_rsn'])} {row.get('peer_event') or ''} {year}".rstrip()]
    if row.get("peer_station"):
        parts[0] += f", {row['peer_station']}"
    site = []
    if number(row.get("peer_magnitude")) is not None:
        site.append(f"M{number(row['peer_magnitude']):.2f}" + (f" {row['peer_mechanism']}" if row.get("peer_mechanism") else ""))
    for key, label, unit in (("peer_rrup_km", "Rrup", "km"), ("peer_vs30_m_s", "Vs30", "m/s")):
        if number(row.get(key)) is not None:
            site.append(f"{label} {number(row[key]):g} {unit}")
    tp = number(row.get("peer_tp_s"))
    ours = number(row.get("velocity_tp_s"))
    if tp is not None or ours is not None:
        site.append("velocity pulse Tp " + ("-" if tp is None else f"{tp:.2f} s") + " (PEER), "
                    + ("-" if ours is None else f"{ours:.2f} s") + " (here)")
    return display(parts[0] + (": " + ", ".join(site) if site else ""))


#: the printed columns right-aligned (widths, aligned on the decimal point)
_RIGHT = ("Eq.31 width", "design width", VERGE_HEADER, "search width")


def _align_failing(body, col):
    """``body`` with the cells of column ``col`` (``0.608 m (+2.5 %)`` or ``-``) padded so that
    their metres line up on the decimal point and their percentages start in one place."""
    parts = [c[col].partition(" (") for c in body]
    head = max((len(h) for h, _, _ in parts), default=0)
    tail = max((len(sep + t) for _, sep, t in parts), default=0)
    return [c[:col] + (h.rjust(head) + (sep + t).ljust(tail),) + c[col + 1:]
            for c, (h, sep, t) in zip(body, parts)]


def _key(row, record="record"):
    return row.get(record) if record == "record" else (row.get("pair") or row.get("record")), row.get("column"), \
        number(row.get("direction_deg"))


def eq31_ratios(summary) -> dict:
    """``{(record or pair, column, direction): max|theta|/alpha of the Eq. 31 design}`` of the rows
    of ``summary.csv``, for :func:`eq31_text` on the design rows."""
    return {_key(r, "pair"): r.get("eq31_width_max_theta_ratio") for r in summary}


def with_eq31_ratio(row, ratios) -> dict:
    """A design row with ``eq31_width_max_theta_ratio`` (from :func:`eq31_ratios`) for its cells."""
    return {**row, "eq31_width_max_theta_ratio": ratios.get(_key(row))}


def table_text(rows, failures=(), summary=()) -> str:
    """The compact table printed at the end of ``pipeline run``: every design row, then every failed
    record (``failures``: rows of ``failures.csv``) with its reason, then the search report's
    metadata of each record of a PEER download (``summary``: rows of ``summary.csv``)."""
    headers = headers_for(rows)
    ratios = eq31_ratios(summary)
    body = [table_cells(with_eq31_ratio(r, ratios)) for r in rows]
    if any(r.get("survives_vertical") is not None for r in rows):
        # the verdict with the vertical, and the design width with it (the widest over a pair's
        # directions, from summary.csv's rows) beside the horizontal one
        widths = {}
        for r in summary:
            key = (r.get("pair") or r.get("record"), r.get("column"))
            w = number(r.get("vertical_design_width_m"))
            if w is not None:
                widths[key] = max(w, widths.get(key, w))
        headers = headers + (VERTICAL_HEADER,)
        body = [c + (vertical_text(r) + (f", design {widths[(r['record'], r.get('column'))]:.3f} m"
                                          if (r["record"], r.get("column")) in widths else ""),)
                for c, r in zip(body, rows)]
    body = _align_failing(body, headers.index("search width"))
    widths = [max([len(h)] + [len(c[i]) for c in body]) for i, h in enumerate(headers)]
    right = {i for i, h in enumerate(headers) if h in _RIGHT}  # widths, aligned on the decimal point

    def line(cells):
        return "  ".join(c.rjust(w) if i in right else c.ljust(w)
                         for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

    lines = [line(headers), line(["-" * w for w in widths])]
    lines += [line(c) for c in body]
    for f in failures:
        lines.append(f"{display(f['record'])}  failed ({f['stage']}): {' '.join(display(f['reason']).split())}")
    lines += [""] + verdict_lines(rows) + [t for t in (governing_print(rows, summary), fine_print(rows)) if t]
    seen = {}
    for r in summary:
        text = metadata_text(r)
        if text:
            seen.setdefault(r.get("pair") or r.get("record"), text)
    if seen:
        lines.append("")
        lines += [f"{display(name)}: {text}" for name, text in seen.items()]
    return "\n".join(lines) + "\n"


def _count(rows, key, value=True) -> int:
    return sum(1 for r in rows if r.get(key) == value)


def verdict_lines(rows) -> list[str]:
    """The lines that end a run (and head ``report.html``): per column, the suite's answer (the
    design width covering every record), the Eq. 31 line, then the fine print of the design width."""
    by_column = {}
    for r in rows:
        by_column.setdefault(r.get("column"), []).append(r)
    out = []
    for column, group in by_column.items():
        widths = [(number(r.get("design_width_m")), r) for r in group]
        widths = [(w, r) for w, r in widths if w is not None]
        if not widths:
            continue
        top, gov = max(widths, key=lambda wr: wr[0])
        n = len(group)
        limit = number(gov.get("design_limit"))
        level = "" if limit is None else f" for max theta/alpha <= {limit:g}"
        line = (f"Suite, column {display(column)}: the design width covering all {n} record(s) is "
                f"{top:.3f} m{level} (set by {display(gov['record'])})")
        verges = [v for v in (number(r.get("overturning_width_m")) for r in group) if v is not None]
        if verges:
            line += f"; the verge (no margin) is {max(verges):.3f} m"
        if gov.get("width_m") is not None:
            safe = _count(group, "verdict", "NO: safe island")
            fails = _count(group, "verdict", "NO")
            exceed = _count(group, "verdict", "NO: exceeds level")
            line += (f"; as it stands ({number(gov['width_m']):.3f} m) it "
                     + ("passes: it survives every record" if not (safe or fails or exceed) and top <= number(gov["width_m"])
                        else f"FAILS: {fails} record(s) overturn it"
                        + ("" if limit is None else f", {exceed} exceed the level")
                        + f", {safe} leave it on a safe island"))
        out.append(line + risk_words(gov))
        out.append(eq31_line(group))
        out += _friction_line(column, group)
    return out


def eq31_line(group) -> str:
    """The Eq. 31 line of one column's design rows: how often its width is below the design width,
    and how often a column of that width overturns under its record."""
    n = len(group)
    below = _count(group, "eq31_below_design")
    over = _count(group, "eq31_width_overturns")
    return (f"Eq. 31 is below the design width on {below} of {n} record(s); a column of Eq. 31's width "
            f"overturns under {'none' if not over else f'{over} of them'}.")


def governing_print(rows, summary) -> str | None:
    """Why the governing pulse is not the best fit, where it is not on some record: the rule, and
    the records (``rows``: design rows, ``summary``: summary.csv's, whose ``pulse_shape`` is the
    best fit)."""
    best = {}
    for r in summary:
        key = (r.get("pair") or r.get("record"), r.get("column"), r.get("direction_deg"))
        best.setdefault(key, r.get("pulse_shape"))
    others = []
    for r in rows:
        shape = best.get((r.get("record"), r.get("column"), r.get("direction_deg")))
        if shape and r.get("governing_shape") and shape != r["governing_shape"]:
            others.append(f"{display(r['record'])} fits {shape} best")
    if not others:
        return None
    shown = "; ".join(dict.fromkeys(others[:3])) + ("; ..." if len(others) > 3 else "")
    return ("Governing pulse: of the shapes that fit almost as well as the best (a score at least 0.7 "
            "of its), the one whose Eq. 31 width is widest, since shapes that fit almost equally well "
            "can ask for very different columns; so it is not always the best fit "
            f"({len(others)} of {len(rows)} row(s) here: {shown}).")


def risk_words(row) -> str:
    """``; at the site it fails at 2.1e-04/yr; the width for the site's target rate is 2.140 m``
    from a design row's risk columns ("" without ``--hazard``; risk.csv says more)."""
    rate, width = (number(row.get(k)) for k in RISK_COLUMNS.names)
    text = ""
    if rate is not None:
        text += f"; at the site it fails at {rate:.2e}/yr"
    if width is not None:
        text += f"; the width for the site's target rate is {width:.3f} m"
    return text


def _friction_line(column, group) -> list[str]:
    """With ``--friction``: how many records make the column slide (outside the model)."""
    judged = [r for r in group if r.get("slides") is not None]
    if not judged:
        return []
    demand = max((number(r.get("friction_demand")) or 0.0) for r in judged)
    n = _count(judged, "slides")
    return [f"Friction, column {display(column)}: {n} of {len(judged)} record(s) make it slide "
            f"(as it stands or at its design width: outside the rocking model, see validity); "
            f"the rocking needs up to {demand:.3g}."]


def check_reach_words() -> str:
    """How far above the search width the check looks, in words ("1.5 times it";
    ``rocking.search.SearchSettings.check_span``)."""
    from rocking.search import DEFAULT_SETTINGS

    span = float(DEFAULT_SETTINGS.check_span)
    return "twice it" if span == 2.0 else f"{span:g} times it"


def check_bin_words() -> str:
    """The width of the check's bins, relative to the search width, in words ("0.5 %";
    ``rocking.search.SearchSettings.check_bin_width``)."""
    from rocking.search import DEFAULT_SETTINGS

    return f"{100.0 * float(DEFAULT_SETTINGS.check_bin_width):g} %"


def margin_print(rows) -> str:
    """What the design width keeps in reserve: under a level, the dependable width and the verge
    beside it; with ``--limit none``, that the design width is the verge; and where a quoted
    width lets the column pass its slenderness angle."""
    limits = {number(r.get("design_limit")) for r in rows if r.get("design_width_m") is not None}
    if not limits:
        return ""
    if limits == {None}:
        return ("Margin: none, the design width is the verge of overturning (--limit none): at it "
                "a column may pass its slenderness angle (max theta/alpha >= 1) and come back; "
                "without --limit the design width keeps max theta/alpha <= 0.5 (docs/design.md). ")
    shown = ", ".join(f"{v:g}" for v in sorted(v for v in limits if v is not None))
    passes = sum(1 for r in rows if passes_text(r.get("overturning_max_theta_ratio")))
    return (f"Margin: the design width keeps max theta/alpha <= {shown} under the record (0.5: the "
            "dependable design, peaks at or below alpha/2) and is at least the verge. Verge (no "
            "margin): the narrowest width found not to overturn; where the level governs it is "
            "checked only above the design width (--limit none checks it in full: it lies between "
            "the two)" + (f"; at the verge the column passes its slenderness angle on {passes} of "
                          f"{len(rows)} row(s) (passes alpha)" if passes else "") + ". ")


def fine_print(rows) -> str | None:
    """What the design width keeps in reserve (:func:`margin_print`) and what was tested above it
    (None where no check ran)."""
    runs = [number(r.get("check_runs")) for r in rows if number(r.get("check_runs"))]
    if not runs:
        return margin_print(rows).strip() or None
    return (margin_print(rows) + "Design width: at least every width the search and the check above it found to "
            f"fail, refined just above the widest; the check ran {min(runs):.0f}"
            + (f"-{max(runs):.0f}" if max(runs) > min(runs) else "")
            + f" widths per record from the search width up to {check_reach_words()} (or the "
            "no-uplift width), more where the response varied from one width to the next; thinner "
            "failing slivers may remain (docs/slivers.md). Search width: the "
            "search's first transition, with how far the design width lies above it.")


def columns_markdown(margin: bool = False, restitution: bool = False) -> str:
    """The section of ``columns.md`` for ``design.csv`` (its columns as :func:`design_columns`)."""
    cell = lambda text: text.replace("|", "\\|")
    lines = ["", "## Columns of `design.csv`", "",
             "One row per record (a pair once, by its governing direction) and column: the answer of "
             "the run, also printed at its end. `summary.csv` has every value. `report.html` shows "
             "these rows (a click on a heading sorts them), every record's classification, fitted "
             "pulse, verdicts and figure, and the failures: open it in a browser from this folder.", "",
             "| column | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{n}` | {u} | {cell(d)} |" for n, u, d in design_columns(margin, restitution)]
    return "\n".join(lines) + "\n"
