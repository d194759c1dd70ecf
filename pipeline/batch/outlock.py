"""One ``pipeline run`` at a time in one ``--out`` folder.

Two runs writing one folder at once would each keep their own view of the manifest and of the
resume journal, and the folder would then be refused by every later run.  The folder itself is
locked (:func:`fcntl.flock` on an open descriptor of the folder, exclusive, not waiting): no file is
added to the folder, the lock goes with the process however it ends (even ``kill -9``), and a
second run is refused at once, before it reads or writes anything, with a one-line reason
(exit status 2).  Nothing is lost: the first run goes on as if alone, and the second can be run
again when the first has finished.
"""
from __future__ import annotations

import contextlib
import os

from ..values import ArgumentError


@contextlib.contextmanager
def locked(folder, what: str = "--out"):
    """Hold the lock of ``folder`` (an existing folder) for the ``with`` block.

    Raises :class:`ArgumentError` when another process holds it.  Where the file system has no
    such locks (some network file systems) the run goes on unlocked, as before.
    """
    from ..reports.cells import display

    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX: no lock
        yield
        return
    fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise ArgumentError(f"{what} {display(folder)} is in use by another pipeline run; wait "
                                "for it to finish or choose another folder") from None
        except OSError:  # no locks on this file system
            pass
        yield
    finally:
        os.close(fd)  # releases the lock
