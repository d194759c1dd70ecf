"""Running a batch of records: in this process, a process pool (``--jobs N``) or dask (``--dask``).

The results do not depend on how the work is spread: each record is processed by the same function,
the reports are assembled in input order, and files are written atomically with fixed formatting.
"""
from __future__ import annotations

import collections
import contextlib
import dataclasses
import os
import pathlib
import sys
from dataclasses import dataclass

from ..reports import design_table, figures, html_report, outfiles, report

from .. import interrupts

from . import joblog, outlock, passes, resume, site
from ..args import ArgumentError, output_folder
from .record import FAILURE_COLUMNS, FAILURE_FIELDS, columns_for, failure, fields_for
from . import executors
from .executors import _serial, execute
from .worker import TEST_KILL_ENV, TEXT  # noqa: F401 (tests set TEST_KILL_ENV through the runner)
from .tasks import Column, Options, Task, expand_inputs, make_tasks, record_ids  # noqa: F401 (also the runner's names)


@dataclass
class RunSummary:
    n_records: int
    n_ok: int
    n_failed: int
    out: pathlib.Path
    n_reused: int = 0
    #: the run's tables as row dicts (``design``, ``summary``, ``failures``, ``suite``): the rows the
    #: CSV reports were written from (pipeline.api.DesignRun makes DataFrames of them)
    tables: dict | None = dataclasses.field(default=None, repr=False)

    @property
    def exit_code(self) -> int:
        return 0 if self.n_failed == 0 else 1


# -- the output folder -------------------------------------------------------------------------------
def prepare_output(out, tasks, plots: bool, options: Options = Options()) -> report.Outputs:
    """Check the output folder before any work is done (:class:`ArgumentError` otherwise): a folder
    (created if needed) that can be written to; no input among the files the run would write; and
    its fixed reports (``summary.csv`` ...), where present, written by an earlier run."""
    out = output_folder(out)
    shown = report.display(out)
    try:
        outputs = report.Outputs(out)
    except report.NotOurs as exc:
        raise ArgumentError(f"--out {shown}: {exc}; choose another folder") from None
    fixed = outfiles.fixed_files(dataclasses.replace(options, plots=plots))
    written = fixed + [n for t in tasks for n in outfiles.record_files(t.record_id, plots)]
    inputs = {}
    for t in tasks:
        for path in (t.path, t.path2):  # both files of a pair are inputs
            if path is None:
                continue
            with contextlib.suppress(OSError, ValueError):
                st = os.stat(path)
                inputs[(st.st_dev, st.st_ino)] = path
    for rel in written:
        try:
            st = os.stat(out / rel)
        except (OSError, ValueError):
            continue
        if (st.st_dev, st.st_ino) in inputs:
            raise ArgumentError(f"the report {report.display(out / rel)} would overwrite the input "
                                f"{report.display(inputs[(st.st_dev, st.st_ino)])}; choose another --out")
    for rel in (f for f in fixed if f != report.MANIFEST):  # the manifest vouches for the rest
        try:
            outputs.check(rel)
        except report.NotOurs as exc:
            raise ArgumentError(f"--out: {exc}; move it away or choose another folder") from None
    return outputs


def _write_record(outputs: report.Outputs, task: Task, res: dict, plots: bool, say) -> None:
    """Write (or remove, for a failed record) the record's own report and figure; a problem doing so
    makes the record a failure of stage ``write`` (the batch goes on)."""
    rid = res["record"]
    problems = []
    try:
        if res["rows"]:
            outputs.write(report.record_csv_name(rid), res.get(TEXT) or report.csv_text(fields_for(task.options), res["rows"]))
        else:  # a report from an earlier run would look like this record's
            outputs.remove(report.record_csv_name(rid))
    except OSError as exc:
        problems.append(exc)
    if plots:
        # the record's figure, and the barcode of the check above the search width where it
        # found failing widths; a figure not drawn this time is removed (an earlier run's)
        for name, data in ((report.record_plot_name(rid), res.get("plot")),
                           (report.record_widths_plot_name(rid), res.get("widths_plot"))):
            try:
                if data:
                    outputs.write(name, data)
                else:
                    outputs.remove(name)
            except OSError as exc:
                problems.append(exc)
    res["widths_plot"] = None
    res["plot"] = None  # thousands of records: keep only the rows in memory
    for exc in problems:
        say(f"pipeline run: {rid}: {report.display(exc)}")
    if problems and not res["failure"]:
        res["failure"] = failure(task, "write", problems[0])


