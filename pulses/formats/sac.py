"""SAC files: the record format (read through obspy), what ``idep`` says about units, and writing
a record as SAC.

By the SAC standard the dependent-variable code ``idep`` gives the quantity *and* its units:
``iacc`` means nm/s^2, ``ivel`` nm/s, ``idisp`` nm (docs/theory.md section 7).  Many files in the wild
hold m/s^2, cm/s^2 or g under ``iacc``; :func:`pulses.read_record` honours the standard unless
the user passes units, and refuses a peak that would then be implausible.
"""
from __future__ import annotations

import os

import numpy as np

from ..errors import RecordError
from ..orientation import orientation, seed_orientation
from .obspy import read as read_by_obspy
from .obspy import trace_metadata
from .registry import UNITS_STANDARD, Reading, ReadOptions, RecordFormat, register

#: SAC ``idep`` enumeration values (as obspy stores them) -> quantity
IDEP_QUANTITY = {8: "acceleration", 7: "velocity", 6: "displacement", 5: "unknown", 50: "volts"}
#: the SAC standard's units for each quantity code
IDEP_STANDARD_UNITS = {8: "nm/s2", 7: "nm/s", 6: "nm"}
IACC = 8
#: SAC ``iftype`` (the kind of file) enumeration values: only a time series is a record
IFTYPE_KIND = {1: "time series", 2: "spectrum (real and imaginary)", 3: "spectrum (amplitude and phase)",
               4: "general x-y data", 51: "general x-y-z data"}
ITIME = 1
#: value SAC uses for an undefined integer header
SAC_UNDEFINED = -12345


def idep_units(idep) -> tuple[str, str | None]:
    """``(quantity, standard units)`` for a SAC ``idep`` value (``None`` or -12345: undefined)."""
    if idep is None or idep == SAC_UNDEFINED:
        return "undefined", None
    idep = int(idep)
    return IDEP_QUANTITY.get(idep, f"code {idep}"), IDEP_STANDARD_UNITS.get(idep)


def sac_orientation(sac, channel="") -> dict:
    """``azimuth`` and ``vertical`` (see :mod:`pulses.orientation`) from SAC headers.

    ``cmpinc`` is the angle from vertical-up in degrees: 0 or 180 is vertical, 90 horizontal, and
    then ``cmpaz`` (degrees clockwise from north) is the azimuth.  Without ``cmpinc`` the channel
    code ``kcmpnm`` is read as a SEED code (``HNZ`` vertical).

    Parameters
    ----------
    sac : mapping
        The SAC header as obspy gives it (``trace.stats.sac``; undefined fields absent).
    channel : str, optional
        The channel code.
    """
    cmpinc = sac.get("cmpinc")
    if cmpinc is None or float(cmpinc) == SAC_UNDEFINED:
        return seed_orientation(channel)
    cmpinc = float(cmpinc)
    if cmpinc in (0.0, 180.0):
        return orientation(vertical=True)
    if cmpinc == 90.0:
        cmpaz = sac.get("cmpaz")
        if cmpaz is not None and float(cmpaz) != SAC_UNDEFINED:
            return orientation(azimuth=float(cmpaz))
        return orientation(vertical=False)
    return {}  # an inclined component: neither vertical nor horizontal


def shortest_float32(value: float) -> float:
    """The shortest decimal that rounds to the same float32 as ``value``.

    SAC stores ``delta`` in 32 bits: 0.005 comes back as 0.004999999888.  Reading it as the
    shortest decimal with the same float32 gives back 0.005 exactly.
    """
    return float(np.format_float_positional(np.float32(value), unique=True, trim="-"))


