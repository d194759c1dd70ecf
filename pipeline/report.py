"""Report files of ``pipeline run``: per-record CSV, ``summary.csv``, ``failures.csv``, ``columns.md``.

Every file is written atomically (to a hidden temporary name in the same folder, then renamed), so an
interrupted run never leaves a half-written report, and the content depends only on the inputs (no
time stamps, fixed number formatting, input order), so re-running into the same folder gives
identical files.
"""
from __future__ import annotations

import contextlib
import csv
import io
import math
import os
import pathlib

#: shapes that get their own group of columns, in this order (``pulses.SHAPES`` names)
SHAPE_NAMES = ("sine", "ricker-sym", "ricker-anti", "rect")

#: a shape "fits" a record when its score is at least this fraction of the best score
FIT_TOLERANCE = 0.7

GOVERNING_RULE = (
    "Among the shapes that fit the record (score at least "
    f"{FIT_TOLERANCE:g} x the best shape's score, listed in `shapes_fitting`), the governing pulse is "
    "the one whose Eq. 31 fixed-point width at the column's height is largest (the most demanding "
    "design; ties go to the better fit). `eq31_width_m` and `governing_eq31_tan_alpha` use it. "
    "Eq. 31 designs depend on the shape, so this rule is conservative among plausible shapes; the "
    "verification under the full record (`overturns`, `eq31_width_overturns`, `verified_width_m`) "
    "does not depend on any shape and is the arbiter."
)


def _shape_key(shape: str) -> str:
    return shape.replace("-", "_")


def _record_columns():
    return [
        ("record", "-", "Record id: the file name without its extension, made unique in input order "
                        "(`-2`, `-3`, ...). The per-record report is `<record>.csv`."),
        ("file", "-", "The record's path as given on the command line."),
        ("station", "-", "Station code from the file header (blank when the format has none)."),
        ("component", "-", "Component or channel from the file header."),
        ("event", "-", "Event name from the file header."),
        ("format", "-", "File format the record was read as."),
        ("units", "-", "Units of the samples, as stated by the file header or given with `--units`; "
                       "samples are converted to m/s^2."),
        ("dt_s", "s", "Sampling interval."),
        ("npts", "-", "Number of samples."),
        ("duration_s", "s", "Time from the first to the last sample."),
        ("pga_g", "g", "Peak absolute ground acceleration."),
        ("pgv_m_s", "m/s", "Peak absolute ground velocity (from the fitter, after its baseline correction)."),
        ("warnings", "-", "Warnings raised while reading the record (such as a peak over 5 g), `; `-separated."),
        ("pulse_shape", "-", "Best-fitting pulse shape: `sine` (one-sine, Eq. 9), `ricker-sym` (symmetric "
                             "Ricker, Eq. 7), `ricker-anti` (antisymmetric Ricker, Eq. 8) or `rect` "
                             "(rectangular)."),
        ("pulse_ap_g", "g", "Amplitude ap of the best-fitting pulse, signed by its polarity."),
        ("pulse_tp_s", "s", "Period Tp of the best-fitting pulse (for the Rickers, the period at the peak "
                            "of the Fourier amplitude)."),
        ("pulse_t0_s", "s", "Arrival time (sine, rect) or centre (Rickers) of the best-fitting pulse, on "
                            "the record's time axis."),
        ("pulse_arrival_s", "s", "Time the best-fitting pulse starts: t0 for sine and rect, t0 - Tp/2 for "
                                 "the Rickers."),
        ("pulse_lp_m", "m", "Persistence length scale Lp = |ap| Tp^2 of the best-fitting pulse."),
        ("pulse_score", "-", "Fit quality of the best pulse: the fitter's score (share of the record's "
                             "energy the pulse explains, 0 to 1)."),
        ("pulse_correlation", "-", "Correlation between the best pulse and the record within the pulse "
                                   "window (-1 to 1)."),
        ("shapes_fitting", "-", f"Shapes that fit the record almost equally well (score at least "
                                f"{FIT_TOLERANCE:g} x the best score), best first, `;`-separated."),
    ]


