"""The restitution from a free-rocking test (docs/theory.md, "Restitution from a test").

A block released from a tilt rocks freely: between impacts its energy
``E = 1/2 I_o theta'^2 + m g R [cos(alpha - |theta|) - cos(alpha)]`` is conserved, and each impact
multiplies it by ``r = eta^2`` (all of it is kinetic at ``theta = 0``).  So the energies at
successive peaks (``theta' = 0``), ``E_n ~ cos(alpha - |theta_n|) - cos(alpha)``, fall as
``E_n = E_0 r^n``, whatever the body's shape: :func:`fit_restitution` fits ``log E_n`` against
``n`` by least squares (``method="peaks"``, needs ``alpha``).  Or, from the angular velocities
on either side of each impact, ``eta_i = |theta'_+| / |theta'_-|`` (``method="impacts"``: local
polynomial fits of the rotation on each side, no ``alpha`` needed; it asks for a finer sampling
than the peaks do).  The uncertainty is the fit's standard error (peaks) or the standard error of
the mean of the impacts' values.

Examples
--------
>>> import rocking
>>> block = rocking.Block.from_dimensions(1.0, 0.25, eta=0.85)
>>> test = rocking.simulate(block, None, theta0=0.8 * block.alpha, duration=8.0)
>>> fit = rocking.fit_restitution(test.t, test.theta, alpha=block.alpha)
>>> round(fit.eta, 4), fit.method
(0.85, 'peaks')
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: peaks within this share of the largest are left out: their energy is lost in the noise and
#: the last hops of a block coming to rest are barely resolved by the sampling
MIN_PEAK_SHARE = 0.02
#: samples on each side of a peak (or an impact) fitted by a polynomial, at least
WINDOW = 5
#: a peak's fit takes the samples down to this share of its height
PEAK_SPAN = 0.7
#: samples fitted on each side of an impact (a velocity needs more of them than a peak's height)
IMPACT_WINDOW = 12
#: degree of those fits: near ``theta = 0`` the acceleration is almost constant (``p^2 sin alpha``)
IMPACT_DEGREE = 2
#: a half-cycle counts where its peak rises above this many times the noise
MIN_PEAK_NOISE = 10.0


@dataclass
class RestitutionFit:
    """The restitution fitted to a free-rocking record.

    Attributes
    ----------
    eta, eta_std : float
        The velocity ratio at impact and its standard error.
    r, r_std : float
        The energy ratio ``eta^2`` and its standard error.
    method : str
        ``"peaks"`` (decay of the peaks' energies) or ``"impacts"`` (velocities at impacts).
    n : int
        Impacts the fit rests on.
    values : ndarray
        Each impact's own ``eta`` (successive peaks' energy ratio, or velocity ratio).
    times : ndarray
        Times (s) of the peaks (or impacts) used.

    Examples
    --------
    >>> import rocking
    >>> block = rocking.Block.from_dimensions(1.0, 0.25, eta=0.9)
    >>> test = rocking.simulate(block, None, theta0=0.7 * block.alpha, duration=10.0)
    >>> fit = rocking.fit_restitution(test.t, test.theta, alpha=block.alpha)
    >>> round(fit.r, 4), fit.as_restitution(band=None)
    (0.81, Restitution('eta=0.9'))
    """

    eta: float
    eta_std: float
    r: float
    r_std: float
    method: str
    n: int
    values: np.ndarray = field(repr=False)
    times: np.ndarray = field(repr=False)

    def factor(self, alpha: float, body=None) -> float:
        """``eta`` over Housner's rule of the body (Eq. 5 for the rectangle) at ``alpha``."""
        from .bodies import Body

        return self.eta / Body.parse(body).eta_housner(alpha)

    def as_restitution(self, band: float | None = 2.0):
        """The fit as a design input (:class:`rocking.restitution.Restitution`, an ``eta``): the
        band ``eta +- band x eta_std`` (clipped to [0, 1]), or the value alone for ``band=None``."""
        from .restitution import Restitution

        if band is None or self.eta_std == 0.0:
            return Restitution(self.eta, kind="eta")
        lo = max(0.0, self.eta - band * self.eta_std)
        hi = min(1.0, self.eta + band * self.eta_std)
        return Restitution(lo, hi, kind="eta")


