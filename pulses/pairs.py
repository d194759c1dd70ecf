"""Two horizontal components of one station: checking, rotating and pairing files (two files are
read as a pair by :func:`pulses.read_pair`).

A pair is two records of the same station in orthogonal horizontal directions.  The component
in the direction ``theta`` measured from the first component towards the second is

    a(theta) = a1 cos(theta) + a2 sin(theta)

(the same for velocities: the rotation is linear).  Checks, as Shahi & Baker's reference code
makes them: the two must share ``dt``; lengths within :data:`MAX_LENGTH_DIFFERENCE` samples are
truncated to the shorter, longer differences are refused.  Where both components state an
azimuth (``metadata["azimuth"]``, degrees clockwise from north) they must be orthogonal within
:data:`ORTHOGONAL_TOLERANCE_DEG`.

:func:`pair_files` groups files of one station from what their names and headers say:
NGA-West2 names ``RSNnnn_EVENT_STAxxx.AT2`` (grouped by record number), ``name_1`` /
``name_2`` / ``name_3`` (3 is vertical), names that differ only in a trailing three-digit
azimuth (``Rinaldi228`` / ``Rinaldi318``), and otherwise the station and event stated in the
header.  Vertical components (``_3``, ``UP``, ``DWN``, ``-V``, ``metadata["vertical"]``) are
recognised and left out.
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, field

import numpy as np

from .errors import RecordError
from .record import Record

#: lengths more than this many samples apart are refused (the reference code's rule)
MAX_LENGTH_DIFFERENCE = 20
#: azimuths more than this many degrees from 90 apart are refused as not orthogonal
ORTHOGONAL_TOLERANCE_DEG = 5.0
#: relative tolerance on equal time steps (AT2 headers print dt to 4 or 5 digits)
DT_RTOL = 1e-6


def _label(record: Record) -> str:
    return str(record.metadata.get("source") or record.name)


def _azimuth(record: Record):
    az = record.metadata.get("azimuth")
    if az is None:
        return None
    try:
        az = float(az)
    except (TypeError, ValueError):
        return None
    return az % 360.0 if math.isfinite(az) else None


def handedness(first: Record, second: Record):
    """+1 where the second component lies 90 deg clockwise of the first (seen from above, e.g.
    north then east), -1 where it lies 90 deg counter-clockwise (e.g. 230 then 140), ``None``
    where either azimuth is unknown."""
    az1, az2 = _azimuth(first), _azimuth(second)
    if az1 is None or az2 is None:
        return None
    return 1 if (az2 - az1) % 360.0 < 180.0 else -1


def check_pair(first: Record, second: Record) -> tuple[Record, Record]:
    """Check that two records form a pair of horizontal components; return them with equal lengths.

    Raises
    ------
    RecordError
        Naming both files: different ``dt``, start times more than half a sample apart, lengths
        more than :data:`MAX_LENGTH_DIFFERENCE` samples apart, a vertical component, or azimuths more than
        :data:`ORTHOGONAL_TOLERANCE_DEG` from orthogonal.

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> first = pulses.Record(3.0 * np.sin(t), 0.01, metadata={"azimuth": 0.0})
    >>> second = pulses.Record(4.0 * np.cos(t[:-5]), 0.01, metadata={"azimuth": 90.0})
    >>> [r.npts for r in pulses.check_pair(first, second)]      # cut to one length
    [995, 995]
    """
    names = f"{_label(first)} and {_label(second)}"
    n = check_time_axis(first, second, names, "a pair", ("the first", "the second"))
    for r in (first, second):
        if r.metadata.get("vertical"):
            raise RecordError(f"{names}: not a pair of horizontals, {_label(r)} is vertical")
    az1, az2 = _azimuth(first), _azimuth(second)
    if az1 is not None and az2 is not None:
        apart = abs((az2 - az1 + 180.0) % 360.0 - 180.0)  # 0..180
        if abs(apart - 90.0) > ORTHOGONAL_TOLERANCE_DEG:
            raise RecordError(f"{names}: not orthogonal, azimuths {az1:g} and {az2:g} deg are "
                              f"{apart:g} deg apart (90 +- {ORTHOGONAL_TOLERANCE_DEG:g} accepted)")
    return truncated(first, n), truncated(second, n)


def check_time_axis(first: Record, other: Record, names: str, group: str, kinds: tuple[str, str]) -> int:
    """Check that ``other`` shares ``first``'s time axis; return the length both are cut to.

    Components are combined sample by sample, so they must share the time step (within
    :data:`DT_RTOL`) and the start (within half a sample), and lengths more than
    :data:`MAX_LENGTH_DIFFERENCE` samples apart are refused (the shorter length is returned).

    Parameters
    ----------
    first, other : pulses.Record
        The records (``other`` compared with ``first``).
    names : str
        The files, as the message names them.
    group : str
        What the records must form, as the message says it: ``"a pair"``, ``"one station's
        components"``.
    kinds : (str, str)
        What ``first`` and ``other`` are, as the message says it: ``("the first", "the second")``,
        ``("the horizontals", "the vertical")``.

    Raises
    ------
    RecordError
        One line naming the files and the differing time steps (s), starts (s) or lengths (samples).
    """
    a, b = kinds
    if abs(first.dt - other.dt) > DT_RTOL * max(first.dt, other.dt):
        raise RecordError(f"{names}: not {group}, time steps differ ({first.dt:g} s for {a}, "
                          f"{other.dt:g} s for {b})")
    if abs(first.t_start - other.t_start) > 0.5 * first.dt:
        # records that start at different times would be added out of step
        raise RecordError(f"{names}: not {group}, they start at different times ({first.t_start:g} s for "
                          f"{a}, {other.t_start:g} s for {b}); cut them to a common start first")
    diff = abs(first.npts - other.npts)
    if diff > MAX_LENGTH_DIFFERENCE:
        raise RecordError(f"{names}: not {group}, lengths differ by {diff} samples ({first.npts} for {a}, "
                          f"{other.npts} for {b}; at most {MAX_LENGTH_DIFFERENCE} are truncated)")
    return min(first.npts, other.npts)


def truncated(record: Record, n: int) -> Record:
    """The first ``n`` samples of ``record`` (the record itself if it has ``n``)."""
    if record.npts == n:
        return record
    return Record(record.acc[:n], record.dt, record.name, record.t_start, record.metadata)


def component(first, second, theta):
    """The component at ``theta`` degrees from the first direction towards the second.

    ``first cos(theta) + second sin(theta)``.

    Parameters
    ----------
    first, second : Record or array_like
        Two orthogonal horizontal components (records of equal length, or arrays).
    theta : float
        Angle in degrees, from the first component's direction towards the second's.

    Returns
    -------
    Record or numpy.ndarray
        A record (same ``dt``, metadata of the first with ``azimuth`` updated where both
        azimuths are known) when records are given, an array otherwise.

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> first = pulses.Record(3.0 * np.sin(t), 0.01, metadata={"azimuth": 0.0})
    >>> second = pulses.Record(4.0 * np.cos(t), 0.01, metadata={"azimuth": 90.0})
    >>> along = pulses.component(first, second, 90.0)
    >>> bool(np.allclose(along.acc, second.acc)), along.metadata["azimuth"]
    (True, 90.0)
    """
    c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
    if not isinstance(first, Record):
        return np.asarray(first, dtype=float) * c + np.asarray(second, dtype=float) * s
    first, second = check_pair(first, second)
    meta = dict(first.metadata)
    meta.pop("component", None)
    meta["azimuth"] = rotated_azimuth(first, second, theta)
    if meta["azimuth"] is None:
        meta.pop("azimuth")
    meta["rotated"] = f"{theta:g} deg from {first.name} towards {second.name}"
    return Record(first.acc * c + second.acc * s, first.dt, f"{first.name}@{theta:g}deg",
                  first.t_start, meta)


def rotate_pair(first: Record, second: Record, theta: float) -> tuple[Record, Record]:
    """The pair rotated by ``theta`` degrees: components at ``theta`` and ``theta + 90``.

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> first = pulses.Record(3.0 * np.sin(t), 0.01, metadata={"azimuth": 0.0})
    >>> second = pulses.Record(4.0 * np.cos(t), 0.01, metadata={"azimuth": 90.0})
    >>> a, b = pulses.rotate_pair(first, second, 30.0)
    >>> round(a.pga, 3)
    3.279
    """
    return component(first, second, theta), component(first, second, theta + 90.0)


def rotated_azimuth(first: Record, second: Record, theta: float):
    """Azimuth (deg clockwise from north, 0..360) of the direction ``theta`` degrees from the
    first component towards the second, from both components' own azimuths; ``None`` where
    either is unknown.  A pair whose second component is 90 deg counter-clockwise of the first
    turns the other way."""
    hand = handedness(first, second)
    if hand is None:
        return None
    return (_azimuth(first) + hand * theta) % 360.0


# -- pairing files ---------------------------------------------------------------------------

_RSN = re.compile(r"^RSN(\d+)(?:_|$)", re.IGNORECASE)
_NUMBERED = re.compile(r"^(.*?)[_-]([123])$")
_AZIMUTH_CODE = re.compile(r"^(.*?[A-Za-z_\-.])(\d{3})$")


@dataclass
class Pairing:
    """What :func:`pair_files` found: ``pairs`` (first, second), ``singles`` (horizontals
    without a partner, or in groups that are ambiguous), ``verticals`` (left out) and ``notes``
    (one line per ambiguous group).

    Examples
    --------
    >>> import pulses
    >>> found = pulses.pair_files(["RSN1_A_1.AT2", "RSN1_A_2.AT2", "RSN2_B_1.AT2"])
    >>> found.pairs
    [('RSN1_A_1.AT2', 'RSN1_A_2.AT2')]
    >>> found.singles
    ['RSN2_B_1.AT2']
    """

    pairs: list = field(default_factory=list)
    singles: list = field(default_factory=list)
    verticals: list = field(default_factory=list)
    notes: list = field(default_factory=list)


def _is_vertical(path, meta) -> bool:
    if meta and meta.get("vertical") is not None:  # the reader's reading of the header comes first
        return bool(meta["vertical"])
    stem = os.path.splitext(os.path.basename(str(path)))[0]
    if _RSN.match(stem) and re.fullmatch(r"RSN\d+_3", stem, re.IGNORECASE):
        return True
    m = _NUMBERED.match(stem)
    if m and m.group(2) == "3":
        return True
    comp = str((meta or {}).get("component", "")).strip().upper()
    if comp in {"UP", "DWN", "DOWN", "V", "VER", "VERT", "VERTICAL", "Z"}:
        return True
    return bool(re.search(r"(?:^|[_\-.\d])(UP|DWN)$", stem, re.IGNORECASE)
                or re.search(r"[_\-.]V$", stem, re.IGNORECASE)
                or re.search(r"[HB][HN]Z$", stem))


def _group_key(path, meta):
    """Which station a file belongs to, from its name, else from its header."""
    stem = os.path.splitext(os.path.basename(str(path)))[0]
    m = _RSN.match(stem)
    if m:
        return ("rsn", int(m.group(1)))
    folder = os.path.dirname(os.path.abspath(str(path)))
    m = _NUMBERED.match(stem)
    if m:
        return ("name", folder, m.group(1).lower())
    m = _AZIMUTH_CODE.match(stem)
    if m:
        return ("azimuth", folder, m.group(1).lower())
    station, event = (meta or {}).get("station"), (meta or {}).get("event")
    if station and event:
        return ("header", folder, str(station).strip().casefold(), str(event).strip().casefold())
    return None


def _codes_orthogonal(path1, path2) -> bool:
    """Whether the trailing three-digit codes of two names read as orthogonal azimuths."""
    codes = [int(_AZIMUTH_CODE.match(os.path.splitext(os.path.basename(str(p)))[0]).group(2))
             for p in (path1, path2)]
    if max(codes) > 360:
        return False
    return abs((codes[1] - codes[0]) % 180 - 90) <= ORTHOGONAL_TOLERANCE_DEG


def _order_key(path, meta):
    stem = os.path.splitext(os.path.basename(str(path)))[0]
    m = _NUMBERED.match(stem)
    return (m.group(2) if m else "", os.path.basename(str(path)))


def pair_files(paths, metadata=None) -> Pairing:
    """Group files into pairs of horizontal components of one station.

    Parameters
    ----------
    paths : sequence of str or path-like
        Record files, in any order.
    metadata : mapping, optional
        ``path -> record.metadata`` for files already read: their ``vertical`` flag and the
        station and event named in the header are used too.

    Returns
    -------
    Pairing
        Groups of exactly two horizontals become pairs (ordered ``_1`` before ``_2``, otherwise
        by file name); a group with more than two horizontals is ambiguous and its files stay
        single (with a note); verticals are listed apart.

    Examples
    --------
    >>> import pulses
    >>> found = pulses.pair_files(["RSN1_A_1.AT2", "RSN1_A_2.AT2", "RSN2_B_1.AT2"])
    >>> found.pairs
    [('RSN1_A_1.AT2', 'RSN1_A_2.AT2')]
    >>> found.singles
    ['RSN2_B_1.AT2']
    """
    metadata = metadata or {}
    result = Pairing()
    groups: dict = {}
    for path in paths:
        meta = metadata.get(path) or metadata.get(str(path))
        if _is_vertical(path, meta):
            result.verticals.append(path)
            continue
        key = _group_key(path, meta)
        if key is None:
            result.singles.append(path)
        else:
            groups.setdefault(key, []).append(path)
    for key, members in groups.items():
        members = list(dict.fromkeys(members))
        if len(members) == 2 and key[0] == "azimuth" and not _codes_orthogonal(*members):
            result.singles.extend(members)  # e.g. run numbers 001 and 002, not azimuths
        elif len(members) == 2:
            meta = [metadata.get(p) or metadata.get(str(p)) for p in members]
            order = sorted(range(2), key=lambda i: _order_key(members[i], meta[i]))
            result.pairs.append((members[order[0]], members[order[1]]))
        elif len(members) == 1:
            result.singles.append(members[0])
        else:
            result.singles.extend(members)
            result.notes.append(f"{len(members)} horizontal files of one station "
                                f"({', '.join(os.path.basename(str(p)) for p in members)}): "
                                f"not paired; name the pair with --pair A B")
    return result
