"""Per-record work of ``pipeline run``: read, fit, design, verify; plain rows out.

:func:`process_record` takes one :class:`Task` (plain, picklable data) and returns a plain dict, so it
runs the same in this process, in a process pool or on a dask worker.  It never raises for a bad record:
the failure comes back with the stage it happened in and the reason.  Everything it computes comes from
the library (``pulses.read_record``, ``pulses.fit_pulse``, ``rocking.simulate``, ``rocking.eq31``,
``rocking.envelope_rule``, ``rocking.min_slenderness_batch`` (``rocking.min_slenderness`` for several
blocks at once), ``rocking.required_width``); nothing here is a second implementation of them.
"""
from __future__ import annotations

import math
import threading
import time

from . import margin, memo, peer_inputs, site, validity, vertical
from ..reports.design_table import check_bin_words, check_reach_words
from ..reports.report import FIT_TOLERANCE, SHAPE_NAMES, Columns, _shape_key, shape_list
from .tasks import MAX_ID_LENGTH, RESERVED_IDS, Column, Options, Task, record_ids  # noqa: F401 (tests import them here)

class StageError(Exception):
    def __init__(self, stage, exc):
        super().__init__(str(exc))
        self.stage = stage
        self.exc = exc


# -- the work ---------------------------------------------------------------------------------------
def _g(x):
    from pulses import G

    return None if x is None else float(x) / G


def process_record(task: Task) -> dict:
    """Process one record; return ``{"index", "record", "file", "rows", "failure", "plot",
    "widths_plot", "seconds"}``.

    ``seconds`` maps each stage (``"verify:required_width"``, ...) to the time it took; it is for
    benchmarks and never written to the reports (which must not depend on timing).
    """
    _local.timings = {}
    try:
        out = _process_record(task)
    finally:
        timings, _local.timings = _local.timings, None
    out["seconds"] = timings
    return out


def _process_record(task: Task) -> dict:
    out = {"index": task.index, "record": task.record_id, "file": task.path, "rows": [],
           "failure": None, "plot": None, "widths_plot": None, "friction_plot": None}
    try:
        rows, fit_parts, designs, friction_parts = _process(task)
        out["rows"] = rows
    except StageError as err:
        out["failure"] = failure(task, err.stage, err.exc)
        return out
    except Exception as exc:  # anything unforeseen fails this record only, never the batch
        if _interrupted(exc):
            raise KeyboardInterrupt from exc
        out["failure"] = failure(task, "internal", exc)
        return out
    if task.options.plots and task.plot:
        from ..reports.plots import run_figure_png

        try:
            out["plot"] = _stage("plot", run_figure_png, task.record_id, *fit_parts)
            out["friction_plot"] = _stage("plot", _friction_png, task.record_id, *friction_parts)
            out["widths_plot"] = _stage("plot", _widths_png, task.record_id, designs)
        except StageError as err:
            out["failure"] = failure(task, err.stage, err.exc)
    return out


def _friction_png(record_id, frictions, mu):
    """``plots/friction/<record>.png``: the friction each column's responses need against time."""
    from ..reports.plot_friction import friction_png

    return friction_png(record_id, frictions, mu)


def _widths_png(record_id, designs):
    """``plots/widths/<record>.png`` where the check above a search width found failing widths
    (docs/slivers.md); None elsewhere."""
    from ..reports.plot_widths import record_widths_png

    return record_widths_png(record_id, {(f"{k:g} m" if not isinstance(k, tuple) else
                                          f"{k[1]} {k[0]:g} m"): v for k, v in designs.items()})


FAILURE_COLUMNS = Columns(
    ("record", "-", "Record id (as in the per-record reports)."),
    ("file", "-", "The record's path as given."),
    ("stage", "-", "Where it failed: `read` (reading the file), `fit` (pulse fitting), `classify` "
                   "(velocity-pulse classification), `design` (design rules), `verify` (full-record time histories), `plot`, `write` (the record "
                   "was processed and its rows are in `summary.csv`, but its own report or figure "
                   "could not be written, or a file that `pipeline run` did not write is in the way "
                   "and was left as it is), `worker` (the process running it died), `cluster` (the "
                   "dask scheduler was lost before the record was computed: run the same command "
                   "again to finish the batch) or `internal` (an unforeseen error: please report it)."),
    ("error", "-", "Type of the error."),
    ("reason", "-", "The error message, in one line."),
)
FAILURE_FIELDS = list(FAILURE_COLUMNS.names)


