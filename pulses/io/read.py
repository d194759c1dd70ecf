"""Read an accelerogram from any supported file into a :class:`pulses.Record` (m/s^2), and two
files as the horizontal components of one station.

:func:`read_record` asks the registry of formats (:mod:`pulses.formats`, one module a format)
which format the file is, reads it with that format's reader and applies the checks every record
gets (:mod:`pulses.formats.checks`).  Formats (``format=``):

``"at2"``
    PEER NGA ``.AT2`` (both header styles); units from the header ("UNITS OF G").
``"text"``
    Plain text or CSV columns (see :mod:`pulses.formats.text`); the user gives ``units`` and
    ``dt`` (``dt`` may come from a time column instead).
``"sac"``, ``"knet"``, every other obspy format (``"mseed"``, ...)
    Through :func:`obspy.read` (:mod:`pulses.formats.obspy`, :mod:`~pulses.formats.sac`,
    :mod:`~pulses.formats.knet`).  SAC: ``idep`` states the quantity; ``iacc`` means nm/s^2 by
    the SAC standard, honoured unless the user passes ``units``.  K-NET: obspy leaves the
    samples in counts and puts the header's scale factor, converted from gal to m/s^2, into
    ``stats.calib``; the reader multiplies by it and removes the mean (the K-NET convention), so
    the units are stated (m/s^2).  Formats that state no units (MiniSEED, ...) need ``units``.

Units are never guessed (docs/theory.md section 7).  A peak below 1e-5 g or above 10 g makes the units
implausible and is refused, naming the units that would make it plausible; a peak above 5 g is
kept with a warning in ``record.metadata["warnings"]``.
"""
from __future__ import annotations

import os
import pathlib

from .. import formats
from ..errors import RecordError
from ..formats import MAX_SAMPLES, ReadOptions
from ..formats.checks import printable, record_fields
from ..pairs import check_pair
from ..record import Record
from ..units import unit_factor


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
    """The record of what a format's reader found (``reading``, a
    :class:`pulses.formats.Reading`), with the checks every record gets
    (:func:`pulses.formats.checks.record_fields`).  ``path`` names the source in messages and in
    ``metadata["source"]``; it need not be a file (a member of a zip read in memory,
    :mod:`pulses.io.peer`)."""
    return Record(**record_fields(path, reading, units, dt, name, column_suffix=column_suffix))


def read_pair(path1, path2, **read_options) -> tuple[Record, Record]:
    """Read two files as the horizontal components of one station.

    Parameters
    ----------
    path1, path2 : str or path-like
        The two component files; orientations are measured from the first towards the second.
    **read_options
        Passed to :func:`pulses.read_record` for both files (``units``, ``dt``, ``format``, ...).

    Returns
    -------
    (Record, Record)
        Accelerations in m/s^2, truncated to the same length (see :func:`pulses.check_pair`).

    Examples
    --------
    >>> from importlib.resources import files
    >>> import pulses
    >>> data = files("pipeline.data")
    >>> first, second = pulses.read_pair(str(data / "synth_sine_055g_0.9s.sac"),
    ...                                  str(data / "synth_broadband_only.sac"))
    >>> first.npts == second.npts, first.dt
    (True, 0.01)
    """
    return check_pair(read_record(path1, **read_options), read_record(path2, **read_options))
