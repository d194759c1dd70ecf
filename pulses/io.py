"""Read an accelerogram from any supported file into a :class:`pulses.Record` (m/s^2).

Formats (``format=``):

``"at2"``
    PEER NGA ``.AT2`` (both header styles); units from the header ("UNITS OF G").
``"text"``
    Plain text or CSV columns (see :mod:`pulses.textfile`); the user gives ``units`` and ``dt``
    (``dt`` may come from a time column instead).
``"sac"`` and every other format obspy reads (``"mseed"``, ``"knet"``, ...)
    Through :func:`obspy.read`.  SAC: ``idep`` states the quantity; ``iacc`` means nm/s^2 by the
    SAC standard, honoured unless the user passes ``units``.  K-NET: obspy leaves the samples in
    counts and puts the header's scale factor, converted from gal to m/s^2, into
    ``stats.calib``; the reader multiplies by it and removes the mean (the K-NET convention), so
    the units are stated (m/s^2).  Formats that state no units (MiniSEED, ...) need ``units``.

Units are never guessed (SPEC section 7).  A peak below 1e-5 g or above 10 g makes the units
implausible and is refused, naming the units that would make it plausible; a peak above 5 g is
kept with a warning in ``record.metadata["warnings"]``.
"""
from __future__ import annotations

import os
import pathlib

import numpy as np

from .at2 import _is_at2, read_at2_file
from .errors import RecordError
from .record import G, Record
from .orientation import orientation, seed_orientation
from .sac import idep_units, sac_orientation, shortest_float32
from .textfile import hint_from_comments, read_text_file, sniff_text
from .units import (
    PLAUSIBLE_MAX_G,
    PLAUSIBLE_MIN_G,
    WARN_PEAK_G,
    canonical_units,
    plausible_units,
    unit_factor,
)

#: fewer samples than this cannot hold a pulse and are refused
MIN_SAMPLES = 10

_FORMAT_ALIASES = {"at2": "at2", "peer": "at2", "text": "text", "txt": "text", "csv": "text",
                   "ascii": "text", "sac": "SAC", "mseed": "MSEED", "miniseed": "MSEED", "knet": "KNET"}


def _units_hint() -> str:
    return "pass units= ('g', 'm/s2', 'cm/s2' or 'gal'; on the command line --units)"


