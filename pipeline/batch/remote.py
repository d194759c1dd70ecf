"""``pipeline run --dask``: records shipped to dask workers as bytes, a dead worker's records retried.

The client reads each record's file and sends its bytes with the task, so a worker needs no access
to the input paths (no shared file system): it writes them to a private temporary folder under the
file's own name (the readers use the name's extension) and reads them from there.  Records are
submitted a window at a time, so the client holds the bytes of only a few records at once.

A record whose worker dies (the task comes back with an error instead of a result) is submitted
once more, alone among the retried records; if that attempt fails too it is a ``worker`` failure.
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


def work_on_bytes(task: Task, data: bytes, data2: bytes | None = None) -> dict:
    """Run on a worker: :func:`pipeline.batch.worker.work` on ``data`` (and ``data2``, the second file of
    a pair), written to private files named as the originals; the result names the original paths."""
    from . import worker

    if not worker._in_worker:
        worker.init_worker()  # also in a worker the nanny restarted after a death
    folder = tempfile.mkdtemp(prefix="pipeline-record-", dir=_scratch())
    swaps = {}
    try:
        local = {}
        for sub, path, raw in (("1", task.path, data), ("2", task.path2, data2)):
            if path is None:
                continue
            os.mkdir(os.path.join(folder, sub))  # two files of a pair may have the same name
            local[sub] = os.path.join(folder, sub, os.path.basename(path) or "record")
            with open(local[sub], "wb") as fh:
                fh.write(raw)
            swaps[local[sub]] = path
        changes = {"path": local["1"]}
        if "2" in local:
            changes["path2"] = local["2"]
        res = worker.work(dataclasses.replace(task, **changes))
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    res["file"] = task.path
    for row in res["rows"]:
        row["file"] = task.path
        if "file2" in row:
            row["file2"] = task.path2
    if res["failure"]:
        res["failure"]["file"] = task.path
        for here, there in swaps.items():
            res["failure"]["reason"] = res["failure"]["reason"].replace(here, there)
    return res


def run_dask(tasks, client, workers: int):
    """Results of every task on ``client``'s cluster, in completion order."""
    from dask.distributed import as_completed

    from .worker import worker_failure

    queue = collections.deque(tasks)
    retries = collections.deque()  # records whose worker died once: one at a time
    window = max(4, 4 * workers)
    pending = as_completed()
    owner = {}  # future key -> (task, attempt)
    retrying = [False]

    def submit(task, attempt):
        data = read_bytes(task.path)
        data2 = None if task.path2 is None else read_bytes(task.path2)
        if data is None or (task.path2 is not None and data2 is None):
            return process_record(task)  # fails at reading, as it would anywhere
        fut = client.submit(work_on_bytes, task, data, data2, pure=False,
                            key=f"record-{task.index}-{attempt}-{uuid.uuid4().hex}")
        owner[fut.key] = (task, attempt)
        pending.add(fut)
        return None

    def fill():
        done = []
        if retries and not retrying[0]:
            retrying[0] = True
            res = submit(retries.popleft(), 2)
            if res is not None:
                retrying[0] = False
                done.append(res)
        while queue and len(owner) < window:
            res = submit(queue.popleft(), 1)
            if res is not None:
                done.append(res)
        return done

    yield from fill()
    while owner:
        fut = next(pending)
        task, attempt = owner.pop(fut.key)
        if attempt == 2:
            retrying[0] = False
        try:
            res = fut.result()
        except Exception as exc:  # the worker died (or the scheduler lost it)
            if attempt == 1:
                retries.append(task)
                res = None
            else:
                res = worker_failure(task, exc)
        fut.release()
        if res is not None:
            yield res
        yield from fill()
