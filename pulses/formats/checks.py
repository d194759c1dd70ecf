"""The checks every record gets, whatever its format: what a format's reader found (a
:class:`pulses.formats.Reading`) becomes a record's samples in m/s^2, or is refused.

Units are never guessed (docs/theory.md section 7): the file's where it states them reliably,
else the user's, else the reading is refused.  The time step is the file's where it states one.
A peak below 1e-5 g or above 10 g makes the units implausible and is refused, naming the units
that would make it plausible; a peak above 5 g is kept with a warning in
``metadata["warnings"]``, as is a large constant offset.
"""
from __future__ import annotations

import pathlib

import numpy as np

from ..errors import RecordError
from ..units import (
    G,
    PLAUSIBLE_MAX_G,
    PLAUSIBLE_MIN_G,
    WARN_PEAK_G,
    canonical_units,
    implausible_peak,
    unit_factor,
)
from .registry import UNITS_STATED

#: fewer samples than this cannot hold a pulse and are refused
MIN_SAMPLES = 10


def _units_hint() -> str:
    return "pass units= ('g', 'm/s2', 'cm/s2' or 'gal'; on the command line --units)"


def record_fields(path: str, reading, units=None, dt=None, name=None, *,
                  column_suffix: bool = False) -> dict:
    """The checks every record gets, on what a format's reader found (``reading``, a
    :class:`pulses.formats.Reading`): units (never guessed), time step, finite samples, plausible
    peak; returns the record's fields, ``pulses.Record(**fields)``: ``acc`` (m/s^2), ``dt``,
    ``name``, ``t_start`` and ``metadata``.  ``path`` names the source in messages and in
    ``metadata["source"]``; it need not be a file (a member of a zip read in memory,
    :mod:`pulses.io.peer`; a trace, :mod:`pulses.formats.traces`)."""
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
    return {"acc": acc, "dt": dt, "name": name, "t_start": float(meta.pop("t_start", 0.0)), "metadata": meta}


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
    if reading.units_rule == UNITS_STATED and units is not None:
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
