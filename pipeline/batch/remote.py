"""``pipeline run --dask``: records shipped to dask workers as bytes, a dead worker's records retried.

The client reads each record's files (a pair's two, and its vertical) and sends their bytes with the task, so a worker needs no access
to the input paths (no shared file system): it writes them to a private temporary folder under the
file's own name (the readers use the name's extension) and reads them from there.  Records are
submitted a window at a time, so the client holds the bytes of only a few records at once, and in
chunks as ``--jobs`` sends them (:func:`pipeline.batch.worker.chunk_size`): a pair's directions
together, its files sent once.

A record whose worker dies (the task comes back with an error instead of a result: every record of
its chunk) is submitted once more, alone among the retried records; if that attempt fails too it
is a ``worker`` failure.
On a local cluster the scheduler gives up on a task at its first worker death
(``distributed.scheduler.allowed-failures`` 0), so the retry is this module's; a remote scheduler
retries by its own setting first (3 by default).
"""
from __future__ import annotations

import collections
import dataclasses
import os
import shutil
import tempfile
import uuid

from .record import process_record
from .tasks import Task


def read_bytes(path: str) -> bytes | None:
    """The file's bytes, or None when it cannot be read here (the record then fails at reading,
    computed on the client, with the reader's own message)."""
    try:
        with open(path, "rb") as fh:
            return fh.read()
    except (OSError, ValueError):
        return None


def _scratch() -> str | None:
    """The dask worker's own folder (None outside a worker: the system's temporary folder).  A
    worker killed while it works on a record cannot remove that record's files; dask removes a dead
    worker's folder when the next worker starts, so they do not pile up in the temporary folder."""
    try:
        from distributed import get_worker

        return get_worker().local_directory
    except (ImportError, ValueError):
        return None


def work_on_bytes(tasks: list[Task], blobs: dict) -> list[dict]:
    """Run on a worker: :func:`pipeline.batch.worker.work` on each of ``tasks``, their files
    (``blobs``: path -> bytes, each file once: a pair's directions share theirs) written to private
    files named as the originals; the results name the original paths."""
    from . import worker

    if not worker._in_worker:
        worker.init_worker()  # also in a worker the nanny restarted after a death
    folder = tempfile.mkdtemp(prefix="pipeline-record-", dir=_scratch())
    try:
        local = {}
        for n, (path, raw) in enumerate(blobs.items()):
            os.mkdir(os.path.join(folder, str(n)))  # two files of a pair may have the same name
            local[path] = os.path.join(folder, str(n), os.path.basename(path) or "record")
            with open(local[path], "wb") as fh:
                fh.write(raw)
        out = []
        for task in tasks:
            fields = [f for f in _file_fields(task) if getattr(task, f) in local]
            res = worker.work(dataclasses.replace(task, **{f: local[getattr(task, f)] for f in fields}))
            out.append(_as_given(res, task, {local[getattr(task, f)]: getattr(task, f) for f in fields}))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    return out


def _as_given(res: dict, task: Task, swaps: dict) -> dict:
    """``res`` of ``task`` run on private copies (``swaps``: copy -> original), naming the originals."""
    from . import worker

    def given(text):
        for here, there in swaps.items():
            text = text.replace(here, there)
        return text

    res["file"] = task.path
    for row in res["rows"]:
        for k, v in row.items():  # the vertical's file, a warning naming a file ...
            if isinstance(v, str):
                row[k] = given(v)
        row["file"] = task.path
        if "file2" in row:
            row["file2"] = task.path2
    res[worker.TEXT] = worker.rows_text(res["rows"], task.options)  # with the paths as given
    if res["failure"]:
        res["failure"]["file"] = task.path
        res["failure"]["reason"] = given(res["failure"]["reason"])
    return res


def _file_fields(task: Task) -> tuple:
    """The fields of ``task`` naming the files it reads: ``path``, and ``path2`` and ``vertical``
    where set."""
    return ("path",) + tuple(f for f in ("path2", "vertical") if getattr(task, f) is not None)