def from_trace(tr, path: str, options: ReadOptions) -> Reading:
    """Interpret a SAC trace obspy read: ``delta`` as written, ``b``, ``kevnm``, ``idep``'s units.

    Raises
    ------
    RecordError
        For a velocity or displacement record (``idep`` = ``ivel``, ``idisp``), or a file that
        is not a time series (``iftype`` other than ``itime``: a spectrum, x-y data).
    """
    sac = tr.stats.sac
    meta = trace_metadata(tr)
    meta["t_start"] = float(sac.get("b", 0.0) or 0.0)
    meta["event"] = str(sac.get("kevnm", "") or "").strip()
    if sac.get("kuser0"):
        meta["sac_name"] = str(sac.get("kuser0")).strip()
    meta.update(sac_orientation(sac, tr.stats.channel))
    quantity, standard = idep_units(sac.get("idep"))
    meta["idep"] = quantity
    if quantity in ("velocity", "displacement"):
        raise RecordError(f"{path}: SAC idep says this is a {quantity} record; records must be ground "
                          f"acceleration (idep = iacc)")
    iftype = sac.get("iftype")
    if iftype is not None and int(iftype) not in (ITIME, SAC_UNDEFINED):  # a spectrum is no record
        kind = IFTYPE_KIND.get(int(iftype), f"code {int(iftype)}")
        raise RecordError(f"{path}: SAC iftype says this file is not a time series but {kind}; "
                          "records must be time series (iftype = itime)")
    reading = Reading(np.asarray(tr.data, dtype=float), shortest_float32(sac.get("delta", tr.stats.delta)),
                      meta, units_rule=UNITS_STANDARD)
    if quantity == "acceleration":
        reading.units = standard  # nm/s2 by the SAC standard; the user may override with units=
    else:
        reading.no_units = f"SAC idep is {quantity}, so the file does not state its units"
    return reading


def write_sac(record, path) -> str:
    """Write ``record`` as a binary SAC file of ground acceleration in nm/s^2 (``idep = iacc``).

    This is the SAC standard, so :func:`pulses.read_record` reads the file back without being
    told units.  SAC stores 32-bit floats: samples come back to a relative 6e-8 and ``dt``
    exactly (see :func:`shortest_float32`).  Station, component and event go into ``kstnm``
    (8 characters), ``kcmpnm`` (8) and ``kevnm`` (16); the record's name into ``kuser0`` (8);
    ``metadata["vertical"]`` and ``metadata["azimuth"]`` into ``cmpinc`` and ``cmpaz``.

    Parameters
    ----------
    record : pulses.Record
        Acceleration in m/s^2.
    path : str or path-like
        Output file (overwritten).

    Returns
    -------
    str
        The path written.

    Examples
    --------
    >>> import os, tempfile, numpy as np, pulses
    >>> rec = pulses.Record(np.sin(np.arange(0.0, 10.0, 0.01)), 0.01, name="demo")
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     back = pulses.read_record(pulses.write_sac(rec, os.path.join(folder, "demo.sac")))
    >>> bool(np.allclose(back.acc, rec.acc)), back.metadata["units"]    # SAC iacc: nm/s^2
    (True, 'nm/s2')
    """
    from obspy.io.sac import SACTrace

    meta = record.metadata or {}
    sac = SACTrace(data=(np.asarray(record.acc, dtype=float) * 1e9).astype(np.float32))
    sac.delta = record.dt
    sac.b = record.t_start
    sac.idep = "iacc"
    sac.iztype = "ib"
    for key, field, width in (("station", "kstnm", 8), ("component", "kcmpnm", 8), ("event", "kevnm", 16)):
        value = str(meta.get(key) or "").strip()
        if value:
            setattr(sac, field, value[:width])
    if meta.get("vertical") is True:
        sac.cmpinc, sac.cmpaz = 0.0, 0.0
    elif meta.get("vertical") is False:
        sac.cmpinc = 90.0
        if meta.get("azimuth") is not None:
            sac.cmpaz = float(meta["azimuth"])
    if record.name:
        sac.kuser0 = str(record.name)[:8]
    path = os.fspath(path)
    try:
        sac.write(path)
    except OSError as exc:
        raise RecordError(f"{path}: cannot write SAC file: {exc.strerror or exc}") from None
    return path


FORMAT = register(RecordFormat(
    name="sac", obspy_name="SAC", from_trace=from_trace,
    read=lambda path, options: read_by_obspy(path, options, "SAC")))
