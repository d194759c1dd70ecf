"""Three components of one station: two horizontals and the vertical, on one time axis.

:func:`check_triplet` checks the horizontals as :func:`pulses.check_pair` does, checks that the
vertical is one and shares their time axis by the pairs' own check
(:func:`pulses.pairs.check_time_axis`), cuts all three to the shortest and turns the vertical
into upward ground acceleration by its stated polarity (:func:`upward`: ``UP`` as it is, ``DWN``
times -1; a vertical whose polarity is not stated is refused, never guessed; docs/theory.md
section 10).  PEER names a vertical's positive direction in its file name and in the second
header line; :func:`vertical_polarity` reads both.
"""
from __future__ import annotations

import os
import re

from .errors import RecordError
from .pairs import _label, check_pair, check_time_axis, truncated
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


# -- the vertical's polarity ------------------------------------------------------------------------
#: PEER writes the polarity at the end of a vertical's name: ``TAF-UP``, ``ORRDWN``
_NAME_POLARITY = re.compile(r"(UP|DWN)$", re.IGNORECASE)


def vertical_polarity(record: Record, file_name: str | None = None) -> int:
    """+1 for a vertical whose samples are positive upwards (``UP``), -1 for positive downwards
    (``DWN``), from the file name and the header's component (docs/theory.md section 10).

    Raises
    ------
    RecordError
        When neither says ``UP`` or ``DWN``, or they disagree: a polarity is never guessed.
    """
    name = file_name or str(record.metadata.get("source") or record.name)
    stem = os.path.splitext(os.path.basename(name))[0]
    said = {}
    m = _NAME_POLARITY.search(stem)
    if m:
        said["file name"] = m.group(1).upper()
    comp = str(record.metadata.get("component") or "").strip().upper()
    m = _NAME_POLARITY.search(comp)
    if m:
        said["header"] = m.group(1)
    if not said:
        raise RecordError(f"{name}: the polarity of this vertical is not stated (neither its name nor "
                          f"its header component {comp!r} says UP or DWN); it is not used")
    if len(set(said.values())) > 1:
        raise RecordError(f"{name}: the file name says {said['file name']} but the header says "
                          f"{said['header']}: polarity unknown, not used")
    return 1 if next(iter(said.values())) == "UP" else -1


def upward(record: Record, file_name: str | None = None) -> Record:
    """The vertical as upward ground acceleration ``uv''`` (m/s^2): multiplied by -1 for ``DWN``."""
    sign = vertical_polarity(record, file_name)
    meta = dict(record.metadata, polarity="UP" if sign > 0 else "DWN", vertical=True)
    return Record(record.acc * sign, record.dt, record.name, record.t_start, meta)
