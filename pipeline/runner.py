"""Running a batch of records: in this process, a process pool (``--jobs N``) or dask (``--dask``).

The results do not depend on how the work is spread: each record is processed by the same function,
the reports are assembled in input order, and files are written atomically with fixed formatting.
"""
from __future__ import annotations

import collections
import contextlib
import glob
import logging
import os
import pathlib
import sys
from dataclasses import dataclass

from . import design_table, html_report, interrupts, joblog, outlock, report, resume, site
from .args import ArgumentError, output_folder
from .batch import (COLUMNS, FAILURE_COLUMNS, FAILURE_FIELDS, FIELDS, Options, Task, failure, process_record,
                    record_ids)


@dataclass
class RunSummary:
    n_records: int
    n_ok: int
    n_failed: int
    out: pathlib.Path
    n_reused: int = 0

    @property
    def exit_code(self) -> int:
        return 0 if self.n_failed == 0 else 1


def expand_inputs(items) -> list[str]:
    """File arguments as given; folders give their entries (sorted; not hidden ones, not folders);
    unexpanded wildcards are globbed.

    A path that does not exist stays in the list: it is reported as a failed record, not an argument
    error, so one missing file does not stop a batch.  So are a folder's entries that cannot be
    read (a symbolic link to nothing, a loop of links, files of a folder without search
    permission), and a folder that cannot be listed: each fails at reading, with the reason.
    """
    paths: list[str] = []
    seen = set()

    def add(p):
        key = os.path.abspath(p)
        if key not in seen:
            seen.add(key)
            paths.append(p)

    for item in items:
        item = str(item)
        if os.path.isdir(item):
            try:
                names = sorted(os.listdir(item))
            except OSError:  # a folder that cannot be read: a failed record, with the reason
                add(item)
                continue
            for name in names:
                full = os.path.join(item, name)
                # every entry but hidden ones and folders: a broken link, a link loop or a file
                # that cannot be looked at is a failed record with the reason, never skipped
                if not name.startswith(".") and not os.path.isdir(full):
                    add(full)
        elif not os.path.exists(item) and glob.has_magic(item):
            matches = sorted(glob.glob(item))
            if not matches:
                add(item)  # reported as not found
            for m in matches:
                add(m)
        else:
            add(item)
    return paths


def make_tasks(paths, columns, options: Options) -> list[Task]:
    ids = record_ids(paths)
    return [Task(i, rid, str(path), tuple(columns), options) for i, (rid, path) in enumerate(zip(ids, paths))]


# -- executors -------------------------------------------------------------------------------------
def _serial(tasks):
    """Records one after the other in this process."""
    for task in tasks:
        interrupts.check()
        yield work(task)


def init_worker() -> None:
    """Set up a worker process: one solver thread (the processes share the CPUs; the solver's
    batches then run on one thread, with the same runs and the same results)."""
    global _in_worker
    _in_worker = True
    from rocking import lanes

    lanes.set_threads(1)


def _size(task) -> int:
    try:
        return os.path.getsize(task.path)
    except OSError:
        return 0


def _init_pool_worker(kill_at: str | None = None) -> None:
    """Set up a pool worker: :func:`init_worker`, and Ctrl-C left to the main process, which stops
    the workers itself (a worker interrupted on its own would only print a traceback).
    ``kill_at``: :data:`TEST_KILL_ENV` as the main process has it now (the fork server that starts
    the workers may have been started before it was set)."""
    import signal

    if kill_at is None:
        os.environ.pop(TEST_KILL_ENV, None)
    else:
        os.environ[TEST_KILL_ENV] = kill_at

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    init_worker()


#: test-only: a record id at which a worker process (never the main one) kills itself with SIGKILL,
#: to test what a batch does when a worker dies; not for use
TEST_KILL_ENV = "PIPELINE_TEST_KILL_WORKER_AT"

_in_worker = False  # set in worker processes by init_worker


def work(task: Task) -> dict:
    """:func:`process_record` as a worker runs it."""
    if _in_worker and os.environ.get(TEST_KILL_ENV) == task.record_id:
        import signal

        os.kill(os.getpid(), signal.SIGKILL)
    import time

    start = time.perf_counter()
    res = process_record(task)
    res[joblog.SECONDS] = time.perf_counter() - start
    res[joblog.WORKER] = joblog.here()
    return res


