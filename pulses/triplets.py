"""Three components of one station: two horizontals and the vertical, on one time axis.

:func:`check_triplet` checks the horizontals as :func:`pulses.check_pair` does, checks that the
vertical is one and shares their time axis by the pairs' own check
(:func:`pulses.pairs.check_time_axis`), cuts all three to the shortest and turns the vertical
into upward ground acceleration by its stated polarity (:func:`pulses.peer.upward`:
``UP`` as it is, ``DWN`` times -1; a vertical whose polarity is not stated is refused, never
guessed; docs/theory.md section 10).
"""
from __future__ import annotations

from .errors import RecordError
from .pairs import _label, check_pair, check_time_axis, truncated
from .peer import upward, vertical_polarity
from .record import Record


def check_triplet(first: Record, second: Record, vertical: Record, vertical_name: str | None = None):
    """``(first, second, upward vertical)`` of one station, cut to one length.

    Raises
    ------
    RecordError
        Naming the files: every reason of :func:`pulses.check_pair`, a third record that is not a
        vertical or whose polarity is not stated, and the vertical off the horizontals' time axis
        (:func:`pulses.pairs.check_time_axis`).

    Examples
    --------
    >>> import numpy as np
    >>> import pulses
    >>> ns = pulses.Record(np.zeros(1000), dt=0.01, name="N", metadata={"azimuth": 0.0})
    >>> ew = pulses.Record(np.zeros(1000), dt=0.01, name="E", metadata={"azimuth": 90.0})
    >>> up = pulses.Record(np.zeros(990), dt=0.01, name="Z_UP", metadata={"vertical": True})
    >>> first, second, vertical = pulses.check_triplet(ns, ew, up)
    >>> first.npts, vertical.npts
    (990, 990)
    """
    first, second = check_pair(first, second)
    names = f"{_label(first)}, {_label(second)} and {_label(vertical)}"
    if vertical.metadata.get("vertical") is False or vertical.metadata.get("azimuth") is not None:
        raise RecordError(f"{names}: {_label(vertical)} is a horizontal component, not a vertical")
    vertical_polarity(vertical, vertical_name)  # refused unless UP or DWN is stated
    n = check_time_axis(first, vertical, names, "one station's components", ("the horizontals", "the vertical"))
    return truncated(first, n), truncated(second, n), upward(truncated(vertical, n), vertical_name)
