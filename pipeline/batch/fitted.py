"""A record in a row of ``pipeline run``: what was read (:data:`RECORD_COLUMNS`: the record's id,
file, header, sampling, peaks and warnings), its best pulse and the shapes that fit it
(:func:`pulses.fit_pulse`), and what every row of the record holds besides (its site columns and
PEER metadata, :func:`base_fields`).
"""
from __future__ import annotations

from . import memo, peer_inputs, site
from .stages import stage
from ..reports.columns import Columns, TEXT, WHOLE
from ..reports.shapes import FIT_TOLERANCE, shape_list


def to_g(x):
    """An acceleration in m/s^2 in g (None stays None)."""
    from pulses import G

    return None if x is None else float(x) / G



RECORD_COLUMNS = Columns(
    ("record", "-", "Record id: the file name without its extension, made file-system safe (other "
                    "characters become `_`; a name longer than 96 characters is cut and ends in a "
                    "short hash of the whole name) and unique in input order (`-2`, `-3`, ...). The "
                    "per-record report is `<record>.csv`.", TEXT),
    ("file", "-", "The record's path as given on the command line (bytes that are not UTF-8 written "
                  "as `\\xff`).", TEXT),
    ("station", "-", "Station code from the file header (blank when the format has none).", TEXT),
    ("component", "-", "Component or channel from the file header.", TEXT),
    ("event", "-", "Event name from the file header.", TEXT),
    ("format", "-", "File format the record was read as.", TEXT),
    ("units", "-", "Units of the samples, as stated by the file header or given with `--units`; "
                   "samples are converted to m/s^2.", TEXT),
    ("dt_s", "s", "Sampling interval."),
    ("npts", "-", "Number of samples.", WHOLE),
    ("duration_s", "s", "Time from the first to the last sample."),
    ("pga_g", "g", "Peak absolute ground acceleration."),
    ("pgv_m_s", "m/s", "Peak absolute ground velocity (from the fitter, after its baseline correction)."),
    ("warnings", "-", "Warnings raised while reading the record (such as a peak over 5 g), `; `-separated.", TEXT),
    ("pulse_shape", "-", f"Best-fitting pulse shape: {shape_list()}.", TEXT),
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
                       "(where the record does not support the weighting).", TEXT),
    ("pulse_correlation", "-", "Correlation between the best pulse and the record within the pulse "
                               "window (-1 to 1)."),
    ("shapes_fitting", "-", f"Shapes that fit the record almost equally well (score at least "
                            f"{FIT_TOLERANCE:g} x the best score), best first, `;`-separated.", TEXT),
)


def record_fields(task, record, fit, best, fitting) -> dict:
    """The :data:`RECORD_COLUMNS` of a record as read and fitted (``best``: its best pulse,
    ``fitting``: the candidates that fit almost as well)."""
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
        "pga_g": to_g(record.pga),
        "pgv_m_s": getattr(fit, "pgv", None),
        "warnings": "; ".join(str(w) for w in warnings),
        "pulse_shape": best.shape,
        "pulse_ap_g": to_g(best.ap),
        "pulse_tp_s": best.tp,
        "pulse_t0_s": best.t0,
        "pulse_arrival_s": getattr(best, "arrival", None),
        "pulse_lp_m": abs(best.ap) * best.tp ** 2,
        "pulse_score": best.score,
        "pulse_fit": getattr(fit, "weighting", None),
        "pulse_correlation": getattr(best, "correlation", None),
        "shapes_fitting": ";".join(c.shape for c in fitting),
    })


def base_fields(task, record, fit, fitting, vertical_note):
    """``(fields, velocity classification)``: what every row of the record holds (its reading, its
    fit, whether it is pulse-like, its PEER metadata) and the classification for its figure."""
    base = record_fields(task, record, fit, fit.best, fitting)
    # a lone record is classified once, for its row and its figure (a pair's classification comes
    # with the task; the figure of a pair's direction classifies the component it draws)
    velocity = None if task.pair_fields else stage("classify", classify, record)
    site_fields, warning = stage("classify", site.site_fields, task, record, velocity)
    if warning:
        base["warnings"] = "; ".join(w for w in (base["warnings"], warning) if w)
    base.update(site_fields)
    base.update(peer_inputs.fields(task))
    if vertical_note:
        base["warnings"] = "; ".join(w for w in (base["warnings"], vertical_note) if w)
    return base, velocity


def classify(record):
    """The record's velocity-pulse classification, or None where it fails (its row then says why)."""
    import pulses

    try:
        return pulses.classify_pulse(record)
    except Exception:  # an unusual record: classified again for the row's warning, drawn without
        return None


def fit_record(record, shapes, weighting):
    """:func:`pulses.fit_pulse` of ``record``, kept while the batch runs (a pair's direction computed
    again in a later pass finds it, :mod:`pipeline.batch.memo`)."""
    import pulses

    key = (memo.samples_key(record), tuple(shapes) if shapes else None, weighting)
    return memo.remembered("fit", key, lambda: pulses.fit_pulse(
        record, shapes=list(shapes) if shapes else None, weighting=weighting))