def worker_failure(task: Task, exc: BaseException) -> dict:
    """The result of a record whose worker process died (twice) while running it."""
    return {"index": task.index, "record": task.record_id, "file": task.path, "rows": [],
            "plot": None, "failure": failure(task, "worker", exc)}


def _pool(tasks, jobs):
    import multiprocessing
    from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
    from concurrent.futures.process import BrokenProcessPool

    plots = any(t.options.plots for t in tasks)
    # Not plain fork: the parent may already run threads (the solver's batch threads), and
    # forking such a process is unsafe.  The fork server starts clean, imports the package once
    # and forks the workers from there (cheap).
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    if ctx.get_start_method() == "forkserver":
        preload = ["pipeline.batch", "pipeline.runner", "pulses", "rocking"]
        if plots:
            preload.append("pipeline.plots")  # matplotlib: ~0.2 s a worker otherwise
        ctx.set_forkserver_preload(preload)
    if plots:
        # the summary plot needs matplotlib here too: import it while the workers start
        import threading

        threading.Thread(target=_import_plots, daemon=True).start()
    others = _child_processes()
    # the largest files first (longer records take longer), so that no long record is left alone at
    # the end while the other workers idle; results are placed by index, so the reports do not
    # depend on this order
    queue = collections.deque(sorted(tasks, key=_size, reverse=True))
    # records in the pool when a worker process died: each is run once more alone, so that the
    # one that kills its worker is known and fails, and the others complete
    suspects = collections.deque()
    # at most this many records submitted at once: a few queued per worker keep them busy, and a
    # dead worker makes only these suspects (and the pool holds no future per record of a long batch)
    window = 2 * jobs
    pool = None
    finished = False
    def new_pool():
        return ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_init_pool_worker,
                                   initargs=(os.environ.get(TEST_KILL_ENV),))

    try:
        while queue or suspects:
            if pool is None:
                pool = new_pool()
            if suspects:  # one record alone in the pool
                task = suspects.popleft()
                fut = pool.submit(work, task)
                while not wait([fut], timeout=0.25)[0]:
                    interrupts.check()
                try:
                    yield fut.result()
                except BrokenProcessPool as exc:  # its second death: a worker failure
                    pool.shutdown(wait=True)
                    pool = None
                    yield worker_failure(task, exc)
                except Exception as exc:
                    yield worker_failure(task, exc)
                continue
            running: dict = {}
            broken = False
            while (queue or running) and not broken:
                while queue and len(running) < window:
                    task = queue.popleft()
                    try:
                        running[pool.submit(work, task)] = task
                    except BrokenProcessPool:
                        queue.appendleft(task)
                        broken = True
                        break
                # a short wait, so that an interrupt whose exception was swallowed still stops the run
                done, _ = wait(running, timeout=0.25, return_when=FIRST_COMPLETED)
                interrupts.check()
                for fut in done:
                    task = running.pop(fut)
                    try:
                        yield fut.result()
                    except BrokenProcessPool:
                        suspects.append(task)
                        broken = True
                    except Exception as exc:  # e.g. a result that cannot be sent back
                        yield worker_failure(task, exc)
            if broken:  # every record still in the broken pool is a suspect
                for fut, task in running.items():
                    if fut.done() and not fut.cancelled() and fut.exception() is None:
                        yield fut.result()
                    else:
                        suspects.append(task)
                pool.shutdown(wait=True)
                pool = None
        finished = True
    finally:
        if pool is not None:
            if finished:
                pool.shutdown(wait=True)
            else:  # interrupted, or the caller stopped early: nothing more is wanted from the workers
                _stop(pool, others)


def _child_processes() -> set:
    """This process's live child processes: those of :mod:`multiprocessing` and, on Linux, any other
    (the fork server, which :mod:`multiprocessing` does not list)."""
    import multiprocessing

    children = {("mp", p.pid, p) for p in multiprocessing.active_children()}
    try:
        for task in os.listdir("/proc/self/task"):
            with open(f"/proc/self/task/{task}/children") as fh:
                children |= {("pid", int(pid), None) for pid in fh.read().split()}
    except (OSError, ValueError):  # not Linux: the fork server ends when this process does
        pass
    return children


