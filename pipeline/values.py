"""The rules of ``pipeline run``'s values, whichever way a value comes: the command line's text,
:func:`pipeline.design`'s numbers, a cell of a ``--scales`` file.  Each rule checks one value (a
number is taken as it is, text is read as a number first) and refuses it with
:class:`ArgumentError`, one line naming what was given; the command line turns it into exit
status 2, :func:`pipeline.design` into a ``ValueError`` with the same words.  The batch
(:mod:`pipeline.batch`) asks these rules, never the command line's parsers (:mod:`pipeline.args`).
"""
from __future__ import annotations

import math
import numbers
import os
import pathlib
import re
import tempfile


class ArgumentError(ValueError):
    """A command-line value that cannot be used (reported in one line, exit status 2)."""


#: the most worker processes a run takes (``--jobs``, ``pipeline.design(jobs=)``): each holds the
#: solver and a record (a few hundred MB)
MAX_JOBS = 256


def jobs_count(jobs: int, name: str) -> int:
    """The number of worker processes for ``jobs`` (0: one per CPU), in 0..:data:`MAX_JOBS`;
    ``name`` is the option or argument the message names."""
    if not 0 <= jobs <= MAX_JOBS:
        raise ValueError(f"{name} must be 0 (one per CPU) to {MAX_JOBS}, got {jobs}")
    return jobs or (os.cpu_count() or 1)



def as_number(value) -> float:
    """``value`` as a float: a number as it is (numpy's included), text read as one; ``ValueError``
    otherwise.  A boolean is no number here."""
    if isinstance(value, numbers.Real) and not isinstance(value, bool):
        return float(value)
    return float(str(value).strip())