# -- the whole run -----------------------------------------------------------------------------------
def run(paths, columns, out, *, options: Options = Options(), jobs: int | None = 1, dask: str | None = None,
        quiet: bool = False, progress: bool | None = None, tasks=None, force: bool = False,
        log=None, lists=None) -> RunSummary:
    """Process ``paths`` for ``columns`` and write every report into ``out``.

    A record whose report in ``out`` was made by an earlier run from the same file content, options
    and package version is kept, not computed again (:mod:`pipeline.batch.resume`), unless ``force``;
    ``summary.csv``, ``failures.csv`` and the plots are rebuilt from every record's report.
    ``log`` (a path) gets one JSON line per record (:mod:`pipeline.batch.joblog`).  ``lists``: files the
    inputs add to the reports, ``{name: text}`` (None: a file of that name from an earlier run is
    removed), such as :data:`pipeline.batch.peer_inputs.NOT_DOWNLOADED`.

    Raises
    ------
    ArgumentError
        When ``out`` is no folder this run can write to, or holds files in the run's way (see
        :func:`prepare_output`); nothing is computed then.
    KeyboardInterrupt
        On Ctrl-C (:class:`pipeline.interrupts.Interrupted` for SIGINT or SIGTERM while
        :func:`pipeline.interrupts.handling` is active): workers stopped, reports already written
        complete, no temporary file left.
    """
    if tasks is None and not all(isinstance(c, Column) for c in columns):  # not an error per record
        raise TypeError("columns: expected pipeline.batch.tasks.Column objects; from Python, "
                        "pipeline.design(records, blocks='7.5x1.8', heights=12.0) takes blocks and heights")
    out = output_folder(out)  # checked before the Path: pathlib makes "" the current folder
    if tasks is None:  # else made by pipeline.batch.site.make_tasks (pairs, directions, scales)
        tasks = make_tasks(paths, columns, options)
    with outlock.locked(out):  # one run at a time in one folder
        return _run_locked(out, tasks, options=options, jobs=jobs, dask=dask, quiet=quiet,
                           progress=progress, force=force, log=log, lists=lists or {})


def _check_log(log, out, tasks, own) -> None:
    """``--log`` never onto an input or one of this run's own files ``own`` (paths relative to
    ``out``; pipeline.reports.outpaths)."""
    if log is not None:
        from ..reports.outpaths import check_output_file

        check_output_file(log, "--log", "log", inputs=[p for t in tasks for p in (t.path, t.path2)],
                          reserved=[out / rel for rel in own], command="run")


