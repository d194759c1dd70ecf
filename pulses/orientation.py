"""Which way a record's component points, as its file states it.

Every reader puts the same two keys into ``record.metadata``:

``azimuth`` : float, degrees clockwise from north in [0, 360)
    Only where the file states it: a PEER AT2 component such as ``228`` or ``PUL164``, a SAC
    horizontal (``cmpinc`` = 90) with ``cmpaz`` set, a K-NET ``N-S`` (0) or ``E-W`` (90).
``vertical`` : bool
    ``True`` for a vertical component, ``False`` for a stated horizontal; absent when the file
    does not say (plain text, a channel code that is not SEED's).

Nothing here is guessed from a file name.
"""
from __future__ import annotations

import math

#: SEED channel codes: band, instrument, orientation; Z is vertical, N, E, 1, 2 horizontal.
#: Only ground-motion instruments count (H, L high and low gain seismometers, G gravimeter,
#: N accelerometer), so that a three-letter station code is not read as a channel.
_SEED_INSTRUMENTS = "HLGN"
_SEED_VERTICAL = "Z"
_SEED_HORIZONTAL = "NE12"


def orientation(azimuth=None, vertical=None) -> dict:
    """The ``azimuth`` and ``vertical`` metadata entries, leaving out what is unknown.

    Parameters
    ----------
    azimuth : float, optional
        Degrees clockwise from north; 360 is written as 0.  A stated azimuth implies a horizontal
        component.
    vertical : bool, optional
        Whether the component is vertical.

    Returns
    -------
    dict
        ``{"azimuth": float, "vertical": bool}`` with only the known entries.
    """
    out = {}
    if azimuth is not None:
        az = float(azimuth)
        if math.isfinite(az):
            out["azimuth"] = az % 360.0
            vertical = False if vertical is None else vertical
    if vertical is not None:
        out["vertical"] = bool(vertical)
    return out


def seed_orientation(channel) -> dict:
    """``vertical`` from a three-character SEED channel code (``HNZ`` vertical, ``HNE`` not).

    SEED's N and E mean north and east only within 5 degrees, so no azimuth is given.
    """
    code = str(channel or "").strip().upper()
    if len(code) != 3 or not code.isalnum() or code[1] not in _SEED_INSTRUMENTS:
        return {}
    if code[2] == _SEED_VERTICAL:
        return orientation(vertical=True)
    if code[2] in _SEED_HORIZONTAL:
        return orientation(vertical=False)
    return {}