def as_whole(value) -> int:
    """``value`` as an int: a whole number as it is, text read as one; ``ValueError`` otherwise."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        return int(value)
    return int(str(value).strip())


def parse_units(text, what: str = "--units"):
    """Canonical spelling of acceleration units (``"gal"`` -> ``"cm/s2"``), None when not given."""
    if text is None:
        return None
    from pulses import RecordError
    from pulses.units import canonical_units

    try:
        return canonical_units(text)
    except RecordError as exc:
        raise ArgumentError(f"{what}: {exc}") from None


#: sampling intervals accepted, s: strong-motion records are sampled at 50 to 1000 Hz; these
#: bounds leave room on both sides and stop typing errors (``--dt 5`` for 0.005 s)
DT_RANGE_S = (1e-5, 1.0)


def parse_dt(text, what: str = "--dt") -> float:
    """``--dt``: a sampling interval in s within :data:`DT_RANGE_S`."""
    dt = parse_positive(text, f"{what} (s)")
    lo, hi = DT_RANGE_S
    if not lo <= dt <= hi:
        raise ArgumentError(f"{what} (s) must lie between {lo:g} s and {hi:g} s, got {dt:g}")
    return dt


#: scale factors accepted on a record, however given (``--scale``, a row of ``--scales``, ``--up-to``,
#: ``simulate --scale``): a thousandth to a thousand times the record; beyond them a typing error
#: is likelier (1e6 designed a column for 874,060 g), and the solver's tested range is left
SCALE_RANGE = (1e-3, 1e3)


def parse_scale(text, what: str = "--scale", *, signed: bool = False, low: float | None = None) -> float:
    """A scale factor on a record within :data:`SCALE_RANGE` (its magnitude, when ``signed``: a
    negative factor reverses the record's polarity); ``low`` raises the lower bound (``--up-to``
    must exceed 1).  The one rule for every way a scale reaches a record."""
    try:
        value = as_number(text)
    except ValueError:
        raise ArgumentError(f"{what}: expected a number, got {text!r}") from None
    lo, hi = SCALE_RANGE
    lo = lo if low is None else low
    size = abs(value) if signed else value
    if not (math.isfinite(value) and lo <= size <= hi):
        sign = "in magnitude " if signed else ""
        raise ArgumentError(f"{what} must lie {sign}between {lo:g} and {hi:g}, got {text!r}")
    return value


def pair_files(pairs, what: str = "--pair") -> list[tuple[str, str]]:
    """The ``--pair A B`` couples, each checked to name two files: both names one file (the same
    name, another path to it, a link to it) is an :class:`ArgumentError` (designing a file as its
    own pair doubles it in one direction and cancels it in the other)."""
    out = []
    for a, b in pairs:
        same = os.path.realpath(a) == os.path.realpath(b)
        if not same:
            try:
                same = os.path.samefile(a, b)
            except (OSError, ValueError):
                pass
        if same:
            from .reports.cells import display

            raise ArgumentError(f"{what} {display(a)} {display(b)}: both name one file; a pair is "
                                "two components of one station")
        out.append((str(a), str(b)))
    return out


def parse_column(text, what: str = "--column"):
    """``--column``: a column number counted from 1, None when not given."""
    if text is None:
        return None
    try:
        column = int(text) if isinstance(text, numbers.Integral) and not isinstance(text, bool) else int(str(text))
    except ValueError:
        column = 0
    if column < 1:
        raise ArgumentError(f"{what} counts from 1, got {text!r}")
    return column


def _float(text, what: str, rule: str) -> float:
    try:
        return as_number(text)
    except ValueError:
        raise ArgumentError(f"{what} {rule}, got {text!r}") from None


def parse_limit(text, what: str = "--limit"):
    """``--limit R``: a performance level max|theta|/alpha, ``0 < R <= 1``; ``none`` (or None: not
    given) -> None, the verge of overturning alone."""
    if text is None or str(text).strip().lower() == "none":
        return None
    rule = "(max|theta|/alpha) must be a number in (0, 1] or none"
    value = _float(text, what, rule)
    if not (math.isfinite(value) and 0.0 < value <= 1.0):
        raise ArgumentError(f"{what} {rule}, got {text!r}")
    return value


#: the largest cap beam mass over the columns' mass of a rocking frame (``--cap-mass-ratio``)
MAX_CAP_MASS_RATIO = 1e3


def parse_cap_mass_ratio(text, what: str = "--cap-mass-ratio") -> float:
    """``--cap-mass-ratio``: a rocking frame's cap beam mass over its columns', 0 (lone columns)
    to :data:`MAX_CAP_MASS_RATIO`."""
    rule = f"must be a number between 0 and {MAX_CAP_MASS_RATIO:g}"
    value = _float(text, what, rule)
    if not (math.isfinite(value) and 0.0 <= value <= MAX_CAP_MASS_RATIO):
        raise ArgumentError(f"{what} {rule}, got {text!r}")
    return value


def parse_up_to(text, what: str = "--up-to") -> float:
    """``--up-to``: the largest scale factor ``--fragility`` examines, above 1 (the scale rule)."""
    return parse_scale(text, what, low=1.0 + 1e-9)


#: the most evenly spaced directions of a pair (``--directions``)
MAX_DIRECTIONS = 180


def parse_directions(text, what: str = "--directions") -> int:
    """``--directions N``: evenly spaced directions added for a pair, 0 to :data:`MAX_DIRECTIONS`."""
    try:
        n = as_whole(text)
    except ValueError:
        raise ArgumentError(f"{what} expects a whole number, got {text!r}") from None
    if not 0 <= n <= MAX_DIRECTIONS:
        raise ArgumentError(f"{what} must be 0 to {MAX_DIRECTIONS}, got {n}")
    return n


def _finite_positive(value: float, what: str) -> float:
    if not math.isfinite(value) or value <= 0.0:
        raise ArgumentError(f"{what} must be a positive finite number, got {value!r}")
    return value


#: sizes of a column accepted on the command line, m: from a 1 cm laboratory specimen to a 1 km
#: tower; beyond them the numbers are typing errors, and the solver's time and length scales
#: (p = sqrt(3 g / 4 R)) leave the range it is tested in
SIZE_RANGE_M = (0.01, 1000.0)


def _size(value: float, what: str) -> float:
    value = _finite_positive(value, what)
    lo, hi = SIZE_RANGE_M
    if not lo <= value <= hi:
        raise ArgumentError(f"{what} must lie between {lo:g} m and {hi:g} m, got {value:g}")
    return value


def parse_block(text: str) -> tuple[float, float]:
    """``"7.5x1.8"`` -> ``(height, width)`` in m, each within :data:`SIZE_RANGE_M`."""
    parts = re.split(r"\s*[xX*]\s*", str(text).strip())
    if len(parts) != 2:
        raise ArgumentError(f"--block expects HEIGHTxWIDTH in m, such as 7.5x1.8; got {text!r}")
    try:
        height, width = float(parts[0]), float(parts[1])
    except ValueError:
        raise ArgumentError(f"--block expects HEIGHTxWIDTH in m, such as 7.5x1.8; got {text!r}") from None
    return block_size(height, width, (text, parts[0], parts[1]))


def block_size(height: float, width: float, given: tuple[str, str, str] | None = None) -> tuple[float, float]:
    """A column's ``(height, width)`` in m, each within :data:`SIZE_RANGE_M`; a column wider than
    high is taken, with a warning that the two may be swapped (``given``: the text and its two
    numbers as written, for the warning; default the numbers)."""
    height, width = _size(float(height), "block height (m)"), _size(float(width), "block width (m)")
    if width > height:  # a column wider than high is allowed, but likelier the two swapped
        import sys

        h, w = (repr(height), repr(width)) if given is None else given[1:]
        text = f"{h}x{w}" if given is None else given[0]
        print(f"pipeline: warning: --block {text} is {width:g} m wide and {height:g} m high (HEIGHTxWIDTH); "
              f"did you mean {w}x{h}?", file=sys.stderr)
    return height, width


#: what a column's text may start with to name its body (``cyl:7.5x1.8``), and the body's kind
#: (rocking.bodies); no prefix: the rectangular block
BODY_PREFIXES = {"cyl": "cylinder", "cylinder": "cylinder", "rect": "rectangular",
                 "rectangular": "rectangular"}


def split_body(text, what: str = "--block") -> tuple[str, str]:
    """``"cyl:7.5x1.8"`` -> ``("cylinder", "7.5x1.8")``; no prefix: ``("rectangular", text)``."""
    head, sep, rest = str(text).strip().partition(":")
    if not sep:
        return "rectangular", str(text)
    kind = BODY_PREFIXES.get(head.strip().lower())
    if kind is None:
        raise ArgumentError(f"{what} {text!r}: unknown body {head!r}; write cyl:HxD for a "
                            "circular column or HxW for a rectangular one")
    return kind, rest


def parse_column_block(text) -> tuple[float, float, str]:
    """``--block``: ``HxW`` (rectangular) or ``cyl:HxD`` (a solid circular column of diameter D
    rocking in a plane) -> ``(height, width, body)``."""
    kind, rest = split_body(text)
    return (*parse_block(rest), kind)


def parse_column_height(text) -> tuple[float, str]:
    """``--height``: ``H`` or ``cyl:H`` -> ``(height, body)``."""
    kind, rest = split_body(text, "--height")
    return parse_length(rest, "--height (m)"), kind


def parse_friction(text):
    """``--friction MU``: a friction coefficient, 0 < MU <= 10; None when not given."""
    if text is None:
        return None
    value = parse_positive(text, "--friction (a friction coefficient)")
    if value > 10.0:
        raise ArgumentError(f"--friction is a friction coefficient (about 0.1 to 1), got {text!r}")
    return value


def parse_length(text: str, what: str = "length (m)") -> float:
    """A column's size in m (``"6"`` or ``"6m"``), within :data:`SIZE_RANGE_M`."""
    try:
        value = float(text) if isinstance(text, numbers.Real) and not isinstance(text, bool) \
            else float(str(text).strip().rstrip("m"))
    except ValueError:
        raise ArgumentError(f"{what}: expected a number in m, got {text!r}") from None
    return _size(value, what)