def _stop(pool, others, grace: float = 1.0) -> None:
    """Stop ``pool`` now: pending records cancelled, its workers (and the fork server it started)
    terminated, killed if they have not ended after ``grace`` seconds.  Processes in ``others``
    (children that existed before the pool) are left alone."""
    import signal
    import time

    with interrupts.deferred():
        pool.shutdown(wait=False, cancel_futures=True)
        known = {pid for _, pid, _ in others}
        found = {}
        for kind, pid, proc in _child_processes():  # a process of multiprocessing's, if it is one
            if pid not in known and found.get(pid) is None:
                found[pid] = proc
        # the resource tracker is left running: it ends by itself when this process does, and
        # this process's queues still report to it
        targets = [(pid, proc) for pid, proc in found.items()
                   if proc is not None or not _is_resource_tracker(pid)]
        for pid, proc in targets:
            _signal(pid, proc, signal.SIGTERM)
        deadline = time.monotonic() + grace
        for pid, proc in targets:
            if proc is not None:
                proc.join(max(0.0, deadline - time.monotonic()))
        for pid, proc in targets:
            if proc is not None and proc.is_alive():
                proc.kill()
                proc.join(1.0)
            elif proc is None:
                _reap(pid, deadline)


def _signal(pid, proc, signum) -> None:
    with contextlib.suppress(OSError):
        if proc is not None:
            proc.terminate()
        else:
            os.kill(pid, signum)


def _reap(pid, deadline) -> None:
    """Kill a child that :mod:`multiprocessing` does not track (the fork server) if it has not ended
    by ``deadline``.  It is not waited for: :mod:`multiprocessing` reaps it (and starts a new one
    if this process runs another pool)."""
    import signal
    import time

    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.02)
    if _alive(pid):
        with contextlib.suppress(OSError):
            os.kill(pid, signal.SIGKILL)


def _alive(pid) -> bool:
    """Whether ``pid`` runs (a process that has ended but is not reaped yet does not)."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return fh.read().rsplit(b")", 1)[1].split()[0] not in (b"Z", b"X")
    except (OSError, IndexError):
        return False


def _is_resource_tracker(pid) -> bool:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as fh:
            return b"resource_tracker" in fh.read()
    except OSError:
        return False


def dask_client(address: str, jobs: int | None):
    """A ``dask.distributed.Client`` on ``address`` or on a new local cluster (``"local"``)."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ArgumentError("--dask needs dask.distributed: pip install 'rocking-columns[dask]'") from None
    if address == "local":
        import dask

        # a task whose worker dies comes back at once; pipeline.remote retries it once itself
        with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
            cluster = LocalCluster(n_workers=jobs or os.cpu_count() or 1, threads_per_worker=1,
                                   processes=True, dashboard_address=None, silence_logs=logging.ERROR)
        return Client(cluster), cluster
    try:
        return Client(address, timeout="20s"), None
    except (OSError, TimeoutError, ValueError) as exc:
        raise ArgumentError(f"--dask: cannot connect to the scheduler at {address!r}: {exc}") from None


def _dask(tasks, address, jobs):
    from .remote import run_dask

    client, cluster = dask_client(address, jobs)
    try:
        client.run(init_worker)
        workers = len(client.scheduler_info().get("workers", {})) or (jobs or 1)
        yield from run_dask(tasks, client, workers)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def execute(tasks, jobs: int | None = 1, dask: str | None = None):
    """Results of :func:`process_record` for every task, in completion order.

    ``jobs`` None (not given) or 1: the records in this process."""
    if dask:
        return _dask(tasks, dask, jobs)
    if jobs is None or jobs <= 1 or len(tasks) <= 1:
        return _serial(tasks)
    return _pool(tasks, min(jobs, len(tasks)))