def _files(task: Task) -> tuple:
    return tuple(getattr(task, f) for f in _file_fields(task))


def _next_chunk(queue, workers: int) -> list[Task]:
    """The next records to send together: up to :func:`pipeline.batch.worker.chunk_size` of
    them, from the queue's head, reading the same files (a pair's directions)."""
    from . import worker

    chunk = [queue.popleft()]
    k = worker.chunk_size(len(queue) + 1, workers)
    while queue and len(chunk) < k and _files(queue[0]) == _files(chunk[0]):
        chunk.append(queue.popleft())
    return chunk


def _reconnected(client, watch) -> bool:
    """Whether ``client`` lost its scheduler's connection and has it again (a dask client
    cancels every future at such a loss); :class:`pipeline.batch.scheduler.ClusterLost` when
    it gives up."""
    import time

    if client.status == "running":
        return False
    while client.status != "running":
        watch.check()
        time.sleep(0.1)
    return True


def run_dask(tasks, client, workers: int, more=None, watch=None):
    """Results of every task on ``client``'s cluster, in completion order; after each result
    taken, ``more()`` gives tasks to run next, ahead of those waiting (a pair's next pass,
    pipeline.batch.executors.execute).  ``watch`` (:class:`pipeline.batch.scheduler.Watch`):
    raises :class:`~pipeline.batch.scheduler.ClusterLost` when the cluster is gone."""
    from concurrent.futures import CancelledError

    from dask.distributed import as_completed

    from .. import interrupts
    from . import scheduler
    from .worker import worker_failure

    watch = watch or scheduler.Watch(client, "?", False)
    reconnections = 0

    queue = collections.deque(tasks)
    retries = collections.deque()  # records whose worker died once: one at a time
    window = max(4, 4 * workers)
    pending = as_completed()
    owner = {}  # future key -> (tasks, attempt)
    retrying = [False]

    def submit(chunk, attempt):
        """Send ``chunk``; return the results of those that fail at reading on this client."""
        blobs = {p: read_bytes(p) for p in dict.fromkeys(p for t in chunk for p in _files(t))}
        if any(blobs[t.path] is None or (t.path2 is not None and blobs[t.path2] is None) for t in chunk):
            return [process_record(t) for t in chunk]  # fails at reading, as it would anywhere
        # a vertical that cannot be read here is left to the worker, whose row then says why it
        # was not used, as a run in one process does
        blobs = {p: raw for p, raw in blobs.items() if raw is not None}
        watch.check()  # a closed client would queue the task for ever
        fut = client.submit(work_on_bytes, chunk, blobs, pure=False,
                            key=f"record-{chunk[0].index}-{attempt}-{uuid.uuid4().hex}")
        owner[fut.key] = (chunk, attempt)
        pending.add(fut)
        return []

    def fill():
        done = []
        if retries and not retrying[0]:
            retrying[0] = True
            res = submit([retries.popleft()], 2)
            if res:
                retrying[0] = False
                done += res
        while queue and len(owner) < window:
            done += submit(_next_chunk(queue, workers), 1)
        return done

    yield from fill()
    while owner:
        fut = scheduler.next_result(pending, watch, interrupts.check)
        chunk, attempt = owner.pop(fut.key)
        if attempt == 2:
            retrying[0] = False
        try:
            results = fut.result()
        except Exception as exc:  # the worker died, or the connection to the scheduler was lost
            if _reconnected(client, watch) or isinstance(exc, CancelledError):
                # nothing went wrong with the records: sent again as they were, a few times
                reconnections += 1
                if reconnections > 3:
                    raise watch.lost() from exc
                if attempt == 1:
                    queue.extendleft(reversed(chunk))
                else:
                    retries.appendleft(chunk[0])
                results = []
            else:
                results = [] if attempt == 1 else [worker_failure(t, exc) for t in chunk]
                if attempt == 1:
                    retries.extend(chunk)
        fut.release()
        yield from results
        if more is not None and results:
            queue.extendleft(reversed(more()))
        yield from fill()
