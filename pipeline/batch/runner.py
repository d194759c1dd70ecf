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

from ..reports import answer, cells, columns, columns_md, design_table, figures, files, html_report, outfiles

from .. import interrupts

from . import joblog, outlock, passes, resume, risk, site
from ..reports import suite as suite_tables
from ..values import ArgumentError, output_folder
from .record import FAILURE_COLUMNS, FAILURE_FIELDS, failure
from .row import columns_for, fields_for, rows_of
from . import executors
from .executors import _serial, execute
from .scheduler import ClusterLost
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
    #: the run's own figures that could not be written (a full disk): left out, exit status 1
    n_unwritten: int = 0

    @property
    def exit_code(self) -> int:
        return 0 if self.n_failed == 0 and not self.n_unwritten else 1


# -- the output folder -------------------------------------------------------------------------------
def prepare_output(out, tasks, plots: bool, options: Options = Options()) -> files.Outputs:
    """Check the output folder before any work is done (:class:`ArgumentError` otherwise): a folder
    (created if needed) that can be written to; no input among the files the run would write; and
    its fixed reports (``summary.csv`` ...), where present, written by an earlier run."""
    out = output_folder(out)
    shown = cells.display(out)
    try:
        outputs = files.Outputs(out)
    except files.NotOurs as exc:
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
            raise ArgumentError(f"the report {cells.display(out / rel)} would overwrite the input "
                                f"{cells.display(inputs[(st.st_dev, st.st_ino)])}; choose another --out")
    for rel in (f for f in fixed if f != outfiles.MANIFEST):  # the manifest vouches for the rest
        try:
            outputs.check(rel)
        except files.NotOurs as exc:
            raise ArgumentError(f"--out: {exc}; move it away or choose another folder") from None
    return outputs


def _write_record(outputs: files.Outputs, task: Task, res: dict, plots: bool, say) -> None:
    """Write (or remove, for a failed record) the record's own report and figure; a problem doing so
    makes the record a failure of stage ``write`` (the batch goes on)."""
    rid = res["record"]
    problems = []
    try:
        if res["rows"]:
            outputs.write(outfiles.record_csv_name(rid), res.get(TEXT) or columns.csv_text(fields_for(task.options), res["rows"]))
        else:  # a report from an earlier run would look like this record's
            outputs.remove(outfiles.record_csv_name(rid))
    except OSError as exc:
        problems.append(exc)
    if plots:
        # the record's figure, and the barcode of the check above the search width where it
        # found failing widths; a figure not drawn this time is removed (an earlier run's)
        for name, data in ((outfiles.record_plot_name(rid), res.get("plot")),
                           (outfiles.record_widths_plot_name(rid), res.get("widths_plot")),
                           (outfiles.record_friction_plot_name(rid), res.get("friction_plot"))):
            try:
                if data:
                    outputs.write(name, data)
                else:
                    outputs.remove(name)
            except OSError as exc:
                problems.append(exc)
    res["widths_plot"] = res["friction_plot"] = None
    res["plot"] = None  # thousands of records: keep only the rows in memory
    for exc in problems:
        say(f"pipeline run: {rid}: {cells.display(exc)}")
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
    outputs, journal = _open(out, tasks, options, log, lists)
    # what each record's rows are (text as in its report), and why it failed; nothing else is kept
    # per record, so that memory stays flat over a long batch
    tasks, held = passes.first_pass(tasks, options)
    plan = passes.Plan(options, held)
    by_pair = pairs_in_passes(tasks, options)
    texts, keys, todo = _reusable(tasks, journal, force, options, plan, by_pair)
    plan.sent(todo)
    failures: list[dict | None] = [None] * len(tasks)
    computed = set()  # the tasks computed (in any pass); the others were reused
    log = _job_log(log, tasks, texts)
    bar = _progress_bar(len(todo) + len(held), quiet, progress)
    say = _sayer(quiet, bar)
    header = columns.csv_text(fields_for(options), [])
    stream = _serial([])

    more = _passes(plan, tasks, journal, keys, texts, options, by_pair, force, bar)
    try:
        staged = any(passes.staged(t, options) for t in tasks)
        todo = todo or (more() if staged else [])
        # one executor for every pass: its workers started once
        stream = execute(todo, jobs=jobs, dask=dask, more=more if staged else None)
        try:
            for res in stream:
                computed.add(res["index"])
                _handle(res, tasks, outputs, journal, keys, texts, failures, options, plan, header, say)
                log.record(res, tasks[res["index"]].record_id)
                if bar is not None:
                    bar.update(1)
        except ClusterLost as exc:  # the reports are written all the same, the rest listed
            _not_computed(exc, tasks, texts, failures, computed, outputs, journal, log, say)
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
    _write_lists(outputs, lists, say)
    with executors.renderer(bool(dask) or bool(jobs and jobs > 1)) as render:
        design, rows, problems, risk_rows = _write_tables(outputs, out, tasks, header, text, failures,
                                                          failed, options, render, jobs=jobs, say=say)
    journal.finish([t.record_id for t in tasks],
                   {p: [tasks[i].record_id for i in ix] for p, ix in by_pair.items()})
    n_failed = len(failures)
    summary = RunSummary(len(tasks), len(tasks) - n_failed, n_failed, out, len(tasks) - len(computed),
                         {"design": design, "summary": rows, "failures": failures,
                          "suite": suite_tables.SUITE_COLUMNS.as_written(suite_tables.suite_rows(rows) if rows else []),
                          "risk": risk_rows},
                         problems)
    if not quiet:
        _print_end(summary, tasks, failed, len(computed), design, failures, rows)
    return summary