def failure(task: Task, stage: str, exc: BaseException) -> dict:
    """A row of ``failures.csv``."""
    reason = " ".join(str(exc).split()) or repr(exc)
    return FAILURE_COLUMNS.row({"record": task.record_id, "file": task.path, "stage": stage,
                                "error": type(exc).__name__, "reason": reason})


def _interrupted(exc: BaseException) -> bool:
    """True if ``exc`` is, or was caused by, Ctrl-C (compiled code wraps it in a SystemError)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


#: per-thread accumulator of the time spent in each stage of the record being processed
_local = threading.local()


def _stage(stage, fn, *args, **kwargs):
    t0 = time.perf_counter()
    try:
        return fn(*args, **kwargs)
    except (KeyboardInterrupt, SystemExit):
        raise
    except Exception as exc:  # every failure of a record is reported, never raised
        if _interrupted(exc):
            raise KeyboardInterrupt from exc
        raise StageError(stage, exc) from exc
    finally:
        timings = getattr(_local, "timings", None)
        if timings is not None:
            key = f"{stage}:{getattr(fn, '__name__', 'call').strip('_')}"
            timings[key] = timings.get(key, 0.0) + time.perf_counter() - t0


# -- report columns, each group declared next to the code that computes it -------------------------
# A row of ``<record>.csv`` / ``summary.csv`` is these groups in this order; ``Columns.row`` refuses
# a group whose keys differ from its declaration (an undeclared key, or a declared one not set).
RECORD_COLUMNS = Columns(
    ("record", "-", "Record id: the file name without its extension, made file-system safe (other "
                    "characters become `_`; a name longer than 96 characters is cut and ends in a "
                    "short hash of the whole name) and unique in input order (`-2`, `-3`, ...). The "
                    "per-record report is `<record>.csv`."),
    ("file", "-", "The record's path as given on the command line (bytes that are not UTF-8 written "
                  "as `\\xff`)."),
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
    ("pulse_shape", "-", f"Best-fitting pulse shape: {shape_list()}."),
    ("pulse_ap_g", "g", "Amplitude ap of the best-fitting pulse, signed by its polarity."),
    ("pulse_tp_s", "s", "Period Tp of the best-fitting pulse (for the Rickers, the period at the peak "
                        "of the Fourier amplitude)."),
    ("pulse_t0_s", "s", "Arrival time (sine, rect) or centre (Rickers) of the best-fitting pulse, on "
                        "the record's time axis."),
    ("pulse_arrival_s", "s", "Time the best-fitting pulse starts: t0 for sine and rect, t0 - Tp/2 for "
                             "the Rickers."),
    ("pulse_lp_m", "m", "Persistence length scale Lp = |ap| Tp^2 of the best-fitting pulse."),
    ("pulse_score", "-", "Fit quality of the best pulse: the fitter's score, the share of the record's "
                         "energy the pulse explains (1 at most), in the metric of `pulse_fit`: weighted "
                         "by the background's spectrum it falls below zero for a pulse whose corners "
                         "the record lacks."),
    ("pulse_fit", "-", "The least squares that fitted the pulses: `background` (weighted by the "
                       "background's spectrum estimated from the record, the default) or `plain` "
                       "(where the record does not support the weighting)."),
    ("pulse_correlation", "-", "Correlation between the best pulse and the record within the pulse "
                               "window (-1 to 1)."),
    ("shapes_fitting", "-", f"Shapes that fit the record almost equally well (score at least "
                            f"{FIT_TOLERANCE:g} x the best score), best first, `;`-separated."),
)


def _record_fields(task: Task, record, fit, best, fitting) -> dict:
    meta = record.metadata or {}
    warnings = meta.get("warnings") or []
    if isinstance(warnings, str):
        warnings = [warnings]
    return RECORD_COLUMNS.row({
        "record": task.record_id,
        "file": task.path,
        "station": meta.get("station"),
        "component": meta.get("component"),
        "event": meta.get("event"),
        "format": meta.get("format"),
        "units": meta.get("units"),
        "dt_s": record.dt,
        "npts": record.npts,
        "duration_s": record.duration,
        "pga_g": _g(record.pga),
        "pgv_m_s": getattr(fit, "pgv", None),
        "warnings": "; ".join(str(w) for w in warnings),
        "pulse_shape": best.shape,
        "pulse_ap_g": _g(best.ap),
        "pulse_tp_s": best.tp,
        "pulse_t0_s": best.t0,
        "pulse_arrival_s": getattr(best, "arrival", None),
        "pulse_lp_m": abs(best.ap) * best.tp ** 2,
        "pulse_score": best.score,
        "pulse_fit": getattr(fit, "weighting", None),
        "pulse_correlation": getattr(best, "correlation", None),
        "shapes_fitting": ";".join(c.shape for c in fitting),
    })


COLUMN_COLUMNS = Columns(
    ("column", "-", "The column as given: `HxW` for `--block`, `H` for `--height`."),
    ("column_kind", "-", "`block` (a column as it stands, `--block`) or `height` (only the width a "
                         "column of this height needs, `--height`; the as-it-stands fields are blank)."),
    ("height_m", "m", "Full height H of the column."),
)


def _column_fields(col: Column) -> dict:
    return COLUMN_COLUMNS.row({"column": col.label, "column_kind": col.kind, "height_m": col.height})


AS_STANDS_DESIGN_COLUMNS = Columns(
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
)


def _as_stands_design(col: Column, block, best, exact) -> dict:
    import rocking

    if block is None:
        return AS_STANDS_DESIGN_COLUMNS.blank()
    p = block.p
    return AS_STANDS_DESIGN_COLUMNS.row({
        "width_m": col.width, "tan_alpha": block.tan_alpha,
        "alpha_deg": math.degrees(block.alpha), "p_rad_s": p, "p_tp": p * best.tp,
        "eq31_tan_alpha": float(rocking.eq31(best.ap, best.tp, p)),
        "envelope_tan_alpha": float(rocking.envelope_rule(best.ap, best.tp, p, shape=best.shape)),
        "exact_tan_alpha": exact[(best.shape, block)],
    })


GOVERNING_COLUMNS = Columns(
    ("governing_shape", "-", "Shape of the governing pulse (the rule is stated in `columns.md`)."),
    ("governing_ap_g", "g", "Amplitude of the governing pulse, signed."),
    ("governing_tp_s", "s", "Period of the governing pulse."),
    ("governing_eq31_tan_alpha", "-", "Eq. 31 minimum tan(alpha) for the governing pulse at the column's p."),
)


def _governing_fields(gov, block) -> dict:
    import rocking

    return GOVERNING_COLUMNS.row({
        "governing_shape": gov.shape, "governing_ap_g": _g(gov.ap), "governing_tp_s": gov.tp,
        "governing_eq31_tan_alpha": None if block is None else float(rocking.eq31(gov.ap, gov.tp, block.p)),
    })


def shape_columns(shape: str) -> Columns:
    """The columns of one pulse shape (``sine``, ...), named ``<shape>_*`` (``-`` as ``_``)."""
    k = _shape_key(shape)
    return Columns(
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
    )


SHAPE_COLUMNS = {shape: shape_columns(shape) for shape in SHAPE_NAMES}


def _shape_fields(shape, candidate, fitting, block, exact, widths) -> dict:
    """The ``<shape>_*`` group: blank where the shape was not tried, does not fit, or (for the
    as-it-stands values) the column is only a height."""
    import rocking

    columns = SHAPE_COLUMNS[shape]
    if candidate is None:
        return columns.blank()
    c, k = candidate, _shape_key(shape)
    eq31_width = None
    for w, f in widths:  # the fitting candidates of this shape (one per shape from the fitter)
        if f.shape == shape:
            eq31_width = w
    return columns.row({
        f"{k}_fits": any(c is f for f in fitting), f"{k}_ap_g": _g(c.ap), f"{k}_tp_s": c.tp,
        f"{k}_score": c.score,
        f"{k}_eq31_tan_alpha": None if block is None else float(rocking.eq31(c.ap, c.tp, block.p)),
        f"{k}_exact_tan_alpha": None if block is None else exact.get((shape, block)),
        f"{k}_eq31_width_m": eq31_width,
    })


AS_STANDS_COLUMNS = Columns(
    ("eq31_adequate", "-", "The column as it stands satisfies Eq. 31 for the governing pulse "
                           "(tan_alpha >= governing_eq31_tan_alpha)."),
    ("overturns", "-", "The column as it stands overturns (|theta| reaches pi/2) under the full record."),
    ("exceeds_alpha", "-", "|theta| of the column as it stands passes alpha at some time under the full record."),
    ("max_theta_ratio", "-", "max|theta|/alpha of the column as it stands under the full record (at "
                             "least pi/(2 alpha) when it overturns)."),
    ("n_impacts", "-", "Number of impacts of the column as it stands under the full record."),
    ("model", "-", "Solver model that answered for the column as it stands (`rocking.simulate`, model=auto)."),
)


def _as_stands_fields(block, governing: dict, res) -> dict:
    if block is None:
        return AS_STANDS_COLUMNS.blank()
    return AS_STANDS_COLUMNS.row({
        "eq31_adequate": block.tan_alpha >= governing["governing_eq31_tan_alpha"],
        "overturns": bool(res.overturned), "exceeds_alpha": bool(res.exceeded_alpha),
        "max_theta_ratio": float(res.max_rotation_ratio), "n_impacts": int(res.n_impacts),
        "model": str(res.model),
    })


EQ31_DESIGN_COLUMNS = Columns(
    ("eq31_width_m", "m", "Width a column of this height needs by Eq. 31 for the governing pulse "
                          "(fixed point in B, since p depends on B; `rocking.required_width`, rule eq31)."),
    ("eq31_width_tan_alpha", "-", "tan(alpha) of the Eq. 31 design, eq31_width_m / height_m."),
    ("eq31_width_overturns", "-", "The Eq. 31 design overturns under the full record."),
    ("eq31_width_max_theta_ratio", "-", "max|theta|/alpha of the Eq. 31 design under the full record."),
    ("eq31_width_model", "-", "Solver model that answered for the Eq. 31 design."),
)


def _eq31_design_fields(height, w31, res31) -> dict:
    return EQ31_DESIGN_COLUMNS.row({
        "eq31_width_m": w31, "eq31_width_tan_alpha": w31 / height,
        "eq31_width_overturns": bool(res31.overturned),
        "eq31_width_max_theta_ratio": float(res31.max_rotation_ratio),
        "eq31_width_model": str(res31.model),
    })


DESIGN_WIDTH_COLUMNS = Columns(
    ("design_width_m", "m", "Design width: the smallest width for which a column of this height "
                              "survives the full record (max|theta|/alpha <= `design_limit` with "
                              "`--limit`), at that width and at every larger one the search and the "
                              "check above it examined: at least every width they found to fail, "
                              "refined just above the widest to a number of 6 significant digits "
                              "that was run and survived, so the value printed is the width tested "
                              "(`rocking.required_width`, rule exact, `.width`); with a vertical component, the wider of the horizontal "
                              "motion's and the one with the vertical (`design_governed_by`). "
                              "Independent of the pulse fit."),
    ("design_tan_alpha", "-", "tan(alpha) of the design width, design_width_m / height_m."),
    ("design_adequate", "-", "The column as it stands is at least as wide as the design width "
                               "(blank for `--height`). A column that survives (`overturns` False) "
                               "but is not design-adequate stands on a safe island: some slightly "
                               "wider column of the same height overturns under the same record."),
    ("search_width_m", "m", "Diagnostic: the search's first transition (the smallest width above "
                            "which every width the search examined survives; `search_width`), "
                            "before the check above it; the design width is at least this."),
    ("design_governed_by", "-", "Which motion sets the design width: `horizontal` (the horizontal "
                                "motion alone) or `with vertical` (the horizontal motion with the "
                                "record's vertical); blank without a vertical."),
    ("design_limit", "-", "The performance level of the design (`--limit` R: max|theta|/alpha <= R); "
                          "blank: overturning, the paper's question."),
    ("overturning_width_m", "m", "With `--limit` R: the overturning design of the same column and "
                                 "record, computed where it can change the level's (the same search, "
                                 "its check only above the level's own design width; with a vertical, "
                                 "the wider of the two motions'). Where it is wider than the level's "
                                 "own width it is the overturning design width in full and "
                                 "`design_width_m` is raised to at least it (a width that overturns "
                                 "fails every level); where not, the level governs and this is what "
                                 "was established: the overturning design width lies between it and "
                                 "`design_width_m` (docs/design.md, \"Performance levels\"). Blank "
                                 "without `--limit`."),
)


def _design_width_fields(col: Column, ver) -> dict:
    return DESIGN_WIDTH_COLUMNS.row({
        "design_width_m": float(ver.width), "design_tan_alpha": float(ver.width) / col.height,
        "design_adequate": None if col.width is None else col.width >= float(ver.width),
        "search_width_m": None if ver.search_width is None else float(ver.search_width),
        "design_governed_by": ver.governed_by, "design_limit": ver.limit,
        "overturning_width_m": ver.overturning_width,
    })


CHECK_COLUMNS = Columns(
    ("failing_share", "-", "What the check above the search width found (docs/slivers.md): near the "
                           "search's first transition (`search_width_m`) the response is chaotic and "
                           "failing slivers thinner than the search's 0.05 % grid may lie above it. "
                           "After the search, a check runs `check_runs` jittered widths (seeded from "
                           "the record, off the search's grid) from the search width up to "
                           f"{check_reach_words()} or the no-uplift width (height x PGA / g), whichever "
                           f"is smaller, in bins of {check_bin_words()} of it, more where the response varies from one "
                           "width to the next (in a direction of a pair, only above a lower bound of the "
                           "pair's design width, docs/site.md): this is the share of them that fail (0: none did; "
                           "blank: no check, as in a direction of a pair whose check could not reach "
                           "the pair's design width). The design width `design_width_m` lies just above the "
                           "widest failing width found."),
    ("widest_failing_width_m", "m", "The widest width the search or the check found to fail above "
                                    "the search width (a failing sliver; blank where none was found, "
                                    "which does not prove there is none); the design width lies just "
                                    "above it."),
    ("check_runs", "-", "Number of widths (solver runs) of the check above the search width: 300 "
                        "and more where the response varies (0: not checked; in a direction of a pair, "
                        "those above a lower bound of the pair's design width, docs/site.md)."),
)


def _check_fields(ver) -> dict:
    return CHECK_COLUMNS.row({
        "failing_share": ver.failing_share, "widest_failing_width_m": ver.widest_failing_width,
        "check_runs": ver.check_runs,
    })


_TO_DESIGN_WIDTH = (RECORD_COLUMNS.columns + site.SITE_COLUMNS.columns + peer_inputs.PEER_COLUMNS.columns
                    + COLUMN_COLUMNS.columns + AS_STANDS_DESIGN_COLUMNS.columns
                    + GOVERNING_COLUMNS.columns + sum((SHAPE_COLUMNS[s].columns for s in SHAPE_NAMES), ())
                    + AS_STANDS_COLUMNS.columns + EQ31_DESIGN_COLUMNS.columns + DESIGN_WIDTH_COLUMNS.columns)
_FROM_CHECK = (CHECK_COLUMNS.columns + site.ENVELOPE_COLUMNS.columns + site.FRAGILITY_COLUMNS.columns
               + vertical.VERTICAL_COLUMNS.columns + validity.VALIDITY_COLUMNS.columns)
#: the columns every run's per-record reports and ``summary.csv`` have, in order: (name, unit,
#: meaning); :func:`columns_for` adds those of a run's options
COLUMNS = _TO_DESIGN_WIDTH + _FROM_CHECK
FIELDS = [name for name, _, _ in COLUMNS]


def columns_for(options) -> tuple:
    """The columns of the reports of a run with ``options``: :data:`COLUMNS` with, after the design
    width's, the margin's under a level and the restitution's with ``--restitution``
    (:func:`pipeline.batch.margin.extra_columns`)."""
    return _TO_DESIGN_WIDTH + margin.extra_columns(options) + _FROM_CHECK


def fields_for(options) -> list:
    """The names of :func:`columns_for`."""
    return [name for name, _, _ in columns_for(options)]


def _base_fields(task, record, fit, fitting, vertical_note):
    """``(fields, velocity classification)``: what every row of the record holds (its reading, its
    fit, whether it is pulse-like, its PEER metadata) and the classification for its figure."""
    base = _record_fields(task, record, fit, fit.best, fitting)
    # a lone record is classified once, for its row and its figure (a pair's classification comes
    # with the task; the figure of a pair's direction classifies the component it draws)
    velocity = None if task.pair_fields else _stage("classify", _classify, record)
    site_fields, warning = _stage("classify", site.site_fields, task, record, velocity)
    if warning:
        base["warnings"] = "; ".join(w for w in (base["warnings"], warning) if w)
    base.update(site_fields)
    base.update(peer_inputs.fields(task))
    if vertical_note:
        base["warnings"] = "; ".join(w for w in (base["warnings"], vertical_note) if w)
    return base, velocity


def _process(task: Task):
    import rocking

    opts = task.options
    record, up, vertical_note = _stage("read", vertical.read_task, task)
    fit = _stage("fit", _fit, record, opts.shapes, opts.weighting)
    best = fit.best
    candidates = list(fit.candidates)
    fitting = rocking.fitting_candidates(fit)
    by_shape = {}
    for c in candidates:  # candidates are ranked: keep the best of each shape
        by_shape.setdefault(c.shape, c)
    base, velocity = _base_fields(task, record, fit, fitting, vertical_note)
    shown_vertical = None if up is None else (up.metadata.get("source") or task.vertical)
    draw = opts.plots and task.plot
    settings = _check_settings(task)

    gamma = opts.cap_mass_ratio
    blocks = {col: rocking.Block.from_dimensions(col.height, col.width, cap_mass_ratio=gamma,
                                                 body=col.body)
              for col in task.columns if col.width is not None}
    exact = _stage("design", _exact_by_body, fitting, list(blocks.values()), gamma, opts.restitution)
    extra_cache = {}

    rows = []
    histories, frictions = [], []
    design_cache = {}
    margin_cache = {}
    eq31_cache = {}
    fields = fields_for(opts)
    for col in task.columns:
        H = col.height
        block = blocks.get(col)
        curves = []
        hk = _height_key(col)

        # -- Eq. 31 width for this height, for every fitting shape: the widest governs ------------
        if hk not in eq31_cache:  # rocking.governing_pulse: pipeline run's rule, in public
            eq31_cache[hk] = _stage("design", rocking.governing_pulse, fit, H, cap_mass_ratio=gamma,
                                    body=col.body)
        widths, w31, gov = eq31_cache[hk].widths, eq31_cache[hk].width, eq31_cache[hk].candidate

        # -- the column as it stands: design rules, then the full record ---------------------------
        def design():
            fields = _as_stands_design(col, block, best, exact)
            fields.update(_governing_fields(gov, block))
            for shape in SHAPE_NAMES:
                fields.update(_shape_fields(shape, by_shape.get(shape), fitting, block, exact, widths))
            return fields

        designed = _stage("design", design)
        res = block_s = None
        if block is not None:   # (with a restitution band: its most demanding value, margin.simulate)
            block_s, res = _stage("verify", margin.simulate, H, col.width, record, opts, draw, body=col.body)
            if draw:
                curves.append((f"as it stands, {col.width:.3g} m wide", block_s, res))

        # -- the Eq. 31 design under the full record ---------------------------------------------
        block31, res31 = _stage("verify", margin.simulate, H, w31, record, opts, draw, body=col.body)
        if draw:
            curves.append((f"Eq. 31 design, {w31:.3g} m wide", block31, res31))

        # -- design width: smallest width surviving the full record (islands respected), above
        #    every width found to fail, with the vertical where there is one; under a level, the
        #    verge beside it (its overturning design) ----------------------------------------------
        if hk not in design_cache:
            design_cache[hk] = design_width(record, up, H, gamma, opts.limit, settings[col], col.body,
                                            opts.restitution)
        ver = design_cache[hk]
        if draw or (opts.limit is not None and hk not in margin_cache):
            curves += _stage("verify", margin.design_curves, H, ver, record, up, opts, margin_cache, draw,
                             hk)
        if draw:
            histories.append((col.label, curves))
        valid, need = _stage("verify", validity.fields, col, block_s, record, up, ver, gamma,
                             opts.friction, block31, extra_cache, opts.restitution)
        frictions.append((col.label, need))

        row = dict(base)
        row.update(_column_fields(col))
        row.update(designed)
        row.update(_as_stands_fields(block, designed, res))
        row.update(_eq31_design_fields(H, w31, res31))
        row.update(_design_width_fields(col, ver))
        row.update(margin_cache.get(hk, margin.MARGIN_COLUMNS.blank()))
        if opts.restitution is not None:
            row.update(margin.restitution_fields(H, ver, opts))
        row.update(_check_fields(ver))
        row.update(_stage("verify", site.extra_fields, H, block, record, fitting, opts, extra_cache,
                          col.body))
        row.update(_stage("verify", vertical.fields, block, record, up, shown_vertical, ver, opts))
        row.update(valid)
        rows.append({k: row[k] for k in fields})

    return rows, (record, fit, fitting, histories, velocity), design_cache, (frictions, opts.friction)


def _height_key(col):
    """What a height's designs are kept under: the height (a rectangular column's, as before), or
    with the body's kind (``(7.5, "cylinder")``)."""
    return col.height if col.body == "rectangular" else (col.height, col.body)