def _column_columns():
    cols = [
        ("column", "-", "The column as given: `HxW` for `--block`, `H` for `--height`."),
        ("column_kind", "-", "`block` (a column as it stands, `--block`) or `height` (only the width a "
                             "column of this height needs, `--height`; the as-it-stands fields are blank)."),
        ("height_m", "m", "Full height H of the column."),
        ("width_m", "m", "Full width B of the column as it stands (blank for `--height`)."),
        ("tan_alpha", "-", "Slenderness tan(alpha) = B/H of the column as it stands."),
        ("alpha_deg", "deg", "Slenderness angle alpha = atan(B/H)."),
        ("p_rad_s", "rad/s", "Frequency parameter p = sqrt(3 g / (4 R)), R = sqrt((H/2)^2 + (B/2)^2)."),
        ("p_tp", "-", "p x Tp of the best-fitting pulse (dimensionless)."),
        ("eq31_tan_alpha", "-", "Eq. 31 minimum tan(alpha) = (ap/g) pTp / (1 + pTp) for the best-fitting "
                                "pulse at the column's p."),
        ("envelope_tan_alpha", "-", "Minimum tan(alpha) by the envelope rule (`rocking.envelope_rule`, "
                                    "conservative for every realisable shape) for the best-fitting pulse."),
        ("exact_tan_alpha", "-", "Exact minimum tan(alpha) for the best-fitting pulse at the column's p: the "
                                 "smallest slenderness that survives the pulse at that and every larger "
                                 "slenderness (time-history analysis, `rocking.min_slenderness`)."),
        ("governing_shape", "-", "Shape of the governing pulse (the rule is stated in `columns.md`)."),
        ("governing_ap_g", "g", "Amplitude of the governing pulse, signed."),
        ("governing_tp_s", "s", "Period of the governing pulse."),
        ("governing_eq31_tan_alpha", "-", "Eq. 31 minimum tan(alpha) for the governing pulse at the column's p."),
    ]
    for shape in SHAPE_NAMES:
        k = _shape_key(shape)
        cols += [
            (f"{k}_fits", "-", f"Whether the `{shape}` shape fits the record (see `shapes_fitting`); "
                               "blank when the shape was not tried (`--shapes`)."),
            (f"{k}_ap_g", "g", f"Amplitude of the best `{shape}` pulse, signed."),
            (f"{k}_tp_s", "s", f"Period of the best `{shape}` pulse."),
            (f"{k}_score", "-", f"Fit quality (score) of the best `{shape}` pulse."),
            (f"{k}_eq31_tan_alpha", "-", f"Eq. 31 minimum tan(alpha) for the `{shape}` pulse at the column's p."),
            (f"{k}_exact_tan_alpha", "-", f"Exact minimum tan(alpha) for the `{shape}` pulse at the column's "
                                          "p (only for shapes that fit)."),
            (f"{k}_eq31_width_m", "m", f"Width a column of this height needs by Eq. 31 for the `{shape}` "
                                       "pulse (fixed point in B; only for shapes that fit)."),
        ]
    cols += [
        ("eq31_adequate", "-", "The column as it stands satisfies Eq. 31 for the governing pulse "
                               "(tan_alpha >= governing_eq31_tan_alpha)."),
        ("overturns", "-", "The column as it stands overturns (|theta| reaches pi/2) under the full record."),
        ("exceeds_alpha", "-", "|theta| of the column as it stands passes alpha at some time under the full record."),
        ("max_theta_ratio", "-", "max|theta|/alpha of the column as it stands under the full record (at "
                                 "least pi/(2 alpha) when it overturns)."),
        ("n_impacts", "-", "Number of impacts of the column as it stands under the full record."),
        ("model", "-", "Solver model that answered for the column as it stands (`rocking.simulate`, model=auto)."),
        ("eq31_width_m", "m", "Width a column of this height needs by Eq. 31 for the governing pulse "
                              "(fixed point in B, since p depends on B; `rocking.required_width`, rule eq31)."),
        ("eq31_width_tan_alpha", "-", "tan(alpha) of the Eq. 31 design, eq31_width_m / height_m."),
        ("eq31_width_overturns", "-", "The Eq. 31 design overturns under the full record."),
        ("eq31_width_max_theta_ratio", "-", "max|theta|/alpha of the Eq. 31 design under the full record."),
        ("eq31_width_model", "-", "Solver model that answered for the Eq. 31 design."),
        ("verified_width_m", "m", "Verified width: the smallest width for which a column of this height "
                                  "survives the full record, at that width and every larger one (a search "
                                  "that finds every transition, so it is not fooled by safe islands; "
                                  "`rocking.required_width`, rule exact). Independent of the pulse fit."),
        ("verified_tan_alpha", "-", "tan(alpha) of the verified width, verified_width_m / height_m."),
        ("verified_adequate", "-", "The column as it stands is at least as wide as the verified width "
                                   "(blank for `--height`). A column that survives (`overturns` False) "
                                   "but is not verified-adequate stands on a safe island: some slightly "
                                   "wider column of the same height overturns under the same record."),
    ]
    return cols


#: (name, unit, description) of every column of the per-record reports and ``summary.csv``
COLUMNS = _record_columns() + _column_columns()
FIELDS = [name for name, _, _ in COLUMNS]