def _run_locked(out, tasks, *, options, jobs, dask, quiet, progress, force, log, lists) -> RunSummary:
    """:func:`run`, the folder locked."""
    outputs = prepare_output(out, tasks, options.plots, options)
    own = outfiles.own_files(tasks, options) + list(lists)   # lists: such as peer-not-downloaded.csv
    _check_log(log, out, tasks, own)
    try:
        journal = resume.Journal(out)
    except report.NotOurs as exc:
        raise ArgumentError(f"--out: {exc}; move it away or choose another folder") from None
    resume.remove_stale_temporaries(out, own)  # left by a run killed while writing

    # what each record's rows are (text as in its report), and why it failed; nothing else is kept
    # per record, so that memory stays flat over a long batch
    tasks, held = passes.first_pass(tasks, options)
    plan = passes.Plan(options, held)
    texts, keys, todo = _reusable(tasks, journal, force, options, plan, held)
    plan.sent(todo)
    failures: list[dict | None] = [None] * len(tasks)
    computed = set()  # the tasks computed (in any pass); the others were reused
    try:
        log = joblog.JobLog(log)
    except OSError as exc:
        raise ArgumentError(f"--log {report.display(log)}: {report.display(exc.strerror or exc)}") from None
    for t in tasks:
        if texts[t.index]:
            log.record(None, t.record_id, reused=True)

    bar = _progress_bar(len(todo) + len(held), quiet, progress)

    def say(msg):
        if quiet:
            return
        if bar is not None:
            bar.write(msg, file=sys.stderr)
        else:
            print(msg, file=sys.stderr)

    header = report.csv_text(fields_for(options), [])
    stream = _serial([])

    more = _passes(plan, tasks, journal, keys, texts, options, outputs, force, bar)
    try:
        staged = any(passes.staged(t, options) for t in tasks)
        todo = todo or (more() if staged else [])
        # one executor for every pass: its workers started once
        stream = execute(todo, jobs=jobs, dask=dask, more=more if staged else None)
        for res in stream:
            computed.add(res["index"])
            _handle(res, tasks, outputs, journal, keys, texts, failures, options, plan, header, say)
            log.record(res, tasks[res["index"]].record_id)
            if bar is not None:
                bar.update(1)
        stream.close()
    finally:
        with interrupts.deferred():
            stream.close()  # an interrupted pool is stopped here, at once
            log.close()
            if bar is not None:
                bar.close()
            with contextlib.suppress(OSError):
                outputs.finish()

    # a pair's failed directions, counted in pairs.csv: its governing direction is over the others
    failed = collections.Counter(site.pair_of(t) for t, f in zip(tasks, failures) if f)
    failures = [f for f in failures if f]
    text = "".join(texts)
    del texts
    for rel, listed in lists.items():  # e.g. the records of a PEER search not in its download
        try:
            if listed is not None:
                outputs.write(rel, listed)
            elif outputs.owned(rel):
                outputs.remove(rel)
        except report.NotOurs as exc:
            say(f"pipeline run: note: {exc}")
    with executors.renderer(bool(dask) or bool(jobs and jobs > 1)) as render:
        design, rows = _write_tables(outputs, out, tasks, header, text, failures, failed, options, render)
    journal.finish([t.record_id for t in tasks])
    n_failed = len(failures)
    n_reused = len(tasks) - len(computed)
    summary = RunSummary(len(tasks), len(tasks) - n_failed, n_failed, out, n_reused,
                         {"design": design, "summary": rows, "failures": failures,
                          "suite": site.suite_rows(rows) if rows else []})
    if not quiet:
        msg = f"pipeline run: {summary.n_ok} of {summary.n_records} records processed"
        if any(t.direction is not None for t in tasks):  # a pair's directions are one task each
            groups = {site.pair_of(t) for t in tasks}
            msg = (f"pipeline run: {len(groups - set(failed))} of {len(groups)} "
                   f"records or pairs processed in every direction ({summary.n_ok} of "
                   f"{summary.n_records} tasks)")
        msg += f" ({n_reused} reused from an earlier run, {len(computed)} computed)"
        if n_failed:
            msg += f", {n_failed} failed (see {report.display(out / report.FAILURES)})"
        print(design_table.table_text(design, failures, rows), end="")
        print(f"{msg}; reports in {report.display(out)}")
    return summary


def _handle(res, tasks, outputs, journal, keys, texts, failures, options, plan, header, say) -> None:
    """One computed task's result: its report and figures written, its rows kept as text, the
    journal and the plan of passes told."""
    i = res["index"]
    task = tasks[i]
    figure = res.get("plot")
    _write_record(outputs, task, res, options.plots and task.plot, say)
    texts[i] = (res.get(TEXT) or report.csv_text(fields_for(task.options), res["rows"]))[len(header):]  # made by the worker
    failures[i] = res["failure"]
    plan.note(task, res["rows"])
    if res["failure"] or not res["rows"] or keys[i] is None:
        journal.drop(task.record_id)
    else:
        journal.add(task.record_id, keys[i], (header + texts[i]).encode("utf-8"),
                    figure if options.plots and task.plot else None)
    if res["failure"]:
        f = res["failure"]
        say(f"pipeline run: {res['record']}: failed ({f['stage']}): {report.display(f['reason'])}")


def _variants(task, options):
    """The forms of ``task`` whose kept report may stand for it: itself, and for a pair's
    direction computed in passes, its checked forms (a later pass of an earlier run)."""
    if not passes.staged(task, options):
        return [task]
    return [task] + [dataclasses.replace(task, check=True, plot=p) for p in (False, True) if p or not task.plot]


def _reuse(t, journal, force, options, version):
    """``(task form, key, rows text)`` of ``t``'s kept report, or ``(t, key, "")``."""
    key = resume.task_key(t, version)
    if not force:
        for v in _variants(t, options):
            k = key if v is t else resume.task_key(v, version)
            kept = journal.reusable(v, k, options.plots and v.plot)
            if kept is not None:
                return v, k, kept
    return t, key, ""


def _reusable(tasks, journal, force: bool, options, plan, held=()):
    """``(texts, keys, todo)``: each task's rows as its kept report holds them ("" where it must be
    computed), its resume key, and the tasks to compute (their journal entries dropped).
    ``tasks`` is updated with the form of each task that was kept; the ``held`` ones (indices)
    are left to a later pass."""
    texts: list[str] = [""] * len(tasks)
    version = resume.package_version()
    keys: list = [None] * len(tasks)
    todo = []
    for t in list(tasks):
        if t.index in held:
            continue
        v, keys[t.index], texts[t.index] = _reuse(t, journal, force, options, version)
        if texts[t.index]:
            tasks[t.index] = v
            plan.note(v, resume.rows_from_text(texts[t.index], fields_for(options)))
        else:
            journal.drop(t.record_id)
            todo.append(t)
    return texts, keys, todo


