"""Every format obspy reads (MiniSEED, GSE2, ...), and the route SAC and K-NET take through obspy.

:func:`obspy.read` detects and reads the file; the trace is then interpreted by the format
registered for obspy's name of it (:mod:`pulses.formats.sac`, :mod:`pulses.formats.knet`), or as
a format that states no units (MiniSEED and the rest: the user gives ``units``).  The channel
code is read as a SEED code for ``metadata["vertical"]``.
"""
from __future__ import annotations

import numpy as np

from ..errors import RecordError
from ..orientation import seed_orientation
from .registry import (
    FALLBACK,
    UNITS_NONE,
    Reading,
    ReadOptions,
    RecordFormat,
    by_obspy_name,
    register,
    too_long,
)


def read_trace(path: str, options: ReadOptions, obspy_name: str | None = None):
    """The one trace of ``path`` that obspy reads (``obspy_name`` = obspy's format, or detected).

    Raises
    ------
    RecordError
        For a file obspy cannot read, one with no traces, gaps, several traces and no choice,
        or more than ``options.max_samples`` samples.
    """
    import obspy

    try:
        stream = obspy.read(path, format=obspy_name)
    except TypeError as exc:
        if "format" in str(exc).lower():
            raise RecordError(f"{path}: unknown format: not PEER AT2, not columns of numbers, and not a "
                              f"format obspy reads (SAC, MiniSEED, K-NET, ...)") from None
        raise RecordError(f"{path}: cannot read: {exc}") from None
    except Exception as exc:  # obspy raises many types for damaged files
        raise RecordError(f"{path}: cannot read as {obspy_name or 'any obspy format'}: "
                          f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
    if len(stream) == 0:
        raise RecordError(f"{path}: the file holds no traces")
    tr = _pick_trace(path, stream, options.trace)
    if tr.stats.npts > options.max_samples:
        raise RecordError(too_long(path, options.max_samples, tr.stats.npts))
    return tr


def trace_metadata(tr) -> dict:
    """The metadata every obspy trace gives: station, component (channel), network, ..."""
    st = tr.stats
    return {"format": str(st.get("_format", "")).lower(), "station": st.station, "component": st.channel,
            "network": st.network, "location": st.location, "event": "",
            "starttime": str(st.starttime), "t_start": 0.0}


def read(path: str, options: ReadOptions, obspy_name: str | None = None) -> Reading:
    """Read ``path`` through obspy and interpret its trace by the format registered for it."""
    if obspy_name is None and options.format is not None:
        obspy_name = str(options.format).strip().upper()
    tr = read_trace(path, options, obspy_name)
    file_format = str(tr.stats.get("_format", obspy_name or "")).upper()
    fmt = by_obspy_name(file_format)
    if fmt is not None and fmt.from_trace is not None:
        return fmt.from_trace(tr, path, options)
    return unitless(tr, file_format)


def unitless(tr, file_format: str) -> Reading:
    """A trace of a format that states no units (MiniSEED, GSE2, ...)."""
    meta = trace_metadata(tr)
    meta.update(seed_orientation(tr.stats.channel))
    return Reading(np.asarray(tr.data, dtype=float), float(tr.stats.delta), meta,
                   units_rule=UNITS_NONE, no_units=f"{file_format} data carry no units")


def _pick_trace(path, stream, trace):
    if trace is not None:
        if isinstance(trace, (int, np.integer)) or (isinstance(trace, str) and trace.isdigit()):
            i = int(trace)
            if not 0 <= i < len(stream):
                raise RecordError(f"{path}: trace {i} asked for, the file holds {len(stream)} (from 0)")
            return stream[i]
        hits = [tr for tr in stream if trace in (tr.id, tr.stats.channel)]
        if len(hits) != 1:
            raise RecordError(f"{path}: no single trace matches {trace!r}; traces: "
                              f"{', '.join(tr.id for tr in stream)}")
        return hits[0]
    if len(stream) == 1:
        return stream[0]
    ids = {tr.id for tr in stream}
    if len(ids) == 1:
        raise RecordError(f"{path}: non-uniform sampling: the trace has {len(stream) - 1} gap(s) or "
                          f"overlap(s); merge or fill them first")
    raise RecordError(f"{path}: {len(stream)} traces ({', '.join(sorted(ids))}); choose one with "
                      f"trace= (--trace)")


#: read by name only (obspy detects them): the fallback for every file, and MiniSEED's names
FORMAT = register(RecordFormat(name=FALLBACK, read=read))
MSEED = register(RecordFormat(
    name="mseed", aliases=("miniseed",), read=lambda path, options: read(path, options, "MSEED")))