FAILURE_COLUMNS = [
    ("record", "-", "Record id (as in the per-record reports)."),
    ("file", "-", "The record's path as given."),
    ("stage", "-", "Where it failed: `read` (reading the file), `fit` (pulse fitting), `design` "
                   "(design rules), `verify` (full-record time histories), `plot`, `worker` (the "
                   "process running it died) or `internal` (an unforeseen error: please report it)."),
    ("error", "-", "Type of the error."),
    ("reason", "-", "The error message, in one line."),
]
FAILURE_FIELDS = [name for name, _, _ in FAILURE_COLUMNS]


# -- formatting --------------------------------------------------------------------------------
def fmt(value) -> str:
    """One cell: floats with 6 significant digits, booleans as True/False, None/NaN blank."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "True" if value else "False"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return "" if math.isnan(value) else ("inf" if value > 0 else "-inf")
        text = f"{value:.6g}"
        return "0" if text == "-0" else text
    try:  # numpy scalars
        import numpy as np

        if isinstance(value, np.bool_):
            return fmt(bool(value))
        if isinstance(value, np.integer):
            return str(int(value))
        if isinstance(value, np.floating):
            return fmt(float(value))
    except ImportError:  # pragma: no cover
        pass
    return " ".join(str(value).split())  # one line


def csv_text(fields, rows) -> str:
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(fields)
    for row in rows:
        writer.writerow([fmt(row.get(f)) for f in fields])
    return buf.getvalue()


# -- atomic writing ------------------------------------------------------------------------------
def write_atomic(path, data) -> pathlib.Path:
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and a rename.

    On any interruption (including Ctrl-C) the temporary file is removed and ``path`` keeps its
    previous content, if any.  Unchanged files are not rewritten.
    """
    path = pathlib.Path(path)
    raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    with contextlib.suppress(OSError):
        if path.is_file() and path.stat().st_size == len(raw) and path.read_bytes() == raw:
            return path
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        with open(tmp, "wb") as fh:
            fh.write(raw)
        os.replace(tmp, path)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
    return path


def remove_quietly(path) -> None:
    with contextlib.suppress(FileNotFoundError):
        pathlib.Path(path).unlink()


# -- the files -------------------------------------------------------------------------------------
def record_csv_path(out, record_id: str) -> pathlib.Path:
    return pathlib.Path(out) / f"{record_id}.csv"


def write_record_csv(out, record_id: str, rows) -> pathlib.Path:
    return write_atomic(record_csv_path(out, record_id), csv_text(FIELDS, rows))


def write_summary(out, rows) -> pathlib.Path:
    return write_atomic(pathlib.Path(out) / "summary.csv", csv_text(FIELDS, rows))


def write_failures(out, failures) -> pathlib.Path:
    return write_atomic(pathlib.Path(out) / "failures.csv", csv_text(FAILURE_FIELDS, failures))


def columns_markdown() -> str:
    lines = [
        "# Reports of `pipeline run`",
        "",
        "Files in this folder:",
        "",
        "- `<record>.csv`: one per record, one row per column (`--block`) or height (`--height`).",
        "- `summary.csv`: the rows of every record's report, in input order (one row per record and column).",
        "- `failures.csv`: records that could not be processed, with the reason (header only when none failed).",
        "- `plots/<record>.png`: the record with its fitted pulses (paper's Fig. 4) and the rotation "
        "histories of each column as it stands and of its Eq. 31 design under the full record "
        "(Figs. 9, 11); `plots/summary.png`: required against actual tan(alpha) across records.",
        "- `columns.md`: this file.",
        "",
        "Accelerations are in g (g = 9.81 m/s^2), lengths in m, times in s. Numbers carry 6 significant "
        "digits; a blank cell means the value does not apply (or, in `<shape>_*` columns, that the shape "
        "does not fit or was not tried). Booleans are `True`/`False`.",
        "",
        "## Governing pulse",
        "",
        GOVERNING_RULE,
        "",
        "## Columns of `<record>.csv` and `summary.csv`",
        "",
        "| column | unit | meaning |",
        "|---|---|---|",
    ]
    cell = lambda text: text.replace("|", "\\|")  # a bare | would end the table cell
    lines += [f"| `{n}` | {u} | {cell(d)} |" for n, u, d in COLUMNS]
    lines += ["", "## Columns of `failures.csv`", "", "| column | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{n}` | {u} | {cell(d)} |" for n, u, d in FAILURE_COLUMNS]
    return "\n".join(lines) + "\n"


def write_columns_md(out) -> pathlib.Path:
    return write_atomic(pathlib.Path(out) / "columns.md", columns_markdown())
