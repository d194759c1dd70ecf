"""Per-record work of ``pipeline run``: read, fit, design, verify; plain rows out.

:func:`process_record` takes one :class:`Task` (plain, picklable data) and returns a plain dict, so it
runs the same in this process, in a process pool or on a dask worker.  It never raises for a bad record:
the failure comes back with the stage it happened in and the reason.  Everything it computes comes from
the library (``pulses.read_record``, ``pulses.fit_pulse``, ``rocking.simulate``, ``rocking.eq31``,
``rocking.envelope_rule``, ``rocking.min_slenderness``, ``rocking.required_width``); nothing here is a
second implementation of them.
"""
from __future__ import annotations

import math
import pathlib
import re
from dataclasses import dataclass, field

from .report import FIT_TOLERANCE, SHAPE_NAMES, _shape_key

RESERVED_IDS = {"summary", "failures", "columns"}


@dataclass(frozen=True)
class Column:
    """A column as it stands (``width`` set) or only a height to size (``width`` None)."""

    height: float
    width: float | None = None

    @property
    def label(self) -> str:
        return f"{self.height:g}x{self.width:g}" if self.width is not None else f"{self.height:g}"

    @property
    def kind(self) -> str:
        return "block" if self.width is not None else "height"


@dataclass(frozen=True)
class Options:
    shapes: tuple | None = None
    units: str | None = None
    dt: float | None = None
    column: int | None = None
    format: str | None = None
    plots: bool = True


@dataclass(frozen=True)
class Task:
    index: int
    record_id: str
    path: str
    columns: tuple = ()
    options: Options = field(default_factory=Options)


class StageError(Exception):
    def __init__(self, stage, exc):
        super().__init__(str(exc))
        self.stage = stage
        self.exc = exc


# -- record ids ------------------------------------------------------------------------------------
def record_ids(paths) -> list[str]:
    """Unique, file-system-safe ids from the file names, in input order."""
    ids, seen = [], {}
    for path in paths:
        name = pathlib.PurePath(str(path)).name
        stem = name.rsplit(".", 1)[0] if "." in name.lstrip(".") else name
        stem = re.sub(r"[^A-Za-z0-9._+-]+", "_", stem).strip("._") or "record"
        if stem.lower() in RESERVED_IDS:
            stem += "-record"
        base, k = stem, 1
        while stem.lower() in seen:
            k += 1
            stem = f"{base}-{k}"
        seen[stem.lower()] = True
        ids.append(stem)
    return ids


# -- the work ---------------------------------------------------------------------------------------
def _read(task: Task):
    import pulses

    opts = task.options
    return pulses.read_record(task.path, format=opts.format, units=opts.units, dt=opts.dt,
                              column=opts.column)


def _g(x):
    from pulses import G

    return None if x is None else float(x) / G


def _fits(candidate, best) -> bool:
    b = float(best.score)
    if not math.isfinite(b) or b <= 0.0:
        return candidate is best
    return float(candidate.score) >= FIT_TOLERANCE * b


def _sim(block, record, history):
    import rocking

    return rocking.simulate(block, record, history=history)


def process_record(task: Task) -> dict:
    """Process one record; return ``{"index", "record", "file", "rows", "failure", "plot"}``."""
    out = {"index": task.index, "record": task.record_id, "file": task.path, "rows": [],
           "failure": None, "plot": None}
    try:
        rows, fit_parts = _process(task)
        out["rows"] = rows
    except StageError as err:
        out["failure"] = failure(task, err.stage, err.exc)
        return out
    if task.options.plots:
        from .plots import record_figure_png

        try:
            out["plot"] = _stage("plot", record_figure_png, task.record_id, *fit_parts)
        except StageError as err:
            out["failure"] = failure(task, err.stage, err.exc)
    return out


def failure(task: Task, stage: str, exc: BaseException) -> dict:
    """A row of ``failures.csv``."""
    reason = " ".join(str(exc).split()) or repr(exc)
    return {"record": task.record_id, "file": task.path, "stage": stage,
            "error": type(exc).__name__, "reason": reason}


def _stage(stage, fn, *args, **kwargs):
    try:
        return fn(*args, **kwargs)
    except (KeyboardInterrupt, SystemExit):
        raise
    except MemoryError as exc:
        raise StageError(stage, exc) from exc
    except Exception as exc:  # every failure of a record is reported, never raised
        raise StageError(stage, exc) from exc