def _import_plots():
    try:
        import pipeline.plots  # noqa: F401
    except Exception:  # pragma: no cover - reported when the summary plot is drawn
        pass


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
    fixed = [report.SUMMARY, report.FAILURES, report.COLUMNS_MD, report.MANIFEST]
    if plots:
        fixed.append(report.SUMMARY_PLOT)
    fixed += site.output_files(options) + answer_files()
    written = fixed + [report.record_csv_name(t.record_id) for t in tasks]
    if plots:
        written += [report.record_plot_name(t.record_id) for t in tasks]
        written += [report.record_widths_plot_name(t.record_id) for t in tasks]
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
            outputs.write(report.record_csv_name(rid), report.csv_text(FIELDS, res["rows"]))
        else:  # a report from an earlier run would look like this record's
            outputs.remove(report.record_csv_name(rid))
    except OSError as exc:
        problems.append(exc)
    if plots:
        try:
            if res.get("plot"):
                outputs.write(report.record_plot_name(rid), res["plot"])
            else:
                outputs.remove(report.record_plot_name(rid))
        except OSError as exc:
            problems.append(exc)
        try:  # the barcode of the check above the verified width, where it found failing widths
            if res.get("widths_plot"):
                outputs.write(report.record_widths_plot_name(rid), res["widths_plot"])
            else:
                outputs.remove(report.record_widths_plot_name(rid))
        except OSError as exc:
            problems.append(exc)
    res["widths_plot"] = None
    res["plot"] = None  # thousands of records: keep only the rows in memory
    for exc in problems:
        say(f"pipeline run: {rid}: {report.display(exc)}")
    if problems and not res["failure"]:
        res["failure"] = failure(task, "write", problems[0])


def _own_files(tasks, options) -> list[str]:
    """Every file a run of ``tasks`` may write into its output folder (paths relative to it)."""
    names = [report.SUMMARY, report.FAILURES, report.COLUMNS_MD, report.SUMMARY_PLOT, report.MANIFEST,
             resume.RESUME] + site.output_files(options) + answer_files()
    return names + [n for t in tasks for n in (report.record_csv_name(t.record_id),
                                               report.record_plot_name(t.record_id),
                                               report.record_widths_plot_name(t.record_id))]


