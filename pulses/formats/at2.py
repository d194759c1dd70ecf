"""PEER NGA ``.AT2`` accelerograms, and the obspy waveform plugin that reads them.

An AT2 file has four header lines and then the samples, in Fortran ``E`` format, usually five a
line, with a short last line::

    PEER NGA STRONG MOTION DATABASE RECORD
    Northridge-01, 1/17/1994, Rinaldi Receiving Sta, 228
    ACCELERATION TIME SERIES IN UNITS OF G
    NPTS=   1991, DT=   .0100 SEC,   0 POLE @    30.00000 HZ, ...
      -.2556093E-02  -.2534838E-02  -.2450926E-02  -.2152656E-02  -.1770125E-02

The older NGA/PEER header writes the fourth line as ``1991    0.0100    NPTS, DT``.  Numbers may
lack a leading zero (``.0100``, ``-.25E-02``) and may touch (no space before a minus sign), so
samples are never read by fixed columns: numpy reads blocks of lines, with a blank put before a
sign that touches the number before it, and a block numpy stops in is read with a regular
expression line by line (which names the line that is not numbers).
The sample count is checked against ``NPTS``: sample ``k`` (0-based) is at ``t = k DT``, so the
record lasts ``(NPTS - 1) DT``.

Once the package is installed, ``obspy.read("x.AT2")`` works through the entry points
``pulses.formats.at2:_is_at2`` and ``pulses.formats.at2:_read_at2`` declared in ``pyproject.toml``.
"""
from __future__ import annotations

import os
import re
import warnings

import numpy as np

from ..errors import RecordError
from ..orientation import orientation, seed_orientation
from ..units import canonical_units
from .registry import (
    MAX_SAMPLES,
    UNITS_STATED,
    Reading,
    ReadOptions,
    RecordFormat,
    join_blocks,
    register,
    too_long,
)

#: one Fortran real: optional sign, digits with optional point (or a point and digits),
#: optional exponent with E or D
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?")
#: NGA-West2 style: ``NPTS=   1991, DT=   .0100 SEC``
_NPTS_DT_NEW = re.compile(r"NPTS\s*=\s*(\d+)\s*,?\s*DT\s*=\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?)",
                          re.IGNORECASE)
#: older NGA/PEER style: ``1991    0.0100    NPTS, DT``
_NPTS_DT_OLD = re.compile(r"^\s*(\d+)\s+([-+]?(?:\d+\.?\d*|\.\d+)(?:[EeDd][-+]?\d+)?)\s+NPTS\s*,?\s*DT",
                          re.IGNORECASE)
#: what the third header line says about the quantity and its units
_UNITS = re.compile(r"IN\s+UNITS\s+OF\s+([A-Z0-9/\^\*\.]+(?:/[A-Z0-9\^\*]+)*)", re.IGNORECASE)


#: a component that is an azimuth in degrees: ``228``, ``0``, ``52.5``
_AZIMUTH_PLAIN = re.compile(r"\d{1,3}(?:\.\d*)?")
#: a station code then a three-digit azimuth: ``PUL164``, ``H-E06230``, ``LCN260``, ``I-ELC180``
_AZIMUTH_CODED = re.compile(r"[A-Z][A-Z0-9_-]*?(\d{3})")
#: vertical components: ``UP``, ``DWN``, ``V``, ``-UP``, ``E06UP``, ``LCN-DWN``
_VERTICAL = re.compile(r"(?:.*[^A-Z])?(?:UP|DWN|DN|DOWN|V|VERT)|[A-Z0-9-]*?(?:UP|DWN)")
#: horizontals that state no azimuth: fault-normal, fault-parallel, NGA-West2's H1 and H2
_HORIZONTAL = {"FN", "FP", "H1", "H2"}
#: compass directions, alone or after a station code and a hyphen (``TCU068-N``)
_COMPASS = {"N": 0.0, "NS": 0.0, "N-S": 0.0, "E": 90.0, "EW": 90.0, "E-W": 90.0, "S": 180.0, "W": 270.0}


def _float(text: str) -> float:
    return float(text.replace("D", "E").replace("d", "e"))


