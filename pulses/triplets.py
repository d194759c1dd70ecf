"""Three components of one station: two horizontals and the vertical, on one time axis.

:func:`check_triplet` checks the horizontals as :func:`pulses.check_pair` does, checks that the
vertical is one and shares their time step and start, cuts all three to the shortest (lengths more
than :data:`pulses.pairs.MAX_LENGTH_DIFFERENCE` samples apart are refused, as for pairs) and turns
the vertical into upward ground acceleration by its stated polarity (:func:`pulses.peer.upward`:
``UP`` as it is, ``DWN`` times -1; a vertical whose polarity is not stated is refused, never
guessed; docs/theory.md section 10).
"""
from __future__ import annotations

from .errors import RecordError
from .pairs import DT_RTOL, MAX_LENGTH_DIFFERENCE, _label, check_pair
from .peer import upward, vertical_polarity
from .record import Record


def _cut(record: Record, n: int) -> Record:
    if record.npts == n:
        return record
    return Record(record.acc[:n], record.dt, record.name, record.t_start, record.metadata)


def check_triplet(first: Record, second: Record, vertical: Record, vertical_name: str | None = None):
    """``(first, second, upward vertical)`` of one station, cut to one length.

    Raises
    ------
    RecordError
        Naming the files: every reason of :func:`pulses.check_pair`, a third record that is not a
        vertical or whose polarity is not stated, a different time step or start, or lengths more
        than :data:`pulses.pairs.MAX_LENGTH_DIFFERENCE` samples apart.
    """
    first, second = check_pair(first, second)
    names = f"{_label(first)}, {_label(second)} and {_label(vertical)}"
    if vertical.metadata.get("vertical") is False or vertical.metadata.get("azimuth") is not None:
        raise RecordError(f"{names}: {_label(vertical)} is a horizontal component, not a vertical")
    vertical_polarity(vertical, vertical_name)  # refused unless UP or DWN is stated
    if abs(first.dt - vertical.dt) > DT_RTOL * max(first.dt, vertical.dt):
        raise RecordError(f"{names}: not one station's components, time steps differ "
                          f"({first.dt:g} s and {vertical.dt:g} s)")
    if abs(first.t_start - vertical.t_start) > 0.5 * first.dt:
        raise RecordError(f"{names}: the vertical starts at {vertical.t_start:g} s, the horizontals at "
                          f"{first.t_start:g} s")
    diff = abs(first.npts - vertical.npts)
    if diff > MAX_LENGTH_DIFFERENCE:
        raise RecordError(f"{names}: lengths differ by {diff} samples ({first.npts} and {vertical.npts}; "
                          f"at most {MAX_LENGTH_DIFFERENCE} are truncated)")
    n = min(first.npts, vertical.npts)
    return _cut(first, n), _cut(second, n), upward(_cut(vertical, n), vertical_name)