def fit_restitution(t, theta, alpha: float | None = None, *, method: str = "peaks",
                    noise: float | None = None) -> RestitutionFit:
    """The coefficient of restitution of a block from a free-rocking record of its rotation.

    Parameters
    ----------
    t, theta : array_like
        Times (s, increasing) and rotation (rad) of the free rocking (released from a tilt, no
        ground motion), as a test measures them.
    alpha : float, optional
        The body's slenderness (rad); needed by ``method="peaks"``.
    method : {"peaks", "impacts"}
        The decay of successive peaks' energies (default), or the angular velocities just before
        and after each impact (module docstring).
    noise : float, optional
        Standard deviation of the rotation's noise (rad); estimated from the record where not
        given.  A half-cycle must rise above 5 times it to count.

    Returns
    -------
    RestitutionFit

    Examples
    --------
    >>> import rocking
    >>> block = rocking.Block.from_dimensions(1.0, 0.25, eta=0.8)
    >>> test = rocking.simulate(block, None, theta0=0.8 * block.alpha, duration=6.0)
    >>> fit = rocking.fit_restitution(test.t, test.theta, alpha=block.alpha)
    >>> round(fit.eta, 4), fit.n >= 3
    (0.8, True)
    """
    t, theta = np.asarray(t, dtype=float).ravel(), np.asarray(theta, dtype=float).ravel()
    if t.size != theta.size or t.size < 4 * WINDOW or not np.all(np.diff(t) > 0):
        raise ValueError("fit_restitution: t and theta of the same length, t increasing, at least "
                         f"{4 * WINDOW} samples")
    if not np.all(np.isfinite(theta)):
        raise ValueError("fit_restitution: theta must be finite")
    if method not in ("peaks", "impacts"):
        raise ValueError(f"fit_restitution: method must be 'peaks' or 'impacts', got {method!r}")
    sigma = _noise(theta) if noise is None else float(noise)
    cycles = _half_cycles(theta, 5.0 * sigma)
    top = max((float(np.max(np.abs(theta[a:b + 1]))) for a, b in cycles), default=0.0)
    floor = max(MIN_PEAK_SHARE * top, MIN_PEAK_NOISE * sigma)
    if method == "peaks":
        if alpha is None or not (0.0 < float(alpha) < math.pi / 2):
            raise ValueError("fit_restitution: method='peaks' needs the body's alpha (rad)")
        return _fit_peaks(t, theta, cycles, float(alpha), floor)
    return _fit_impacts(t, theta, cycles, floor)


def _noise(theta) -> float:
    """The noise's standard deviation, from the third differences (smooth motion has almost none:
    each is ~ sqrt(20) sigma of white noise), by their median absolute value."""
    d3 = np.diff(theta, 3)
    return float(np.median(np.abs(d3)) / 0.6745 / math.sqrt(20.0))


def _half_cycles(theta, band):
    """``[(first, last)]`` index ranges of the half-cycles: runs of one sign that rise above
    ``band`` (noise near ``theta = 0`` does not split a half-cycle)."""
    above = np.flatnonzero(np.abs(theta) > band)
    if above.size == 0:
        return []
    sign = np.sign(theta[above])
    cut = np.flatnonzero(sign[1:] != sign[:-1]) + 1
    groups = np.split(above, cut)
    return [(int(g[0]), int(g[-1])) for g in groups]


def _peak(t, theta, lo, hi):
    """``(t, |theta|)`` of the peak of a half-cycle: a quartic fitted to the samples about its
    largest one down to :data:`PEAK_SPAN` of it (at least :data:`WINDOW` each side): the peaks of
    free rocking are ``alpha - A cosh(p t)``, which a quadratic fits only near the top, and a
    window set by height, not by the noisy largest sample, keeps the noise from lifting it."""
    seg = np.abs(theta[lo:hi + 1])
    k = int(np.argmax(seg))
    high = seg >= PEAK_SPAN * seg[k]
    a, b = k, k
    while a > 0 and high[a - 1]:
        a -= 1
    while b < seg.size - 1 and high[b + 1]:
        b += 1
    a, b = min(a, max(0, k - WINDOW)), max(b, min(seg.size - 1, k + WINDOW))
    if b - a < 4:
        return float(t[lo + k]), float(seg[k])
    x = t[lo + a:lo + b + 1] - t[lo + k]
    scale = max(abs(x[0]), abs(x[-1]))          # fitted in x / scale: well conditioned
    poly = np.polyfit(x / scale, seg[a:b + 1], 4 if b - a >= 8 else 2)
    fine = np.linspace(x[0], x[-1], 8 * (b - a) + 1)
    vals = np.polyval(poly, fine / scale)
    j = int(np.argmax(vals))
    return float(t[lo + k] + fine[j]), float(vals[j])