def read_record(path, format=None, units=None, *, dt=None, column=None, trace=None, name=None) -> Record:
    """Read one ground-acceleration record.

    Parameters
    ----------
    path : str or path-like
        The record file.
    format : str, optional
        ``"at2"``, ``"text"`` (or ``"csv"``), ``"sac"``, ``"mseed"``, ``"knet"`` or any obspy
        format name.  Detected from the content when left out.
    units : str, optional
        Units of the samples in the file: ``"g"``, ``"m/s2"``, ``"cm/s2"`` (= ``"gal"``),
        ``"mm/s2"`` or ``"nm/s2"``.  Required where the file states none (text, MiniSEED, SAC
        without ``idep``); for SAC it overrides the standard reading of ``iacc`` (nm/s^2).  AT2
        and K-NET files state their units reliably: there it is not applied, and a disagreement
        is reported in ``metadata["warnings"]``.
    dt : float, optional
        Sampling interval in s, for text files without a time column.  Where the file states
        its time step (header, time column) that one is used, and a disagreement is reported in
        ``metadata["warnings"]``.
    column : int, optional
        Text files: which column holds the acceleration, counted from 1.
    trace : int or str, optional
        obspy formats holding several traces: the index (from 0) or the trace id or channel.
    name : str, optional
        Name of the record in reports (default: the file name, plus ``:colN`` for a chosen column).

    Returns
    -------
    pulses.Record
        Acceleration in m/s^2.  ``record.metadata`` has ``station``, ``component``, ``event``,
        ``units`` (as stated in the file or given by the user), ``units_source`` (``"file"`` or
        ``"user"``), ``format``, ``source`` (the path), ``warnings`` (list of str) and
        format-specific entries.

    Raises
    ------
    RecordError
        With a one-line message for a missing, empty, truncated or unknown file, a header that
        disagrees with the data, NaN or infinite samples, too few samples, non-uniform sampling,
        a velocity or displacement record, missing or implausible units.
    """
    path = os.fspath(path)
    p = pathlib.Path(path)
    if not p.exists():
        raise RecordError(f"{path}: no such file")
    if p.is_dir():
        raise RecordError(f"{path}: is a directory, not a record file")
    if p.stat().st_size == 0:
        raise RecordError(f"{path}: the file is empty")
    fmt = _resolve_format(path, format)
    if units is not None:
        unit_factor(units)  # refuse unknown or velocity units before reading
    if fmt == "at2":
        values, file_dt, meta, stated = _read_at2(path)
    elif fmt == "text":
        values, file_dt, meta, stated = _read_text(path, column)
    else:
        values, file_dt, meta, stated = _read_obspy(path, fmt, units, trace)

    # -- units: from the file where it states them, from the user otherwise ----------------
    # AT2 ("UNITS OF G") and K-NET (scale factor) state their units reliably: units passed for a
    # batch of files are not applied to them, and a disagreement is reported as a warning.
    # SAC's iacc is overridden by the user's units (files in the wild break the standard).
    reliable = fmt == "at2" or meta.get("format") == "knet"
    meta.setdefault("warnings", [])
    if reliable and units is not None:
        if unit_factor(units) != unit_factor(stated):
            meta["warnings"].append(f"units {units!r} passed but the file states {stated}: used {stated}")
        units = None
    if units is not None:
        used_units, units_source = canonical_units(units), "user"
    elif stated is not None:
        used_units, units_source = stated, "file"
    else:
        hint = hint_from_comments(meta.get("comments", [])) if fmt == "text" else ""
        raise RecordError(f"{path}: the file does not state its units{hint}; {_units_hint()}")
    acc = np.asarray(values, dtype=float) * unit_factor(used_units)

    # -- time step ---------------------------------------------------------------------------
    if dt is not None:
        dt = float(dt)
        if not (np.isfinite(dt) and dt > 0):
            raise RecordError(f"{path}: dt must be a positive time step in s, got {dt!r}")
        if file_dt is not None:  # the file's own time step wins
            if abs(dt - file_dt) > 1e-6 * file_dt:
                meta["warnings"].append(f"dt={dt:g} s passed but the file says {file_dt:g} s: used {file_dt:g} s")
            dt = file_dt
    elif file_dt is not None:
        dt = file_dt
    else:
        hint = hint_from_comments(meta.get("comments", []))
        raise RecordError(f"{path}: the file does not state its time step{hint}; pass dt= in s "
                          f"(--dt on the command line)")

    meta.update(units=used_units, units_source=units_source, source=path,
                format=meta.get("format", fmt), dt=dt)
    meta.setdefault("warnings", [])
    for key in ("station", "component", "event"):
        meta.setdefault(key, "")
    _validate(path, acc, values, used_units, units_source, meta)
    if name is None:
        name = p.name + (f":col{meta['column']}" if meta.get("columns", 1) > 1 else "")
    return Record(acc, dt, name=name, t_start=float(meta.pop("t_start", 0.0)), metadata=meta)


def _resolve_format(path: str, format) -> str:
    if format is not None:
        key = str(format).strip().lower()
        return _FORMAT_ALIASES.get(key, str(format).strip().upper())
    if path.lower().endswith(".at2") or _is_at2(path):
        return "at2"
    if path.lower().endswith((".vt2", ".dt2")):
        return "at2"  # PEER velocity/displacement: read, then refused with a clear message
    if sniff_text(path):
        return "text"
    return "obspy"


def _read_at2(path):
    values, dt, header = read_at2_file(path)
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
    return values, dt, meta, stated


def _read_text(path, column):
    values, dt_time, info = read_text_file(path, column=column)
    meta = {"format": "text", "comments": info["comments"], "columns": info["columns"],
            "column": info["column"], "time_column": info["time_column"],
            "component": f"column {info['column']}" if info["columns"] > 1 else ""}
    return values, dt_time, meta, None


