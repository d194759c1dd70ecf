"""Collapse fragility of a rocking column (or frame) as it stands.

:func:`critical_scale`
    The smallest factor ``k`` for which ``k`` times a record overturns the block (incremental
    dynamic analysis reduced to its collapse point), with the safe islands above it.
:func:`fragility`
    Over a suite of records: the lognormal fit of the critical scales (or of the critical PGAs),
    ``P(overturn | x) = Phi(ln(x / median) / beta)``.

Overturning is not monotonic in the scale (a record scaled up can leave the block standing where
a weaker one toppled it), so no plain bisection: a coarse geometric scan of the factors, then
every gap below the first failure is halved down to ``step`` (0.5 %) wherever the block rocked,
and down to ``resolution`` (0.1 %) where it came near tipping (failing slivers of real records
are often that thin), then the first fail bracket is bisected to ``rtol``.  All scans run as
batches of :func:`rocking.simulate_many` (one record, many scales).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pulses import G

from . import scan
from .block import Block
from .search import _failed, _peak, check_limit

#: default largest scale factor examined
UP_TO = 10.0
#: default number of scan factors, geometric from the uplift factor to ``up_to``
N_SCAN = 160
#: gaps between scanned factors (below the first failure) wider than this, relative, are halved
#: while either end came near tipping (``max|theta|/alpha >= NEAR``)
RESOLUTION = 1e-3
#: ... and wider than this wherever either end rocked at all
STEP = 5e-3
#: ``max|theta|/alpha`` at which a surviving run counts as near tipping
NEAR = 0.5
#: relative width to which the first fail bracket is bisected
RTOL = 1e-6
#: at most this many halving rounds (each a batch): 2.3 % gaps reach 1e-3 in 5
MAX_ROUNDS = 40


@dataclass
class CriticalScale:
    """Outcome of :func:`critical_scale`.

    Attributes
    ----------
    scale : float or None
        Smallest factor found to overturn the block (the failing end of the first fail bracket,
        refined to ``rtol``; the factor just below it survives).  None: no factor up to
        :attr:`up_to` overturned it (the critical scale is above ``up_to``).
    islands : list of (float, float)
        Factor ranges above :attr:`scale` where the block survives again, as the scan saw them
        (ends at the midpoints of their brackets, bisected to ``step`` relative).  A last island
        ending at :attr:`up_to` means the block survived from there to the end of the scan.
    up_to : float
        Largest factor examined.
    uplift_scale : float
        Below this factor (``g tan(alpha) / PGA``) the block never uplifts.
    pga : float
        Peak ground acceleration of the unscaled record, m/s^2.
    n_scan, step, resolution, near, rtol : int, float, float, float, float
        The scan settings used (see :func:`critical_scale`).
    runs, calls : int
        Solver runs, and batch-solver calls.
    limit : float or None
        The performance level R (None: overturning): :attr:`scale` is then the smallest factor at
        which ``max|theta|/alpha`` exceeds R (or the block overturns).

    Examples
    --------
    >>> import numpy as np, pulses, rocking
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.3 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> cs = rocking.critical_scale(rocking.Block.from_dimensions(7.5, 1.8), rec, up_to=3.0)
    >>> round(cs.critical_pga / pulses.G, 3)       # the PGA that overturns the column
    0.527
    """

    scale: float | None
    islands: list
    up_to: float
    uplift_scale: float
    pga: float
    n_scan: int
    step: float
    resolution: float
    near: float
    rtol: float
    runs: int
    calls: int
    transitions: tuple = field(default=(), repr=False)
    #: the performance level: the scale at which ``max|theta|/alpha`` first exceeds it (None:
    #: overturning)
    limit: float | None = None

    @property
    def overturns(self) -> bool:
        """Whether some factor up to :attr:`up_to` overturns the block."""
        return self.scale is not None

    @property
    def critical_pga(self) -> float | None:
        """PGA of the critically scaled record, m/s^2 (None when nothing overturned)."""
        return None if self.scale is None else self.scale * self.pga

    def as_dict(self) -> dict:
        """The fields (scale factors, PGA in m/s^2, islands as pairs) and ``critical_pga``: plain,
        JSON-safe."""
        from pulses.export import fields_dict

        return fields_dict(self, properties=("overturns", "critical_pga"))


def critical_scale(block, record, up_to=UP_TO, *, n_scan=N_SCAN, step=STEP,
                   resolution=RESOLUTION, near=NEAR, rtol=RTOL, model="fast",
                   limit=None) -> CriticalScale:
    """Smallest factor ``k <= up_to`` for which ``k`` times ``record`` overturns ``block`` (or,
    with ``limit`` R, makes ``max|theta|/alpha`` exceed R).

    Parameters
    ----------
    block : Block
        The column (or frame, ``Block.from_dimensions(..., cap_mass_ratio=gamma)``) as it stands.
    record : pulses.Record or pulses.Pulse
        Ground acceleration, m/s^2.
    up_to : float
        Largest factor examined (default :data:`UP_TO`).
    n_scan : int
        Factors scanned, geometric from the uplift factor ``g tan(alpha)/PGA`` (below which
        nothing moves) to ``up_to``: 2.3 % apart with the defaults when the uplift factor is 0.25.
    step : float
        Below the first failing factor, every gap between scanned factors wider than this
        (relative) is halved, repeatedly, where the block uplifted at either end; the edges of
        the islands above are bisected to it.
    resolution : float
        ... and every gap wider than this where either end reached ``max|theta|/alpha >= near``
        (or failed).
    near : float
        ``max|theta|/alpha`` from which a surviving run counts as near tipping.
    rtol : float
        Relative width to which the first fail bracket is bisected.
    model : {"fast", "linear"}
        Solver model of :func:`rocking.simulate_many`.
    limit : float, optional
        Performance level R in (0, 1]: a factor fails where ``max|theta|/alpha > R`` (or the block
        overturns); ``near`` is then a share of R.  None (default): overturning.

    Returns
    -------
    CriticalScale
        ``.scale`` (None if nothing up to ``up_to`` overturns), ``.islands`` and the settings.

    Notes
    -----
    A failing band narrower than the gaps around it can be missed (by any finite scan): below the
    answer, gaps are ``resolution`` wide where the block came within ``near`` of tipping and
    ``step`` wide elsewhere; real records have failing slivers thinner than 0.01 % (README
    "Rocking frames and collapse fragility").  ``tests/test_fragility.py`` checks the answer against a 1000-factor brute-force
    scan on three real records.

    Examples
    --------
    >>> import numpy as np, pulses, rocking
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.3 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> cs = rocking.critical_scale(rocking.Block.from_dimensions(7.5, 1.8), rec, up_to=3.0)
    >>> round(cs.scale, 3), cs.overturns
    (1.756, True)
    """
    if not isinstance(block, Block):
        raise TypeError("critical_scale: block must be a rocking.Block")
    up_to = float(up_to)
    _check_settings(up_to, n_scan, step, resolution, near, rtol)
    limit = check_limit(limit)
    pga = _peak(record)
    uplift = block.uplift_acceleration / pga if pga > 0 else math.inf
    settings = dict(up_to=up_to, uplift_scale=uplift, pga=pga, n_scan=int(n_scan),
                    step=float(step), resolution=float(resolution), near=float(near), rtol=float(rtol),
                    limit=limit)
    if not up_to > uplift:
        return CriticalScale(None, [], runs=0, calls=0, **settings)
    pts = scan.Points(_verdicts(block, record, model, limit), uplift)
    # 1. the scan (the uplift factor itself is known: at |ug''| = g tan(alpha) nothing moves)
    pts.add(np.geomspace(uplift, up_to, int(n_scan) + 1)[1:])
    # 2. halve the gaps below the first failure (or everywhere, if none): to `step` where the
    #    block rocked, to `resolution` where it nearly tipped
    scan.refine_gaps(pts, step, resolution, near, MAX_ROUNDS)
    x, f, _ = pts.sorted()
    if not f.any():
        return CriticalScale(None, [], runs=pts.runs, calls=pts.calls, **settings)
    # 3. bisect the first fail bracket (the lowest failure is the one followed) to rtol
    scale = scan.bisect_first(pts, rtol)
    # 4. islands above: every verdict change above the first failure bisected to `step`
    islands, transitions = _islands(pts, scale, step, up_to)
    return CriticalScale(scale, islands, runs=pts.runs, calls=pts.calls,
                         transitions=transitions, **settings)


def _check_settings(up_to, n_scan, step, resolution, near, rtol) -> None:
    if not (math.isfinite(up_to) and up_to > 0):
        raise ValueError(f"critical_scale: up_to must be positive and finite, got {up_to!r}")
    if int(n_scan) != n_scan or n_scan < 2:
        raise ValueError(f"critical_scale: n_scan must be an integer >= 2, got {n_scan!r}")
    for name, value, lo, hi in (("step", step, 0.0, 1.0), ("resolution", resolution, 0.0, 1.0),
                                ("near", near, 0.0, 1.0),
                                ("rtol", rtol, 0.0, 1.0)):
        if not (lo < float(value) <= hi):
            raise ValueError(f"critical_scale: {name} must lie in ({lo:g}, {hi:g}], got {value!r}")


def _verdicts(block, record, model, limit=None):
    """``run(scales) -> (failed, nearness)`` of ``block`` under ``scales`` times ``record``, in
    one batch: failed is overturned (or ``max|theta|/alpha > limit``); a failing run counts as
    near (nearness inf), else ``max|theta|/alpha`` over the level (1 for overturning)."""
    import rocking

    def run(scales):
        res = rocking.simulate_many(block, record, scales, model=model)
        f = _failed(res, "overturn", limit)
        return f, np.where(f, np.inf, np.asarray(res.max_rotation_ratio, dtype=float) / (limit or 1.0))

    return run


def _islands(pts, scale, step, up_to):
    """The failing islands above ``scale`` and the factors where the verdict changes: every change
    above the first failure bisected to ``step``, all together (one batch per halving); each bracket
    keeps the half where the verdict changes."""
    x, f, _ = pts.sorted()
    sel = x >= scale
    x, f = x[sel], f[sel]
    ch = np.nonzero(f[1:] != f[:-1])[0]
    blo, bhi, flo = x[ch], x[ch + 1], f[ch]
    for _ in range(MAX_ROUNDS):
        wide = (bhi - blo) > step * bhi
        if not wide.any():
            break
        mid = 0.5 * (blo[wide] + bhi[wide])
        vm = pts.add(mid)
        lo_w, hi_w = blo[wide], bhi[wide]
        same = vm == flo[wide]                 # the change lies in the upper half
        blo[wide] = np.where(same, mid, lo_w)
        bhi[wide] = np.where(same, hi_w, mid)
    order = np.argsort(blo)
    edges = list(zip(0.5 * (blo[order] + bhi[order]), flo[order]))   # (value, fails below it?)
    islands, start = [], None
    for value, fails_below in edges:
        if fails_below:
            start = value
        elif start is not None:
            islands.append((float(start), float(value)))
            start = None
    if start is not None:
        islands.append((float(start), up_to))
    return islands, tuple(float(v) for v, _ in edges)


# ---------------------------------------------------------------------------------------------
# suite: the lognormal fragility curve
# ---------------------------------------------------------------------------------------------
@dataclass
class Fragility:
    """Lognormal collapse fragility: ``P(overturn | x) = Phi(ln(x / median) / beta)``.

    Attributes
    ----------
    median : float
        Median critical intensity (a scale factor, or a PGA in g; see :attr:`measure`).
    beta : float
        Lognormal dispersion: the standard deviation of ``ln`` of the critical intensities.
    measure : str
        ``"scale"`` (factor on the records), ``"pga"`` (PGA of the scaled record, g), or the
        measure of a hazard curve (``"PGA"``, ``"PGV"`` in cm/s, ``"SA(1.0)"`` in g: the critical
        scale times the measure of the unscaled record, :func:`fragility`'s ``intensities``).
    values : ndarray
        The critical intensities fitted (``inf`` for records that did not overturn up to their
        ``up_to``: right-censored there).
    censored_at : ndarray
        For each censored record, the largest intensity examined.
    limit : float or None
        The performance level of the critical scales (``max|theta|/alpha`` exceeding it; None:
        overturning): ``P(max|theta|/alpha > limit | x)``.

    Examples
    --------
    >>> import rocking
    >>> f = rocking.fragility([1.2, 1.5, 2.0, None], up_to=3.0)
    >>> round(f.probability(f.median), 3)
    0.5
    """

    median: float
    beta: float
    measure: str
    values: np.ndarray = field(repr=False)
    censored_at: np.ndarray = field(repr=False)
    limit: float | None = None

    @property
    def n(self) -> int:
        """Records (or record directions) in the fit."""
        return int(self.values.size)

    def probability(self, x):
        """Probability of overturning at intensity ``x`` (same measure as :attr:`median`)."""
        from scipy.special import ndtr

        x = np.asarray(x, dtype=float)
        with np.errstate(divide="ignore"):
            z = np.log(x / self.median) / self.beta
        out = ndtr(z)
        return float(out) if out.ndim == 0 else out

    def as_dict(self) -> dict:
        """``median``, ``beta``, ``measure``, ``n`` and the fitted values (``None`` for censored
        records): plain, JSON-safe."""
        from pulses.export import plain

        return plain({"median": self.median, "beta": self.beta, "measure": self.measure, "n": self.n,
                      "values": self.values, "censored_at": self.censored_at})

    def goodness_of_fit(self, n_boot: int = 200, seed: int = 0):
        """How well the lognormal fits the critical values: Kolmogorov-Smirnov's distance and its
        p-value by a parametric bootstrap (:func:`rocking.risk.fit.goodness_of_fit`)."""
        from .risk.fit import goodness_of_fit

        return goodness_of_fit(self, n_boot=n_boot, seed=seed)

    def bootstrap(self, n: int = 200, seed: int = 0):
        """``(medians, betas)`` of the fit to ``n`` resamplings of the records with replacement:
        its sampling uncertainty (:func:`rocking.risk.fit.bootstrap`)."""
        from .risk.fit import bootstrap

        return bootstrap(self, n=n, seed=seed)

    def empirical(self):
        """``(x, share)``: the sorted critical intensities and the share of records overturned at
        or below each (the points the curve is fitted to; censored records never count)."""
        x = np.sort(self.values[np.isfinite(self.values)])
        return x, np.arange(1, x.size + 1) / self.values.size


def _measure(measure, intensities):
    """The measure's name as the fit keeps it (``scale``, ``pga``, or a hazard curve's)."""
    if measure in ("scale", "pga") and intensities is None:
        return measure
    from pulses.intensity import measure_name, parse_measure

    try:
        name = measure_name(*parse_measure(measure))
    except ValueError as exc:
        raise ValueError(f"fragility: measure must be 'scale', 'pga' or a hazard curve's (PGA, "
                         f"PGV, SA(T)): {exc}") from None
    if intensities is None:
        raise ValueError(f"fragility: measure {name} needs intensities= (the {name} of each "
                         "unscaled record, pulses.intensity)")
    return name


def fragility(critical, *, measure="scale", up_to=None, limit=None, intensities=None) -> Fragility:
    """Lognormal fragility fitted by maximum likelihood to the critical scales of a suite.

    Parameters
    ----------
    critical : sequence of CriticalScale or float
        One entry per record (or record and direction).  Numbers are critical scale factors
        (``measure="scale"``) or critical PGAs in g (``measure="pga"``); ``None`` or ``inf``
        means the record did not overturn the block up to ``up_to``.
    measure : {"scale", "pga"}
        Fit the scale factors, or the PGAs (g) of the critically scaled records (from
        :attr:`CriticalScale.critical_pga`; needs :class:`CriticalScale` entries).
    up_to : float, optional
        For numeric entries that did not overturn: the largest intensity examined.
    limit : float, optional
        The performance level the critical scales were found for (``critical_scale(...,
        limit=)``; None: overturning); a :class:`CriticalScale` entry of another level is refused.
    intensities : sequence of float, optional
        With a hazard curve's ``measure`` (``"PGA"``, ``"PGV"``, ``"SA(1.0)"``): the measure of each
        record as given (unscaled; g, or cm/s for PGV), one per entry.  A record scaled by ``k``
        has ``k`` times each of them, so the critical value is the critical scale times it.

    Returns
    -------
    Fragility
        Without censored records ``median = exp(mean(ln x))`` and ``beta = std(ln x)`` (the
        maximum-likelihood estimates, ``ddof = 0``).  Records that did not overturn are
        right-censored at their largest intensity and the likelihood
        ``prod pdf(x_i) prod (1 - cdf(c_j))`` is maximised numerically.

    Examples
    --------
    >>> import rocking
    >>> f = rocking.fragility([1.2, 1.5, 2.0, None], up_to=3.0)   # critical scales; None: not up to 3
    >>> round(f.median, 3), round(f.beta, 3), f.n
    (1.921, 0.442, 4)
    """
    measure = _measure(measure, intensities)
    limit = check_limit(limit)
    critical = list(critical)
    ims = None if intensities is None else [float(v) for v in intensities]
    if ims is not None and len(ims) != len(critical):
        raise ValueError(f"fragility: {len(ims)} intensities for {len(critical)} critical scales")
    values, limits = [], []
    for i, item in enumerate(critical):
        if isinstance(item, CriticalScale) and item.limit != limit:
            raise ValueError(f"fragility: a critical scale for limit {item.limit!r} among those "
                             f"for limit {limit!r} (max|theta|/alpha; None: overturning)")
        if isinstance(item, CriticalScale):
            unit = ims[i] if ims is not None else 1.0 if measure == "scale" else item.pga / G
            values.append(math.inf if item.scale is None else item.scale * unit)
            limits.append(item.up_to * unit)
        else:
            try:
                v = math.inf if item is None else float(item)
            except (TypeError, ValueError):
                raise ValueError(f"fragility: entries must be CriticalScale results or numbers, "
                                 f"got {item!r}") from None
            if math.isinf(v) and up_to is None:
                raise ValueError("fragility: a record that did not overturn needs up_to "
                                 "(the largest intensity examined)")
            unit = 1.0 if ims is None else ims[i]
            values.append(v * unit)
            limits.append(math.nan if up_to is None else float(up_to) * unit)
    values, limits = np.asarray(values, dtype=float), np.asarray(limits, dtype=float)
    if values.size == 0:
        raise ValueError("fragility: no critical scales given")
    if np.any(~(values > 0)):
        raise ValueError("fragility: critical intensities must be positive")
    done = np.isfinite(values)
    if done.sum() < 2:
        raise ValueError(f"fragility: at least two records must overturn the block to fit a "
                         f"lognormal curve; {int(done.sum())} of {values.size} did")
    logs = np.log(values[done])
    mu, beta = float(logs.mean()), float(logs.std())
    cens = np.log(limits[~done])
    if cens.size:
        mu, beta = _censored_mle(logs, cens, mu, max(beta, 1e-3))
    if not beta > 0:
        raise ValueError("fragility: every record has the same critical intensity (beta = 0)")
    return Fragility(math.exp(mu), beta, measure, values, limits[~done], limit)


def _censored_mle(logs, cens, mu0, beta0):
    """Maximum likelihood ``(mu, beta)`` of a normal fit to ``logs`` with right-censored ``cens``."""
    from scipy.optimize import minimize
    from scipy.special import log_ndtr

    def nll(v):
        mu, lb = v
        beta = math.exp(lb)
        z = (logs - mu) / beta
        return -(np.sum(-0.5 * z * z - lb) + np.sum(log_ndtr(-(cens - mu) / beta)))

    res = minimize(nll, [mu0, math.log(beta0)], method="Nelder-Mead",
                   options={"xatol": 1e-12, "fatol": 1e-14, "maxiter": 20000})
    return float(res.x[0]), float(math.exp(res.x[1]))
