"""The command line's shared parts: option groups several sub-commands declare (records' reading,
pairs, restitution, weighting), and the reading of quantities written with their units
(``0.71g``, ``14deg``).

The rules every value follows, however it is given, are :mod:`pipeline.values`; every parser here
raises its :class:`~pipeline.values.ArgumentError` with a one-line message, which the command
line turns into exit status 2.  Units of acceleration are those of :mod:`pulses.units` (one place).
"""
from __future__ import annotations

import math
import re

from .values import ArgumentError, parse_column, parse_dt, parse_units


def add_record_options(parser) -> None:
    """Add the options that tell :func:`pulses.read_record` what a file does not say:
    ``--units``, ``--dt``, ``--column``, ``--format``, ``--trace``.  Read them back with
    :func:`record_options`."""
    from pulses.units import CANONICAL_UNITS

    units = ", ".join("cm/s2 (gal)" if u == "cm/s2" else u for u in CANONICAL_UNITS)
    parser.add_argument("--units", help="units of the samples where a file states none (text, "
                                        f"MiniSEED), or to override SAC's iacc = nm/s^2: {units}; "
                                        "not applied to AT2 and K-NET files, which state theirs")
    parser.add_argument("--dt", help="sampling interval in s, for text files without a time column")
    parser.add_argument("--column", help="text files: the column holding the acceleration, counted from 1")
    parser.add_argument("--format", help="file format when detection from the content is not wanted "
                                         "(at2, text, sac, mseed, knet, or any obspy format)")
    parser.add_argument("--trace", help="files holding several traces (MiniSEED ...): index (from 0), "
                                        "id or channel")


def add_pair_options(parser, *, default: str, action: str) -> None:
    """Add ``--pair A B`` (repeatable) and ``--pairs auto|none`` (pairing the horizontal components
    of one station, as :func:`pulses.pair_files` does); ``action`` says what is done with a pair
    and ``default`` is the ``--pairs`` default."""
    parser.add_argument("--pair", nargs=2, action="append", default=[], metavar=("A", "B"),
                        help=f"{action} A and B as the two horizontal components of one station "
                             "(angles measured from A towards B); repeatable")
    described = {"auto": "pair the other files from their names and headers, verticals left out",
                 "none": "every file is one component"}
    parser.add_argument("--pairs", choices=["auto", "none"], default=default,
                        help="; ".join(f"{k}{' (default)' if k == default else ''}: {v}"
                                       for k, v in described.items()))


def record_options(args) -> dict:
    """Keyword arguments of :func:`pulses.read_record` from the options of
    :func:`add_record_options` (checked: :class:`ArgumentError` for a bad value)."""
    return {"format": args.format, "units": parse_units(args.units),
            "dt": None if args.dt is None else parse_dt(args.dt),
            "column": parse_column(args.column), "trace": args.trace}


def parse_acceleration(text: str, default_unit: str | None = None, signed: bool = True) -> float:
    """``"0.71g"``, ``"6.9m/s2"``, ``"690gal"`` -> m/s^2.

    A bare number needs ``default_unit``; units are never guessed.
    """
    s = str(text).strip().replace(" ", "")
    m = re.fullmatch(r"([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)(.*)", s)
    if not m:
        raise ArgumentError(f"cannot read acceleration {text!r}; write e.g. 0.71g or 6.96m/s2")
    from pulses import RecordError
    from pulses.units import unit_factor

    value, unit = float(m.group(1)), m.group(2).lower() or default_unit
    if unit is None:
        raise ArgumentError(f"acceleration {text!r} has no unit; write e.g. {text}g or {text}m/s2")
    try:
        value *= unit_factor(unit)
    except RecordError as exc:
        raise ArgumentError(f"acceleration {text!r}: {exc}") from None
    if not math.isfinite(value) or (not signed and value <= 0.0) or value == 0.0:
        raise ArgumentError(f"acceleration must be a non-zero finite value, got {text!r}")
    return value


def parse_angle(text: str) -> float:
    """``"14deg"``, ``"0.24rad"``, ``"tan0.24"`` -> radians.  A bare number is refused."""
    s = str(text).strip().lower().replace(" ", "")
    try:
        if s.endswith("deg"):
            value = math.radians(float(s[:-3]))
        elif s.endswith("rad"):
            value = float(s[:-3])
        elif s.startswith("tan"):
            value = math.atan(float(s[3:].lstrip("=")))
        else:
            raise ArgumentError(f"angle {text!r} needs a unit: 14deg, 0.244rad or tan0.24")
    except ValueError:
        raise ArgumentError(f"cannot read angle {text!r}; write 14deg, 0.244rad or tan0.24") from None
    if not (math.isfinite(value) and 0.0 < value < math.pi / 2):
        raise ArgumentError(f"angle must lie strictly between 0 and 90 deg, got {text!r}")
    return value


RESTITUTION_HELP = ("the restitution at impact: a factor of Eq. 5 (0.97: 0.97 times Housner's eta at "
                    "each width; tests find 0.67 on rubber, 0.95-0.97 on concrete), eta=V (the "
                    "velocity ratio, the same at every width) or r=V (the energy ratio, eta squared); "
                    "LOW:HIGH a band, whose answer covers it (every one of 5 values, ends included, "
                    "run; the most demanding governs). Default: Eq. 5")


def add_restitution_option(parser) -> None:
    """``--restitution``: read back with :func:`parse_restitution`."""
    parser.add_argument("--restitution", metavar="VALUE", default=None, help=RESTITUTION_HELP)


def add_weighting_option(p) -> None:
    """``--weighting``: the least squares of the pulse fit (:func:`pulses.fit_pulse`'s ``weighting``)."""
    p.add_argument("--weighting", choices=("background", "plain"), default="background",
                   help="pulse fit: least squares weighted by the background's spectrum estimated from "
                        "the record (default), or plain least squares, for comparison")


class ShapeNames:
    """The names of the pulse shapes (:data:`pulses.SHAPES`), as ``choices`` of an option, read
    when first asked (checking a value, printing help): the command line starts without importing
    ``pulses``.  ``extra``: names accepted besides the shapes (``"all"``).  Give the option a
    ``metavar``: argparse would otherwise list the choices when the option is declared."""

    def __init__(self, *extra: str):
        self.extra = extra

    def names(self) -> list[str]:
        from pulses import SHAPES

        return [*self.extra, *SHAPES]

    def __iter__(self):
        return iter(self.names())

    def __contains__(self, name) -> bool:
        return name in self.names()

    def __str__(self) -> str:
        """The names, comma-separated: ``%(shapes)s`` in the help of an option whose action has
        ``shapes = ShapeNames()`` (argparse formats help with the action's attributes)."""
        return ", ".join(self.names())
