"""Compiling the solver before a workload starts, with the work shared between processes.

On its first use after an install the solver is compiled by numba (tens of seconds of one core)
and cached on disk.  Several processes that start at once would each compile the same functions.
:func:`warm_up` instead runs the workload's :data:`GROUPS` (calls of ``rocking``'s public
functions on tiny inputs of exactly the types the real calls use, so that the compiled versions
are the same) in every process that takes part, and the processes share the compilation: before
a process compiles a function of ``rocking`` it takes that function's lock (a file in a folder
the processes share); a process that meets a function another one is compiling stops that group
(numba's ``numba:compile`` event comes before the compilation, and an exception raised there
abandons it), goes on with its other groups, and comes back once the lock is released: the
function is then in numba's disk cache and is loaded, not compiled again.  A lock is released
once the function's cache is written (at the process's next compilation event, or when the group
returns).  Different processes thus compile different functions at the same time (the callees
of one entry point while another compiles a second entry point), and every process ends with
every group run, compiled or loaded.  The only numba interfaces used are public ones: the event
API (``numba.core.event``) and ``cache=True``.

When the cache is warm nothing is compiled and the groups only load what the workload would load
on its first call anyway (and run for a few milliseconds).
"""
from __future__ import annotations

import hashlib
import math
import multiprocessing
import os
import pathlib
import shutil
import signal
import tempfile
import time
from dataclasses import dataclass

from numba.core import event

from . import _compiling

#: the packages whose compiled functions are shared out by locks (their functions are cached on
#: disk, so that one process can load what another compiled); numba's own helpers are compiled
#: by each process that needs them (they are small and not cached)
PACKAGES = ("rocking.",)
#: longest a process waits for the functions other processes are compiling before it compiles
#: them itself too (s): far longer than the whole compilation of the solver on a slow machine
WAIT_LIMIT = 900.0
_POLL = 0.02  # s between looks at a lock another process holds


# -- the groups: rocking's public functions on tiny inputs of the real types ----------------------
def _column():
    from .block import Block

    return Block.from_dimensions(7.5, 1.8)  # tan(alpha) 0.24


def _record():
    """One second of a 0.6 g sine at 100 samples/s: uplifts the column of :func:`_column` (the
    solver is not run at all for a block that stays at rest); made as a read record is, by
    ``pulses.Record``."""
    import numpy as np

    from pulses import G, Record

    t = np.arange(101) * 0.01
    return Record(0.6 * G * np.sin(2.0 * math.pi * t / 0.5), 0.01, name="warm-up")


def _simulate():
    """``rocking.simulate`` of a record (with and without its history) and of a pulse: the
    single-run engine."""
    import pulses

    from .solver import simulate

    block, record = _column(), _record()
    simulate(block, record)
    simulate(block, record, history=False)
    simulate(block, pulses.OneSine(0.6 * pulses.G, 0.5))


def _design():
    """What a design search runs: exact minimum slenderness of pulses (``rocking.min_slenderness``
    and ``rocking.min_slenderness_batch`` as ``pipeline run`` calls it, runs one by one) and the
    verified width under a record (``rocking.required_width``, rule exact: runs in lanes)."""
    import pulses

    from .slenderness import min_slenderness, min_slenderness_batch
    from .widths import required_width

    min_slenderness_batch("sine", [2.0], [0.5], refine="top", ksection=2)
    min_slenderness(pulses.OneSine(0.6 * pulses.G, 0.5), 2.0)
    required_width(7.5, _record(), rule="exact")


#: the groups :func:`warm_up` runs, by name: each calls public functions of ``rocking`` on tiny
#: inputs, of the types the real calls use; together they cover ``pipeline run`` (checked by
#: ``tests/test_warmup.py`` and ``benchmarks/bench_first_run.py --warm-up``)
GROUPS = {"simulate": _simulate, "design": _design}


@dataclass(frozen=True)
class WarmUp:
    """What :func:`warm_up` did in this process.

    Attributes
    ----------
    groups : tuple of str
        The groups run (all of them complete, unless listed in ``failed``).
    compiled : int
        Functions of ``rocking`` this process compiled (0 when the cache was warm).
    seconds : float
        Wall-clock time of the warm-up in this process (s).
    waited : float
        Time spent waiting for functions other processes were compiling (s).
    helpers : int
        Helper processes started.
    failed : tuple of (str, str)
        Groups that raised, and the error (the warm-up never raises for them: the workload's own
        call will report the problem).
    """

    groups: tuple
    compiled: int
    seconds: float
    waited: float
    helpers: int = 0
    failed: tuple = ()


class _Busy(Exception):
    """Raised from the compilation event of a function another process is compiling."""


