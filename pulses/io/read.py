"""Read an accelerogram from any supported file into a :class:`pulses.Record` (m/s^2).

Each format is one module registered in :mod:`pulses.formats`; :func:`read_record` dispatches to
it and applies the checks every record gets.  Formats (``format=``):

``"at2"``
    PEER NGA ``.AT2`` (both header styles); units from the header ("UNITS OF G").
``"text"``
    Plain text or CSV columns (see :mod:`pulses.formats.text`); the user gives ``units`` and ``dt``
    (``dt`` may come from a time column instead).
``"sac"`` (:mod:`pulses.formats.sac`), ``"knet"`` (:mod:`pulses.formats.knet`), every other obspy format (``"mseed"``, ...)
    Through :func:`obspy.read` (:mod:`pulses.formats.obspy`).  SAC: ``idep`` states the quantity;
    ``iacc`` means nm/s^2 by the SAC standard, honoured unless the user passes ``units``.  K-NET: obspy leaves the samples in
    counts and puts the header's scale factor, converted from gal to m/s^2, into
    ``stats.calib``; the reader multiplies by it and removes the mean (the K-NET convention), so
    the units are stated (m/s^2).  Formats that state no units (MiniSEED, ...) need ``units``.

Units are never guessed (docs/theory.md section 7).  A peak below 1e-5 g or above 10 g makes the units
implausible and is refused, naming the units that would make it plausible; a peak above 5 g is
kept with a warning in ``record.metadata["warnings"]``.
"""
from __future__ import annotations

import os
import pathlib

import numpy as np

from .. import formats
from ..errors import RecordError
from ..formats import MAX_SAMPLES, ReadOptions
from ..record import Record
from ..units import (
    G,
    PLAUSIBLE_MAX_G,
    PLAUSIBLE_MIN_G,
    WARN_PEAK_G,
    canonical_units,
    implausible_peak,
    unit_factor,
)

#: fewer samples than this cannot hold a pulse and are refused
MIN_SAMPLES = 10


def _units_hint() -> str:
    return "pass units= ('g', 'm/s2', 'cm/s2' or 'gal'; on the command line --units)"


def read_record(path, format=None, units=None, *, dt=None, column=None, trace=None, name=None,
                max_samples=MAX_SAMPLES) -> Record:
    """Read one ground-acceleration record.

    Parameters
    ----------
    path : str, bytes or path-like
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
        Name of the record in reports (default: the file name, plus ``:colN`` for a chosen
        column; bytes that are not UTF-8 and characters that do not print written as escapes,
        see :func:`printable`).
    max_samples : int, optional
        A record with more samples is refused (default :data:`pulses.formats.MAX_SAMPLES`,
        10^7); text and AT2 files are refused while reading, before memory grows further.

    Returns
    -------
    pulses.Record
        Acceleration in m/s^2.  ``record.metadata`` has ``station``, ``component``, ``event``,
        ``units`` (as stated in the file or given by the user), ``units_source`` (``"file"`` or
        ``"user"``), ``format``, ``source`` (the path), ``warnings`` (list of str), ``azimuth``
        and ``vertical`` where the file states them (see :mod:`pulses.orientation`) and
        format-specific entries.

    Raises
    ------
    RecordError
        With a one-line message for a missing, empty, truncated or unknown file, a header that
        disagrees with the data, NaN or infinite samples, too few or too many samples,
        non-uniform sampling, a velocity or displacement record, missing or implausible units.

    Notes
    -----
    The formats are those registered in :mod:`pulses.formats` (one module each); this function
    only dispatches to them and applies the checks every record gets.

    Examples
    --------
    >>> import importlib.resources, pulses
    >>> path = importlib.resources.files("pipeline.data") / "synth_sine_055g_0.9s.sac"   # a bundled record
    >>> rec = pulses.read_record(str(path))
    >>> rec.dt, round(rec.pga / pulses.G, 3)
    (0.01, 0.634)
    >>> pulses.read_record("no-such-file.sac")
    Traceback (most recent call last):
    ...
    pulses.errors.RecordError: no-such-file.sac: no such file
    """
    path = os.fsdecode(path)  # bytes too; bytes that are not UTF-8 kept as surrogates (PEP 383)
    shown = printable(path)
    try:
        return _read(path, format, units, dt, column, trace, name, max_samples)
    except RecordError as exc:
        if shown == path:
            raise
        raise RecordError(str(exc).replace(path, shown)) from None  # messages print and write safely