def design_width(record, up, height, cap_mass_ratio, limit, settings, body="rectangular", restitution=None):
    """The design width of a column ``height`` (m) tall under ``record`` (with its vertical ``up``
    where there is one, :func:`pipeline.batch.vertical.design`).  With a level ``limit``: the
    level's design first, then the overturning design where it can change it (a width that
    overturns fails every level; ``rocking.required_width(..., overturning=True)``: its search, its
    check above the level's width), the level with each motion at least that motion's
    overturning width; ``.overturning_width`` is that design's width.  ``restitution``: a
    :class:`rocking.restitution.Restitution` (a band: the design covering it, each value designed
    so) or None (Eq. 5)."""
    import rocking

    kw = dict(rule="exact", cap_mass_ratio=cap_mass_ratio, settings=settings, body=body, eta=restitution)
    over = None if limit is None else True
    alone = _stage("verify", rocking.required_width, height, record, limit=limit, overturning=over, **kw)
    return _stage("verify", vertical.design, record, up, height, alone, cap_mass_ratio, limit, over,
                  body, restitution)


def _check_settings(task: Task) -> dict:
    """The search's settings for each column: the check above the design width where
    pipeline.batch.passes asks for it (docs/slivers.md)."""
    from rocking.search import DEFAULT_SETTINGS

    base = DEFAULT_SETTINGS if task.check else DEFAULT_SETTINGS.replace(check_runs=0)
    above = dict(zip(task.columns, task.check_above))
    return {col: base.replace(check_above=above.get(col, 0.0)) for col in task.columns}