def _open(out, tasks, options, log, lists):
    """``(outputs, journal)`` of the run's folder ``out``, checked (:func:`prepare_output`, the
    ``--log`` file), the temporaries a killed run left there removed."""
    outputs = prepare_output(out, tasks, options.plots, options)
    own = outfiles.own_files(tasks, options) + list(lists)   # lists: such as peer-not-downloaded.csv
    _check_log(log, out, tasks, own)
    try:
        journal = resume.Journal(out)
    except files.NotOurs as exc:
        raise ArgumentError(f"--out: {exc}; move it away or choose another folder") from None
    resume.remove_stale_temporaries(out, own)  # left by a run killed while writing
    return outputs, journal


def _job_log(log, tasks, texts):
    """The ``--log`` of the run (:class:`pipeline.batch.joblog.JobLog`), the reused records noted."""
    try:
        log = joblog.JobLog(log)
    except OSError as exc:
        raise ArgumentError(f"--log {cells.display(log)}: {cells.display(exc.strerror or exc)}") from None
    for t in tasks:
        if texts[t.index]:
            log.record(None, t.record_id, reused=True)
    return log


def _sayer(quiet, bar):
    """``say(msg)``: a message on stderr (above the progress bar ``bar``; none with ``quiet``)."""
    def say(msg):
        if quiet:
            return
        if bar is not None:
            bar.write(msg, file=sys.stderr)
        else:
            print(msg, file=sys.stderr)
    return say


def _write_lists(outputs, lists, say) -> None:
    """The files the inputs add (``{name: text}``; None: an earlier run's removed), such as the
    records of a PEER search not in its download."""
    for rel, listed in lists.items():
        try:
            if listed is not None:
                outputs.write(rel, listed)
            elif outputs.owned(rel):
                outputs.remove(rel)
        except files.NotOurs as exc:
            say(f"pipeline run: note: {exc}")


def _print_end(summary, tasks, failed, n_computed, design, failures, rows) -> None:
    """The table of the answer and the run's last line."""
    msg = f"pipeline run: {summary.n_ok} of {summary.n_records} records processed"
    if any(t.direction is not None for t in tasks):  # a pair's directions are one task each
        groups = {site.pair_of(t) for t in tasks}
        msg = (f"pipeline run: {len(groups - set(failed))} of {len(groups)} "
               f"records or pairs processed in every direction ({summary.n_ok} of "
               f"{summary.n_records} tasks)")
    msg += f" ({summary.n_reused} reused from an earlier run, {n_computed} computed)"
    if summary.n_failed:
        msg += f", {summary.n_failed} failed (see {cells.display(summary.out / outfiles.FAILURES)})"
    print(answer.table_text(design, failures, rows), end="")
    print(f"{msg}; reports in {cells.display(summary.out)}")


def _not_computed(exc, tasks, texts, failures, computed, outputs, journal, log, say) -> None:
    """Every task without a result when the dask cluster was lost (``exc``): a failure of stage
    ``cluster``, its report of an earlier run removed; a later run computes them."""
    reason = ClusterLost(f"{exc}; not computed: run the same command again to finish the batch")
    left = [t for t in tasks if not texts[t.index] and failures[t.index] is None]
    for t in left:
        computed.add(t.index)
        failures[t.index] = failure(t, "cluster", reason)
        journal.drop(t.record_id)
        for name in (outfiles.record_csv_name(t.record_id), outfiles.record_plot_name(t.record_id),
                     outfiles.record_widths_plot_name(t.record_id)):
            with contextlib.suppress(OSError, files.NotOurs):
                if outputs.owned(name):
                    outputs.remove(name)
        log.record({"failure": failures[t.index]}, t.record_id)
    say(f"pipeline run: {exc}: {len(left)} task(s) not computed, listed in failures.csv; run the "
        "same command again to finish the batch")


