"""A hazard curve: the annual rate at which an intensity measure exceeds each level at a site.

:class:`HazardCurve` holds what every reader of :mod:`rocking.risk.formats` returns: the measure
(``PGA``, ``PGV`` or ``SA(T)``), its units, the levels and their annual rates of exceedance, and
where the curve came from.  It is checked when made: a curve that is not one (a single point,
levels that do not rise, rates that rise with the level, negative or NaN values) is refused with
a one-line :class:`HazardError` that says what is wrong, and so is a curve whose measure or units
are not stated.  Levels are kept in the package's units of each measure (g for PGA and SA, cm/s
for PGV, as OpenQuake and the USGS give them); a curve in other units is converted once, here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pulses.intensity import UNITS, measure_name, parse_measure

#: units accepted for each kind of measure, and their factor to the package's unit
_TO_PACKAGE = {
    "g": {"g": 1.0, "m/s2": 1.0 / 9.80665, "m/s^2": 1.0 / 9.80665, "cm/s2": 0.01 / 9.80665,
          "cm/s^2": 0.01 / 9.80665, "gal": 0.01 / 9.80665},
    "cm/s": {"cm/s": 1.0, "m/s": 100.0, "mm/s": 0.1},
}


class HazardError(ValueError):
    """A hazard curve that cannot be used, or a file that does not give one (one line)."""


def to_package_units(measure: str, units: str) -> float:
    """The factor from ``units`` to the package's unit of ``measure`` (g, or cm/s for PGV);
    :class:`HazardError` for units that do not fit the measure."""
    name, _ = parse_measure(measure)
    unit = UNITS[name]
    key = str(units).strip().lower().replace(" ", "").replace("sec", "s")
    factors = _TO_PACKAGE[unit]
    if key not in factors:
        raise HazardError(f"units {units!r} do not fit {measure}: expected one of "
                          f"{', '.join(sorted(factors))}")
    return factors[key]


@dataclass(frozen=True)
class HazardCurve:
    """Annual rates of exceedance of an intensity measure at a site.

    Parameters
    ----------
    measure : str
        ``"PGA"``, ``"PGV"`` or ``"SA(T)"`` (T in s); other spellings (``SA1P0``) are read.
    imls : array_like
        The levels, rising, in ``units``.
    rates : array_like
        Annual rate at which the measure exceeds each level (not increasing; zeros after the last
        positive rate are kept: the curve stops there).
    units : str
        Units of ``imls``: ``g``, ``m/s2``, ``cm/s2`` for PGA and SA; ``cm/s``, ``m/s`` for PGV.
        The curve keeps them in g (cm/s for PGV).
    source : str
        Where the curve came from (a file and its format), for the reports.
    site : (float, float) or None
        Longitude and latitude, where the file gives them.
    investigation_time : float or None
        The file's investigation time (years) where its values were probabilities.

    Examples
    --------
    >>> from rocking.risk import HazardCurve
    >>> c = HazardCurve("SA1P0", [0.1, 0.2, 0.4], [1e-2, 3e-3, 5e-4], units="g")
    >>> c.measure, c.period, c.units
    ('SA(1.0)', 1.0, 'g')
    >>> HazardCurve("PGA", [0.1, 0.2], [1e-3, 2e-3], units="g")
    Traceback (most recent call last):
    ...
    rocking.risk.curve.HazardError: hazard curve (PGA): the rates rise with the level (0.002 at 0.2 after 0.001 at 0.1); a rate of exceedance cannot grow with the level
    """

    measure: str
    imls: np.ndarray = field(repr=False)
    rates: np.ndarray = field(repr=False)
    units: str = ""
    source: str = ""
    site: tuple | None = None
    investigation_time: float | None = None

    def __post_init__(self):
        who = f"hazard curve{f' {self.source}' if self.source else ''}"
        if self.measure is None or not str(self.measure).strip():
            raise HazardError(f"{who}: the intensity measure is not stated (give it: PGA, PGV or SA(T))")
        try:
            name, period = parse_measure(self.measure)
        except ValueError as exc:
            raise HazardError(f"{who}: {exc}") from None
        canon = measure_name(name, period)
        if self.units is None or not str(self.units).strip():
            raise HazardError(f"{who} ({canon}): the units of the levels are not stated (give them: "
                              f"{', '.join(sorted(_TO_PACKAGE[UNITS[name]]))})")
        factor = to_package_units(canon, self.units)
        imls, rates = _arrays(self.imls, self.rates, f"{who} ({canon})")
        object.__setattr__(self, "measure", canon)
        object.__setattr__(self, "imls", imls * factor)
        object.__setattr__(self, "rates", rates)
        object.__setattr__(self, "units", UNITS[name])

    @property
    def name(self) -> str:
        """``PGA``, ``PGV`` or ``SA``."""
        return parse_measure(self.measure)[0]

    @property
    def period(self) -> float | None:
        """The oscillator period of ``SA(T)``, s (None for PGA and PGV)."""
        return parse_measure(self.measure)[1]

    @property
    def n(self) -> int:
        return int(self.imls.size)

    def rate_at(self, x):
        """``lambda(x)``, log-log interpolated between the points (held at the first rate below the
        first level, 0 above the last level or past the first zero rate)."""
        from .rate import interpolate

        return interpolate(self, x)

    def level_at(self, rate: float) -> float | None:
        """The level exceeded at ``rate`` per year (log-log interpolation); None outside the curve."""
        pos = self.rates > 0
        x, y = self.imls[pos], self.rates[pos]
        if not (y[-1] <= rate <= y[0]):
            return None
        return float(np.exp(np.interp(-math.log(rate), -np.log(y), np.log(x))))

    def describe(self) -> str:
        """``SA(1.0) in g, 20 levels 0.005-7.38, rates 5.6e-04-1.3e-10 per year (file.csv, OpenQuake)``."""
        pos = self.rates[self.rates > 0]
        text = (f"{self.measure} in {self.units}, {self.n} levels {self.imls[0]:.4g}-{self.imls[-1]:.4g}, "
                f"rates {pos[0]:.2g}-{pos[-1]:.2g} per year")
        return text + (f" ({self.source})" if self.source else "")

    def as_dict(self) -> dict:
        from pulses.export import plain

        return plain({"measure": self.measure, "units": self.units, "imls": self.imls,
                      "rates": self.rates, "source": self.source, "site": self.site,
                      "investigation_time": self.investigation_time})


def _arrays(imls, rates, who):
    try:
        x = np.asarray(imls, dtype=float).ravel()
        y = np.asarray(rates, dtype=float).ravel()
    except (TypeError, ValueError):
        raise HazardError(f"{who}: levels and rates must be numbers") from None
    if x.size != y.size:
        raise HazardError(f"{who}: {x.size} levels but {y.size} rates")
    if x.size < 2:
        raise HazardError(f"{who}: {x.size} point(s); a curve needs at least two levels")
    for what, v in (("level", x), ("rate", y)):
        bad = ~np.isfinite(v)
        if bad.any():
            raise HazardError(f"{who}: a {what} is not a number ({v[bad][0]!r} at point "
                              f"{int(np.argmax(bad)) + 1})")
    if np.any(x <= 0):
        raise HazardError(f"{who}: the levels must be positive, got {x[x <= 0][0]:g}")
    if np.any(np.diff(x) <= 0):
        i = int(np.argmax(np.diff(x) <= 0))
        raise HazardError(f"{who}: the levels must rise ({x[i + 1]:g} after {x[i]:g})")
    if np.any(y < 0):
        raise HazardError(f"{who}: a rate is negative ({y[y < 0][0]:g})")
    rise = np.diff(y) > 1e-9 * np.maximum(y[:-1], 1e-300)   # a last-digit wobble is no rise
    if rise.any():
        i = int(np.argmax(rise))
        raise HazardError(f"{who}: the rates rise with the level ({y[i + 1]:.3g} at {x[i + 1]:g} "
                          f"after {y[i]:.3g} at {x[i]:g}); a rate of exceedance cannot grow with the level")
    y = np.minimum.accumulate(y)
    if (y > 0).sum() < 2:
        raise HazardError(f"{who}: fewer than two positive rates; the curve says nothing here")
    return x, y


def rates_from_poes(poes, investigation_time, who="hazard curve") -> np.ndarray:
    """Annual rates ``-ln(1 - poe) / T`` of probabilities of exceedance in ``T`` years;
    :class:`HazardError` for a probability outside [0, 1) or a time that is not positive."""
    p = np.asarray(poes, dtype=float)
    t = float(investigation_time) if investigation_time is not None else math.nan
    if not (math.isfinite(t) and t > 0):
        raise HazardError(f"{who}: the investigation time must be a positive number of years, got "
                          f"{investigation_time!r}")
    if np.any(~np.isfinite(p)):
        raise HazardError(f"{who}: a probability is not a number")
    if np.any((p < 0) | (p >= 1)):
        bad = p[(p < 0) | (p >= 1)][0]
        raise HazardError(f"{who}: a probability of exceedance is {bad:g}; it must lie in [0, 1) "
                          "(1 would be an infinite rate)")
    return -np.log1p(-p) / t