def _classify(record):
    """The record's velocity-pulse classification, or None where it fails (its row then says why)."""
    import pulses

    try:
        return pulses.classify_pulse(record)
    except Exception:  # an unusual record: classified again for the row's warning, drawn without
        return None


#: the parts a bracket of the exact minimum slenderness is cut into at each step (:func:`_exact_by_shape`)
EXACT_KSECTION = 4


def _exact_by_body(fitting, blocks, cap_mass_ratio=0.0, restitution=None) -> dict:
    """:func:`_exact_by_shape` for the blocks of each body, by its own impact rule."""
    exact = {}
    for kind in dict.fromkeys(["rectangular"] + [b.body.kind for b in blocks]):
        exact.update(_exact_by_shape(fitting, [b for b in blocks if b.body.kind == kind],
                                     cap_mass_ratio, kind, restitution))
    return exact


def _exact_by_shape(fitting, blocks, cap_mass_ratio=0.0, body="rectangular", restitution=None) -> dict:
    """Exact minimum tan(alpha) of every fitting pulse for every block: ``{(shape, block): tan}``.

    One ``rocking.min_slenderness_batch`` call per shape covers all the blocks (the similarity law:
    only pTp and ap/g matter), which gives the same numbers as ``rocking.min_slenderness`` (to its
    1e-9 refinement): the same scan, but only the deciding transition refined, cut in four at each
    step (three runs a solver call: a pulse run is short, and a call's own cost, not the runs,
    decides; measured, 10 % less CPU than bisection on the pulses fitted to a real pair's
    directions, 40 % at pTp 2-4, answers within 1e-9 relative of it; the safe islands below it
    are not reported here).  ``restitution``: as the run's (a band: the answer covering it).
    """
    import rocking
    from pulses import G

    out = {}
    if not blocks:
        return out
    for c in fitting:
        p_tp = [b.p * c.tp for b in blocks]
        key = (c.shape, tuple(p_tp), abs(c.ap) / G, cap_mass_ratio)  # its every input
        if body != "rectangular":
            key += (body,)
        if restitution is not None:
            key += (str(restitution),)
        res = memo.remembered("slenderness", key, lambda: rocking.min_slenderness_batch(
            c.shape, p_tp, [abs(c.ap) / G] * len(blocks), refine="top", ksection=EXACT_KSECTION,
            cap_mass_ratio=cap_mass_ratio, body=body, eta=restitution))
        for b, r in zip(blocks, res):
            out[(c.shape, b)] = float(r.tan_alpha)
    return out


def _fit(record, shapes, weighting):
    import pulses

    key = (memo.samples_key(record), tuple(shapes) if shapes else None, weighting)
    return memo.remembered("fit", key, lambda: pulses.fit_pulse(
        record, shapes=list(shapes) if shapes else None, weighting=weighting))
