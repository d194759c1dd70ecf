"""The answer of ``pipeline run`` in view: ``design.csv`` and the table printed at the end of a run.

One row per record (a pair counts once, by its governing direction: the widest verified width) and
column, with what an engineer decides on: is the record pulse-like, which pulse governs Eq. 31,
the width Eq. 31 asks for, the verified width under the full record, and whether the column as it
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
    ("direction_deg", "deg", "For a pair: the governing direction (the widest verified width); blank "
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
    ("verified_width_m", "m", "Verified width: the smallest width surviving the full record at it and "
                              "at every larger width (for a pair: the widest over its directions)."),
    ("width_m", "m", "Width of the column as it stands (blank for `--height`)."),
    ("survives", "-", "The column as it stands does not overturn under the record (in any direction "
                      "of a pair); blank for `--height`."),
    ("verified_adequate", "-", "The column as it stands is at least the verified width (it survives "
                               "with no safe island); blank for `--height`."),
    ("max_theta_ratio", "-", "Largest max|theta|/alpha of the column as it stands over the directions."),
)
DESIGN_FIELDS = list(DESIGN_COLUMNS.names)


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


def _num(value):
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def design_rows(rows, failed=None) -> list[dict]:
    """The rows of ``design.csv`` from the rows of ``summary.csv`` (dicts of typed values) and
    ``failed`` (``{pair: directions that failed}``)."""
    out = []
    for (pair, column), group in _groups(rows).items():
        gov = max(group, key=lambda r: _num(r.get("verified_width_m")) or -math.inf)  # first of equals
        block = gov.get("column_kind") == "block"
        ratios = [_num(r.get("max_theta_ratio")) for r in group]
        ratios = [v for v in ratios if v is not None]
        out.append(DESIGN_COLUMNS.row({
            "record": pair, "column": column,
            "direction_deg": gov.get("direction_deg"),
            "n_directions": len(group), "n_directions_failed": (failed or {}).get(pair, 0),
            "scale": gov.get("scale"),
            "pulse_like": gov.get("pulse_like"), "velocity_tp_s": gov.get("velocity_tp_s"),
            "governing_shape": gov.get("governing_shape"), "governing_ap_g": gov.get("governing_ap_g"),
            "governing_tp_s": gov.get("governing_tp_s"),
            "eq31_width_m": gov.get("eq31_width_m"), "eq31_width_overturns": gov.get("eq31_width_overturns"),
            "verified_width_m": gov.get("verified_width_m"),
            "width_m": gov.get("width_m") if block else None,
            "survives": (None if not block else
                         _bool_all([None if r.get("overturns") is None else not r["overturns"] for r in group])),
            "verified_adequate": _bool_all([r.get("verified_adequate") for r in group]) if block else None,
            "max_theta_ratio": max(ratios) if (block and ratios) else None,
        }))
    return out


def design_csv(rows, failed=None) -> str:
    """The text of ``design.csv``."""
    return csv_text(DESIGN_FIELDS, design_rows(rows, failed))


# -- the printed table -------------------------------------------------------------------------------
def _yes(value, yes="yes", no="no"):
    if value is None:
        return "-"
    return yes if value else no


def _m(value):
    v = _num(value)
    return "-" if v is None else f"{v:.3f}"


def pulse_text(row) -> str:
    """``sine +0.71g 0.80s``: the governing pulse of a design row."""
    shape, ap, tp = row.get("governing_shape"), _num(row.get("governing_ap_g")), _num(row.get("governing_tp_s"))
    if not shape or ap is None or tp is None:
        return "-"
    return f"{shape} {ap:+.2f}g {tp:.2f}s"


def survives_text(row) -> str:
    """``yes``, ``yes, safe island`` (survives, but narrower than the verified width), ``NO`` or ``-``."""
    s = row.get("survives")
    if s is None:
        return "-"
    if not s:
        return "NO"
    return "yes" if row.get("verified_adequate") else "yes, safe island"


HEADERS = ("record", "column", "pulse-like", "governing pulse", "Eq.31 width", "verified width", "survives")


def table_cells(row) -> tuple[str, ...]:
    """The printed cells of one design row (also the batch table of ``report.html``)."""
    name = display(row["record"])
    d = _num(row.get("direction_deg"))
    if d is not None and (row.get("n_directions") or 1) > 1:
        name += f" @{d:.0f}deg"
    return (name, display(row.get("column") or "-"), _yes(row.get("pulse_like")), pulse_text(row),
            _m(row.get("eq31_width_m")) + (" m" if _num(row.get("eq31_width_m")) is not None else ""),
            _m(row.get("verified_width_m")) + (" m" if _num(row.get("verified_width_m")) is not None else ""),
            survives_text(row))


def table_text(rows, failures=()) -> str:
    """The compact table printed at the end of ``pipeline run``: every design row, then every failed
    record (``failures``: rows of ``failures.csv``) with its reason."""
    body = [table_cells(r) for r in rows]
    widths = [max([len(h)] + [len(c[i]) for c in body]) for i, h in enumerate(HEADERS)]
    right = {4, 5}  # widths, aligned on the decimal point

    def line(cells):
        return "  ".join(c.rjust(w) if i in right else c.ljust(w)
                         for i, (c, w) in enumerate(zip(cells, widths))).rstrip()

    lines = [line(HEADERS), line(["-" * w for w in widths])]
    lines += [line(c) for c in body]
    for f in failures:
        lines.append(f"{display(f['record'])}  failed ({f['stage']}): {' '.join(display(f['reason']).split())}")
    return "\n".join(lines) + "\n"


def columns_markdown() -> str:
    """The section of ``columns.md`` for ``design.csv``."""
    cell = lambda text: text.replace("|", "\\|")
    lines = ["", "## Columns of `design.csv`", "",
             "One row per record (a pair once, by its governing direction) and column: the answer of "
             "the run, also printed at its end. `summary.csv` has every value. `report.html` shows "
             "these rows (a click on a heading sorts them), every record's classification, fitted "
             "pulse, verdicts and figure, and the failures: open it in a browser from this folder.", "",
             "| column | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{n}` | {u} | {cell(d)} |" for n, u, d in DESIGN_COLUMNS.columns]
    return "\n".join(lines) + "\n"
