"""Running a batch of records: in this process, a process pool (``--jobs N``) or dask (``--dask``).

The results do not depend on how the work is spread: each record is processed by the same function,
the reports are assembled in input order, and files are written atomically with fixed formatting.
"""
from __future__ import annotations

import glob
import logging
import os
import pathlib
import sys
from dataclasses import dataclass

from . import report
from .args import ArgumentError
from .batch import Options, Task, failure, process_record, record_ids


@dataclass
class RunSummary:
    n_records: int
    n_ok: int
    n_failed: int
    out: pathlib.Path

    @property
    def exit_code(self) -> int:
        return 0 if self.n_failed == 0 else 1


def expand_inputs(items) -> list[str]:
    """File arguments as given; folders give their files (sorted); unexpanded wildcards are globbed.

    A path that does not exist stays in the list: it is reported as a failed record, not an argument
    error, so one missing file does not stop a batch.
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
            for name in sorted(os.listdir(item)):
                full = os.path.join(item, name)
                if not name.startswith(".") and os.path.isfile(full):
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
    for task in tasks:
        yield process_record(task)


def init_worker() -> None:
    """Set up a worker process: one compiled-solver thread (the processes share the CPUs), and
    the solver's batches always in its one-thread variants (the same runs, the same results; the
    threaded variants would only add their start-up, and their compilation on a fresh install)."""
    import rocking.engine

    rocking.engine.PARALLEL_MIN_RUNS = sys.maxsize
    try:
        import numba

        numba.set_num_threads(1)
    except Exception:  # pragma: no cover - numba missing or threading layer not started
        pass


def _size(task) -> int:
    try:
        return os.path.getsize(task.path)
    except OSError:
        return 0


def _pool(tasks, jobs):
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    plots = any(t.options.plots for t in tasks)
    # Not plain fork: the parent may already run OpenMP threads (numba's parallel solver), and
    # forking such a process is unsafe.  The fork server starts clean, imports the package once
    # and forks the workers from there (cheap, and compilation caches are loaded only once).
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    if ctx.get_start_method() == "forkserver":
        preload = ["pipeline.batch", "pulses", "rocking"]
        if plots:
            preload.append("pipeline.plots")  # matplotlib: ~0.2 s a worker otherwise
        ctx.set_forkserver_preload(preload)
    if plots:
        # the summary plot needs matplotlib here too: import it while the workers start
        import threading

        threading.Thread(target=_import_plots, daemon=True).start()
    with ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=init_worker) as pool:
        # the largest files first (longer records take longer), so that no long record is left
        # alone at the end while the other workers idle; results are placed by index, so the
        # reports do not depend on this order
        futures = {pool.submit(process_record, t): t for t in sorted(tasks, key=_size, reverse=True)}
        try:
            for fut in as_completed(futures):
                try:
                    yield fut.result()
                except Exception as exc:  # the worker process died (e.g. out of memory)
                    t = futures[fut]
                    yield {"index": t.index, "record": t.record_id, "file": t.path, "rows": [],
                           "plot": None, "failure": failure(t, "worker", exc)}
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            raise


def dask_client(address: str, jobs: int | None):
    """A ``dask.distributed.Client`` on ``address`` or on a new local cluster (``"local"``)."""
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError:
        raise ArgumentError("--dask needs dask.distributed: pip install 'rocking-columns[dask]'") from None
    if address == "local":
        cluster = LocalCluster(n_workers=jobs or os.cpu_count() or 1, threads_per_worker=1,
                               processes=True, dashboard_address=None, silence_logs=logging.ERROR)
        return Client(cluster), cluster
    try:
        return Client(address, timeout="20s"), None
    except (OSError, TimeoutError, ValueError) as exc:
        raise ArgumentError(f"--dask: cannot connect to the scheduler at {address!r}: {exc}") from None


def _dask(tasks, address, jobs):
    from dask.distributed import as_completed

    client, cluster = dask_client(address, jobs)
    try:
        client.run(init_worker)
        futures = client.map(process_record, tasks, pure=False)
        index = {f.key: t for f, t in zip(futures, tasks)}
        for fut in as_completed(futures):
            try:
                yield fut.result()
            except Exception as exc:
                t = index[fut.key]
                yield {"index": t.index, "record": t.record_id, "file": t.path, "rows": [],
                       "plot": None, "failure": failure(t, "worker", exc)}
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def execute(tasks, jobs: int | None = 1, dask: str | None = None):
    """Results of :func:`process_record` for every task, in completion order."""
    if dask:
        return _dask(tasks, dask, jobs)
    jobs = jobs or 1
    if jobs <= 1 or len(tasks) <= 1:
        return _serial(tasks)
    return _pool(tasks, min(jobs, len(tasks)))


def _import_plots():
    try:
        import pipeline.plots  # noqa: F401
    except Exception:  # pragma: no cover - reported when the summary plot is drawn
        pass


# -- the whole run -----------------------------------------------------------------------------------
def run(paths, columns, out, *, options: Options = Options(), jobs: int | None = 1, dask: str | None = None,
        quiet: bool = False, progress: bool | None = None) -> RunSummary:
    """Process ``paths`` for ``columns`` and write every report into ``out``."""
    out = pathlib.Path(out)
    out.mkdir(parents=True, exist_ok=True)
    tasks = make_tasks(paths, columns, options)
    if progress is None:
        progress = (not quiet) and sys.stderr.isatty()
    bar = None
    if progress:
        import shutil

        from tqdm import tqdm

        # a terminal that reports a size of 0 x 0 (some pseudo-terminals) would hide the bar
        size = shutil.get_terminal_size((100, 24))
        bar = tqdm(total=len(tasks), unit="record", file=sys.stderr, desc="pipeline run",
                   ncols=min(size.columns or 100, 120), nrows=size.lines or 24)

    def say(msg):
        if quiet:
            return
        if bar is not None:
            bar.write(msg, file=sys.stderr)
        else:
            print(msg, file=sys.stderr)

    results = [None] * len(tasks)
    plots_dir = out / "plots"
    try:
        for res in execute(tasks, jobs=jobs, dask=dask):
            results[res["index"]] = res
            rid = res["record"]
            if res["rows"]:
                report.write_record_csv(out, rid, res["rows"])
            else:
                report.remove_quietly(report.record_csv_path(out, rid))
            if res.get("plot"):
                report.write_atomic(plots_dir / f"{rid}.png", res["plot"])
                res["plot"] = None  # thousands of records: keep only the rows in memory
            elif options.plots:
                report.remove_quietly(plots_dir / f"{rid}.png")
            if res["failure"]:
                f = res["failure"]
                say(f"pipeline run: {rid}: failed ({f['stage']}): {f['reason']}")
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()

    rows = [row for res in results for row in res["rows"]]
    failures = [res["failure"] for res in results if res["failure"]]
    report.write_summary(out, rows)
    report.write_failures(out, failures)
    report.write_columns_md(out)
    if options.plots:
        from .plots import summary_figure_png

        report.write_atomic(plots_dir / "summary.png", summary_figure_png(rows))
    n_failed = sum(1 for res in results if res["failure"])
    summary = RunSummary(len(tasks), len(tasks) - n_failed, n_failed, out)
    if not quiet:
        msg = f"pipeline run: {summary.n_ok} of {summary.n_records} records processed"
        if n_failed:
            msg += f", {n_failed} failed (see {out / 'failures.csv'})"
        print(f"{msg}; reports in {out}")
    return summary
