"""obspy traces in and out: what an :class:`obspy.Trace` in memory says as a record's fields
(its units from what the reader put in ``trace.stats``, or given: never guessed), and a record as
a trace.  :meth:`pulses.Record.from_trace` and :meth:`pulses.Record.to_trace` are the doors.

A trace is interpreted as the file it came from would be (:mod:`pulses.formats.sac`,
:mod:`pulses.formats.knet`, the AT2 plugin's ``stats.at2``), then gets every check
:func:`pulses.read_record` makes (:mod:`pulses.formats.checks`).  Nothing here builds a record:
the record type stands on this package, not the reverse.
"""
from __future__ import annotations

import os

import numpy as np

from ..errors import RecordError
from ..units import unit_factor
from .at2 import reading_of
from .checks import record_fields
from .obspy import unitless
from .registry import Reading, ReadOptions, by_obspy_name

#: ``trace.stats`` key under which :func:`record_trace` keeps what a trace does not hold otherwise
STATS_KEY = "pulses"


def _source(tr, name) -> str:
    """The name a trace goes by in messages and ``metadata["source"]``: the file the AT2 plugin
    read it from, or ``name``, or the trace's id."""
    at2 = tr.stats.get("at2") or {}
    return str(at2.get("source") or name or tr.id)


def _reading(tr, path: str) -> Reading:
    """What the trace says, as the format it was read from states it."""
    fmt_name = str(tr.stats.get("_format", "")).upper()
    fmt = by_obspy_name(fmt_name) if fmt_name else None
    if fmt is not None and fmt.from_trace is not None:
        return fmt.from_trace(tr, path, ReadOptions())
    if "at2" in tr.stats:  # the AT2 plugin's header (pulses.formats.at2._read_at2)
        header = {"lines": ["", "", ""], **dict(tr.stats.at2)}
        return reading_of(path, np.asarray(tr.data, dtype=float), float(tr.stats.delta), header)
    return unitless(tr, fmt_name or "this trace's")


def trace_fields(tr, units=None, *, name=None) -> dict:
    """The fields of :meth:`pulses.Record.from_trace`'s record, ``Record(**fields)``: ``acc``
    (m/s^2), ``dt``, ``name``, ``t_start`` and ``metadata``."""
    kept = tr.stats.get(STATS_KEY)
    if kept is not None:  # a record's own trace (record_trace): m/s^2, its name, start and metadata
        return _own(tr, kept, units)
    path = _source(tr, name)
    shown = name if name is not None else os.path.basename(path)
    return record_fields(path, _reading(tr, path), units, None, shown)


def _own(tr, kept, units) -> dict:
    if units is not None and units != "m/s2":
        if unit_factor(units) != 1.0:
            raise RecordError(f"{kept.name}: the trace was made by Record.to_trace and holds m/s2, "
                              f"not {units!r}")
    dt = float(tr.stats.delta)
    if abs(dt - kept.dt) <= 1e-12 * kept.dt:  # obspy keeps 1/dt: take back the record's own dt
        dt = kept.dt
    t_start = kept.t_start + (float(tr.stats.starttime.timestamp) - kept.starttime)
    return {"acc": np.array(tr.data, dtype=float), "dt": dt, "name": kept.name, "t_start": t_start,
            "metadata": dict(kept.metadata)}


def record_trace(record):
    """:meth:`pulses.Record.to_trace`: ``record`` (a :class:`pulses.Record`) as a trace."""
    from obspy import Trace, UTCDateTime
    from obspy.core.util import AttribDict

    meta = record.metadata
    start = UTCDateTime(0) + record.t_start
    tr = Trace(data=np.array(record.acc, dtype=float), header={
        "delta": record.dt, "starttime": start, "station": str(meta.get("station") or ""),
        "channel": str(meta.get("component") or ""), "network": str(meta.get("network") or ""),
        "location": str(meta.get("location") or "")})
    tr.stats[STATS_KEY] = AttribDict({"name": record.name, "t_start": record.t_start, "dt": record.dt,
                                      "starttime": float(start.timestamp), "units": "m/s2",
                                      "metadata": dict(meta)})
    return tr
