"""One line on stderr while the compiled solver is being built (numba, on its first use after an
install; the machine code is then cached on disk and later runs load it in milliseconds)."""
from __future__ import annotations

import contextlib
import sys

from numba.core import event

MESSAGE = ("rocking: compiling the solver for this machine (numba); this happens once, the result "
           "is cached on disk")

_done = set()      # entry points whose first call in this process has returned
_said = False      # the line is printed at most once per process


def announce(print_it: bool = True) -> None:
    """Print :data:`MESSAGE` unless this process has already done so; ``print_it=False``: only
    note that it was said (by another process of the same run, :mod:`rocking.warmup`)."""
    global _said
    if not _said:
        _said = True
        if print_it:
            print(MESSAGE, file=sys.stderr, flush=True)


class _Notice(event.Listener):
    """Prints :data:`MESSAGE` when a compilation starts (numba broadcasts ``numba:compile`` only
    on a cache miss: loading cached machine code sends no such event)."""

    def on_start(self, ev):
        announce()

    def on_end(self, ev):
        pass


def first_call_done(entry) -> bool:
    """Whether a first call of ``entry`` has returned in this process (nothing left to notice)."""
    return entry in _done or _said


@contextlib.contextmanager
def compiling_notice(entry):
    """Around a call of the compiled ``entry``: the first time only, listen for compilation."""
    if entry in _done or _said:
        yield
        return
    with event.install_listener("numba:compile", _Notice()):
        yield
    _done.add(entry)
