"""The stages of one record's work (``read``, ``fit``, ``classify``, ``design``, ``verify``, ``plot``):
:func:`stage` runs a step of a stage, times it, and turns any error into a :class:`StageError`
naming the stage, which :func:`pipeline.batch.record.process_record` reports as the record's
failure (``failures.csv``'s ``stage``); Ctrl-C is never turned into a failure.
"""
from __future__ import annotations

import threading
import time


class StageError(Exception):
    """A step of ``stage`` failed with ``exc``: the record fails there."""

    def __init__(self, stage, exc):
        super().__init__(str(exc))
        self.stage = stage
        self.exc = exc


def interrupted(exc: BaseException) -> bool:
    """True if ``exc`` is, or was caused by, Ctrl-C (compiled code wraps it in a SystemError)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


#: per thread, ``seconds``: the time spent in each stage of the record being processed (a dict,
#: or None while none is)
timings = threading.local()


def stage(stage, fn, *args, **kwargs):
    """``fn(*args, **kwargs)`` as a step of ``stage``: timed (:data:`timings`), an error raised as a
    :class:`StageError` of ``stage``."""
    t0 = time.perf_counter()
    try:
        return fn(*args, **kwargs)
    except (KeyboardInterrupt, SystemExit):
        raise
    except Exception as exc:  # every failure of a record is reported, never raised
        if interrupted(exc):
            raise KeyboardInterrupt from exc
        raise StageError(stage, exc) from exc
    finally:
        seconds = getattr(timings, "seconds", None)
        if seconds is not None:
            key = f"{stage}:{getattr(fn, '__name__', 'call').strip('_')}"
            seconds[key] = seconds.get(key, 0.0) + time.perf_counter() - t0