def parse_positive(text: str, what: str) -> float:
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise ArgumentError(f"{what}: expected a number, got {text!r}") from None
    return _finite_positive(value, what)


def parse_shapes(items):
    """``["sine", "ricker-sym"]`` or ``["all"]`` (commas allowed) -> tuple of shape names."""
    if not items:
        return None
    from pulses import SHAPES

    names = []
    for item in items:
        for name in str(item).replace(",", " ").split():
            if name == "all":
                names.extend(SHAPES)
            elif name in SHAPES:
                names.append(name)
            else:
                raise ArgumentError(f"unknown pulse shape {name!r}; choose from {', '.join(SHAPES)} or all")
    return tuple(dict.fromkeys(names))


def output_folder(path, what: str = "--out") -> pathlib.Path:
    """An output folder, created if needed and checked writable before any work is done."""
    from .reports.cells import display

    if path is None or not str(path).strip():  # pathlib would make "" the current folder
        raise ArgumentError(f"{what}: an empty folder name; name a folder (. for this one)")
    out = pathlib.Path(path)
    if os.path.lexists(out) and not out.is_dir():
        raise ArgumentError(f"{what} {display(out)} exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(dir=out, prefix=".pipeline-probe.")
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise ArgumentError(f"{what} {display(out)} is not a folder this command can write to: "
                            f"{exc.strerror or exc}") from None
    return out


def parse_restitution(text, what: str = "--restitution"):
    """A :class:`rocking.restitution.Restitution` from ``0.97``, ``0.95:1.05`` (factors of Eq. 5),
    ``eta=0.9`` (the velocity ratio) or ``r=0.81`` (the energy ratio); None when not given."""
    if text is None:
        return None
    from rocking.restitution import Restitution

    try:
        return Restitution.parse(text)
    except ValueError as exc:
        raise ArgumentError(f"{what}: {str(exc).removeprefix('restitution: ')}") from None


#: what ``--restitution`` says in every command's help
