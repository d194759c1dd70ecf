"""Where the records of a batch run: in this process, a process pool (``--jobs N``) or dask
(``--dask``).  Each gives the results of :func:`pipeline.batch.worker.work` for every task, in completion
order; none changes a result.
"""
from __future__ import annotations

import collections
import contextlib
import logging
import os

from .. import interrupts
from ..values import ArgumentError
from . import memo, worker
from .lifeline import lifeline
from ..reports.figures import draw
from .worker import TEST_KILL_ENV, _init_pool_worker, init_worker, work, work_many, worker_failure


def _serial(tasks, more=None):
    """Records one after the other in this process (and those ``more()`` gives, see :func:`execute`,
    next), keeping what a later pass reuses (:mod:`pipeline.batch.memo`) while they run."""
    memo.on()
    queue = collections.deque(tasks)
    try:
        while queue:
            interrupts.check()
            yield work(queue.popleft())
            if more is not None:
                queue.extendleft(reversed(more()))
    finally:
        memo.off()


def _size(task) -> int:
    try:
        return os.path.getsize(task.path)
    except OSError:
        return 0


def _pool(tasks, jobs, more=None):
    """The results of ``tasks`` (and of the passes ``more`` gives) from a pool of ``jobs`` worker
    processes, as they come; a worker that dies makes its records suspects, each run once more
    alone, so that only the record that kills its worker fails."""
    from concurrent.futures import ProcessPoolExecutor

    ctx = _pool_context(any(t.options.plots for t in tasks))
    others = _child_processes()
    # the largest files first (longer records take longer), so that no long record is left alone at
    # the end while the other workers idle; results are placed by index, so the reports do not
    # depend on this order
    queue = collections.deque(sorted(tasks, key=_size, reverse=True))
    # records in the pool when a worker process died: each is run once more alone, so that the
    # one that kills its worker is known and fails, and the others complete
    suspects = collections.deque()
    pool = None
    finished = False

    def new_pool():
        return ProcessPoolExecutor(max_workers=jobs, mp_context=ctx, initializer=_init_pool_worker,
                                   initargs=(os.environ.get(TEST_KILL_ENV), lifeline(), worker.quiet_now()))

    try:
        while queue or suspects or _refill(queue, more):
            if pool is None:
                pool = new_pool()
            if suspects:  # one record alone in the pool
                res, broken = _alone(pool, suspects.popleft())
                if broken:  # its second death: a worker failure
                    pool.shutdown(wait=True)
                    pool = None
                yield res
                continue
            running, broken = yield from _in_chunks(pool, queue, suspects, jobs, more)
            if broken:  # every record still in the broken pool is a suspect
                for fut, chunk in running.items():
                    if fut.done() and not fut.cancelled() and fut.exception() is None:
                        yield from fut.result()
                    else:
                        suspects.extend(chunk)
                pool.shutdown(wait=True)
                pool = None
        finished = True
    finally:
        if pool is not None:
            if finished:
                pool.shutdown(wait=True)
            else:  # interrupted, or the caller stopped early: nothing more is wanted from the workers
                _stop(pool, others)


def _pool_context(plots: bool):
    """The multiprocessing context of the pool: the fork server, the package preloaded in it (and
    matplotlib where there are figures), or spawn where there is no fork server."""
    import multiprocessing

    # Not plain fork: the parent may already run threads (the solver's batch threads), and
    # forking such a process is unsafe.  The fork server starts clean, imports the package once
    # and forks the workers from there (cheap).
    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    if ctx.get_start_method() == "forkserver":
        preload = ["pipeline.batch.record", "pipeline.batch.runner", "pulses", "rocking"]
        if plots:
            preload.append("pipeline.reports.figures.record")  # matplotlib: ~0.2 s a worker otherwise
        ctx.set_forkserver_preload(preload)
    return ctx


def _alone(pool, task):
    """``(result, pool broken)`` of ``task`` run alone in ``pool`` (a suspect): its worker dying
    again makes it a worker failure."""
    from concurrent.futures import wait
    from concurrent.futures.process import BrokenProcessPool

    fut = pool.submit(work, task)
    while not wait([fut], timeout=0.25)[0]:
        interrupts.check()
    try:
        return fut.result(), False
    except BrokenProcessPool as exc:
        return worker_failure(task, exc), True
    except Exception as exc:
        return worker_failure(task, exc), False