def _check_entry(path) -> None:
    """A :class:`RecordError` saying why ``path`` is no file that can be read, if it is not: missing,
    a symbolic link to nothing or in a loop, in a folder without search permission, a folder, a
    FIFO, a device or a socket (by :func:`os.stat`, before anything opens it)."""
    import errno
    import stat

    try:
        st = os.stat(path)
    except OSError as exc:
        if exc.errno == errno.ENOENT and os.path.islink(path):
            raise RecordError(f"{path}: a symbolic link to a file that does not exist "
                              f"({printable(os.readlink(path))})") from None
        if exc.errno == errno.ENOENT:
            raise RecordError(f"{path}: no such file") from None
        if exc.errno == errno.ELOOP:
            raise RecordError(f"{path}: a loop of symbolic links") from None
        raise RecordError(f"{path}: cannot be read: {exc.strerror or exc}") from None
    if stat.S_ISDIR(st.st_mode):
        try:
            os.listdir(path)
        except OSError as exc:
            raise RecordError(f"{path}: a folder whose files cannot be listed: {exc.strerror or exc}") from None
        raise RecordError(f"{path}: is a directory, not a record file")
    if not stat.S_ISREG(st.st_mode):  # reading a FIFO or /dev/zero would block or never end
        raise RecordError(f"{path}: {special_kind(st.st_mode)}, not a record file: not opened")


def special_kind(mode: int) -> str:
    """What a file that is neither a regular file nor a folder is, in words (``a FIFO`` ...)."""
    import stat

    for test, what in ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return what
    return "not a regular file"


def _read(path, format, units, dt, column, trace, name, max_samples) -> Record:
    """:func:`read_record` on a ``str`` path: dispatch to the format, then the common checks."""
    p = pathlib.Path(path)
    _check_entry(path)
    if p.stat().st_size == 0:
        raise RecordError(f"{path}: the file is empty")
    fmt = formats.detect(path) if format is None else (formats.by_name(format) or
                                                         formats.by_name(formats.FALLBACK))
    if units is not None:
        unit_factor(units)  # refuse unknown or velocity units before reading
    reading = fmt.read(path, ReadOptions(column=column, trace=trace, max_samples=int(max_samples),
                                         format=format))
    return record_from_reading(path, reading, units, dt, name, column_suffix=True)


def record_from_reading(path: str, reading, units=None, dt=None, name=None, *,
                        column_suffix: bool = False) -> Record:
    """The checks every record gets, on what a format's reader found (``reading``, a
    :class:`pulses.formats.Reading`): units (never guessed), time step, finite samples, plausible
    peak.  ``path`` names the source in messages and in ``metadata["source"]``; it need not be a
    file (a member of a zip read in memory, :mod:`pulses.io.peer`)."""
    if units is not None:
        unit_factor(units)
    meta = reading.metadata
    meta.setdefault("warnings", [])
    # units and time step both looked at before either is refused: all of a file's missing
    # settings in one message, not one per run
    problems = []
    try:
        used_units, units_source = _units(path, reading, units)
    except RecordError as exc:
        problems.append(str(exc))
    try:
        dt = _time_step(path, reading, dt)
    except RecordError as exc:
        problems.append(str(exc))
    if problems:
        prefix = f"{path}: "
        raise RecordError(prefix + "; and ".join(p[len(prefix):] if p.startswith(prefix) else p for p in problems))
    acc = np.asarray(reading.values, dtype=float) * unit_factor(used_units)
    meta.update(units=used_units, units_source=units_source, source=path, dt=dt)
    for key in ("station", "component", "event"):
        meta.setdefault(key, "")
    _validate(path, acc, reading.values, used_units, units_source, meta)
    if name is None:
        name = printable(pathlib.PurePath(path).name)
        if column_suffix and meta.get("columns", 1) > 1:
            name += f":col{meta['column']}"
    return Record(acc, dt, name=name, t_start=float(meta.pop("t_start", 0.0)), metadata=meta)