# -- the whole run -----------------------------------------------------------------------------------
def run(paths, columns, out, *, options: Options = Options(), jobs: int | None = 1, dask: str | None = None,
        quiet: bool = False, progress: bool | None = None, tasks=None, force: bool = False,
        log=None) -> RunSummary:
    """Process ``paths`` for ``columns`` and write every report into ``out``.

    A record whose report in ``out`` was made by an earlier run from the same file content, options
    and package version is kept, not computed again (:mod:`pipeline.resume`), unless ``force``;
    ``summary.csv``, ``failures.csv`` and the plots are rebuilt from every record's report.
    ``log`` (a path) gets one JSON line per record (:mod:`pipeline.joblog`).

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
    out = output_folder(out)  # checked before the Path: pathlib makes "" the current folder
    if tasks is None:  # else made by pipeline.site.make_tasks (pairs, directions, scales)
        tasks = make_tasks(paths, columns, options)
    with outlock.locked(out):  # one run at a time in one folder
        return _run_locked(out, tasks, options=options, jobs=jobs, dask=dask, quiet=quiet,
                           progress=progress, force=force, log=log)


def _run_locked(out, tasks, *, options, jobs, dask, quiet, progress, force, log) -> RunSummary:
    """:func:`run`, the folder locked."""
    outputs = prepare_output(out, tasks, options.plots, options)
    if log is not None:  # never onto an input or one of this run's own files (pipeline.outpaths)
        from .outpaths import check_output_file

        check_output_file(log, "--log", "log", inputs=[p for t in tasks for p in (t.path, t.path2)],
                          reserved=[out / rel for rel in _own_files(tasks, options)], command="run")
    try:
        journal = resume.Journal(out)
    except report.NotOurs as exc:
        raise ArgumentError(f"--out: {exc}; move it away or choose another folder") from None
    resume.remove_stale_temporaries(out, _own_files(tasks, options))  # left by a run killed while writing

    # what each record's rows are (text as in its report), and why it failed; nothing else is kept
    # per record, so that memory stays flat over a long batch
    texts: list[str] = [""] * len(tasks)
    failures: list[dict | None] = [None] * len(tasks)
    version = resume.package_version()
    keys = [resume.task_key(t, version) for t in tasks]
    todo = []
    for t, key in zip(tasks, keys):
        kept = None if force else journal.reusable(t, key, options.plots)
        if kept is None:
            journal.drop(t.record_id)
            todo.append(t)
        else:
            texts[t.index] = kept
    n_reused = len(tasks) - len(todo)
    try:
        log = joblog.JobLog(log)
    except OSError as exc:
        raise ArgumentError(f"--log {report.display(log)}: {report.display(exc.strerror or exc)}") from None
    for t in tasks:
        if texts[t.index]:
            log.record(None, t.record_id, reused=True)

    if progress is None:
        progress = (not quiet) and sys.stderr.isatty()
    bar = None
    if progress and todo:
        import shutil

        from tqdm import tqdm

        # a terminal that reports a size of 0 x 0 (some pseudo-terminals) would hide the bar
        size = shutil.get_terminal_size((100, 24))
        bar = tqdm(total=len(todo), unit="record", file=sys.stderr, desc="pipeline run",
                   ncols=min(size.columns or 100, 120), nrows=size.lines or 24)

    def say(msg):
        if quiet:
            return
        if bar is not None:
            bar.write(msg, file=sys.stderr)
        else:
            print(msg, file=sys.stderr)

    header = report.csv_text(FIELDS, [])
    stream = execute(todo, jobs=jobs, dask=dask) if todo else _serial([])
    try:
        for res in stream:
            i = res["index"]
            task = tasks[i]
            figure = res.get("plot")
            _write_record(outputs, task, res, options.plots, say)
            texts[i] = report.csv_text(FIELDS, res["rows"])[len(header):]
            failures[i] = res["failure"]
            if res["failure"] or not res["rows"] or keys[i] is None:
                journal.drop(task.record_id)
            else:
                journal.add(task.record_id, keys[i], (header + texts[i]).encode("utf-8"),
                            figure if options.plots else None)
            if res["failure"]:
                f = res["failure"]
                say(f"pipeline run: {res['record']}: failed ({f['stage']}): {report.display(f['reason'])}")
            log.record(res, task.record_id)
            if bar is not None:
                bar.update(1)
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
    outputs.write(report.SUMMARY, header + text)
    outputs.write(report.FAILURES, report.csv_text(FAILURE_FIELDS, failures))
    outputs.write(report.COLUMNS_MD, report.columns_markdown(COLUMNS, FAILURE_COLUMNS.columns)
                  + site.columns_markdown() + design_table.columns_markdown())
    # the rows as the reports hold them, so that a resumed run writes the same files
    rows = resume.rows_from_text(text)
    site.write_outputs(outputs, rows, FIELDS, options, failed)
    if options.plots:
        from .plots import summary_figure_png

        outputs.write(report.SUMMARY_PLOT, summary_figure_png(rows))
    design = write_answer(outputs, out, tasks, rows, failures, failed, options)
    outputs.finish()
    journal.finish([t.record_id for t in tasks])
    n_failed = len(failures)
    summary = RunSummary(len(tasks), len(tasks) - n_failed, n_failed, out, n_reused)
    if not quiet:
        msg = f"pipeline run: {summary.n_ok} of {summary.n_records} records processed"
        if any(t.direction is not None for t in tasks):  # a pair's directions are one task each
            groups = {site.pair_of(t) for t in tasks}
            msg = (f"pipeline run: {len(groups - set(failed))} of {len(groups)} "
                   f"records or pairs processed in every direction ({summary.n_ok} of "
                   f"{summary.n_records} tasks)")
        msg += f" ({n_reused} reused from an earlier run, {len(todo)} computed)"
        if n_failed:
            msg += f", {n_failed} failed (see {report.display(out / report.FAILURES)})"
        print(design_table.table_text(design, failures, rows), end="")
        print(f"{msg}; reports in {report.display(out)}")
    return summary


# -- the answer in view: design.csv, report.html (pipeline.design_table, pipeline.html_report) --------
def answer_files() -> list[str]:
    """The files :func:`write_answer` writes into ``--out``."""
    return [design_table.DESIGN_CSV] + html_report.output_files()


def write_answer(outputs, out, tasks, rows, failures, failed, options) -> list[dict]:
    """Write ``design.csv`` and ``report.html``; return the design rows (printed after the run)."""
    design = design_table.design_rows(rows, failed)
    outputs.write(design_table.DESIGN_CSV, report.csv_text(design_table.DESIGN_FIELDS, design))
    ids = [t.record_id for t in tasks]
    this_run = set(site.output_files(options))  # a figure of an earlier run with other options is not shown
    names = {k: rel for k, rel in (("summary", report.SUMMARY_PLOT), ("suite", site.SUITE_PLOT),
                                   ("fragility", site.FRAGILITY_PLOT)) if k == "summary" or rel in this_run}
    figures = html_report.figures_in(out, ids, options.plots, names)
    outputs.write(html_report.REPORT_HTML, html_report.report_html(design, rows, failures, ids, figures))
    return design