def _handle(res, tasks, outputs, journal, keys, texts, failures, options, plan, header, say) -> None:
    """One computed task's result: its report and figures written, its rows kept as text, the
    journal and the plan of passes told."""
    i = res["index"]
    task = tasks[i]
    figure = res.get("plot")
    _write_record(outputs, task, res, options.plots and task.plot, say)
    texts[i] = (res.get(TEXT) or columns.csv_text(fields_for(task.options), res["rows"]))[len(header):]  # made by the worker
    failures[i] = res["failure"]
    if passes.staged(task, options):  # the plan decides on the rows as the report holds them
        plan.note(task, rows_of(texts[i], options))
    if res["failure"] or not res["rows"] or keys[i] is None:
        journal.drop(task.record_id)
    else:
        journal.add(task.record_id, keys[i], (header + texts[i]).encode("utf-8"),
                    figure if options.plots and task.plot else None,
                    resume.form_text(task) if passes.staged(task, options) else None)
    if res["failure"]:
        f = res["failure"]
        say(f"pipeline run: {res['record']}: failed ({f['stage']}): {cells.display(f['reason'])}")


def _reuse(t, journal, force, version):
    """``(key, rows text)`` of ``t``'s kept report (made by this very form of ``t``), or ``(key, "")``."""
    key = resume.task_key(t, version)
    kept = None if force else journal.reusable(t, key, t.options.plots and t.plot)
    return key, kept or ""


def pairs_in_passes(tasks, options) -> dict:
    """``{pair: [indices]}`` of the pairs computed in passes (pipeline.batch.passes)."""
    out: dict = {}
    for t in tasks:
        if passes.staged(t, options):
            out.setdefault(site.pair_of(t), []).append(t.index)
    return out


def _settled_pair(tasks, indices, journal, version):
    """``{index: (task form, key, rows text)}`` of a pair whose passes an earlier run finished
    (pipeline.batch.resume.Journal.settle), every direction's report kept in the form it was
    made in; empty where any is not."""
    pair = site.pair_of(tasks[indices[0]])
    if journal.settled(pair) is None:
        return {}
    out = {}
    for i in indices:
        form = resume.with_form(tasks[i], journal.forms.get(tasks[i].record_id))
        if form is None:
            return {}
        key, text = _reuse(form, journal, False, version)
        if not text:
            return {}
        out[i] = (form, key, text)
    if journal.pair_digest([tasks[i].record_id for i in indices]) != journal.settled(pair):
        return {}
    return out


def _reusable(tasks, journal, force: bool, options, plan, by_pair):
    """``(texts, keys, todo)``: each task's rows as its kept report holds them ("" where it must be
    computed), its resume key, and the tasks to compute (their journal entries dropped).
    ``tasks`` is updated with the form of each task that was kept: a pair whose passes an earlier
    run finished is kept whole; the held directions of the others (``plan.held``, indices) are
    left to a later pass."""
    texts: list[str] = [""] * len(tasks)
    version = resume.code_version()
    keys: list = [None] * len(tasks)
    todo = []
    for indices in by_pair.values():
        kept = {} if force else _settled_pair(tasks, indices, journal, version)
        for i, (form, keys[i], texts[i]) in kept.items():
            tasks[i] = form
            plan.note(form, rows_of(texts[i], options))
        plan.held -= set(kept)
    for t in list(tasks):
        if t.index in plan.held or texts[t.index]:
            continue
        keys[t.index], texts[t.index] = _reuse(t, journal, force, version)
        if texts[t.index]:
            plan.note(t, rows_of(texts[t.index], options))
        else:
            journal.drop(t.record_id)
            todo.append(t)
    return texts, keys, todo


def _passes(plan, tasks, journal, keys, texts, options, by_pair, force, bar):
    """The executor's ``more``: the tasks of the next pass (pipeline.batch.passes: a pair's
    directions, then its governing one checked, ...), counted on the progress bar."""
    def more():
        later = _later_pass(plan, tasks, journal, keys, texts, options, force)
        _settle(plan, tasks, journal, by_pair)
        if later and bar is not None:
            bar.total += len(later)
            bar.refresh()
        return later
    return more


