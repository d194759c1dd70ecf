"""The annual rate of failure: a fragility against a hazard curve (docs/risk.md, "Theory").

``lambda_F = integral of P(F | x) |d lambda(x)|``.  Between two points of the curve ``lambda`` is
interpolated linearly in ``log x, log lambda`` (a power law ``lambda_i (x / x_i)^(-k_i)`` on each
interval); with the lognormal fragility ``Phi(ln(x / theta) / beta)`` each interval is then
integrated exactly (:func:`interval_rates`), and any other fragility (a callable) by Gauss-Legendre
quadrature in ``ln x``, 16 nodes per interval.  Below the first point ``lambda`` is held at its
first value: written as ``integral of lambda dP``, that adds ``lambda_0 P(F | x_0)``, the share
reported as ``below_first``.  Above the last point, or past the first zero rate, nothing is added.
OpenQuake's ``classical_damage`` uses a discrete rule instead (:func:`discrete_rate`); the two
differ by a few percent on coarse curves.

Also here: the closed form for a power law, return periods, probabilities in ``N`` years,
survival over an age, and targets written ``2%/50``.

Examples
--------
>>> import numpy as np
>>> from rocking.risk import HazardCurve
>>> from rocking.risk.rate import failure_rate, power_law_rate
>>> x = np.geomspace(1e-3, 10.0, 101)                       # 25 points per decade
>>> curve = HazardCurve("PGA", x, 1e-4 * x ** -2.5, units="g")
>>> r = failure_rate(curve, median=0.5, beta=0.4)
>>> round(r.rate / power_law_rate(1e-4, 2.5, 0.5, 0.4) - 1, 9)
0.0
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

#: Gauss-Legendre nodes per interval for a fragility given as a callable
NODES = 16


def power_law_rate(k0: float, k: float, median: float, beta: float) -> float:
    """``k0 theta^(-k) exp(k^2 beta^2 / 2)``: the rate of failure of the lognormal fragility
    ``(theta, beta)`` under the power-law curve ``lambda(x) = k0 x^(-k)``."""
    return float(k0 * median ** (-k) * math.exp(0.5 * (k * beta) ** 2))


def _positive(curve):
    """The points up to the last positive rate (the curve stops at its first zero)."""
    pos = np.nonzero(curve.rates > 0)[0]
    last = pos[-1] + 1
    return curve.imls[:last], curve.rates[:last]


def interpolate(curve, x):
    """``lambda(x)`` of the curve: log-log between points, the first rate below the first level, 0
    above the last positive rate."""
    xs, ys = _positive(curve)
    x = np.asarray(x, dtype=float)
    with np.errstate(divide="ignore"):
        out = np.exp(np.interp(np.log(x), np.log(xs), np.log(ys)))
    out = np.where(x > xs[-1], 0.0, out)
    return float(out) if out.ndim == 0 else out


def slopes(curve) -> np.ndarray:
    """``k_i``: the power of each interval between positive rates (``lambda ~ x^(-k_i)``)."""
    xs, ys = _positive(curve)
    return -np.diff(np.log(ys)) / np.diff(np.log(xs))


def _ndtr_diff(za, zb):
    """``Phi(zb) - Phi(za)`` for ``za <= zb``, accurately in both tails."""
    from scipy.special import ndtr

    za, zb = np.asarray(za, dtype=float), np.asarray(zb, dtype=float)
    upper = za > 0
    return np.where(upper, ndtr(-za) - ndtr(-zb), ndtr(zb) - ndtr(za))


def interval_rates(curve, median: float, beta: float) -> np.ndarray:
    """The rate of failure contributed by each interval between the curve's positive rates,
    integrated exactly for the lognormal fragility: with ``u = ln x``, ``lambda = c e^(-k u)``,

        integral of Phi((u - mu)/beta) k c e^(-k u) du
          = [lambda Phi]_b^a + c exp(-k mu + k^2 beta^2 / 2) [Phi((u - mu + k beta^2)/beta)]_a^b.
    """
    from scipy.special import ndtr

    xs, ys = _positive(curve)
    a, b = np.log(xs[:-1]), np.log(xs[1:])
    k = -np.diff(np.log(ys)) / (b - a)
    mu = math.log(median)
    za, zb = (a - mu) / beta, (b - mu) / beta
    first = ys[:-1] * ndtr(za) - ys[1:] * ndtr(zb)
    log_c = np.log(ys[:-1]) + k * a
    shift = k * beta
    with np.errstate(over="ignore", under="ignore"):
        second = np.exp(log_c - k * mu + 0.5 * shift * shift) * _ndtr_diff(za + shift, zb + shift)
    second = np.where(k > 0, second, 0.0)       # a flat interval adds nothing
    return np.maximum(first + second, 0.0)


def interval_rates_numeric(curve, probability) -> np.ndarray:
    """The same for any fragility ``probability(x)`` (vectorised), by Gauss-Legendre quadrature in
    ``ln x`` with :data:`NODES` nodes per interval."""
    xs, ys = _positive(curve)
    a, b = np.log(xs[:-1]), np.log(xs[1:])
    k = -np.diff(np.log(ys)) / (b - a)
    t, w = np.polynomial.legendre.leggauss(NODES)
    half = 0.5 * (b - a)
    u = (0.5 * (a + b))[:, None] + half[:, None] * t[None, :]
    lam = ys[:-1, None] * np.exp(-k[:, None] * (u - a[:, None]))
    p = np.asarray(probability(np.exp(u)), dtype=float)
    return np.sum(w[None, :] * p * k[:, None] * lam, axis=1) * half


@dataclass
class FailureRate:
    """The rate of failure of one fragility at one site (:func:`failure_rate`).

    Attributes
    ----------
    rate : float
        ``lambda_F``, per year.
    below_first : float
        The part of :attr:`rate` from below the curve's first level (``lambda_0 P(F | x_0)``).
    lows, highs, contributions : ndarray
        Each interval of the curve and the rate it contributes (the disaggregation by the measure).
    method : str
        How the intervals were integrated.
    above_last : float
        What the curve leaves out above its last positive rate, at most: ``lambda_N P(F | x_N)``
        (not in :attr:`rate`; small where the curve reaches levels the column fails at anyway).
    """

    rate: float
    below_first: float
    lows: np.ndarray = field(repr=False)
    highs: np.ndarray = field(repr=False)
    contributions: np.ndarray = field(repr=False)
    method: str = "log-log interpolation, exact per interval"
    above_last: float = 0.0

    @property
    def below_first_share(self) -> float:
        """Share of the rate from below the first level (0 where the rate is 0)."""
        return self.below_first / self.rate if self.rate > 0 else 0.0

    @property
    def return_period(self) -> float:
        """``1 / rate``, years (inf for a zero rate)."""
        return return_period(self.rate)

    def probability_in(self, years: float) -> float:
        """``1 - exp(-rate years)``: probability of at least one failure in ``years``."""
        return probability_in(self.rate, years)

    def survival(self, age: float) -> float:
        """``exp(-rate age)``: probability of standing through ``age`` years."""
        return survival(self.rate, age)

    def bands(self, edges):
        """Shares of the rate per band ``[edges[j], edges[j+1])`` of the measure (the share below
        the first level goes to the band holding it), summing to 1 over bands covering the curve."""
        edges = np.asarray(edges, dtype=float)
        out = np.zeros(edges.size - 1)
        mids = np.sqrt(self.lows * self.highs)
        idx = np.clip(np.searchsorted(edges, mids, side="right") - 1, 0, out.size - 1)
        np.add.at(out, idx, self.contributions)
        first = np.clip(np.searchsorted(edges, self.lows[0], side="right") - 1, 0, out.size - 1)
        out[first] += self.below_first
        return out / self.rate if self.rate > 0 else out


def failure_rate(curve, median=None, beta=None, *, probability=None) -> FailureRate:
    """``lambda_F`` of a lognormal fragility (``median``, ``beta``) or of any ``probability(x)``
    against ``curve`` (a :class:`rocking.risk.HazardCurve`; the fragility in its measure and
    units)."""
    xs, ys = _positive(curve)
    if probability is None:
        if not (median is not None and median > 0 and beta is not None and beta > 0):
            raise ValueError("failure_rate: give a lognormal fragility's median > 0 and beta > 0, "
                             "or probability=")
        contrib = interval_rates(curve, float(median), float(beta))
        from scipy.special import ndtr

        p0 = float(ndtr(math.log(xs[0] / median) / beta))
        pn = float(ndtr(math.log(xs[-1] / median) / beta))
        method = "log-log interpolation, exact per interval (lognormal)"
    else:
        contrib = interval_rates_numeric(curve, probability)
        p0, pn = (float(v) for v in np.asarray(probability(np.array([xs[0], xs[-1]])), dtype=float))
        method = f"log-log interpolation, Gauss-Legendre ({NODES} nodes per interval)"
    below = float(ys[0] * p0)
    return FailureRate(float(contrib.sum() + below), below, xs[:-1], xs[1:], contrib, method,
                       float(ys[-1] * pn))


def discrete_rate(curve, probability) -> float:
    """OpenQuake's discrete rule, for comparison: the rate of occurrence of each level (between the
    midpoints of its neighbours, the first from the first level, the last to the last) times
    ``probability`` at the level."""
    xs, ys = _positive(curve)
    mids = np.sqrt(xs[1:] * xs[:-1])
    lam = np.concatenate([[ys[0]], interpolate(curve, mids), [0.0]])
    occ = lam[:-1] - lam[1:]
    return float(np.sum(occ * np.asarray(probability(xs), dtype=float)))


# -- what follows from a rate -------------------------------------------------------------------
def return_period(rate: float) -> float:
    return math.inf if rate <= 0 else 1.0 / rate


def probability_in(rate: float, years: float) -> float:
    """``1 - exp(-rate years)`` (Poisson)."""
    return float(-math.expm1(-rate * years))


def survival(rate: float, age: float) -> float:
    """``exp(-rate age)``: the probability of having stood ``age`` years."""
    return float(math.exp(-rate * age))


_POE = re.compile(r"^\s*([0-9.eE+-]+)\s*(%?)\s*/\s*([0-9.eE+-]+)\s*(?:y|yr|yrs|years?)?\s*$")


def parse_poe(text) -> tuple[float, float]:
    """``(probability, years)`` of ``"2%/50"``, ``"0.02/50"`` or ``"10% / 50 years"``; one-line
    :class:`ValueError` otherwise."""
    m = _POE.match(str(text))
    try:
        p, years = float(m.group(1)), float(m.group(3))
    except (AttributeError, ValueError):
        raise ValueError(f"target probability: expected P%/N (e.g. 2%/50: 2 % in 50 years), got "
                         f"{text!r}") from None
    if m.group(2):
        p /= 100.0
    if not (0.0 < p < 1.0 and math.isfinite(years) and years > 0):
        raise ValueError(f"target probability {text!r}: the probability must lie between 0 and "
                         "100 % and the years be positive")
    return p, years


def rate_for(probability: float, years: float) -> float:
    """The annual rate whose probability in ``years`` is ``probability``: ``-ln(1 - p) / N``."""
    return float(-math.log1p(-probability) / years)
