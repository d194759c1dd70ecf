"""obspy in and out: a record from an :class:`obspy.Trace` in memory (its units from what the
reader put in ``trace.stats``, or given: never guessed), a record as a trace, and a
:class:`obspy.Stream` of two or three components as a pair or a triplet.

A trace is interpreted as the file it came from would be (:mod:`pulses.formats.sac`, :mod:`pulses.formats.knet`,
the AT2 plugin's ``stats.at2``), then gets every check :func:`pulses.read_record` makes
(:func:`pulses.io.record_from_reading`).
"""
from __future__ import annotations

import os

import numpy as np

from ..errors import RecordError
from ..record import Record
from . import registry as formats

#: ``trace.stats`` key under which :func:`to_trace` keeps what a trace does not hold otherwise
STATS_KEY = "pulses"


def _source(tr, name) -> str:
    """The name a trace goes by in messages and ``metadata["source"]``: the file the AT2 plugin
    read it from, or ``name``, or the trace's id."""
    at2 = tr.stats.get("at2") or {}
    return str(at2.get("source") or name or tr.id)


def _reading(tr, path: str) -> formats.Reading:
    """What the trace says, as the format it was read from states it."""
    from . import obspy as obspyformat

    fmt_name = str(tr.stats.get("_format", "")).upper()
    fmt = formats.by_obspy_name(fmt_name) if fmt_name else None
    if fmt is not None and fmt.from_trace is not None:
        return fmt.from_trace(tr, path, formats.ReadOptions())
    if "at2" in tr.stats:  # the AT2 plugin's header (pulses.formats.at2._read_at2)
        from .at2 import reading_of

        header = {"lines": ["", "", ""], **dict(tr.stats.at2)}
        return reading_of(path, np.asarray(tr.data, dtype=float), float(tr.stats.delta), header)
    return obspyformat.unitless(tr, fmt_name or "this trace's")


def from_trace(tr, units=None, *, name=None) -> Record:
    """:meth:`pulses.Record.from_trace`."""
    kept = tr.stats.get(STATS_KEY)
    if kept is not None:  # a record's own trace (to_trace): m/s^2, its name, start and metadata
        return _own(tr, kept, units)
    from ..io.read import record_from_reading

    path = _source(tr, name)
    shown = name if name is not None else os.path.basename(path)
    return record_from_reading(path, _reading(tr, path), units, None, shown)


def _own(tr, kept, units) -> Record:
    if units is not None and units != "m/s2":
        from ..units import unit_factor

        if unit_factor(units) != 1.0:
            raise RecordError(f"{kept.name}: the trace was made by Record.to_trace and holds m/s2, "
                              f"not {units!r}")
    dt = float(tr.stats.delta)
    if abs(dt - kept.dt) <= 1e-12 * kept.dt:  # obspy keeps 1/dt: take back the record's own dt
        dt = kept.dt
    t_start = kept.t_start + (float(tr.stats.starttime.timestamp) - kept.starttime)
    return Record(np.array(tr.data, dtype=float), dt, name=kept.name, t_start=t_start,
                  metadata=dict(kept.metadata))


def to_trace(record: Record):
    """:meth:`pulses.Record.to_trace`."""
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


def from_stream(stream, units=None):
    """The records of an :class:`obspy.Stream` of one station's components: a pair, or a triplet.

    Parameters
    ----------
    stream : obspy.Stream
        Two horizontal components (orientations measured from the first towards the second), or
        those two and a vertical (told by its channel code or header, its polarity stated).
    units : str, optional
        Units of the traces' data where ``trace.stats`` does not state them
        (:meth:`pulses.Record.from_trace`).

    Returns
    -------
    (Record, Record) or (Record, Record, Record)
        As :func:`pulses.check_pair` (two) or :func:`pulses.check_triplet` (three: the vertical
        last, upward) return them: in m/s^2, cut to one length.

    Raises
    ------
    ValueError
        A stream of another number of traces.
    pulses.RecordError
        Every reason of :meth:`pulses.Record.from_trace` and of the pair and triplet checks.

    Examples
    --------
    >>> import numpy as np, obspy, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> traces = [obspy.Trace(a * np.sin(t) * np.exp(-t / 3), header={"delta": 0.01, "channel": c})
    ...           for a, c in ((0.3, "HNN"), (0.2, "HNE"))]
    >>> first, second = pulses.from_stream(obspy.Stream(traces), units="g")
    >>> round(first.pga / pulses.G, 2), second.npts
    (0.19, 1000)
    """
    from ..pairs import check_pair
    from ..triplets import check_triplet

    records = [from_trace(tr, units) for tr in stream]
    if len(records) == 2:
        return check_pair(*records)
    if len(records) == 3:
        vertical = [r for r in records if r.metadata.get("vertical") is True]
        if len(vertical) != 1:
            raise RecordError(f"a stream of three components needs exactly one vertical (by its channel "
                              f"code or header); found {len(vertical)} among "
                              f"{', '.join(tr.id for tr in stream)}")
        h1, h2 = [r for r in records if r is not vertical[0]]
        return check_triplet(h1, h2, vertical[0])
    raise ValueError(f"from_stream: expected a Stream of two horizontal components (a pair) or three "
                     f"(a triplet with its vertical), got {len(records)} traces")
