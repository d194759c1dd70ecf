"""One task in a worker: :func:`work` runs :func:`pipeline.batch.record.process_record` as a worker (this
process, a pool's process or a dask worker) runs it, with the time it took and where.
"""
from __future__ import annotations

import os

from . import joblog, memo
from .quiet import quiet_now  # noqa: F401 (what the pools' initializers are given)
from .record import failure, process_record
from .row import fields_for
from .tasks import Task


def init_worker(quiet: bool = False) -> None:
    """Set up a worker process: one solver thread (the processes share the CPUs; the solver's
    batches then run on one thread, with the same runs and the same results); ``quiet``: no
    warning printed (``--quiet``: what a record's reading warns of is in its rows)."""
    global _in_worker
    _in_worker = True
    from rocking import lanes

    lanes.set_threads(1)
    if quiet:
        import warnings

        warnings.simplefilter("ignore")


def _init_pool_worker(kill_at: str | None = None, line=None, quiet: bool = False) -> None:
    """Set up a pool worker: :func:`init_worker`, and Ctrl-C left to the main process, which stops
    the workers itself (a worker interrupted on its own would only print a traceback).
    ``kill_at``: :data:`TEST_KILL_ENV` as the main process has it now (the fork server that starts
    the workers may have been started before it was set).  ``line``: the main process's
    :func:`pipeline.batch.lifeline.lifeline`; the worker ends when the main process does.
    ``quiet``: :func:`quiet_now` in the main process."""
    import signal

    from .lifeline import hold

    hold(line)

    if kill_at is None:
        os.environ.pop(TEST_KILL_ENV, None)
    else:
        os.environ[TEST_KILL_ENV] = kill_at

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    init_worker(quiet)


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

    if _in_worker:  # a pair's direction computed again in a later pass reuses its search and fit
        memo.on()  # (in this process: while the batch runs, pipeline.batch.executors._serial)
    start, cpu = time.perf_counter(), time.process_time()
    res = process_record(task)
    res[joblog.SECONDS] = time.perf_counter() - start
    # this process's CPU (all its threads) on the task: a pool's workers are no children of the
    # main process's to getrusage (forkserver), so a batch's CPU is the sum of these
    res[joblog.CPU] = time.process_time() - cpu
    res[joblog.WORKER] = joblog.here()
    res[TEXT] = rows_text(res["rows"], task.options)
    return res


#: at most this many records go to a worker at once: each submission costs the main process
#: about a millisecond (the task and its result through the pool's queues and threads), as much
#: as it spends on the record's result, so a long batch sends them in chunks
CHUNK = 8


def chunk_size(queued: int, jobs: int) -> int:
    """How many of the ``queued`` records (largest first) to send in the next submission: up to
    :data:`CHUNK` while each worker has at least four chunks' worth left, down to one record
    at a time towards the end of the queue, so that no worker is left idle while another
    finishes a chunk."""
    return max(1, min(CHUNK, queued // (4 * jobs)))


def work_many(tasks: list[Task]) -> list[dict]:
    """:func:`work` on each of ``tasks`` in turn (a pool's submission of several,
    :data:`CHUNK`)."""
    return [work(task) for task in tasks]


#: the result key of the record's report as CSV text (header and rows), made in the worker so that
#: the main process only writes it (pipeline.batch.runner)
TEXT = "text"


def rows_text(rows, options):
    """``<record>.csv``'s text of ``rows`` (the columns of the run's ``options``), or None where
    they do not match the columns (the main process then fails as it did)."""
    from ..reports.columns import csv_text, ReportError

    try:
        return csv_text(fields_for(options), rows)
    except ReportError:
        return None


def worker_failure(task: Task, exc: BaseException) -> dict:
    """The result of a record whose worker process died (twice) while running it."""
    return {"index": task.index, "record": task.record_id, "file": task.path, "rows": [],
            "plot": None, "failure": failure(task, "worker", exc)}
