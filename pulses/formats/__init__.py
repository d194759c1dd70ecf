"""Record formats: what a file, or a trace obspy read, states, one module a format, registered once.

:func:`pulses.read_record` asks the registry (:mod:`pulses.formats.registry`) which format a file
is and reads it with that format's reader; it knows no format by name.  Each module here is one
format, as obspy's waveform plugins are (``obspy.io.sac``: ``_is_sac`` detects, ``_read_sac``
reads): :mod:`~pulses.formats.at2` (PEER NGA), :mod:`~pulses.formats.text` (columns of numbers),
:mod:`~pulses.formats.sac`, :mod:`~pulses.formats.knet` (K-NET, KiK-net) and
:mod:`~pulses.formats.obspy` (every other format obspy reads, MiniSEED among them; the fallback).

A reader returns a :class:`Reading`, the samples in the file's units and what the file states
about them, never a record: the record type stands on this package.  :mod:`pulses.formats.checks`
applies the rules every record obeys (units never guessed, the time step, a plausible peak) and
:mod:`pulses.formats.traces` interprets an obspy trace as the file it was read from.

Adding a format
---------------
1. Write one module, named after the format: ``pulses/formats/<name>.py`` (a format kept outside
   the package is a module of its own that does steps 2 to 6 and is imported before reading).
2. Give it ``read(path, options) -> Reading`` (``options`` a :class:`ReadOptions`): the samples
   as the file holds them; ``dt`` where the file states it; ``metadata`` with ``format``,
   ``station``, ``component``, ``event`` and the orientation
   (:func:`pulses.orientation.orientation`); the units as the file states them, ``units`` and
   ``units_rule``: :data:`UNITS_STATED` (stated reliably: a user's units are not applied),
   :data:`UNITS_STANDARD` (implied by a standard: a user's units override) or
   :data:`UNITS_NONE` (the user gives them; ``no_units`` says why, ``hint`` quotes comments that
   seem to mention units or the time step).  Never guess units, a time step or a polarity.
3. Refuse what cannot be read with a one-line :class:`pulses.RecordError` that starts with the
   path and, where the user can fix it, says what to pass; refuse more than
   ``options.max_samples`` samples while reading (:func:`too_long`), before memory grows.
4. Give it ``detect(path) -> bool`` where the content tells the format: cheap (the first lines
   or bytes) and never raising; ``sniff_order`` places it among the other detectors (AT2 10,
   text 20: the stricter first).  A format without one is read by its ``format=`` name only.
5. For a format obspy reads: set ``obspy_name``, give ``from_trace(trace, path, options) ->
   Reading`` and read through :func:`pulses.formats.obspy.read`, so that a trace obspy read
   (:meth:`pulses.Record.from_trace`) is interpreted as its file would be.
6. Register it once, at the bottom of its module: ``FORMAT = register(RecordFormat(...))``, and
   import the module below, so that the registry is complete whenever this package is imported.
7. Test it in ``tests/test_records.py``: a real file of the format read by
   :func:`pulses.read_record` (units, time step, orientation), detection against the other
   formats' files, each refusal's message; and give it a row in ``docs/records.md``.
"""
from . import at2, knet, obspy, sac, text  # noqa: F401  (each registers its format)
from .registry import (
    FALLBACK,
    MAX_SAMPLES,
    UNITS_NONE,
    UNITS_STANDARD,
    UNITS_STATED,
    Reading,
    ReadOptions,
    RecordFormat,
    by_name,
    by_obspy_name,
    detect,
    join_blocks,
    register,
    registered,
    too_long,
    unregister,
)

__all__ = ["FALLBACK", "MAX_SAMPLES", "UNITS_NONE", "UNITS_STANDARD", "UNITS_STATED", "Reading",
           "ReadOptions", "RecordFormat", "by_name", "by_obspy_name", "detect", "join_blocks",
           "register", "registered", "too_long", "unregister"]