def _in_chunks(pool, queue, suspects, jobs, more):
    """Yield the results of ``queue``'s records sent to ``pool`` in chunks (:func:`worker.chunk_size`)
    until the queue is done or the pool breaks; return ``(the submissions still running, broken)``."""
    from concurrent.futures import FIRST_COMPLETED, wait
    from concurrent.futures.process import BrokenProcessPool

    # at most this many submissions (chunks of records, worker.chunk_size) at once: a few queued per
    # worker keep them busy, and a dead worker makes only their records suspects (and the pool
    # holds no future per record of a long batch)
    window = 2 * jobs
    running: dict = {}
    broken = False
    while (queue or running) and not broken:
        while queue and len(running) < window:
            chunk = [queue.popleft() for _ in range(worker.chunk_size(len(queue), jobs))]
            try:
                running[pool.submit(work_many, chunk)] = chunk
            except BrokenProcessPool:
                queue.extendleft(reversed(chunk))
                broken = True
                break
        # a short wait, so that an interrupt whose exception was swallowed still stops the run
        done, _ = wait(running, timeout=0.25, return_when=FIRST_COMPLETED)
        interrupts.check()
        for fut in done:
            chunk = running.pop(fut)
            try:
                yield from fut.result()
            except BrokenProcessPool:
                suspects.extend(chunk)
                broken = True
            except Exception as exc:  # e.g. a result that cannot be sent back
                if len(chunk) > 1:  # each again alone: only the record at fault fails
                    suspects.extend(chunk)
                else:
                    yield worker_failure(chunk[0], exc)
        if more is not None and done:  # a pair's next pass as soon as it has none out
            queue.extendleft(reversed(more()))
    return running, broken


def _refill(queue, more) -> bool:
    """Whether ``more()`` (every result so far taken) gave tasks, now in ``queue`` (largest first)."""
    extra = more() if more is not None else []
    queue.extend(sorted(extra, key=_size, reverse=True))
    return bool(extra)


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

        # a task whose worker dies comes back at once; pipeline.batch.remote retries it once itself
        with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
            cluster = LocalCluster(n_workers=jobs or os.cpu_count() or 1, threads_per_worker=1,
                                   processes=True, dashboard_address=None, silence_logs=logging.ERROR)
        return Client(cluster), cluster
    from .scheduler import CONNECT_TIMEOUT

    # what is no scheduler was refused before the run (pipeline.batch.scheduler.check_address)
    try:
        return Client(address, timeout=CONNECT_TIMEOUT), None
    except Exception as exc:  # what a client raises for a scheduler it cannot talk to varies
        raise ArgumentError(f"--dask {address}: cannot connect to the scheduler: "
                            f"{' '.join(str(exc).split()) or type(exc).__name__}") from None


def _dask(tasks, address, jobs, more=None):
    from .remote import run_dask
    from .scheduler import ClusterLost, Watch

    try:
        client, cluster = dask_client(address, jobs)
    except ArgumentError as exc:  # checked before the run: the scheduler went away since
        if address == "local":
            raise
        raise ClusterLost(str(exc)) from None
    watch = Watch(client, address, cluster is not None)
    try:
        try:
            client.run(init_worker, cluster is not None and worker.quiet_now())
            workers = len(client.scheduler_info().get("workers", {})) or (jobs or 1)
        except Exception as exc:
            raise watch.lost() from exc
        while tasks:
            yield from run_dask(tasks, client, workers, more, watch)
            tasks = more() if more is not None else []
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def execute(tasks, jobs: int | None = 1, dask: str | None = None, more=None):
    """Results of :func:`process_record` for every task, in completion order.

    ``jobs`` None (not given) or 1: the records in this process.  ``more``: called after each
    result has been taken, it gives the tasks to run next (empty: none), ahead of those waiting,
    on the same workers (a pair's later passes, :mod:`pipeline.batch.passes`: the pool and its
    processes are started once, and no pass runs in this process when ``jobs`` asks for
    workers)."""
    if dask:
        return _dask(tasks, dask, jobs, more)
    if jobs is None or jobs <= 1 or (len(tasks) <= 1 and more is None):
        return _serial(tasks, more)
    return _pool(tasks, jobs if more is not None else min(jobs, len(tasks)), more)


@contextlib.contextmanager
def renderer(away: bool):
    """``render(name, *args)``: :func:`draw` in a worker process where ``away`` (the run's records
    ran elsewhere: the run's own figures, matplotlib included, are no work for this process
    either), else here.  The worker is started at the first figure."""
    if not away:
        yield draw
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures import TimeoutError as Waiting  # the builtin one only from Python 3.11

    pool = None

    def render(name, *args):
        nonlocal pool
        if pool is None:
            methods = multiprocessing.get_all_start_methods()
            ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
            pool = ProcessPoolExecutor(1, mp_context=ctx, initializer=_init_pool_worker,
                                       initargs=(None, lifeline(), worker.quiet_now()))
        fut = pool.submit(draw, name, *args)
        while True:  # a short wait, so that Ctrl-C stops the run
            try:
                return fut.result(timeout=0.25)
            except Waiting:
                interrupts.check()

    try:
        yield render
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)