def _settle(plan, tasks, journal, by_pair) -> None:
    """Note in the journal the pairs whose passes are done (a later run keeps them whole)."""
    while plan.done:
        pair = plan.done.pop()
        journal.settle(pair, [tasks[i].record_id for i in by_pair.get(pair, ())])


def _later_pass(plan, tasks, journal, keys, texts, options, force):
    """The tasks of the next pass (pipeline.batch.passes) that must be computed; those an earlier run
    kept are taken as they are."""
    version = resume.code_version()
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
                plan.note(t, rows_of(kept, options))
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


class _Figures:
    """``outputs`` for the run's own files, where a figure that cannot be written (a full disk)
    is said and counted (``problems``) and the run goes on to ``design.csv`` and ``report.html``;
    a figure with no rows to draw is not drawn, and an earlier run's is removed."""

    def __init__(self, outputs, say):
        self.outputs, self.say, self.problems = outputs, say, 0

    def __getattr__(self, name):
        return getattr(self.outputs, name)

    def write(self, rel, data):
        if not str(rel).endswith(".png"):
            return self.outputs.write(rel, data)
        try:
            return self.outputs.write(rel, data)
        except OSError as exc:
            self.problems += 1
            self.say(f"pipeline run: {cells.display(exc)}; the figure is left out")
            self.drop(rel)  # not an earlier run's in its place
            return None

    def drop(self, rel) -> None:
        """No figure at ``rel`` this run: an earlier run's is removed (where it is the tool's)."""
        with contextlib.suppress(OSError, files.NotOurs):
            if self.outputs.owned(rel):
                self.outputs.remove(rel)


def _write_tables(outputs, out, tasks, header, text, failures, failed, options, render=None, jobs=1,
                  say=print):
    """Write the run's own files from every record's rows (``text``: summary.csv's rows as the records'
    reports hold them, below ``header``); return the design rows, the rows of summary.csv, how
    many figures could not be written and the rows of risk.csv."""
    outputs = _Figures(outputs, say)
    outputs.write(outfiles.SUMMARY, header + text)
    outputs.write(outfiles.FAILURES, columns.csv_text(FAILURE_FIELDS, failures))
    outputs.write(outfiles.COLUMNS_MD, columns_md.columns_md(
        columns_for(options).columns, FAILURE_COLUMNS.columns, margin=options.limit is not None,
        restitution=options.restitution is not None, risk=options.risk is not None))
    # the rows as the reports hold them, so that a resumed run writes the same files
    rows = rows_of(text, options)
    suite_tables.write_tables(outputs, rows, fields_for(options), options, failed, render)
    answers, risk_rows = risk.write_outputs(outputs, tasks, rows, options, render, jobs, say)  # --hazard
    if options.plots and rows:
        outputs.write(outfiles.SUMMARY_PLOT, (render or figures.draw)("record:summary_figure_png", rows))
    elif options.plots:  # every record failed: no empty figures
        for rel in (outfiles.SUMMARY_PLOT, outfiles.SUITE_PLOT, outfiles.FRAGILITY_PLOT):
            outputs.drop(rel)
    design = write_answer(outputs, out, tasks, rows, failures, failed, options, answers)
    outputs.finish()
    return design, rows, outputs.problems, risk_rows


# -- the answer in view: design.csv, report.html (pipeline.reports.design_table, pipeline.reports.html_report) --------
def write_answer(outputs, out, tasks, rows, failures, failed, options, answers=None) -> list[dict]:
    """Write ``design.csv`` and ``report.html``; return the design rows (printed after the run).
    ``answers``: each column's risk at the site (pipeline.batch.risk.write_outputs)."""
    design = design_table.design_rows(rows, failed, answers)
    outputs.write(outfiles.DESIGN_CSV, columns.csv_text(design_table.design_fields(rows), design))
    ids = [t.record_id for t in tasks]
    this_run = set(outfiles.fixed_files(options))  # a figure of an earlier run with other options is not shown
    names = {k: rel for k, rel in (("summary", outfiles.SUMMARY_PLOT), ("suite", outfiles.SUITE_PLOT),
                                   ("fragility", outfiles.FRAGILITY_PLOT), ("risk_widths", risk.RISK_WIDTHS_PLOT),
                                   ("risk_disaggregation", risk.RISK_DISAGG_PLOT)) if k == "summary" or rel in this_run}
    figures = html_report.figures_in(out, ids, options.plots, names)
    outputs.write(outfiles.REPORT_HTML, html_report.report_html(design, rows, failures, ids, figures))
    return design