def _process(task: Task):
    import rocking

    opts = task.options
    record = _stage("read", _read, task)
    fit = _stage("fit", _fit, record, opts.shapes)
    best = fit.best
    candidates = list(fit.candidates)
    fitting = [c for c in candidates if _fits(c, best)]
    by_shape = {}
    for c in candidates:  # candidates are ranked: keep the best of each shape
        by_shape.setdefault(c.shape, c)

    meta = record.metadata or {}
    warnings = meta.get("warnings") or []
    if isinstance(warnings, str):
        warnings = [warnings]
    base = {
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
        "pulse_lp_m": abs(best.ap) * best.tp ** 2,
        "pulse_score": best.score,
        "pulse_correlation": getattr(best, "correlation", None),
        "shapes_fitting": ";".join(c.shape for c in fitting),
    }

    rows = []
    histories = []
    verified_cache = {}
    eq31_width_cache = {}
    for col in task.columns:
        row = dict(base)
        row.update({"column": col.label, "column_kind": col.kind, "height_m": col.height})
        H = col.height
        curves = []

        # -- Eq. 31 width for this height, for every fitting shape: the widest governs --
        def eq31_widths():
            widths = []
            for c in fitting:
                w = rocking.required_width(H, c.pulse, rule="eq31").width
                widths.append((float(w), c))
            # widest first, ties to the better fit (fitting is ranked best first)
            return max(widths, key=lambda wc: wc[0])

        if H not in eq31_width_cache:
            eq31_width_cache[H] = _stage("design", eq31_widths)
        w31, gov = eq31_width_cache[H]
        row.update({"governing_shape": gov.shape, "governing_ap_g": _g(gov.ap),
                    "governing_tp_s": gov.tp, "eq31_width_m": w31, "eq31_width_tan_alpha": w31 / H})

        # -- the column as it stands ---------------------------------------------------------------
        block = None
        if col.width is not None:
            block = rocking.Block.from_dimensions(H, col.width)
            p = block.p

            def design_as_stands():
                d = {
                    "width_m": col.width, "tan_alpha": block.tan_alpha,
                    "alpha_deg": math.degrees(block.alpha), "p_rad_s": p, "p_tp": p * best.tp,
                    "eq31_tan_alpha": float(rocking.eq31(best.ap, best.tp, p)),
                    "envelope_tan_alpha": float(rocking.envelope_rule(best.ap, best.tp, p, shape=best.shape)),
                    "exact_tan_alpha": float(rocking.min_slenderness(best.pulse, p).tan_alpha),
                    "governing_eq31_tan_alpha": float(rocking.eq31(gov.ap, gov.tp, p)),
                }
                for shape in SHAPE_NAMES:
                    k = _shape_key(shape)
                    c = by_shape.get(shape)
                    if c is None:
                        continue
                    fits = any(c is f for f in fitting)
                    d[f"{k}_fits"] = fits
                    d[f"{k}_ap_g"] = _g(c.ap)
                    d[f"{k}_tp_s"] = c.tp
                    d[f"{k}_score"] = c.score
                    d[f"{k}_eq31_tan_alpha"] = float(rocking.eq31(c.ap, c.tp, p))
                    if fits:
                        d[f"{k}_exact_tan_alpha"] = (d["exact_tan_alpha"] if c is best else
                                                     float(rocking.min_slenderness(c.pulse, p).tan_alpha))
                d["eq31_adequate"] = block.tan_alpha >= d["governing_eq31_tan_alpha"]
                return d

            row.update(_stage("design", design_as_stands))
            res = _stage("verify", _sim, block, record, opts.plots)
            row.update({"overturns": bool(res.overturned), "exceeds_alpha": bool(res.exceeded_alpha),
                        "max_theta_ratio": float(res.max_rotation_ratio),
                        "n_impacts": int(res.n_impacts), "model": str(res.model)})
            if opts.plots:
                curves.append((f"as it stands, {col.width:.3g} m wide", block, res))
        else:
            for shape in SHAPE_NAMES:
                c = by_shape.get(shape)
                if c is not None:
                    k = _shape_key(shape)
                    row.update({f"{k}_fits": any(c is f for f in fitting), f"{k}_ap_g": _g(c.ap),
                                f"{k}_tp_s": c.tp, f"{k}_score": c.score})

        # -- the Eq. 31 design under the full record ---------------------------------------------
        block31 = rocking.Block.from_dimensions(H, w31)
        res31 = _stage("verify", _sim, block31, record, opts.plots)
        row.update({"eq31_width_overturns": bool(res31.overturned),
                    "eq31_width_max_theta_ratio": float(res31.max_rotation_ratio),
                    "eq31_width_model": str(res31.model)})
        if opts.plots:
            curves.append((f"Eq. 31 design, {w31:.3g} m wide", block31, res31))
            histories.append((col.label, curves))

        # -- verified width: smallest width surviving the full record (islands respected) ---------
        if H not in verified_cache:
            verified_cache[H] = _stage("verify", lambda: rocking.required_width(H, record, rule="exact"))
        ver = verified_cache[H]
        row.update({"verified_width_m": float(ver.width), "verified_tan_alpha": float(ver.width) / H})
        if col.width is not None:
            row["verified_adequate"] = col.width >= float(ver.width)
        rows.append(row)

    return rows, (record, fit, fitting, histories)


def _fit(record, shapes):
    import pulses

    if shapes:
        return pulses.fit_pulse(record, shapes=list(shapes))
    return pulses.fit_pulse(record)