def parse_npts_dt(line: str) -> tuple[int, float] | None:
    """``(NPTS, DT)`` from the fourth header line in either style, or ``None``."""
    m = _NPTS_DT_NEW.search(line) or _NPTS_DT_OLD.search(line)
    if not m:
        return None
    return int(m.group(1)), _float(m.group(2))


def _quantity_and_units(line: str) -> tuple[str, str | None]:
    """``("acceleration", "g")`` from ``ACCELERATION TIME SERIES IN UNITS OF G``."""
    upper = line.upper()
    if "VELOCITY" in upper:
        quantity = "velocity"
    elif "DISPLACEMENT" in upper:
        quantity = "displacement"
    elif "ACCELERATION" in upper:
        quantity = "acceleration"
    else:
        quantity = "unknown"
    m = _UNITS.search(line)
    units = m.group(1).rstrip(",.").lower() if m else None
    if units in ("cm/sec/sec", "cm/sec2", "cm/s/s", "cm/sec^2"):
        units = "cm/s2"
    return quantity, units


def _title_fields(line: str) -> dict:
    """Event, date, station and component from the second header line.

    ``Northridge-01, 1/17/1994, Rinaldi Receiving Sta, 228`` -> event ``Northridge-01``, date
    ``1/17/1994``, station ``Rinaldi Receiving Sta``, component ``228``.  With three fields the
    date stays inside the event field (``IMPERIAL VALLEY 10/15/79 2316, El Centro Array #4, 140``).
    """
    fields = [f.strip() for f in line.strip().split(",")]
    out = {"event": "", "date": "", "station": "", "component": ""}
    dated = [i for i, f in enumerate(fields) if re.fullmatch(r"\d{1,2}/\d{1,2}/\d{2,4}(\s+[\d:]+)?", f)]
    if dated and len(fields) >= dated[0] + 3:  # event(s), date, station(s), component
        i = dated[0]
        out.update(event=", ".join(fields[:i]), date=fields[i],
                   station=", ".join(fields[i + 1:-1]), component=fields[-1])
    elif len(fields) >= 3:
        out.update(event=", ".join(fields[:-2]), station=fields[-2], component=fields[-1])
    elif len(fields) == 2:
        out.update(event=fields[0], station=fields[1])
    elif fields:
        out.update(event=fields[0])
    return out


def component_orientation(component: str) -> dict:
    """``azimuth`` and ``vertical`` (see :mod:`pulses.orientation`) from an AT2 component.

    ``228`` and ``PUL164`` give azimuths 228 and 164 (degrees clockwise from north), ``N``,
    ``E-W`` and ``TCU068-N`` 0, 90 and 0; ``UP``,
    ``DWN``, ``V`` and ``-UP`` are vertical; ``FN``, ``FP``, ``H1`` and ``H2`` horizontal with no
    stated azimuth; anything else says nothing.
    """
    code = str(component or "").strip().upper()
    m = _AZIMUTH_PLAIN.fullmatch(code)
    if m and float(code) <= 360.0:
        return orientation(azimuth=float(code))
    m = _AZIMUTH_CODED.fullmatch(code)
    if m and float(m.group(1)) <= 360.0:
        return orientation(azimuth=float(m.group(1)))
    compass = _COMPASS.get(code, _COMPASS.get(code.rsplit("-", 1)[-1]))
    if compass is not None:
        return orientation(azimuth=compass)
    if _VERTICAL.fullmatch(code):
        return orientation(vertical=True)
    if code in _HORIZONTAL:
        return orientation(vertical=False)
    return seed_orientation(code)


def read_at2_file(path, max_samples: int = MAX_SAMPLES) -> tuple[np.ndarray, float, dict]:
    """Read a PEER ``.AT2`` file.

    The samples are read in blocks of lines, each parsed by numpy, so memory stays
    proportional to the samples (8 bytes each).

    Parameters
    ----------
    path : str or path-like
        The file.
    max_samples : int, optional
        A longer record is refused (:data:`pulses.formats.MAX_SAMPLES` by default).

    Returns
    -------
    values : ndarray
        The samples as written in the file (for acceleration files, in g).
    dt : float
        Sampling interval, s.
    header : dict
        ``title``, ``event``, ``date``, ``station``, ``component``, ``azimuth`` and ``vertical``
        (where the component states them, see :func:`component_orientation`), ``quantity``
        (``"acceleration"``, ``"velocity"``, ...), ``units`` (as stated, e.g. ``"g"``), ``npts``,
        ``dt``, ``header_style`` (``"NPTS=, DT="`` or ``"NPTS, DT"``) and the four header
        ``lines``.

    Raises
    ------
    RecordError
        For a missing, empty, truncated or corrupt file, one whose sample count disagrees
        with ``NPTS``, or one longer than ``max_samples``.
    """
    path = os.fspath(path)
    try:
        with open(path, "r", encoding="utf-8-sig", errors="replace") as fh:
            return read_at2_stream(fh, path, max_samples)
    except FileNotFoundError:
        raise RecordError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise RecordError(f"{path}: is a directory, not a record file") from None
    except OSError as exc:
        raise RecordError(f"{path}: cannot read: {exc.strerror or exc}") from None


