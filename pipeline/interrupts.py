"""Ctrl-C (SIGINT) and SIGTERM on the command line: noted once, never lost, never raised twice.

Python's own handler raises :class:`KeyboardInterrupt` at every SIGINT, wherever the main thread is:
a second Ctrl-C then lands inside the clean-up of the first (a half-removed temporary file, workers
never stopped), and one that lands inside a callback Python cannot raise from (a finaliser, a
compiled library's callback) is printed and swallowed, and the run goes on as if nothing happened.

While :func:`handling` is active, the first signal raises :class:`Interrupted` (a
:class:`KeyboardInterrupt`) and is remembered in :func:`pending`; later signals are only noted, so
the clean-up runs to its end.  Code that must not be cut in the middle (writing a report, stopping
workers) runs inside :func:`deferred`: a signal arriving there is raised when the block ends.  Long
loops call :func:`check` between steps, so a signal whose exception was swallowed still stops them.
"""
from __future__ import annotations

import contextlib
import signal
import threading

#: exit status of a command ended by each signal (128 + the signal number, as a shell reports it)
EXIT_STATUS = {signal.SIGINT: 128 + signal.SIGINT, signal.SIGTERM: 128 + signal.SIGTERM}


class Interrupted(KeyboardInterrupt):
    """The run was stopped by SIGINT or SIGTERM (``signum``)."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum

    @property
    def exit_status(self) -> int:
        return EXIT_STATUS.get(self.signum, 130)


class _State:
    """Signal state of this process (signal handlers are process-wide)."""

    def __init__(self):
        self.signum = None  # first signal received while handling
        self.raised = False  # Interrupted raised once already
        self.defer = 0  # depth of deferred() blocks
        self.active = 0  # depth of handling() blocks


_state = _State()


def _handler(signum, frame):
    if _state.signum is None:
        _state.signum = signum
    if _state.raised or _state.defer:
        return
    _state.raised = True
    raise Interrupted(_state.signum)


@contextlib.contextmanager
def handling(to_exit: bool = False):
    """Handle SIGINT and SIGTERM as described in the module's docstring for the block's duration.

    With ``to_exit`` (the process ends after the block), once a signal has been received further
    signals are ignored, so that they cannot turn a clean exit into a traceback or a death by
    signal.  Outside the main thread (where handlers
    cannot be installed) it does nothing.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {sig: signal.signal(sig, _handler) for sig in EXIT_STATUS}
    _state.active += 1
    try:
        yield
    finally:
        _state.active -= 1
        if not _state.active and not (to_exit and _state.signum is not None):
            for sig, old in previous.items():
                signal.signal(sig, old)
        elif not _state.active:
            # ignored, not only noted: Python's exit resets handlers it installed to the default,
            # and a signal then would kill the process before its exit handlers ran
            for sig in previous:
                signal.signal(sig, signal.SIG_IGN)


def pending() -> int | None:
    """The signal received while :func:`handling` was active, or None."""
    return _state.signum


def check() -> None:
    """Raise :class:`Interrupted` if a signal arrived and its exception has not reached here.

    Call it between steps of long loops: a signal whose exception a callback swallowed still
    stops the loop.
    """
    if _state.signum is not None and not _state.defer:
        _state.raised = True
        raise Interrupted(_state.signum)


@contextlib.contextmanager
def deferred():
    """Run the block whole: a signal arriving inside is raised (once) when the block ends."""
    _state.defer += 1
    try:
        yield
    finally:
        _state.defer -= 1
    if _state.signum is not None and not _state.raised and not _state.defer:
        _state.raised = True
        raise Interrupted(_state.signum)


def reset() -> None:
    """Forget a received signal (for a new command in the same process, such as a test)."""
    _state.signum, _state.raised = None, False