def _name(dispatcher) -> str:
    f = dispatcher.py_func
    return f"{f.__module__}.{f.__qualname__}"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # exists, owned by someone else
        return True
    return True


def _create(path: pathlib.Path) -> bool:
    """Create ``path`` holding this process's id, atomically; False if it exists."""
    try:
        fd = os.open(path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
    except FileExistsError:
        return False
    with os.fdopen(fd, "w") as fh:
        fh.write(str(os.getpid()))
    return True


def _holder(path: pathlib.Path) -> int | None:
    try:
        return int(path.read_text() or 0) or None
    except (OSError, ValueError):
        return None


class _Locks(event.Listener):
    """The ``numba:compile`` listener of one process: takes a function's lock before it is
    compiled, or abandons the compilation (:class:`_Busy`) when another process holds it."""

    def __init__(self, folder: pathlib.Path, first_compile=None, packages: tuple = PACKAGES):
        self.folder = folder
        self.packages = packages
        self.first_compile = first_compile  # called at this process's first compilation
        self.stack = []        # lock (or None) of every compilation under way, innermost last
        self.written = []      # locks of functions compiled, whose cache is written by now
        self.blocked = None    # the lock another process holds, which stopped the current group
        self.exclusive = True  # False after too long a wait: compile without locks
        self.compiled = 0

    def on_start(self, ev):
        self.stack.append(None)  # first: numba sends the end event whatever happens here
        # a compilation that ended before this event has had its cache written since
        self.release_written()
        if self.first_compile is not None:
            first, self.first_compile = self.first_compile, None
            first()
        if self.blocked is not None:  # the group is being abandoned: nothing more in it
            raise _Busy(str(self.blocked))
        name = _name(ev.data["dispatcher"])
        if not self.exclusive or not name.startswith(self.packages):
            return
        lock = self.folder / (hashlib.sha1(name.encode()).hexdigest()[:20] + ".lock")
        try:
            taken = self._take(lock)
        except OSError:  # the folder is gone or read-only: compile without sharing
            self.exclusive = False
            return
        if not taken:
            self.blocked = lock
            raise _Busy(name)
        self.stack[-1] = lock

    def on_end(self, ev):
        lock = self.stack.pop() if self.stack else None
        if lock is None:
            return
        if self.blocked is not None:  # abandoned (:class:`_Busy`): nothing was written
            _unlink(lock)
        else:  # numba writes the cache right after this event (or nothing, after an error)
            self.written.append(lock)
            self.compiled += 1

    def _take(self, lock: pathlib.Path) -> bool:
        if _create(lock):
            return True
        pid = _holder(lock)
        if pid is not None and not _alive(pid):  # its process died: the lock is free
            _unlink(lock)
            return _create(lock)
        return False

    def release_written(self):
        while self.written:
            _unlink(self.written.pop())


def _unlink(path: pathlib.Path) -> None:
    try:
        path.unlink()
    except OSError:  # already released (or the folder is gone)
        pass


def _wait(locks, limit: float, check) -> bool:
    """Wait until one of ``locks`` is released (or its process has died); False after ``limit``
    seconds.  ``check()`` is called at every look."""
    end = time.monotonic() + limit
    while time.monotonic() < end:
        check()
        for lock in locks:
            pid = _holder(lock)
            if not lock.exists() or (pid is not None and not _alive(pid)):
                return True
        time.sleep(_POLL)
    return False


def _slot(folder: pathlib.Path) -> int:
    """This process's number among those sharing ``folder`` (0 for the first): where in the list
    of groups it starts, so that processes starting together start on different groups."""
    k = 0
    while not _create(folder / f"slot-{k}"):
        k += 1
    return k


def _notice(folder: pathlib.Path) -> None:
    """The one line saying the solver is compiling: printed by the first process of those sharing
    ``folder`` that compiles something, and by none of the others."""
    _compiling.announce(print_it=_create(folder / "notice"))


def warm_up(groups=None, *, helpers: int = 0, shared=None, wait_limit: float = WAIT_LIMIT,
            check=None) -> WarmUp:
    """Compile (or load from numba's disk cache) the compiled solver a workload needs.

    Runs the :data:`GROUPS` named in ``groups`` (default: all, which covers ``pipeline run``)
    in this process.  Processes that call it at the same time with the same ``shared`` folder
    compile different functions and load the others' from the cache (module doc).  When the
    cache is warm it only loads what the groups' first calls would load anyway.

    Parameters
    ----------
    groups : iterable of str, optional
        Names of :data:`GROUPS` to run.
    helpers : int
        Processes to start, when something must be compiled, to share the compilation with this
        one (each runs the same groups; at most one per group besides this process); they end
        before this function returns.  0: none.  They are started as :mod:`multiprocessing`
        starts processes: a script that asks for helpers keeps its own work under
        ``if __name__ == "__main__":``.
    shared : str or path-like, optional
        A folder shared by the processes that warm up together (each given the same one); a
        temporary folder by default (for this process and its helpers).
    wait_limit : float
        Longest wait for functions other processes are compiling before this process compiles
        them itself (s).
    check : callable, optional
        Called with no arguments between groups and while waiting; whatever it raises stops the
        warm-up (e.g. a command line's check for Ctrl-C, which a compilation cannot always be
        interrupted by).

    Returns
    -------
    WarmUp
        What was compiled, how long it took (s), which groups failed.

    Raises
    ------
    ValueError
        For an unknown group name.
    """
    names = tuple(GROUPS) if groups is None else tuple(groups)
    unknown = [n for n in names if n not in GROUPS]
    if unknown:
        raise ValueError(f"unknown warm-up group(s) {', '.join(map(repr, unknown))}; "
                         f"known: {', '.join(GROUPS)}")
    return _run_groups({n: GROUPS[n] for n in names}, helpers=helpers, shared=shared,
                       wait_limit=wait_limit, check=check)


def _run_groups(groups: dict, *, helpers: int = 0, shared=None, wait_limit: float = WAIT_LIMIT,
                packages: tuple = PACKAGES, check=None) -> WarmUp:
    """:func:`warm_up` of ``groups`` (name: function of no arguments, defined at a module's top
    level when there are helpers), sharing out the functions of ``packages``."""
    names = tuple(groups)
    start = time.perf_counter()
    own = shared is None
    folder = pathlib.Path(tempfile.mkdtemp(prefix="rocking-warm-up-")) if own else pathlib.Path(shared)
    folder.mkdir(parents=True, exist_ok=True)
    started = []
    check = check or (lambda: None)
    # one group per process at most: more processes would find nothing to do
    helpers = max(0, min(int(helpers), len(names) - 1))

    def first_compile():
        _notice(folder)
        for _ in range(helpers):
            started.append(_start_helper(folder, groups, wait_limit, packages))

    ok = False
    try:
        k = _slot(folder)
        order = list(names[k % len(names):] + names[:k % len(names)]) if names else []
        locks = _Locks(folder, first_compile, packages)
        waited, failed = 0.0, []
        with event.install_listener("numba:compile", locks):
            while order:
                blockers = []
                for name in list(order):
                    check()
                    locks.blocked = None
                    try:
                        groups[name]()
                    except Exception as exc:  # noqa: BLE001 - reported in the result
                        if locks.blocked is None:
                            failed.append((name, f"{type(exc).__name__}: {exc}"))
                            order.remove(name)
                        else:
                            blockers.append(locks.blocked)
                        continue
                    finally:
                        locks.release_written()  # the group returned: its caches are written
                    order.remove(name)
                if order and blockers and len(blockers) == len(order):
                    t = time.perf_counter()
                    if not _wait(blockers, max(0.0, wait_limit - waited), check):
                        locks.exclusive = False  # waited too long: compile it here too
                    waited += time.perf_counter() - t
        ok = True
        return WarmUp(names, locks.compiled, time.perf_counter() - start, waited, len(started),
                      tuple(failed))
    finally:
        _end_helpers(started, grace=2.0 if ok else 0.0)
        if own:
            shutil.rmtree(folder, ignore_errors=True)


def _context():
    # not plain fork: the calling process may run threads (numba's, a thread pool), and forking
    # such a process is unsafe
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")


def _start_helper(folder, groups, wait_limit, packages):
    proc = _context().Process(target=_helper, args=(str(folder), groups, wait_limit, packages),
                              daemon=True, name="rocking-warm-up")
    proc.start()
    return proc


def _helper(folder, groups, wait_limit, packages):
    """A helper process: the same groups in the same folder.  Ctrl-C is left to the process that
    started it, which ends its helpers."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        _run_groups(groups, shared=folder, wait_limit=wait_limit, packages=packages)
    except Exception:  # noqa: BLE001 - a helper only saves time; the caller compiles what is left
        pass


def _end_helpers(procs, grace: float = 2.0) -> None:
    """Once this process has run every group, what its helpers still do is only loading: they
    are given ``grace`` seconds, then stopped."""
    deadline = time.monotonic() + grace
    for proc in procs:
        proc.join(max(0.0, deadline - time.monotonic()))
    for proc in procs:
        if proc.is_alive():
            proc.terminate()
            proc.join(5.0)
        if proc.is_alive():
            proc.kill()
            proc.join()