def printable(text: str) -> str:
    """``text`` safe to print and to write as UTF-8 (a record's default name, error messages).

    Bytes of a file name that are not UTF-8 (which Python keeps as lone surrogates, PEP 383) and
    characters that do not print (newline, tab, other controls) are written as backslash escapes
    (``\\xff``, ``\\n``); everything else is kept.
    """
    try:
        raw = text.encode("utf-8", "surrogateescape")
    except UnicodeEncodeError:  # a lone surrogate that did not come from a byte
        raw = text.encode("utf-8", "backslashreplace")
    text = raw.decode("utf-8", "backslashreplace")
    if text.isprintable():
        return text
    return "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in text)


def _units(path, reading, units):
    """``(units used, "file" or "user")`` by the rule the format's reading states."""
    stated = reading.units
    # files that state their units reliably (AT2 "UNITS OF G", K-NET's scale factor): units passed
    # for a batch of files are not applied to them, and a disagreement is reported as a warning;
    # a standard's units (SAC iacc) yield to the user's (files in the wild break the standard)
    if reading.units_rule == formats.UNITS_STATED and units is not None:
        if unit_factor(units) != unit_factor(stated):
            reading.metadata["warnings"].append(f"units {units!r} passed but the file states {stated}: "
                                                f"used {stated}")
        units = None
    if units is not None:
        return canonical_units(units), "user"
    if stated is not None:
        return stated, "file"
    raise RecordError(f"{path}: {reading.no_units}; {_units_hint()}")


def _time_step(path, reading, dt):
    """The time step in s: the file's where it states one (a differing ``dt`` is warned of)."""
    file_dt = reading.dt
    if dt is not None:
        dt = float(dt)
        if not (np.isfinite(dt) and dt > 0):
            raise RecordError(f"{path}: dt must be a positive time step in s, got {dt!r}")
        if file_dt is not None:  # the file's own time step wins
            if abs(dt - file_dt) > 1e-6 * file_dt:
                reading.metadata["warnings"].append(f"dt={dt:g} s passed but the file says {file_dt:g} s: "
                                                    f"used {file_dt:g} s")
            dt = file_dt
        return dt
    if file_dt is not None:
        return file_dt
    raise RecordError(f"{path}: the file does not state its time step{reading.hint}; pass dt= in s "
                      f"(--dt on the command line)")


#: a record whose samples sit this fraction of their motion away from zero (median against the
#: largest departure from it) is reported: ground acceleration swings about zero (a fling's
#: permanent velocity moves the median of a real record by well under 1 % of its peak), so such an
#: offset is a baseline or a sensor's static reading (1 g: gravity on a vertical sensor), which
#: every design would otherwise take for ground motion
OFFSET_WARN_FRACTION = 0.1


def _check_offset(path, acc, meta) -> None:
    """Warn of a large constant offset (:data:`OFFSET_WARN_FRACTION`); refuse a record that is one
    constant throughout (no motion at all: nothing to design for)."""
    offset = float(np.median(acc))
    motion = float(np.max(np.abs(acc - offset)))
    if motion == 0.0:
        raise RecordError(f"{path}: every sample is {offset / G:.4g} g: a constant, no ground motion")
    if abs(offset) > OFFSET_WARN_FRACTION * motion:
        meta["warnings"].append(
            f"the samples sit {offset / G:+.3g} g from zero (median), {abs(offset) / motion:.0%} of their "
            "motion: a constant offset (baseline, gravity) is designed for as ground motion; "
            "remove it if it is not")


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
        where = "given" if units_source == "user" else "stated in the file"
        raise RecordError(f"{path}: {implausible_peak(float(np.max(np.abs(raw))), units, where)}")
    if peak_g > WARN_PEAK_G:
        meta["warnings"].append(f"peak acceleration {peak_g:.3g} g is above {WARN_PEAK_G:g} g: check the units")
    _check_offset(path, acc, meta)
