"""Per-record work of ``pipeline run``: read, fit, design, verify; plain rows out.

:func:`process_record` takes one :class:`~pipeline.batch.tasks.Task` (plain, picklable data) and
returns a plain dict, so it runs the same in this process, in a process pool or on a dask worker.
It never raises for a bad record: the failure comes back with the stage it happened in and the
reason (:mod:`pipeline.batch.stages`).  A row is made for each column of the task
(:func:`column_row`), its groups filled by the modules that declare them (:mod:`pipeline.batch.row`
puts them in order).  Everything it computes comes from the library (``pulses.read_record``,
``pulses.fit_pulse``, ``rocking.simulate``, ``rocking.governing_pulse``, ``rocking.required_width``,
``rocking.min_slenderness_batch`` ...); nothing here is a second implementation of them.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from . import as_stands, fitted, fragility, margin, rules, stages, validity, vertical, widths
from .read import read_task
from .row import fields_for
from .stages import StageError, stage
from .tasks import Task
from ..reports.columns import Columns


def process_record(task: Task) -> dict:
    """Process one record; return ``{"index", "record", "file", "rows", "failure", "plot",
    "widths_plot", "seconds"}``.

    ``seconds`` maps each stage (``"verify:required_width"``, ...) to the time it took; it is for
    benchmarks and never written to the reports (which must not depend on timing).
    """
    stages.timings.seconds = {}
    try:
        out = _process_record(task)
    finally:
        seconds, stages.timings.seconds = stages.timings.seconds, None
    out["seconds"] = seconds
    return out


def _process_record(task: Task) -> dict:
    """:func:`process_record` but for its timings."""
    out = {"index": task.index, "record": task.record_id, "file": task.path, "rows": [],
           "failure": None, "plot": None, "widths_plot": None, "friction_plot": None}
    try:
        rows, fit_parts, designs, friction_parts = _process(task)
        out["rows"] = rows
    except StageError as err:
        out["failure"] = failure(task, err.stage, err.exc)
        return out
    except Exception as exc:  # anything unforeseen fails this record only, never the batch
        if stages.interrupted(exc):
            raise KeyboardInterrupt from exc
        out["failure"] = failure(task, "internal", exc)
        return out
    if task.options.plots and task.plot:
        from ..reports.figures.record import run_figure_png

        try:
            out["plot"] = stage("plot", run_figure_png, task.record_id, *fit_parts)
            out["friction_plot"] = stage("plot", _friction_png, task.record_id, *friction_parts)
            out["widths_plot"] = stage("plot", _widths_png, task.record_id, designs)
        except StageError as err:
            out["failure"] = failure(task, err.stage, err.exc)
    return out


def _friction_png(record_id, frictions, mu):
    """``plots/friction/<record>.png``: the friction each column's responses need against time."""
    from ..reports.figures.friction import friction_png

    return friction_png(record_id, frictions, mu)


def _widths_png(record_id, designs):
    """``plots/widths/<record>.png`` where the check above a search width found failing widths
    (docs/slivers.md); None elsewhere."""
    from ..reports.figures.widths import record_widths_png

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


@dataclass
class _Record:
    """One record (or direction) in the work: what every row of it shares, and what its columns'
    designs keep for the others (by height, :func:`pipeline.batch.widths.height_key`)."""

    task: Task
    record: object
    #: the upward vertical, or None
    up: object
    fit: object
    fitting: list
    #: the best candidate fitted of each shape
    by_shape: dict
    #: the groups every row of the record has (fitted.base_fields)
    base: dict
    #: the velocity-pulse classification, for the figure
    velocity: object
    #: the vertical's name in the rows
    shown_vertical: object
    draw: bool
    settings: dict
    #: a :class:`rocking.Block` per column as it stands
    blocks: dict
    #: the exact minimum slenderness, ``{(shape, block): tan(alpha)}``
    exact: dict
    governed: dict = field(default_factory=dict)
    designs: dict = field(default_factory=dict)
    margins: dict = field(default_factory=dict)
    #: the record's cache of the envelope's and validity's designs
    extra: dict = field(default_factory=dict)


