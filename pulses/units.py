"""Units of ground acceleration accepted for records (docs/theory.md section 7).

Acceleration is carried in m/s^2 inside the package.  A record's units come from its header where
the format states them and from the user otherwise; they are never guessed.
"""
from __future__ import annotations

import math

from .errors import RecordError

#: g, m/s^2: the value of the paper the design rules come from (Makris & Vassiliou 2012), used
#: wherever the package turns g into m/s^2 or back: samples given in g, ``ap`` and PGA in g,
#: ``ap / (g tan alpha)`` and ``p = sqrt(3 g / 4 R)``.  Standard gravity is 9.80665 m/s^2 (0.03 %
#: less): an acceleration in g made here from m/s^2 is 0.03 % below one made with it (docs/theory.md)
G = 9.81

#: accepted spellings -> factor to m/s^2
ACCELERATION_UNITS = {
    "g": G,
    "m/s2": 1.0, "m/s^2": 1.0, "m/s**2": 1.0, "mps2": 1.0,
    "cm/s2": 0.01, "cm/s^2": 0.01, "cm/sec2": 0.01, "cm/sec^2": 0.01, "gal": 0.01,
    "mm/s2": 1e-3, "mm/s^2": 1e-3,
    "nm/s2": 1e-9, "nm/s^2": 1e-9,
}

#: canonical names, in the order messages suggest them
CANONICAL_UNITS = ("g", "m/s2", "cm/s2", "mm/s2", "nm/s2")

#: a peak outside [PLAUSIBLE_MIN_G, PLAUSIBLE_MAX_G] (in g) makes the stated units implausible
PLAUSIBLE_MIN_G = 1e-5
PLAUSIBLE_MAX_G = 10.0
#: a peak above this (in g) is kept but reported as a warning
WARN_PEAK_G = 5.0


def unit_factor(units: str) -> float:
    """Factor that turns a value in ``units`` into m/s^2.

    Parameters
    ----------
    units : str
        One of ``g``, ``m/s2``, ``cm/s2`` (``gal``), ``mm/s2``, ``nm/s2`` (``^2`` spellings too).

    Raises
    ------
    RecordError
        For an unknown or non-acceleration unit.
    """
    key = str(units).strip().lower().replace(" ", "")
    if key in ACCELERATION_UNITS:
        return ACCELERATION_UNITS[key]
    if key in ("m/s", "cm/s", "mm/s", "nm/s", "m", "cm", "mm", "nm", "in/s", "in"):
        raise RecordError(f"units {units!r} are velocity or displacement; records must be ground "
                          f"acceleration (g, m/s2, cm/s2, gal)")
    raise RecordError(f"unknown acceleration units {units!r}; use one of g, m/s2, cm/s2, gal, mm/s2, nm/s2")


def canonical_units(units: str) -> str:
    """The canonical spelling of ``units`` (``"gal"`` -> ``"cm/s2"``)."""
    factor = unit_factor(units)
    for name in CANONICAL_UNITS:
        if ACCELERATION_UNITS[name] == factor:
            return name
    return str(units)


def implausible_peak(raw_peak: float, units: str, where: str) -> str | None:
    """Why a record whose largest sample is ``raw_peak`` in ``units`` is no accelerogram (its peak
    outside :data:`PLAUSIBLE_MIN_G` to :data:`PLAUSIBLE_MAX_G`), naming the units that would make
    it one; None where it is plausible.  ``where``: how the units came ("given", "stated in the
    file", "assumed")."""
    peak_g = raw_peak * unit_factor(units) / G
    if PLAUSIBLE_MIN_G <= peak_g <= PLAUSIBLE_MAX_G:
        return None
    options = [(u, pg) for u, pg in plausible_units(raw_peak) if u != units]
    listed = " or ".join(f"{u} (peak {pg:.2g} g)" for u, pg in options)
    fix = (f"if the samples are in {listed}, pass units='{options[0][0]}' (--units {options[0][0]})"
           if options else "no acceleration units make it plausible")
    return (f"peak {raw_peak:.4g} {units} ({where}) is {peak_g:.3g} g, implausible for an accelerogram "
            f"(outside {PLAUSIBLE_MIN_G:g} to {PLAUSIBLE_MAX_G:g} g); {fix}")


def plausible_units(peak_raw: float) -> list[tuple[str, float]]:
    """Units under which a raw peak value would be a plausible accelerogram peak.

    Returns ``(units, peak in g)`` pairs for the canonical units that put the peak between 1e-3 g
    and 5 g (a range every real strong-motion record falls in), the likeliest (peak nearest
    0.3 g) first.
    """
    out = []
    for name in CANONICAL_UNITS:
        peak_g = peak_raw * ACCELERATION_UNITS[name] / G
        if 1e-3 <= peak_g <= WARN_PEAK_G:
            out.append((name, peak_g))
    # most likely first: the peak nearest 0.3 g (on a log scale), typical of strong motion
    return sorted(out, key=lambda item: abs(math.log10(item[1] / 0.3)))
