"""Worker processes that end when the main process dies, however it dies.

A pool's workers wait for their next task on a queue whose writing end they hold themselves, so
they never see the main process go: killed with SIGKILL (as an out-of-memory killer or a batch
scheduler does), a ``pipeline run --jobs 2`` left its two workers idle for good, and with them
the fork server (which ends when every process it served has) and the resource tracker (when every
process holding its pipe has): about 500 MB.

The main process keeps the writing end of a pipe (:func:`lifeline`) that no other process holds; each
worker gets the reading end (through ``initargs``, which :mod:`multiprocessing` passes to a
forkserver or spawned child) and a thread of its own waits on it: the pipe ends when the main
process does, in every way it can end, and the worker ends at once (:func:`hold`).  Then the fork
server and the resource tracker end by themselves.  On Linux the worker also asks the kernel
(``prctl(PR_SET_PDEATHSIG)``) to kill it when its parent, the fork server, goes.
"""
from __future__ import annotations

import os
import threading

_ends = None  # (reading end, writing end) of this process's lifeline, made once


def lifeline():
    """The reading end (a :class:`multiprocessing.connection.Connection`) of this process's
    lifeline, to hand to worker processes with their ``initargs`` (see the module's docstring)."""
    global _ends
    if _ends is None:
        import multiprocessing

        _ends = multiprocessing.Pipe(duplex=False)
    return _ends[0]


def hold(line) -> None:
    """In a worker: end this process as soon as the process that made ``line`` (:func:`lifeline`)
    has ended; ``line`` None: nothing to watch."""
    _die_with_parent()
    if line is None:
        return

    def watch():
        try:
            line.recv_bytes()  # nothing is ever sent: this returns at the end of the pipe
        except (EOFError, OSError):
            pass
        os._exit(1)  # the main process is gone: nothing this worker does is wanted

    threading.Thread(target=watch, name="pipeline-lifeline", daemon=True).start()


def _die_with_parent() -> None:
    """Linux: SIGKILL this process when its parent (the fork server) ends."""
    import sys

    if not sys.platform.startswith("linux"):
        return
    try:
        import ctypes
        import signal

        libc = ctypes.CDLL(None, use_errno=True)
        PR_SET_PDEATHSIG = 1
        libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):  # no libc to ask: the lifeline alone
        pass