def _passes(plan, tasks, journal, keys, texts, options, outputs, force, bar):
    """The executor's ``more``: the tasks of the next pass (pipeline.batch.passes: a pair's
    directions, then its governing one checked, ...), counted on the progress bar."""
    def more():
        later = _later_pass(plan, tasks, journal, keys, texts, options, outputs, force)
        if later and bar is not None:
            bar.total += len(later)
            bar.refresh()
        return later
    return more


def _later_pass(plan, tasks, journal, keys, texts, options, outputs, force):
    """The tasks of the next pass (pipeline.batch.passes) that must be computed; those an earlier run
    kept are taken as they are."""
    version = resume.package_version()
    todo = []
    while True:
        wanted = plan.next_pass(tasks)
        if not wanted:
            plan.sent(todo)
            return todo
        found = False
        for t in wanted:
            key = resume.task_key(t, version)
            kept = None if force else journal.reusable(t, key, options.plots and t.plot)
            keys[t.index] = key
            if kept is None:
                journal.drop(t.record_id)
                tasks[t.index] = t
                todo.append(t)
            else:
                tasks[t.index] = t
                texts[t.index] = kept
                plan.note(t, resume.rows_from_text(kept, fields_for(options)))
                found = True
        if todo or not found:
            plan.sent(todo)
            return todo


def _progress_bar(n_todo: int, quiet: bool, progress: bool | None):
    """A tqdm bar over ``n_todo`` records on a terminal (``progress`` None: when stderr is one), or None."""
    if progress is None:
        progress = (not quiet) and sys.stderr.isatty()
    if not (progress and n_todo):
        return None
    import shutil

    from tqdm import tqdm

    # a terminal that reports a size of 0 x 0 (some pseudo-terminals) would hide the bar
    size = shutil.get_terminal_size((100, 24))
    return tqdm(total=n_todo, unit="record", file=sys.stderr, desc="pipeline run",
                ncols=min(size.columns or 100, 120), nrows=size.lines or 24)


def _write_tables(outputs, out, tasks, header, text, failures, failed, options, render=None):
    """Write the run's own files from every record's rows (``text``: summary.csv's rows as the records'
    reports hold them, below ``header``); return the design rows and the rows of summary.csv."""
    outputs.write(report.SUMMARY, header + text)
    outputs.write(report.FAILURES, report.csv_text(FAILURE_FIELDS, failures))
    outputs.write(report.COLUMNS_MD, report.columns_markdown(columns_for(options), FAILURE_COLUMNS.columns)
                  + site.columns_markdown() + design_table.columns_markdown(options.limit is not None,
                                                                           options.restitution is not None))
    # the rows as the reports hold them, so that a resumed run writes the same files
    rows = resume.rows_from_text(text, fields_for(options))
    site.write_outputs(outputs, rows, fields_for(options), options, failed, render)
    if options.plots:
        outputs.write(report.SUMMARY_PLOT, (render or figures.draw)("plots:summary_figure_png", rows))
    design = write_answer(outputs, out, tasks, rows, failures, failed, options)
    outputs.finish()
    return design, rows


# -- the answer in view: design.csv, report.html (pipeline.reports.design_table, pipeline.reports.html_report) --------
def write_answer(outputs, out, tasks, rows, failures, failed, options) -> list[dict]:
    """Write ``design.csv`` and ``report.html``; return the design rows (printed after the run)."""
    design = design_table.design_rows(rows, failed)
    outputs.write(design_table.DESIGN_CSV, report.csv_text(design_table.design_fields(rows), design))
    ids = [t.record_id for t in tasks]
    this_run = set(outfiles.fixed_files(options))  # a figure of an earlier run with other options is not shown
    names = {k: rel for k, rel in (("summary", report.SUMMARY_PLOT), ("suite", report.SUITE_PLOT),
                                   ("fragility", report.FRAGILITY_PLOT)) if k == "summary" or rel in this_run}
    figures = html_report.figures_in(out, ids, options.plots, names)
    outputs.write(html_report.REPORT_HTML, html_report.report_html(design, rows, failures, ids, figures))
    return design