def read_at2_stream(fh, path: str, max_samples: int = MAX_SAMPLES) -> tuple[np.ndarray, float, dict]:
    """:func:`read_at2_file` on an open text stream ``fh`` (a file, or ``io.StringIO`` of a
    member read in memory from a zip); ``path`` names it in messages."""
    lines = [fh.readline() for _ in range(4)]
    lines = [ln for ln in lines if ln]
    if not "".join(lines).strip() and not _rest_has_text(fh):
        raise RecordError(f"{path}: the file is empty")
    if len(lines) < 4:
        raise RecordError(f"{path}: truncated PEER AT2 file: {len(lines)} line(s), the header alone has 4")
    npts_dt = parse_npts_dt(lines[3])
    if npts_dt is None:
        raise RecordError(f"{path}: not a PEER AT2 file: line 4 should give NPTS and DT "
                          f"(e.g. 'NPTS=  1991, DT= .0100 SEC'), found {lines[3].strip()[:60]!r}")
    npts, dt = npts_dt
    if npts > max_samples:
        raise RecordError(too_long(path, max_samples, npts))
    blocks, count, lineno = [], 0, 4
    while True:
        block = fh.readlines(_BLOCK_CHARS)
        if not block:
            break
        values = _parse_block(path, block, lineno)
        lineno += len(block)
        count += values.size
        if count > max_samples:
            raise RecordError(too_long(path, max_samples))
        blocks.append(values)
    data = join_blocks(blocks)
    style = "NPTS=, DT=" if _NPTS_DT_NEW.search(lines[3]) else "NPTS, DT"
    if data.size != npts:
        what = "truncated" if data.size < npts else "longer than its header says"
        raise RecordError(f"{path}: {what}: header NPTS={npts} but the file holds {data.size} samples")
    if not (np.isfinite(dt) and dt > 0):
        raise RecordError(f"{path}: header DT={dt!r} is not a positive time step")
    quantity, units = _quantity_and_units(lines[2])
    fields = _title_fields(lines[1])
    header = {"title": lines[1].strip(), **fields, **component_orientation(fields["component"]),
              "quantity": quantity, "units": units, "npts": npts, "dt": dt, "header_style": style,
              "lines": [ln.rstrip() for ln in lines[:4]]}
    return data, dt, header


#: characters read per block of sample lines
_BLOCK_CHARS = 1 << 22
#: a character that numpy is not given directly (only numbers, D exponents turned into E first)
_NOT_FAST = re.compile(r"[^0-9.+\-EeDd \t\n]")
_D_TO_E = str.maketrans("Dd", "Ee")
#: a sign that touches the number before it (``-.1E-02-.2E-02``); an exponent's sign follows E
_TOUCHING_SIGN = re.compile(r"(?<=[\d.])(?=[-+])")


def _rest_has_text(fh) -> bool:
    """Whether anything but blanks follows in ``fh`` (read in blocks)."""
    while True:
        block = fh.read(_BLOCK_CHARS)
        if not block:
            return False
        if block.strip():
            return True


def _from_text(text: str) -> np.ndarray | None:
    """The numbers in ``text`` (blank-separated) by numpy, or ``None`` where it stops early."""
    with warnings.catch_warnings():
        # where numpy stops early it raises ValueError, or (older numpy) warns and returns less
        warnings.simplefilter("error", DeprecationWarning)
        try:
            return np.fromstring(text, dtype=float, sep=" ")
        except (ValueError, DeprecationWarning):
            return None