def _fit_peaks(t, theta, cycles, alpha, floor) -> RestitutionFit:
    peaks = [_peak(t, theta, lo, hi) for lo, hi in cycles]
    # consecutive half-cycles only: the fit counts one impact between two peaks
    kept = []
    for pk in peaks:
        if pk[1] < floor:
            break
        kept.append(pk)
    tp = np.array([p[0] for p in kept])
    amp = np.minimum(np.array([p[1] for p in kept]), alpha)
    energy = np.cos(alpha - amp) - math.cos(alpha)
    if energy.size < 3:
        raise ValueError(f"fit_restitution: {energy.size} peaks above the noise; at least 3 "
                         "(two impacts) are needed")
    n = np.arange(energy.size, dtype=float)
    logs = np.log(energy)
    # weights: 1 / the standard deviation of log E_n that a noise on the peak's height gives
    # (d log E / d theta = sin(alpha - theta) / E; the noise's own size scales them all alike)
    weights = energy / np.maximum(np.sin(alpha - amp), 1e-9)
    (slope, icpt), cov = np.polyfit(n, logs, 1, w=weights, cov=True)
    r = math.exp(slope)
    slope_std = math.sqrt(max(cov[0, 0], 0.0))
    eta = math.sqrt(r)
    values = np.sqrt(energy[1:] / energy[:-1])
    return RestitutionFit(eta, 0.5 * eta * slope_std, r, r * slope_std, "peaks",
                          int(energy.size - 1), values, tp)


def _fit_impacts(t, theta, cycles, floor) -> RestitutionFit:
    vb_all, va_all, times = [], [], []
    for (a0, a1), (b0, b1) in zip(cycles[:-1], cycles[1:]):
        if max(np.max(np.abs(theta[a0:a1 + 1])), np.max(np.abs(theta[b0:b1 + 1]))) < floor:
            break
        if b0 - a1 > 2 * WINDOW:       # the block rested between: not one impact
            continue
        before = slice(max(a0, a1 - IMPACT_WINDOW + 1), a1 + 1)
        after = slice(b0, min(b1, b0 + IMPACT_WINDOW - 1) + 1)
        if before.stop - before.start < 5 or after.stop - after.start < 5:
            continue
        t0 = 0.5 * (t[a1] + t[b0])                 # fitted about the impact: well conditioned
        pb = np.polyfit(t[before] - t0, theta[before], IMPACT_DEGREE)
        pa = np.polyfit(t[after] - t0, theta[after], IMPACT_DEGREE)
        tc = _crossing(pb, pa, t[a1] - t0, t[b0] - t0)
        vb_all.append(np.polyval(np.polyder(pb), tc))
        va_all.append(np.polyval(np.polyder(pa), tc))
        times.append(t0 + tc)
    if len(vb_all) < 2:
        raise ValueError("fit_restitution: fewer than 2 impacts resolved; sample the rotation "
                         "more finely or use method='peaks'")
    vb, va = np.array(vb_all), np.array(va_all)
    # least squares through the origin, v_after = eta v_before: the fast impacts weigh most
    eta = float(np.dot(va, vb) / np.dot(vb, vb))
    resid = va - eta * vb
    std = float(math.sqrt(np.dot(resid, resid) / (vb.size - 1) / np.dot(vb, vb)))
    return RestitutionFit(eta, std, eta * eta, 2.0 * eta * std, "impacts", int(vb.size),
                          va / vb, np.array(times))


def _crossing(pb, pa, lo, hi) -> float:
    """The impact's time: where the fit before it reaches 0, between the last sample before it
    and the first after (the midpoint of the gap where it does not)."""
    roots = [x.real for x in np.roots(pb) if abs(x.imag) < 1e-12 and lo <= x.real <= hi]
    if roots:
        return float(min(roots))
    roots = [x.real for x in np.roots(pa) if abs(x.imag) < 1e-12 and lo <= x.real <= hi]
    return float(roots[0]) if roots else 0.5 * (lo + hi)
