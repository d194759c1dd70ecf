"""How good a lognormal fragility is: its fit to the critical values and its sampling uncertainty.

:func:`goodness_of_fit`
    Kolmogorov-Smirnov's distance ``D`` between the records' critical values and the fitted
    lognormal (over the values below the censoring level: a record that did not fail is only known
    to lie above it), and the p-value of ``D`` by a parametric bootstrap: samples of the same size
    drawn from the fit, censored where the records were, refitted, ``D`` again (Lilliefors' idea:
    the tabulated KS p-value would be far too kind to a curve fitted to the same values).
:func:`bootstrap`
    The fit repeated on resamplings of the records with replacement: the medians and betas a
    different suite of the same kind could have given (the band of the rate in the reports).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GoodnessOfFit:
    """``ks``: Kolmogorov-Smirnov distance; ``p_value``: its parametric-bootstrap p-value (small:
    the lognormal does not describe the critical values); ``n_boot``: samples drawn."""

    ks: float
    p_value: float
    n_boot: int


def _ks(values, censored_at, median, beta):
    """KS distance between the empirical distribution (censored records counted in ``n`` but never
    as failed) and the lognormal, over the failed values."""
    from scipy.special import ndtr

    x = np.sort(values[np.isfinite(values)])
    n = values.size
    if x.size == 0:
        return 0.0
    cdf = ndtr(np.log(x / median) / beta)
    upper = np.arange(1, x.size + 1) / n
    lower = np.arange(0, x.size) / n
    return float(max(np.max(upper - cdf), np.max(cdf - lower)))


def _fit_censored(values, cens):
    from ..fragility import _censored_mle

    done = np.isfinite(values)
    logs = np.log(values[done])
    if logs.size < 2:
        raise ValueError("fewer than two failures")
    mu, beta = float(logs.mean()), float(logs.std())
    if done.all():
        return float(np.exp(mu)), beta
    mu, beta = _censored_mle(logs, np.log(cens[~done]), mu, max(beta, 1e-3))
    return float(np.exp(mu)), float(beta)


def _censor_levels(f):
    """The censoring level of each entry of ``f.values`` (inf for those that failed)."""
    levels = np.full(f.values.size, np.inf)
    levels[~np.isfinite(f.values)] = f.censored_at
    return levels


def goodness_of_fit(f, n_boot: int = 200, seed: int = 0) -> GoodnessOfFit:
    """Kolmogorov-Smirnov distance of the fit ``f`` (a :class:`rocking.Fragility`) and its
    parametric-bootstrap p-value over ``n_boot`` samples (``seed``: reproducible)."""
    levels = _censor_levels(f)
    d = _ks(f.values, levels, f.median, f.beta)
    rng = np.random.default_rng(seed)
    worse, drawn = 0, 0
    for _ in range(int(n_boot)):
        sample = f.median * np.exp(f.beta * rng.standard_normal(f.values.size))
        sample = np.where(sample > levels, np.inf, sample)
        try:
            m, b = _fit_censored(sample, levels)
        except ValueError:
            continue
        drawn += 1
        worse += _ks(sample, levels, m, b) >= d
    return GoodnessOfFit(d, (worse + 1) / (drawn + 1), drawn)


def bootstrap(f, n: int = 200, seed: int = 0):
    """``(medians, betas)`` of the lognormal refitted to ``n`` resamplings of ``f``'s records with
    replacement (resamplings with fewer than two failures, or all alike, are left out)."""
    levels = _censor_levels(f)
    rng = np.random.default_rng(seed)
    medians, betas = [], []
    for _ in range(int(n)):
        idx = rng.integers(0, f.values.size, f.values.size)
        v, c = f.values[idx], levels[idx]
        try:
            m, b = _fit_censored(v, c)
        except ValueError:
            continue
        if b > 1e-6:
            medians.append(m)
            betas.append(b)
    return np.array(medians), np.array(betas)
