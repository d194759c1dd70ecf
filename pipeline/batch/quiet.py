"""A quiet batch (``--quiet``, ``pipeline.design(quiet=True)``): no warning printed by the main
process or by the worker processes it starts (what a record's reading warns of is in its rows'
``warnings``)."""
from __future__ import annotations

import contextlib

#: whether this process runs a quiet batch now (:func:`quieted`): the workers it starts are quiet too
_quiet = False


@contextlib.contextmanager
def quieted(quiet: bool):
    """A batch with ``--quiet`` (``pipeline.design(quiet=True)``): no warning printed in this
    process while it runs (obspy's, numpy's; a record's own are in its rows' ``warnings``), nor
    in the worker processes it starts (:func:`quiet_now`, their initializers' argument), nor the
    log lines of a local dask cluster's client."""
    global _quiet
    if not quiet:
        yield
        return
    import logging
    import warnings

    before, _quiet = _quiet, True
    loggers = [logging.getLogger(n) for n in ("distributed", "distributed.client")]
    levels = [lg.level for lg in loggers]
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            for lg in loggers:
                lg.setLevel(logging.CRITICAL + 1)
            yield
    finally:
        _quiet = before
        for lg, level in zip(loggers, levels):
            lg.setLevel(level)


def quiet_now() -> bool:
    """Whether the workers started now should print no warning (:func:`quieted`)."""
    return _quiet
