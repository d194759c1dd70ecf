"""The text of ``columns.md``, which ``pipeline run`` writes into ``--out``: the files of the folder
and every column of every report, each table from the declarations of its columns (their name,
unit and meaning), so the file says what the reports hold in the words of the code that fills
them.
"""
from __future__ import annotations

from .outfiles import (MANIFEST, RESUME, RISK_CSV, RISK_DISAGG_CSV, RISK_RECORDS_CSV,
                       RISK_WIDTHS_CSV)
from .shapes import GOVERNING_RULE


def _section(title, intro, columns) -> list[str]:
    """The lines of one section: its title, its introduction (None: none) and the table of
    ``columns`` (``(name, unit, meaning)``)."""
    lines = ["", f"## {title}", ""] + ([intro, ""] if intro is not None else [])
    lines += ["| column | unit | meaning |", "|---|---|---|"]
    return lines + [f"| `{n}` | {u} | {_cell(d)} |" for n, u, d in columns]


def _cell(text: str) -> str:
    return text.replace("|", "\\|")  # a bare | would end the table cell


def _text(lines) -> str:
    return "\n".join(lines) + "\n"


def columns_md(columns, failure_columns, *, margin: bool, restitution: bool, risk: bool) -> str:
    """``columns.md`` of a run: ``columns`` and ``failure_columns`` are the ``(name, unit,
    meaning)`` of the per-record reports and of ``failures.csv``, in report order; ``margin``,
    ``restitution`` and ``risk``: the run's options add those columns (a performance level,
    ``--restitution``, ``--hazard``)."""
    out = _text(_records(columns, failure_columns)) + _text(_suite()) + _text(_design(margin, restitution))
    return out + (_text(_risk()) if risk else "")


def _records(columns, failure_columns) -> list[str]:
    """The files of the folder, and the columns of the per-record reports and of ``failures.csv``."""
    lines = [
        "# Reports of `pipeline run`",
        "",
        "Files in this folder:",
        "",
        "- `<record>.csv`: one per record, one row per column (`--block`) or height (`--height`).",
        "- `summary.csv`: the rows of every record's report, in input order (one row per record and column).",
        "- `failures.csv`: records that could not be processed, with the reason (header only when none failed).",
        "- `design.csv`: the answer, one row per record (a pair once) and column (below); printed at the end of the run.",
        "- `report.html`: the batch to review in a browser, opened from this folder (no server, no network).",
        "- `plots/<record>.png`: the record with its fitted pulses (paper's Fig. 4), its velocity with the "
        "extracted velocity pulse, and the rotation histories of each column as it stands, of its Eq. 31 "
        "design and at its design width under the full record (Figs. 9, 11); `plots/summary.png`: "
        "required against actual tan(alpha) across records.",
        "- `plots/widths/<record>.png` (only where the check above a search width found failing "
        "widths): the verdict against the width above the search width, a barcode of the widths "
        "that fail, with the design width (`failing_share`, `widest_failing_width_m`; docs/slivers.md).",
        "- `columns.md`: this file.",
        f"- `{MANIFEST}`: the files `pipeline run` wrote here (with a hash of their content). A later "
        "run into this folder replaces or removes only those, and only while their content is still "
        "what it wrote; any other file in its way is left as it is, and the run says so.",
        f"- `{RESUME}`: for each record computed, a key of its file content, options and "
        "the package's code (version, installed files, solver settings) and a hash of its report: a later run into this folder with the same "
        "command keeps those records and computes only the others (`--force`: all).",
        "",
        "Accelerations are in g (g = 9.81 m/s^2, the value of the paper the design rules come from, "
        "in every conversion; standard gravity is 9.80665 m/s^2), lengths in m, times in s. Numbers carry 6 significant "
        "digits; a blank cell means the value does not apply (or, in `<shape>_*` columns, that the shape "
        "does not fit or was not tried). Booleans are `True`/`False`.",
        "",
        "Text cells (file names, and what the records' headers say: `station`, `component`, `event`, "
        "...) that start with `=`, `+`, `-`, `@`, a tab or a carriage return get a leading apostrophe "
        "(`'`), so that a spreadsheet opening the file shows them as text and never evaluates them as "
        "a formula; numbers are written as they are.",
        "",
        "## Governing pulse",
        "",
        GOVERNING_RULE,
    ]
    lines += _section("Columns of `<record>.csv` and `summary.csv`", None, columns)
    return lines + _section("Columns of `failures.csv`", None, failure_columns)


def _suite() -> list[str]:
    """The sections of the suite's files (:mod:`pipeline.reports.suite`)."""
    from .suite import FRAGILITY_CURVE_COLUMNS, FRAGILITY_SUMMARY_COLUMNS, PAIR_COLUMNS, SUITE_COLUMNS

    lines = _section("Columns of `pairs.csv`",
                     "One row per record of the suite (a pair, or a single component) and column: the "
                     "row of `summary.csv` of its governing direction (the widest design width), "
                     "after these two columns.", PAIR_COLUMNS.columns)
    lines += _section("Columns of `suite.csv`",
                      "One row per column, over every record of the suite (failed records left out; "
                      "they are in `failures.csv`). A record's *governing* design width is the widest "
                      "over its directions. `plots/suite.png`: share of the records whose governing "
                      "design width is at most a given width, with the column's width and the Eq. 31 "
                      "widths marked.", SUITE_COLUMNS.columns)
    lines += _section("Columns of `fragility.csv` (`--fragility`)",
                      "One row per column as it stands: the lognormal collapse fragility of the suite. "
                      "`fragility_curve.csv` gives the fitted curves point by point, and "
                      "`plots/fragility.png` draws them with the records' critical values.",
                      FRAGILITY_SUMMARY_COLUMNS.columns)
    return lines + _section("Columns of `fragility_curve.csv`", "The fitted curves, 60 points each "
                            "(median x exp(z beta), z from -2.5 to 2.5).", FRAGILITY_CURVE_COLUMNS.columns)


def _design(margin: bool, restitution: bool) -> list[str]:
    """The section of ``design.csv`` (its columns as :func:`pipeline.reports.design_table.design_columns`)."""
    from .design_table import design_columns

    return _section("Columns of `design.csv`",
                    "One row per record (a pair once, by its governing direction) and column: the answer of "
                    "the run, also printed at its end. `summary.csv` has every value. `report.html` shows "
                    "these rows (a click on a heading sorts them), every record's classification, fitted "
                    "pulse, verdicts and figure, and the failures: open it in a browser from this folder.",
                    design_columns(margin, restitution))


def _risk() -> list[str]:
    """The sections of the risk files (``--hazard``, :mod:`pipeline.batch.risk`)."""
    from rocking.risk import rows

    lines = []
    for name, intro, cols in (
            (RISK_CSV, "One row per column and failure mode as it stands, and one for the width for "
                       "the target. `fragility.xml`: each column's fragility as an OpenQuake NRML "
                       "fragility model (continuous logncdf; mean and stddev of the measure).",
             rows.RISK_COLUMNS),
            (RISK_RECORDS_CSV, "The critical values the fragilities are fitted to, record by record.",
             rows.RECORD_COLUMNS),
            (RISK_WIDTHS_CSV, "Every width computed for the target (`plots/risk_widths.png`).",
             rows.WIDTH_COLUMNS),
            (RISK_DISAGG_CSV, "The rate per interval of the hazard curve "
                              "(`plots/risk_disaggregation.png`).", rows.DISAGGREGATION_COLUMNS)):
        lines += _section(f"Columns of `{name}` (`--hazard`)", intro, cols.columns)
    return lines
