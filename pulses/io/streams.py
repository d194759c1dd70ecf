"""The records of an :class:`obspy.Stream` of one station's components: a pair or a triplet."""
from __future__ import annotations

from ..errors import RecordError
from ..pairs import check_pair
from ..record import Record
from ..triplets import check_triplet


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
    records = [Record.from_trace(tr, units) for tr in stream]
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