def _parse_block(path: str, lines: list, lineno: int) -> np.ndarray:
    """The samples of a block of AT2 lines (the first is line ``lineno + 1`` of the file)."""
    text = "".join(lines)
    if not _NOT_FAST.search(text):
        text = text.translate(_D_TO_E)
        values = _from_text(text)
        if values is None:
            values = _from_text(_TOUCHING_SIGN.sub(" ", text))
        if values is not None:
            return values
    # anything numpy did not read is read line by line, to name the line at fault
    tokens = []
    for n, line in enumerate(lines, start=lineno + 1):
        found = _NUMBER.findall(line)
        if _NUMBER.sub("", line).strip():
            raise RecordError(f"{path}: line {n} is not a list of numbers: {line.strip()[:60]!r}")
        tokens.extend(found)
    return np.array([_float(v) for v in tokens], dtype=float)


def read(path: str, options: ReadOptions) -> Reading:
    """The AT2 format's reader: acceleration only, in the units the header states.

    Raises
    ------
    RecordError
        For a velocity or displacement file (``.VT2``, ``.DT2``), a header that states no
        units or units that are not acceleration, and every error of :func:`read_at2_file`.
    """
    values, dt, header = read_at2_file(path, max_samples=options.max_samples)
    return reading_of(path, values, dt, header)


def reading_of(path: str, values, dt: float, header: dict) -> Reading:
    """The :class:`pulses.formats.Reading` of AT2 samples and header (see :func:`read`)."""
    if header["quantity"] in ("velocity", "displacement"):
        raise RecordError(f"{path}: this is a {header['quantity']} record ({header['lines'][2].strip()}); "
                          f"give the acceleration record (.AT2) instead")
    if header["quantity"] != "acceleration" or header["units"] is None:
        raise RecordError(f"{path}: the AT2 header does not say 'ACCELERATION ... IN UNITS OF ...': "
                          f"{header['lines'][2].strip()[:60]!r}")
    try:
        stated = canonical_units(header["units"])
    except RecordError:
        raise RecordError(f"{path}: the AT2 header states units {header['units']!r}, which are not "
                          f"acceleration units this reader knows") from None
    meta = {k: header[k] for k in ("event", "date", "station", "component", "title", "header_style",
                                   "azimuth", "vertical") if k in header}
    meta.update(format="at2", npts_header=header["npts"], units_stated=header["units"])
    return Reading(values, dt, meta, units=stated, units_rule=UNITS_STATED)


def detect(path: str) -> bool:
    """An AT2 file by name (``.AT2``; ``.VT2``, ``.DT2`` to refuse them clearly) or by content."""
    return str(path).lower().endswith((".at2", ".vt2", ".dt2")) or _is_at2(path)


# -- obspy waveform plugin -----------------------------------------------------------------
def _is_at2(filename) -> bool:
    """obspy plugin hook: True if ``filename`` starts like a PEER AT2 file (never raises)."""
    try:
        with open(filename, "r", encoding="utf-8-sig", errors="replace") as fh:
            head = [fh.readline() for _ in range(5)]
    except Exception:
        return False
    return len(head) >= 4 and parse_npts_dt(head[3]) is not None and bool(_NUMBER.search(head[4]))


def _read_at2(filename, headonly=False, **kwargs):
    """obspy plugin hook: read a PEER AT2 file into an :class:`obspy.Stream` of one trace.

    The trace holds the samples as written in the file (g for acceleration files); the header
    is kept in ``trace.stats.at2`` (``units``, ``quantity``, ``event``, ``date``, ...).
    """
    from obspy import Stream, Trace
    from obspy.core.util import AttribDict

    data, dt, header = read_at2_file(filename)
    tr = Trace(data=np.zeros(0) if headonly else data)
    tr.stats.delta = dt
    tr.stats.station = header["station"]
    tr.stats.channel = header["component"]
    if headonly:
        tr.stats.npts = header["npts"]
    tr.stats.at2 = AttribDict({k: v for k, v in header.items() if k != "lines"})
    if isinstance(filename, (str, os.PathLike)):  # the name pulses.Record.from_trace gives the record
        tr.stats.at2.source = os.fspath(filename)
    return Stream([tr])


FORMAT = register(RecordFormat(name="at2", aliases=("peer",), detect=detect, read=read, sniff_order=10))
