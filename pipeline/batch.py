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
import pathlib
import re
import threading
import time
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
    """Process one record; return ``{"index", "record", "file", "rows", "failure", "plot", "seconds"}``.

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
           "failure": None, "plot": None}
    try:
        rows, fit_parts = _process(task)
        out["rows"] = rows
    except StageError as err:
        out["failure"] = failure(task, err.stage, err.exc)
        return out
    except Exception as exc:  # anything unforeseen fails this record only, never the batch
        if _interrupted(exc):
            raise KeyboardInterrupt from exc
        out["failure"] = failure(task, "internal", exc)
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
        "pulse_arrival_s": getattr(best, "arrival", None),
        "pulse_lp_m": abs(best.ap) * best.tp ** 2,
        "pulse_score": best.score,
        "pulse_correlation": getattr(best, "correlation", None),
        "shapes_fitting": ";".join(c.shape for c in fitting),
    }

    blocks = {col: rocking.Block.from_dimensions(col.height, col.width)
              for col in task.columns if col.width is not None}
    exact = _stage("design", _exact_by_shape, fitting, list(blocks.values()))

    rows = []
    histories = []
    verified_cache = {}
    eq31_cache = {}
    for col in task.columns:
        row = dict(base)
        row.update({"column": col.label, "column_kind": col.kind, "height_m": col.height})
        H = col.height
        curves = []

        # -- Eq. 31 width for this height, for every fitting shape: the widest governs ------------
        def eq31_widths():
            return [(float(rocking.required_width(H, c.pulse, rule="eq31").width), c) for c in fitting]

        if H not in eq31_cache:
            eq31_cache[H] = _stage("design", eq31_widths)
        widths = eq31_cache[H]
        w31, gov = max(widths, key=lambda wc: wc[0])  # ties: the better fit (ranked first)
        row.update({"governing_shape": gov.shape, "governing_ap_g": _g(gov.ap),
                    "governing_tp_s": gov.tp, "eq31_width_m": w31, "eq31_width_tan_alpha": w31 / H})
        for shape in SHAPE_NAMES:
            c = by_shape.get(shape)
            if c is None:
                continue
            k = _shape_key(shape)
            row.update({f"{k}_fits": any(c is f for f in fitting), f"{k}_ap_g": _g(c.ap),
                        f"{k}_tp_s": c.tp, f"{k}_score": c.score})
        for w, c in widths:
            row[f"{_shape_key(c.shape)}_eq31_width_m"] = w

        # -- the column as it stands -----------------------------------------------------------------
        if col.width is not None:
            block = blocks[col]
            p = block.p

            def design_as_stands():
                d = {
                    "width_m": col.width, "tan_alpha": block.tan_alpha,
                    "alpha_deg": math.degrees(block.alpha), "p_rad_s": p, "p_tp": p * best.tp,
                    "eq31_tan_alpha": float(rocking.eq31(best.ap, best.tp, p)),
                    "envelope_tan_alpha": float(rocking.envelope_rule(best.ap, best.tp, p, shape=best.shape)),
                    "exact_tan_alpha": exact[(best.shape, block)],
                    "governing_eq31_tan_alpha": float(rocking.eq31(gov.ap, gov.tp, p)),
                }
                for c in by_shape.values():
                    k = _shape_key(c.shape)
                    d[f"{k}_eq31_tan_alpha"] = float(rocking.eq31(c.ap, c.tp, p))
                    if (c.shape, block) in exact:
                        d[f"{k}_exact_tan_alpha"] = exact[(c.shape, block)]
                d["eq31_adequate"] = block.tan_alpha >= d["governing_eq31_tan_alpha"]
                return d

            row.update(_stage("design", design_as_stands))
            res = _stage("verify", _sim, block, record, opts.plots)
            row.update({"overturns": bool(res.overturned), "exceeds_alpha": bool(res.exceeded_alpha),
                        "max_theta_ratio": float(res.max_rotation_ratio),
                        "n_impacts": int(res.n_impacts), "model": str(res.model)})
            if opts.plots:
                curves.append((f"as it stands, {col.width:.3g} m wide", block, res))

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
            verified_cache[H] = _stage("verify", rocking.required_width, H, record, rule="exact")
        ver = verified_cache[H]
        row.update({"verified_width_m": float(ver.width), "verified_tan_alpha": float(ver.width) / H})
        if col.width is not None:
            row["verified_adequate"] = col.width >= float(ver.width)
        rows.append(row)

    return rows, (record, fit, fitting, histories)


def _exact_by_shape(fitting, blocks) -> dict:
    """Exact minimum tan(alpha) of every fitting pulse for every block: ``{(shape, block): tan}``.

    One ``rocking.min_slenderness_batch`` call per shape covers all the blocks (the similarity law:
    only pTp and ap/g matter), which gives the same numbers as ``rocking.min_slenderness`` (to its
    1e-9 refinement): the same scan, but only the deciding transition refined, by bisection
    (about half the runs; the safe islands below it are not reported here).
    """
    import rocking
    from pulses import G

    out = {}
    if not blocks:
        return out
    for c in fitting:
        p_tp = [b.p * c.tp for b in blocks]
        res = rocking.min_slenderness_batch(c.shape, p_tp, [abs(c.ap) / G] * len(blocks),
                                            refine="top", ksection=2)
        for b, r in zip(blocks, res):
            out[(c.shape, b)] = float(r.tan_alpha)
    return out


def _fit(record, shapes):
    import pulses

    if shapes:
        return pulses.fit_pulse(record, shapes=list(shapes))
    return pulses.fit_pulse(record)