def _read_and_fit(task: Task) -> _Record:
    """The stages every column of a task shares: read, fit, classify, the blocks as they stand and
    their exact minimum slenderness."""
    import rocking

    opts = task.options
    record, up, vertical_note = stage("read", read_task, task)
    fit = stage("fit", fitted.fit_record, record, opts.shapes, opts.weighting)
    fitting = rocking.fitting_candidates(fit)
    by_shape = {}
    for c in fit.candidates:  # candidates are ranked: keep the best of each shape
        by_shape.setdefault(c.shape, c)
    base, velocity = fitted.base_fields(task, record, fit, fitting, vertical_note)
    shown_vertical = None if up is None else (up.metadata.get("source") or task.vertical)
    settings = widths.check_settings(task)
    gamma = opts.cap_mass_ratio
    blocks = {col: rocking.Block.from_dimensions(col.height, col.width, cap_mass_ratio=gamma, body=col.body)
              for col in task.columns if col.width is not None}
    exact = stage("design", rules.exact_by_body, fitting, list(blocks.values()), gamma, opts.restitution)
    return _Record(task, record, up, fit, fitting, by_shape, base, velocity, shown_vertical,
                   opts.plots and task.plot, settings, blocks, exact)


def _process(task: Task):
    """``(rows, the record figure's parts, the designs by height, the friction figure's parts)``."""
    r = _read_and_fit(task)
    rows, histories, frictions = [], [], []
    fields = fields_for(task.options)
    for col in task.columns:
        row, curves, need = column_row(r, col)
        if r.draw:
            histories.append((col.label, curves))
        frictions.append((col.label, need))
        rows.append({k: row[k] for k in fields})
    return rows, (r.record, r.fit, r.fitting, histories, r.velocity), r.designs, (frictions, task.options.friction)


def column_row(r: _Record, col):
    """``(row, curves of the record's figure, friction demands)`` of one column of a record: the
    rules for the column as it stands and for its height, each design verified under the full
    record, the design width, and what the options add."""
    opts, H, block, gamma = r.task.options, col.height, r.blocks.get(col), r.task.options.cap_mass_ratio
    hk = widths.height_key(col)
    governed = stage("design", rules.governing, r.fit, col, gamma, r.governed, hk)
    designed = stage("design", rules.design_fields, col, block, r.fit, r.fitting, r.by_shape, r.exact, governed)
    curves, res, block_s = [], None, None
    if block is not None:   # (with a restitution band: its most demanding value, margin.simulate)
        block_s, res = stage("verify", margin.simulate, H, col.width, r.record, opts, r.draw, body=col.body)
        curves.append((f"as it stands, {col.width:.3g} m wide", block_s, res))
    w31 = governed.width
    block31, res31 = stage("verify", rules.eq31_design, H, w31, r.record, opts, r.draw, col.body)
    curves.append((f"Eq. 31 design, {w31:.3g} m wide", block31, res31))
    # the design width: smallest width surviving the full record (islands respected), above every
    # width found to fail, with the vertical where there is one; under a level, the verge beside it
    if hk not in r.designs:
        r.designs[hk] = widths.design_width(r.record, r.up, H, gamma, opts.limit, r.settings[col], col.body,
                                            opts.restitution)
    ver = r.designs[hk]
    if r.draw or (opts.limit is not None and hk not in r.margins):
        curves += stage("verify", margin.design_curves, H, ver, r.record, r.up, opts, r.margins, r.draw, hk)
    valid, need = stage("verify", validity.fields, col, block_s, r.record, r.up, ver, gamma, opts.friction,
                        block31, r.extra, opts.restitution)
    row = dict(r.base)
    row.update(as_stands.column_fields(col))
    row.update(designed)
    row.update(as_stands.as_stands_fields(block, designed, res))
    row.update(rules.eq31_fields(H, w31, res31))
    row.update(widths.design_width_fields(col, ver))
    row.update(r.margins.get(hk, margin.MARGIN_COLUMNS.blank()))
    if opts.restitution is not None:
        row.update(margin.restitution_fields(H, ver, opts))
    row.update(widths.check_fields(ver))
    row.update(stage("verify", rules.envelope_fields, H, r.record, r.fitting, opts, r.extra, col.body))
    row.update(stage("verify", fragility.fields, H, block, r.record, opts))
    row.update(stage("verify", vertical.fields, block, r.record, r.up, r.shown_vertical, ver, opts))
    row.update(valid)
    return row, (curves if r.draw else []), need