def _read_obspy(path, fmt, units, trace):
    import obspy

    try:
        stream = obspy.read(path, format=None if fmt == "obspy" else fmt)
    except TypeError as exc:
        if "format" in str(exc).lower():
            raise RecordError(f"{path}: unknown format: not PEER AT2, not columns of numbers, and not a "
                              f"format obspy reads (SAC, MiniSEED, K-NET, ...)") from None
        raise RecordError(f"{path}: cannot read: {exc}") from None
    except Exception as exc:  # obspy raises many types for damaged files
        raise RecordError(f"{path}: cannot read as {fmt if fmt != 'obspy' else 'any obspy format'}: "
                          f"{str(exc).splitlines()[0] if str(exc) else type(exc).__name__}") from None
    if len(stream) == 0:
        raise RecordError(f"{path}: the file holds no traces")
    tr = _pick_trace(path, stream, trace)
    st = tr.stats
    file_format = str(st.get("_format", fmt)).upper()
    meta = {"format": file_format.lower(), "station": st.station, "component": st.channel,
            "network": st.network, "location": st.location, "event": "",
            "starttime": str(st.starttime), "t_start": 0.0}
    values = np.asarray(tr.data, dtype=float)
    dt = float(st.delta)
    stated = None
    if file_format == "SAC":
        sac = st.sac
        dt = shortest_float32(sac.get("delta", dt))
        meta["t_start"] = float(sac.get("b", 0.0) or 0.0)
        meta["event"] = str(sac.get("kevnm", "") or "").strip()
        if sac.get("kuser0"):
            meta["sac_name"] = str(sac.get("kuser0")).strip()
        meta.update(sac_orientation(sac, st.channel))
        quantity, standard = idep_units(sac.get("idep"))
        meta["idep"] = quantity
        if quantity in ("velocity", "displacement"):
            raise RecordError(f"{path}: SAC idep says this is a {quantity} record; records must be ground "
                              f"acceleration (idep = iacc)")
        if quantity == "acceleration":
            stated = standard  # nm/s2 by the SAC standard; the user may override with units=
        elif units is None:
            raise RecordError(f"{path}: SAC idep is {quantity}, so the file does not state its units; "
                              f"{_units_hint()}")
    elif file_format == "KNET":
        # obspy keeps counts and puts the scale factor (gal/count, converted to m/s^2) in calib
        values = (values - values.mean()) * float(st.calib)
        stated = "m/s2"
        knet = st.get("knet", {})
        meta["event"] = f"M{knet.get('mag', '')} {knet.get('evot', '')}".strip()
        meta["knet_accmax_gal"] = knet.get("accmax")
        meta.update(knet_orientation(st.channel))
        meta["notes"] = ["K-NET: samples times the header scale factor, mean removed"]
    else:
        meta.update(seed_orientation(st.channel))
    if file_format != "KNET" and units is None and stated is None:
        raise RecordError(f"{path}: {file_format} data carry no units; {_units_hint()}")
    return values, dt, meta, stated


#: K-NET ``Dir.`` (obspy's channel, KiK-net's 1-6 mapped to NS1 ... UD2) -> orientation
_KNET_DIRECTIONS = {"NS": orientation(azimuth=0.0), "EW": orientation(azimuth=90.0),
                    "UD": orientation(vertical=True)}


def knet_orientation(channel) -> dict:
    """``azimuth`` and ``vertical`` from a K-NET or KiK-net direction (``N-S`` 0, ``E-W`` 90, ``U-D``)."""
    return dict(_KNET_DIRECTIONS.get(str(channel or "").strip().upper()[:2], {}))


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


def _validate(path, acc, raw, units, units_source, meta):
    bad = ~np.isfinite(acc)
    if bad.any():
        first = int(np.argmax(bad))
        raise RecordError(f"{path}: {int(bad.sum())} sample(s) are NaN or infinite (first at sample {first})")
    if acc.size < MIN_SAMPLES:
        raise RecordError(f"{path}: only {acc.size} sample(s); a record needs at least {MIN_SAMPLES}")
    peak_g = float(np.max(np.abs(acc))) / G
    if peak_g == 0.0:
        raise RecordError(f"{path}: every sample is zero")
    if not PLAUSIBLE_MIN_G <= peak_g <= PLAUSIBLE_MAX_G:
        raw_peak = float(np.max(np.abs(raw)))
        options = [(u, pg) for u, pg in plausible_units(raw_peak) if u != units]
        where = "given" if units_source == "user" else "stated in the file"
        listed = " or ".join(f"{u} (peak {pg:.2g} g)" for u, pg in options)
        fix = (f"if the samples are in {listed}, pass units='{options[0][0]}' (--units {options[0][0]})"
               if options else "no acceleration units make it plausible")
        raise RecordError(f"{path}: peak {raw_peak:.4g} {units} ({where}) is {peak_g:.3g} g, implausible "
                          f"for an accelerogram (outside {PLAUSIBLE_MIN_G:g} to {PLAUSIBLE_MAX_G:g} g); {fix}")
    if peak_g > WARN_PEAK_G:
        meta["warnings"].append(f"peak acceleration {peak_g:.3g} g is above {WARN_PEAK_G:g} g: check the units")
