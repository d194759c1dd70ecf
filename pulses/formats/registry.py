"""The registry of record formats that :func:`pulses.read_record` reads, and what a format's
reader returns.

A format module builds one :class:`RecordFormat` (how to detect the file, how to read it) and
passes it to :func:`register`; its reader returns a :class:`Reading` that says what the file
states about its units (``units``, ``units_rule``).  :func:`pulses.read_record` only asks the
registry and checks; it knows no format by name.  How to add one: :mod:`pulses.formats`.

Formats read by obspy (SAC, K-NET, MiniSEED, ...) are detected by obspy: the ``obspy`` format
reads the file with :func:`obspy.read` and hands the trace to the format registered for obspy's
name of it (``obspy_name``), or reads it as a format that states no units.
"""
from __future__ import annotations

import dataclasses
from typing import Callable

import numpy as np

#: how far a file's stated units are trusted (``Reading.units_rule``)
UNITS_STATED = "stated"        # the file states them reliably (AT2, K-NET): a user's units are not applied
UNITS_STANDARD = "standard"    # a standard implies them (SAC iacc = nm/s^2): a user's units override
UNITS_NONE = "none"            # the file states none (text, MiniSEED): the user gives them

#: records longer than this are refused.  10^7 samples is 28 h at 100 Hz and 14 h at 200 Hz,
#: hundreds of times the longest strong-motion records (minutes); it keeps one record's arrays
#: near 80 MB each, so a batch of workers stays within an ordinary machine's memory.
MAX_SAMPLES = 10_000_000


def too_long(path: str, limit: int, count: int | None = None) -> str:
    """The one-line message for a record longer than ``limit`` samples (``count`` if known)."""
    held = f"{count} samples" if count is not None else f"more than {limit} samples"
    return (f"{path}: {held}; a record may have at most {limit} (max_samples): cut it to the "
            f"strong motion, or pass a larger max_samples")


def join_blocks(blocks: list) -> np.ndarray:
    """Arrays read block by block as one array, emptying ``blocks`` while copying them, so the
    memory peak is the result plus one block rather than twice the record."""
    out = np.empty(sum(b.size for b in blocks))
    at = 0
    while blocks:
        block = blocks.pop(0)
        out[at:at + block.size] = block
        at += block.size
    return out


@dataclasses.dataclass(frozen=True)
class ReadOptions:
    """What the caller says about the file, passed to every format's reader.

    Attributes
    ----------
    column : int or None
        Text files: the acceleration column, counted from 1.
    trace : int or str or None
        obspy formats with several traces: index from 0, trace id or channel.
    max_samples : int
        Records longer than this are refused (:data:`MAX_SAMPLES` by default).
    format : str or None
        The ``format=`` name the caller gave (the obspy fallback passes it on to obspy).
    """

    column: int | None = None
    trace: int | str | None = None
    max_samples: int = MAX_SAMPLES
    format: str | None = None


@dataclasses.dataclass
class Reading:
    """What a format's reader found in a file, before units and checks are applied.

    Attributes
    ----------
    values : ndarray
        The samples in the file's units.
    dt : float or None
        Sampling interval stated by the file (header, time column), s.
    metadata : dict
        Header information; ``format`` names the format read.
    units : str or None
        Units the file states (canonical spelling), or ``None``.
    units_rule : str
        :data:`UNITS_STATED`, :data:`UNITS_STANDARD` or :data:`UNITS_NONE`.
    no_units : str
        Why the units are unknown, for the error message when the user gives none.
    hint : str
        File comments that seem to mention units or the time step, quoted in error messages.
    """

    values: np.ndarray
    dt: float | None
    metadata: dict
    units: str | None = None
    units_rule: str = UNITS_NONE
    no_units: str = "the file does not state its units"
    hint: str = ""


@dataclasses.dataclass(frozen=True)
class RecordFormat:
    """One record format.

    Attributes
    ----------
    name : str
        The ``format=`` name (lower case).
    read : callable
        ``read(path, options) -> Reading``; raises :class:`pulses.RecordError` with one line.
    detect : callable, optional
        ``detect(path) -> bool``, never raising; formats without one are found by name only
        (or by obspy).
    aliases : tuple of str
        Other ``format=`` names.
    sniff_order : int
        Detectors run in increasing order.
    obspy_name : str, optional
        obspy's name of the format; then ``from_trace(trace, path, options) -> Reading``
        interprets a trace obspy read.
    from_trace : callable, optional
    """

    name: str
    read: Callable
    detect: Callable | None = None
    aliases: tuple = ()
    sniff_order: int = 100
    obspy_name: str | None = None
    from_trace: Callable | None = None


_FORMATS: dict[str, RecordFormat] = {}
_NAMES: dict[str, RecordFormat] = {}
_OBSPY: dict[str, RecordFormat] = {}
#: the format used when no detector claims a file, and for names no format registered
FALLBACK = "obspy"


def register(fmt: RecordFormat) -> RecordFormat:
    """Add ``fmt`` to the registry (its name and aliases must be new); returns it."""
    for key in (fmt.name, *fmt.aliases):
        if key.lower() in _NAMES and _NAMES[key.lower()] is not _FORMATS.get(fmt.name):
            raise ValueError(f"record format name {key!r} is registered already")
    _FORMATS[fmt.name] = fmt
    for key in (fmt.name, *fmt.aliases):
        _NAMES[key.lower()] = fmt
    if fmt.obspy_name:
        _OBSPY[fmt.obspy_name.upper()] = fmt
    return fmt


def unregister(name: str) -> None:
    """Remove the format registered as ``name`` (and its aliases and obspy name)."""
    fmt = _FORMATS.pop(name)
    for key in [k for k, f in _NAMES.items() if f is fmt]:
        del _NAMES[key]
    for key in [k for k, f in _OBSPY.items() if f is fmt]:
        del _OBSPY[key]


def registered() -> list[RecordFormat]:
    """The registered formats, in sniffing order."""
    return sorted(_FORMATS.values(), key=lambda f: f.sniff_order)


def by_name(name: str) -> RecordFormat | None:
    """The format registered under ``name`` or an alias of it (any case), or ``None``."""
    return _NAMES.get(str(name).strip().lower())


def by_obspy_name(name: str) -> RecordFormat | None:
    """The format that interprets traces obspy read as ``name`` (``"SAC"``), or ``None``."""
    return _OBSPY.get(str(name).strip().upper())


def detect(path: str) -> RecordFormat:
    """The first registered format whose detector claims ``path``, else the fallback."""
    for fmt in registered():
        if fmt.detect is not None and fmt.detect(path):
            return fmt
    return _FORMATS[FALLBACK]
