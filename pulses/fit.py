"""Fitting acceleration pulses to a record (docs/theory.md section 3; Vassiliou & Makris 2011).

For every candidate shape (rectangular, one-sine, symmetric and antisymmetric Ricker):

1. **Match** the record with the shape over periods and times: the wavelet transform with the
   pulse as mother wavelet (:mod:`pulses.cwt`), on a log-spaced grid of periods.  The best match
   maximises the share of the record's energy explained by a pulse of least-squares amplitude.
2. **Refine** ``ap``, ``Tp`` and ``t0`` by least squares on the record's samples inside a window
   around the pulse (Levenberg-Marquardt with the analytic Jacobian; for the rectangle a grid
   search over its two edges, see :func:`_refine_edges`).  A straight-line baseline is fitted
   together with the pulse inside the window (``baseline=True``), so slow drift of the record
   does not bias the pulse; it is not part of the pulse and not counted in its score.
3. **Weight** (the default, ``weighting="background"``; ``"plain"`` stops after step 2, for
   comparison): the background's spectrum is estimated from the record (:class:`Background`),
   first away from the best plain fit's pulse, then from the residual of that shape's fit
   weighted by the first estimate (:func:`_estimate_background`); every other shape is refit by
   least squares weighted by the inverse of the second (generalised least squares,
   :func:`_refine_weighted`), each weighted fit kept unless the record departs from the pulse
   model (Hausman's test, :func:`pulses.weighted.difference_covariance`), and the candidates are ranked by the
   share of the record's energy they explain in the same metric (:func:`_weighted`; the plain
   fit answers where the record does not support the weighting, ``PulseFit.weighting``).

A sampled pulse is the pulse evaluated at the sample times, except the rectangular pulse, whose
point samples do not locate its edges more finely than ``dt``: it is sampled as its average over
each sample's cell ``[t_i - dt/2, t_i + dt/2]``.

Quality of a candidate:

- ``score``: share of the record's energy the pulse explains, ``1 - ||x - p||^2 / ||x||^2`` over
  the whole record (1 for a record that is exactly the pulse); where the weighted least squares
  answered the norm is the weighted one, ``||v||^2 = v' S^-1 v`` with ``S`` the background's estimated
  covariance (every frequency of the record weighted by the inverse of the background's power
  there), the metric whose minimum the weighted least squares find;
- ``correlation``: ``<x, p> / (||x|| ||p||)`` within the pulse window (support of the rectangular
  and one-sine pulses; ``t0 +- Tp`` for the symmetric and ``t0 +- 1.25 Tp`` for the
  antisymmetric Ricker, which hold all but 1e-3 of their amplitude).

Candidates are ranked by score; every shape is reported, because shapes that fit almost equally
well can imply very different designs.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import fft as sfft

from .baseline import pgv as _pgv
from .baseline import significant_duration
from .cwt import Matcher, _dot, unit_energy
from .lsq import baseline_projector, levenberg_marquardt, pulse_normal_equations
from .record import G, Record
from .shapes import SHAPES, Pulse, make_pulse, shape_class
from .weighted import WeightedWindow

#: shapes fitted by default (every registered shape), in the order they are reported on ties
DEFAULT_SHAPES = tuple(SHAPES)
#: ratio between neighbouring periods of the coarse grid.  Half a step (3 %) off the true period,
#: the matched filter still explains 99.8 % of a Ricker's and 97 % of a rectangle's energy, so
#: the search lands in the right basin and least squares does the rest
GRID_RATIO = 1.06
#: for the antisymmetric shapes, a match of the other polarity is refined too when it explains
#: at least this share of what the best match explains
SECOND_START = 0.85
#: least squares refines the match, it does not replace it: Tp stays within this factor of the
#: matched period and t0 within one matched period of the matched time (with background motion
#: that reaches low frequencies, a free fit can trade a short pulse for a long swell of noise)
TP_LEASH = 1.5
#: least margin (s) of record kept on each side of the pulse by the refinement: the straight-line
#: baseline fitted with the pulse is pinned down by the motion around it, so that it does not
#: trade off against a short pulse
FIT_MARGIN = 1.0
#: length (s) of the segments over which the background's spectrum is averaged: at least
#: SEGMENT s and SEGMENT_PERIODS periods of the best plain fit
SEGMENT = 2.5
SEGMENT_PERIODS = 2.5
#: the segments that overlap the best plain pulse's window widened by this many of its periods
#: on each side are left out of the background's spectrum (:class:`Background`): there the
#: residual holds the plain fit's own error, whose corners reach frequencies where the
#: background has almost no power.  Half a period beyond the window holds the true pulse where
#: the plain fit is off by its noise limit (t0 within 5 % of Tp in 86 % of the README's cases at
#: 30 % noise, Tp within 15 % in 76 %)
SKIP_PERIODS = 0.5
#: length (s) over which the record is tapered to zero at each end for the weighted score
SCORE_TAPER = 1.0
#: white noise added to the background's spectrum, as a share of its mean power: bounds the
#: weight of frequencies where the background has (almost) no power
LOADING = 1e-3
#: record kept each side of the pulse by the weighted least squares: GLS_MARGIN s or
#: GLS_MARGIN_PERIODS periods if longer (enough for the baseline and the low frequencies a long
#: pulse needs; on the README's synthetic records 5 s either side did no better, and cost 9 % more)
GLS_MARGIN = 3.0
GLS_MARGIN_PERIODS = 1.0
#: the weighted estimate is refused when it differs from the plain one by more than noise
#: explains: Hausman's statistic (chi-square of 3 degrees of freedom under the model) above its
#: 99.9 % point
GLS_HAUSMAN = 16.27


class FitError(ValueError):
    """Input the pulse fit cannot use: a record with nothing to fit, or a period range that is
    not one.  The message is one line that says what is wrong.

    Examples
    --------
    >>> import numpy as np, pulses
    >>> try:
    ...     pulses.fit_pulse(pulses.Record(np.sin(np.arange(20) / 3.0), 0.01))
    ... except pulses.FitError as exc:
    ...     print(exc)
    record 'record' (0.19 s) is too short to fit pulses of at least 0.2 s
    """


# -- sampled unit pulses ---------------------------------------------------------------------
def unit_samples(shape: str, tp: float, t0: float, t, dt: float) -> np.ndarray:
    """Unit-amplitude pulse at sample times ``t`` (s): point samples, cell averages for ``rect``."""
    return shape_class(shape).sampled(tp, t0, t, dt)


def unit_samples_and_derivatives(shape: str, tp: float, t0: float, t, dt: float):
    """Unit pulse at ``t`` and its derivatives with respect to ``tp`` and ``t0`` (for the Jacobian)."""
    return shape_class(shape).sampled_with_derivatives(tp, t0, t, dt)


def pulse_window(shape: str, tp: float, t0: float) -> tuple[float, float]:
    """Interval (s) over which a candidate's ``correlation`` is measured."""
    lo, hi = shape_class(shape).window_tau
    return t0 + lo * tp, t0 + hi * tp


def _fit_window(shape: str, tp: float, t0: float) -> tuple[float, float]:
    """Interval (s) of samples used by the least-squares refinement: the pulse plus a margin."""
    margin = max(0.5 * tp, FIT_MARGIN)
    lo, hi = shape_class(shape).fit_tau
    return t0 + lo * tp - margin, t0 + hi * tp + margin


def _covers(idx: slice, shape: str, tp: float, t0: float, dt: float, n: int) -> bool:
    """True if the samples ``idx`` hold the pulse with at least half the fit margin around it."""
    lo, hi = _fit_window(shape, tp, t0)
    half = 0.5 * max(0.5 * tp, FIT_MARGIN)
    return (idx.start == 0 or idx.start * dt <= lo + half) and (idx.stop >= n or (idx.stop - 1) * dt >= hi - half)


# -- results -----------------------------------------------------------------------------------
@dataclass
class Candidate:
    """One fitted pulse shape.

    Attributes
    ----------
    shape : str
        A name of :data:`pulses.SHAPES` (the shapes of docs/theory.md section 2).
    ap : float
        Amplitude, m/s^2, signed by polarity.
    tp : float
        Period, s.
    t0 : float
        Arrival (rect, sine) or centre (Rickers), s, on the record's time axis.
    score : float
        Share of the record's energy the pulse explains (0-1).
    correlation : float
        Correlation of record and pulse within the pulse window (-1 to 1).
    pulse : pulses.Pulse
        The pulse object (``make_pulse(shape, ap, tp, t0)``).
    rank : int
        1 for the best candidate of the record, 2 for the runner-up, ...
    fit_window : (float, float) or None
        First and last sample times (s) used by the least-squares refinement (``None`` if the
        refinement did not improve on the coarse match).

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> best = pulses.fit_pulse(rec, shapes=["sine"]).best
    >>> best.rank, round(best.t0, 3), type(best.pulse).__name__
    (1, 2.0, 'OneSine')
    """

    shape: str
    ap: float
    tp: float
    t0: float
    score: float
    correlation: float
    pulse: Pulse = field(repr=False)
    rank: int = 0
    fit_window: tuple | None = field(default=None, repr=False)

    @property
    def ap_g(self) -> float:
        """Amplitude in g (signed)."""
        return self.ap / G

    @property
    def polarity(self) -> int:
        """+1 or -1: the sign of ``ap``."""
        return 1 if self.ap >= 0 else -1

    @property
    def lp(self) -> float:
        """Length scale ``Lp = |ap| Tp^2``, m."""
        return abs(self.ap) * self.tp**2

    @property
    def arrival(self) -> float:
        """Time the pulse starts, s: ``t0`` for rect and sine, ``t0 - Tp/2`` for the Rickers."""
        return self.pulse.arrival

    def as_dict(self) -> dict:
        return {"shape": self.shape, "rank": self.rank, "ap_m_s2": self.ap, "ap_g": self.ap_g,
                "tp_s": self.tp, "t0_s": self.t0, "arrival_s": self.arrival, "polarity": self.polarity,
                "lp_m": self.lp, "score": self.score, "correlation": self.correlation}


@dataclass
class PulseFit:
    """Pulse fits of one record, best first.

    Attributes
    ----------
    name : str
        Record name.
    candidates : list of Candidate
        One per shape, ranked by ``score`` (best first; ``rank`` 1 is the best).
    pga : float
        Peak ground acceleration of the record, m/s^2.
    pgv : float
        Peak ground velocity, m/s, after the baseline correction of :mod:`pulses.baseline`.
    duration : float
        Length of the record, s.
    significant_duration : float
        D5-95 (time between 5 % and 95 % of the Arias intensity), s.
    weighting : str
        The least squares that gave the candidates: ``"background"`` (weighted by the
        background's spectrum) or ``"plain"`` (asked for, or where the record did not support
        the weighting: see :func:`fit_pulse`).

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> fit = pulses.fit_pulse(rec, shapes=["sine", "ricker-sym"])
    >>> [c.shape for c in fit.candidates], fit["sine"] is fit.best
    (['sine', 'ricker-sym'], True)
    """

    name: str
    candidates: list
    pga: float
    pgv: float
    duration: float
    significant_duration: float
    weighting: str = "plain"

    @property
    def best(self) -> Candidate:
        """The candidate that explains the most of the record's energy."""
        return self.candidates[0]

    def __getitem__(self, shape: str) -> Candidate:
        """The candidate of one shape: ``fit["sine"]``."""
        for c in self.candidates:
            if c.shape == shape:
                return c
        raise KeyError(f"no {shape!r} candidate; fitted shapes: {', '.join(c.shape for c in self.candidates)}")

    def to_frame(self):
        """One row per candidate (pandas DataFrame), best first, with the record's peaks."""
        import pandas as pd

        rows = []
        for c in self.candidates:
            row = {"record": self.name, **c.as_dict(), "best": c.rank == 1,
                   "pga_g": self.pga / G, "pgv_m_s": self.pgv, "duration_s": self.duration,
                   "d5_95_s": self.significant_duration, "weighting": self.weighting}
            rows.append(row)
        return pd.DataFrame(rows)

    def as_dict(self) -> dict:
        return {"record": self.name, "pga_g": self.pga / G, "pgv_m_s": self.pgv,
                "duration_s": self.duration, "d5_95_s": self.significant_duration,
                "weighting": self.weighting, "best": self.best.shape,
                "candidates": [c.as_dict() for c in self.candidates]}


# -- the fitter ------------------------------------------------------------------------------------
def default_tp_range(record: Record) -> tuple[float, float]:
    """Periods searched by default, s: from ``max(0.2 s, 10 dt)`` to ``min(10 s, duration / 4)``.

    0.2 s is below any pulse period that matters for rocking columns (Eq. 6 gives 0.67 s for
    Mw 5); a pulse longer than a quarter of the record cannot be told from a trend in it.  The
    least-squares refinement may end slightly outside the searched range.
    """
    tp_min = max(0.2, 10.0 * record.dt)
    tp_max = min(10.0, 0.25 * record.duration)
    if tp_min >= 10.0:  # ten samples a period: no period up to 10 s has them
        raise FitError(f"record {record.name!r} is sampled every {record.dt:g} s, too coarsely to fit "
                       f"pulses: a period of at most 10 s needs 10 samples (dt at most 1 s; "
                       f"strong-motion records are sampled at 50 to 1000 Hz)")
    if tp_max <= tp_min:
        raise FitError(f"record {record.name!r} ({record.duration:g} s) is too short to fit pulses of "
                         f"at least {tp_min:g} s")
    return tp_min, tp_max


def fit_pulse(record: Record, shapes=None, *, tp_range=None, baseline: bool = True,
              weighting: str = "background") -> PulseFit:
    """Fit every candidate pulse shape to a record.

    Parameters
    ----------
    record : pulses.Record
        Ground acceleration, m/s^2.
    shapes : iterable of str, optional
        Shapes to fit (names of :data:`pulses.SHAPES`; default all four).
    tp_range : (float, float), optional
        Shortest and longest period searched, s (default :func:`default_tp_range`).
    baseline : bool, optional
        Fit a straight-line baseline together with the pulse inside the refinement window
        (default True).
    weighting : {"background", "plain"}, optional
        ``"background"`` (default): after plain least squares, refine every shape once more with
        the residual weighted by the inverse of the background's spectrum, estimated from the
        record itself (generalised least squares, :class:`Background`), and rank the candidates
        by the share of the record's energy they explain in that metric.  More accurate ap and
        Tp, and the shape right more often, on synthetic records with band-limited background
        motion; about twice the cost of the plain fit (README, "Accuracy on synthetic records").
        Where the weighting would overturn the plain ranking although the record does not
        follow the plain winner at the frequencies the weights favour (Hausman's test), the
        plain fit answers, and ``PulseFit.weighting`` says so.
        ``"plain"``: ordinary least squares only (every frequency weighted alike), ranked by the
        plain share of energy; kept for comparison.

    Returns
    -------
    PulseFit
        Candidates ranked by score, ``.best``, the record's PGA, PGV and duration, and the least
        squares that answered.  A record the plain fit explains to round-off has no background
        to weight by: its fit is the plain one.

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> fit = pulses.fit_pulse(rec, shapes=["sine", "ricker-sym"])
    >>> fit.best.shape, round(fit.best.ap_g, 3), round(fit.best.tp, 3)
    ('sine', 0.5, 1.0)
    """
    shapes = tuple(DEFAULT_SHAPES if shapes is None else shapes)
    for s in shapes:
        shape_class(s)  # an unknown name fails here, before any work
    if not shapes:
        raise FitError("no pulse shape to fit")
    tp_min, tp_max = default_tp_range(record) if tp_range is None else _checked_tp_range(tp_range, record)
    x, amplitude = _normalised(record)
    dt = record.dt
    t = np.arange(x.size) * dt  # time from the first sample; record.t_start is added at the end
    matcher = Matcher(x, dt, tp_min, tp_max)
    n_grid = max(2, int(math.ceil(math.log(tp_max / tp_min) / math.log(GRID_RATIO))) + 1)
    tps = np.geomspace(tp_min, tp_max, n_grid)
    energy = _dot(x, x)
    if weighting not in ("background", "plain"):
        raise FitError(f"weighting must be 'background' or 'plain', got {weighting!r}")
    # the weighted least squares estimate the background once per record, from the best plain fit
    # of every shape: a shape's fit does not depend on which others were asked for
    fitted = shapes if weighting == "plain" else tuple(dict.fromkeys((*shapes, *DEFAULT_SHAPES)))
    fits = {}
    for shape in fitted:
        score = -np.inf
        for start in _coarse(matcher, shape, tps, t[-1]):
            trial = _refine(x, t, dt, shape, *start, baseline)
            s, p_trial = _score(x, t, dt, shape, trial, energy)
            if s > score:
                score, fits[shape] = s, (start, trial, p_trial)
    # the share of energy explained, in the metric of the least squares used
    scores, weighted_scores = _plain_scores(x, fits, energy), None
    if weighting == "background":
        fits, weighted_scores = _weighted(x, t, dt, fits, scores, energy, baseline, shapes)
        scores = scores if weighted_scores is None else weighted_scores
    fits = {shape: fits[shape] for shape in shapes}
    candidates = []
    for shape, (_, (ap, tp, t0, idx), p) in fits.items():
        score = scores[shape]
        lo, hi = pulse_window(shape, tp, t0)
        inside = (t >= lo) & (t <= hi)
        xw, pw = x[inside], p[inside]
        denom = math.sqrt(_dot(xw, xw) * _dot(pw, pw))
        corr = _dot(xw, pw) / denom if denom > 0 else 0.0
        t0_abs = t0 + record.t_start
        window = None if idx is None else (record.t_start + idx.start * dt, record.t_start + (idx.stop - 1) * dt)
        ap *= amplitude
        candidates.append(Candidate(shape, ap, tp, t0_abs, score, corr, make_pulse(shape, ap, tp, t0_abs),
                                    fit_window=window))
    order = sorted(range(len(candidates)), key=lambda i: -candidates[i].score)
    ranked = [candidates[i] for i in order]
    for k, c in enumerate(ranked, start=1):
        c.rank = k
    return PulseFit(record.name, ranked, record.pga, _pgv(record.acc, dt), record.duration,
                    significant_duration(record.acc, dt), "plain" if weighted_scores is None else "background")


def _weighted(x, t, dt, fits, plain_scores, energy, baseline, wanted=None):
    """The weighted least squares of the ``wanted`` shapes (default: all) from their plain fits
    (``fits``: shape -> ``(match, trial, samples)``, every shape of :data:`DEFAULT_SHAPES` at
    least), and their scores: the share of the record's energy each explains in the weighted
    metric; the plain fits and None where the weighting is not used.

    Whether it is used, and the background's spectrum, come from every shape of ``fits`` (the
    best plain fit among them): a shape's weighted fit is the same whichever are ``wanted``.

    It is not used where the record has no background to weight by (the plain fit explains it
    to round-off), nor where it would overturn the plain ranking although the plain winner's own
    weighted refit was refused (:func:`_estimate_background`): then the weighted metric rests on
    a spectrum the record does not support, and it would rank the winner by its plain fit's
    corners, misplaced for the weights (on the README's records, a short one-sine in 0.1-25 Hz
    background at 15 %, whose plain Tp was 12 % off).
    """
    wanted = tuple(fits) if wanted is None else tuple(wanted)
    order = sorted(fits, key=_canonical)  # ties go the same way whichever shapes were asked
    best = max(order, key=plain_scores.get)
    resid = x - fits[best][2]
    if _dot(resid, resid) <= 1e-24 * energy:
        return fits, None
    background, best_fit, accepted = _estimate_background(x, t, dt, best, fits[best], energy, baseline)
    if background is None:
        return fits, None

    def refit(shape):
        match, trial, _ = fits[shape]
        if shape == best:
            return (match, *best_fit)
        trial = _refine_weighted(x, t, dt, shape, match, trial, background, baseline)
        return (match, trial, _score(x, t, dt, shape, trial, energy)[1])

    # the ranking test below needs every shape; otherwise only those asked for
    weighted = {shape: refit(shape) for shape in (order if not accepted else wanted)}
    scores = background.explained(x, {shape: p for shape, (_, _, p) in weighted.items()})
    if not accepted and max((s for s in order), key=scores.get) != best:
        return fits, None
    return weighted, scores


def _canonical(shape: str) -> int:
    """Place of ``shape`` in :data:`DEFAULT_SHAPES` (shapes outside it after)."""
    return DEFAULT_SHAPES.index(shape) if shape in DEFAULT_SHAPES else len(DEFAULT_SHAPES)


def _plain_scores(x, fits, energy) -> dict:
    """Share of the record's energy each fit's samples explain (``fits``: shape -> ``(match,
    trial, samples)``)."""
    return {shape: 1.0 - _dot(x - p, x - p) / energy for shape, (_, _, p) in fits.items()}


def _score(x, t, dt, shape, trial, energy):
    """Share of the record's energy a refined ``(ap, Tp, t0, window)`` explains, and its samples."""
    p = trial[0] * shape_class(shape).sampled_on_grid(trial[1], trial[2], t, dt)
    r = x - p
    return 1.0 - _dot(r, r) / energy, p


def _checked_tp_range(tp_range, record: Record) -> tuple[float, float]:
    """``(tp_min, tp_max)`` as floats; FitError unless ``2 dt < tp_min <= tp_max <= duration``."""
    try:
        tp_min, tp_max = (float(v) for v in tp_range)
    except (TypeError, ValueError):
        raise FitError(f"tp_range must be two periods in s, got {tp_range!r}") from None
    if not (math.isfinite(tp_min) and math.isfinite(tp_max) and 0.0 < tp_min <= tp_max):
        raise FitError(f"tp_range must be two finite periods with 0 < shortest <= longest, got {tp_range!r} s")
    if tp_min <= 2.0 * record.dt:
        raise FitError(f"tp_range: the shortest period {tp_min:g} s must span more than two samples "
                       f"(2 dt = {2.0 * record.dt:g} s)")
    if tp_max > record.duration:
        raise FitError(f"tp_range: the longest period {tp_max:g} s exceeds the duration of record "
                       f"{record.name!r} ({record.duration:g} s)")
    return tp_min, tp_max


def _normalised(record: Record) -> tuple[np.ndarray, float]:
    """The samples divided by a power of two near their peak, and that power (m/s^2).

    A power of two scales every floating-point operation exactly, so the fit of the normalised
    samples is the fit of the record, without overflow in its sums of squares of sums of squares.
    """
    peak = float(np.max(np.abs(record.acc)))
    if peak == 0.0:
        raise FitError(f"record {record.name!r} is zero everywhere: there is no pulse to fit")
    if not math.isfinite(float(np.dot(record.acc / peak, record.acc / peak)) * peak * peak):
        raise FitError(f"record {record.name!r}: samples up to {peak:.3g} m/s^2 are too large for their "
                       "energy (sum of squares) to be a number; check the units")
    amplitude = math.ldexp(1.0, math.frexp(peak)[1])
    return record.acc / amplitude, amplitude


def _coarse(matcher: Matcher, shape: str, tps, t_end: float):
    """Starting ``(ap, Tp, t0)`` of one shape for the least squares.

    The best match; for the antisymmetric shapes also the best match of the other polarity, and
    for every shape the best match of a clearly different period (another octave), each when it
    explains at least :data:`SECOND_START` as much of the record.  An antisymmetric shape
    matches nearly as well with the opposite polarity half a lobe away, and in strong background
    motion a pulse and a swell of another period can match about equally: refining both and
    keeping the better avoids settling on the wrong one.
    """
    polarities, octaves = matcher.best_match(shape, tps, t_end)
    first = polarities[0]
    picks = [first]
    if shape_class(shape).antisymmetric and abs(polarities[1][0]) >= SECOND_START * abs(first[0]):
        picks.append(polarities[1])
    for match in octaves:
        if abs(match[0]) < SECOND_START * abs(first[0]):
            break
        if not (first[1] / TP_LEASH <= match[1] <= first[1] * TP_LEASH):
            picks.append(match)
            break
    starts = []
    for share, tp, t0 in picks:
        # share = c|c| / (||w||^2 ||x||^2) and ap = c / ||w||^2, so |ap| = sqrt(|share|) ||x|| / ||w||
        norm_w = math.sqrt(unit_energy(shape) * tp / matcher.dt)
        ap = math.copysign(math.sqrt(abs(share) * matcher.energy) / norm_w, share)
        starts.append((ap, tp, t0))
    return starts


def _refine(x, t, dt, shape, ap0, tp0, t00, baseline):
    """Least-squares ``(ap, Tp, t0, window)`` near a starting guess; the guess if refinement fails.

    Levenberg-Marquardt on the samples inside the fit window, with the analytic Jacobian; the
    straight-line baseline ``c0 + c1 (t - tc)`` is fitted alongside when ``baseline`` is True
    (projected out: the residual and Jacobian are taken orthogonal to 1 and ``t - tc``).
    """

    def window(tp, t0):
        lo, hi = _fit_window(shape, tp, t0)
        i0 = max(0, int(math.floor(lo / dt)))
        i1 = min(x.size, int(math.ceil(hi / dt)) + 1)
        return slice(i0, i1)

    best = (ap0, tp0, t00, None)
    cls = shape_class(shape)
    if cls.boxcar:
        return _refine_edges(x, t, dt, shape, best, window, baseline, tp0, t00)
    ap, tp, t0 = ap0, tp0, t00
    for _ in range(3):  # refit when the pulse moved outside the window of the previous pass
        idx = window(tp, t0)
        if idx.stop - idx.start < 6:
            break
        tw, xw = t[idx], x[idx]
        project = baseline_projector(tw, baseline)
        xp = project(xw)
        try:
            p_new, cost = levenberg_marquardt(pulse_normal_equations(cls, xp, tw, dt, baseline),
                                              np.array([ap, tp, t0]), scale=np.array([abs(ap) or 1.0, tp, tp]),
                                              lower=np.array([-np.inf, tp0 / TP_LEASH, t00 - tp0]),
                                              upper=np.array([np.inf, tp0 * TP_LEASH, t00 + tp0]))
        except np.linalg.LinAlgError:
            break
        ap_new, tp_new, t0_new = (float(v) for v in p_new)
        if not all(map(math.isfinite, (ap_new, tp_new, t0_new))) or tp_new <= 2 * dt:
            break
        # accept when it beats the starting (Tp, t0) on this window's own objective
        m0 = project(cls.sampled_on_grid(tp, t0, tw, dt))
        start_sse = _dot(xp, xp) - _dot(m0, xp) ** 2 / max(_dot(m0, m0), 1e-300)
        if cost > start_sse * (1 + 1e-12):
            break
        best = (ap_new, tp_new, t0_new, idx)
        ap, tp, t0 = ap_new, tp_new, t0_new
        if _covers(idx, shape, tp, t0, dt, x.size):
            break
    return best


def segment_periodograms(x, dt: float, nseg: int):
    """Periodograms of the half-overlapping Hann segments of ``x``: Welch's estimate before the
    average.

    Segments of ``nseg`` samples every ``nseg - nseg // 2``, each less its mean, times the
    periodic Hann window ``w_k = (1 - cos(2 pi k / nseg)) / 2``; one-sided power spectral density
    ``2 |rfft|^2 dt / sum(w^2)`` (the zero and, for an even ``nseg``, the Nyquist bins not doubled),
    in the units of ``x`` squared per Hz.  These are ``scipy.signal.spectrogram(x, 1 / dt,
    "hann", nseg, nseg // 2, detrend="constant")``'s (density scaling), computed without
    importing ``scipy.signal`` (half a second or more on a cold start: it imports ``scipy.stats``).

    Parameters
    ----------
    x : ndarray, shape (n,)
        Samples, ``n >= nseg``.
    dt : float
        Sampling step, s.
    nseg : int
        Samples per segment.

    Returns
    -------
    freq : ndarray, shape (nseg // 2 + 1,)
        Frequencies, Hz.
    power : ndarray, shape (nseg // 2 + 1, number of segments)
        One periodogram per column, segments in time order.
    """
    x = np.asarray(x, dtype=float)
    step = nseg - nseg // 2
    segments = np.lib.stride_tricks.sliding_window_view(x, nseg)[::step]
    window = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(nseg) / nseg)
    spectra = sfft.rfft(window * (segments - segments.mean(axis=-1, keepdims=True)), axis=-1)
    power = (spectra.real**2 + spectra.imag**2) * (dt / float(np.sum(window * window)))
    power[:, 1:(None if nseg % 2 else -1)] *= 2.0
    return sfft.rfftfreq(nseg, dt), power.T


class Background:
    """The background motion's power spectrum, estimated from a residual, as least-squares weights.

    Welch's average of periodograms of the residual (Hann segments of :data:`SEGMENT` s, half
    overlapping; below two of its frequency steps no lower than there), plus :data:`LOADING`
    times its mean: white noise that bounds the weight of
    frequencies where the background has almost no power.  Segments that overlap the interval
    ``skip`` (s from the first sample; the pulse) are left out, unless that leaves no power.
    Weighting each frequency of a residual by the inverse of this power is generalised least
    squares (the noise's covariance taken as the circulant of this spectrum).
    """

    def __init__(self, resid, dt: float, segment: float = None, skip=None):
        resid = np.asarray(resid, dtype=float)
        self.dt = float(dt)
        segment = SEGMENT if segment is None else segment
        nseg = int(min(resid.size, max(16, round(segment / dt))))
        # Welch's estimate, one periodogram per segment so that some can be left out
        self.freq, periodograms = segment_periodograms(resid, dt, nseg)
        keep = np.ones(periodograms.shape[1], dtype=bool)
        if skip is not None:
            starts = np.arange(keep.size) * (nseg - nseg // 2) * dt
            keep = (starts + (nseg - 1) * dt < skip[0]) | (starts > skip[1])
        power = periodograms[:, keep].mean(axis=1) if keep.any() else np.zeros(self.freq.size)
        if not np.any(power > 0):  # nothing left, or only round-off of an exact fit there
            power = periodograms.mean(axis=1)
        # below two frequency steps the segments (their means removed) cannot measure the
        # power: it is taken as no lower than there
        low = self.freq < 2.0 / (nseg * dt)
        if np.any(low) and not np.all(low):
            power[low] = np.maximum(power[low], power[np.argmin(low)])
        self.power = power + LOADING * float(np.mean(power))

    @property
    def usable(self) -> bool:
        """Whether the spectrum has finite, positive power everywhere (weights to divide by)."""
        return bool(np.all(np.isfinite(self.power) & (self.power > 0)))

    def weights(self, nfft: int) -> np.ndarray:
        """Weights of the ``nfft // 2 + 1`` bins of a real FFT of ``nfft`` points such that
        ``sum(w * Re(U conj(V)))`` is ``u' S^-1 v`` (``S`` the background's covariance, circulant)."""
        f = np.arange(nfft // 2 + 1) / (nfft * self.dt)
        w = 2.0 / (nfft * np.interp(f, self.freq, self.power * (0.5 / self.dt)))
        w[0] *= 0.5
        if nfft % 2 == 0:
            w[-1] *= 0.5
        return w

    def explained(self, x, pulses: dict) -> dict:
        """Share of the weighted energy of the samples ``x`` that each pulse (samples on the same
        times, by name) explains: ``1 - r' S^-1 r / x' S^-1 x`` with ``r = x - p``.

        The metric is circular (a Fourier transform of the record): ``x`` and ``r`` are tapered
        to zero over :data:`SCORE_TAPER` s at each end first (half a Hann window), so that the
        jump from the record's last sample back to its first, which the weights would see as
        motion at every frequency, does not count, and a pulse cannot gain by cancelling it.
        """
        nfft = sfft.next_fast_len(x.size, real=True)
        w = self.weights(nfft)
        m = max(1, min(x.size // 4, int(round(SCORE_TAPER / self.dt))))
        taper = np.ones(x.size)
        ramp = 0.5 - 0.5 * np.cos(np.pi * (np.arange(m) + 0.5) / m)
        taper[:m], taper[-m:] = ramp, ramp[::-1]

        def energy(v):
            V = sfft.rfft(v * taper, nfft)
            return float(np.sum(w * (V.real**2 + V.imag**2)))

        xx = energy(x)
        return {name: 1.0 - energy(x - p) / xx for name, p in pulses.items()}


def _estimate_background(x, t, dt, shape, fit, energy, baseline):
    """The background's spectrum (:class:`Background`) from the record and its best plain fit
    ``fit = (match, trial, samples)`` of ``shape``, and that shape's weighted fit with the first
    estimate, as ``((ap, Tp, t0, window), samples)``, and whether that refit was accepted (else
    it is the plain fit: :func:`_refine_weighted`); ``(None, None, False)`` if the residual has
    no power to weight by.

    Two passes.  The plain fit's residual holds its own error where the pulse is, and a
    one-sine's or a rectangle's corners put that error at frequencies where the background has
    almost no power: the first estimate leaves out the segments near the pulse
    (:data:`SKIP_PERIODS`).  The best shape is refit with it; that fit's error being much
    smaller, the spectrum is estimated again from the whole of its residual, which counts the
    background where it is strongest too: around the pulse, on a real record; the other shapes
    are refit with this second estimate (on Rinaldi 228, with the first one the one-sine's Tp
    would move 4 % from the plain fit's, with the second 2 %).  Segments of
    :data:`SEGMENT` s or :data:`SEGMENT_PERIODS` plain periods if longer, to resolve the
    spectrum down to the pulse's own frequencies.
    """
    match, trial, p = fit
    _, tp, t0, _ = trial
    segment = max(SEGMENT, SEGMENT_PERIODS * tp)
    lo, hi = pulse_window(shape, tp, t0)
    first = Background(x - p, dt, segment, skip=(lo - SKIP_PERIODS * tp, hi + SKIP_PERIODS * tp))
    if not first.usable:
        return None, None, False
    refit = _refine_weighted(x, t, dt, shape, match, trial, first, baseline)
    samples = p if refit is trial else _score(x, t, dt, shape, refit, energy)[1]
    second = Background(x - samples, dt, segment)
    return (second if second.usable else first), (refit, samples), refit is not trial


def _refine_weighted(x, t, dt, shape, match, start, background, baseline):
    """Generalised least squares ``(ap, Tp, t0, window)`` from a plain least-squares ``start``.

    The residual over the pulse and :data:`GLS_MARGIN` s (or :data:`GLS_MARGIN_PERIODS`) of
    record each side is weighted by the inverse of the background's spectrum
    (:class:`Background`), in the frequency domain, the straight-line baseline fitted alongside
    in the same metric (:meth:`pulses.weighted.WeightedWindow.search`: for a shape with corners
    a scan of the period and a lattice of the pulse's edges around Levenberg-Marquardt; for a
    smooth shape, whose weighted minimum lies in the plain one's basin, the descent from
    ``start``).  ``start`` is returned when nothing beats it on the weighted objective, or when
    the two estimates differ by more than noise of the estimated spectrum explains
    (:func:`pulses.weighted.difference_covariance`, Hausman's test).  By Gauss-Markov, under
    that spectrum the weighted estimate scatters less than the plain one,
    whatever the shape and period; it is used wherever the record follows the model.
    """
    cls = shape_class(shape)
    ap, tp, t0, _ = start
    lo, hi = cls.fit_tau
    margin = max(GLS_MARGIN, GLS_MARGIN_PERIODS * tp)
    i0 = max(0, int(math.floor((t0 + lo * tp - margin) / dt)))
    i1 = min(x.size, int(math.ceil((t0 + hi * tp + margin) / dt)) + 1)
    idx = slice(i0, i1)
    gls = WeightedWindow(cls, x[idx], t[idx], dt, background.weights, baseline, tp)
    difference = gls.difference_covariance(ap, tp, t0)
    if difference is None:
        return start
    start_cost, _ = gls.profiled(tp, t0)
    _, tp0, t00 = match
    try:
        p_new, cost = gls.search(tp, t0, lower=np.array([-np.inf, tp0 / TP_LEASH, t00 - tp0]),
                                 upper=np.array([np.inf, tp0 * TP_LEASH, t00 + tp0]))
    except np.linalg.LinAlgError:
        return start
    ap_new, tp_new, t0_new = (float(v) for v in p_new)
    if not all(map(math.isfinite, (ap_new, tp_new, t0_new))) or tp_new <= 2 * dt or \
            cost > start_cost * (1 + 1e-12):
        return start
    # the record must follow the pulse model where the weights look: on a record whose
    # background was filtered away above some frequency, a rectangle's or one-sine's edges are
    # not in the record either, and a weighted fit would shrink the pulse to hide them.  Under
    # the model the two estimates differ only by noise of known covariance (Hausman's test)
    d = np.array([ap_new - ap, tp_new - tp, t0_new - t0])
    if float(d @ np.linalg.pinv(difference) @ d) > GLS_HAUSMAN:
        return start
    return (ap_new, tp_new, t0_new, idx)


def _refine_edges(x, t, dt, shape, best, window, baseline, tp0, t00):
    """Least squares for a boxcar shape (the rectangular pulse): a search over its two edges.

    The cell-averaged rectangle is piecewise linear in its edges, with a kink each time an edge
    crosses a cell boundary, and with background motion the sum of squares has a shallow local
    minimum in almost every cell: a gradient method stalls.  The edges are scanned one at a time
    over +-0.15 Tp, then both together on grids that shrink to 1e-7 Tp.  The amplitude (and
    the baseline) are solved linearly for each pair of edges, in O(1) from prefix sums.
    """
    ap, tp, t0, _ = best
    for _ in range(3):
        idx = window(tp, t0)
        if idx.stop - idx.start < 6:
            break
        tw, xw = t[idx], x[idx]
        tc = float(tw.mean())
        extra = [np.ones_like(tw), tw - tc] if baseline else []

        n = tw.size
        ramp = tw - tc if baseline else np.zeros(n)
        # with the baseline (columns 1 and t - tc, orthogonal since tc is the mean time) projected
        # out, the amplitude and the remaining sum of squares follow from a few dot products
        n_ramp = _dot(ramp, ramp) or 1.0
        x_perp = xw - (xw.mean() + ramp * _dot(ramp, xw) / n_ramp if baseline else 0.0)
        sxx = _dot(x_perp, x_perp)
        prefix_x = np.concatenate([[0.0], np.cumsum(x_perp)])
        prefix_r = np.concatenate([[0.0], np.cumsum(ramp)])

        def sse(edges):
            # the cell-averaged rectangle is 1 on whole cells and a fraction on the two edge
            # cells, so its dot products with x, 1 and (t - tc) come from prefix sums in O(1)
            start, end = edges
            if end - start <= dt:
                return sxx * (1.0 + (dt - (end - start)))
            k1 = int(math.floor((start - tw[0]) / dt + 0.5))
            k2 = int(math.floor((end - tw[0]) / dt + 0.5))
            if k1 == k2:
                parts = ((k1, (end - start) / dt),)
            else:
                parts = ((k1, (tw[0] + (k1 + 0.5) * dt - start) / dt),
                         (k2, (end - (tw[0] + (k2 - 0.5) * dt)) / dt))
            lo, hi = min(max(k1 + 1, 0), n), min(max(k2, 0), n)
            mx = prefix_x[hi] - prefix_x[lo]
            m1 = float(hi - lo)
            mr = prefix_r[hi] - prefix_r[lo]
            mm = m1
            for k, w in parts:
                if 0 <= k < n:
                    mx += w * x_perp[k]
                    m1 += w
                    mr += w * ramp[k]
                    mm += w * w
            if baseline:  # squared norm of the pulse column after projecting out the baseline
                mm -= m1 * m1 / n + mr * mr / n_ramp
            if mm <= 1e-12:
                return sxx
            return sxx - mx * mx / mm

        def sse_many(starts, ends):
            """:func:`sse` for arrays of edge pairs (the scan's many trials at once)."""
            k1 = np.floor((starts - tw[0]) / dt + 0.5).astype(int)
            k2 = np.floor((ends - tw[0]) / dt + 0.5).astype(int)
            same = k1 == k2
            w1 = np.where(same, (ends - starts) / dt, (tw[0] + (k1 + 0.5) * dt - starts) / dt)
            w2 = np.where(same, 0.0, (ends - (tw[0] + (k2 - 0.5) * dt)) / dt)
            lo = np.minimum(np.maximum(k1 + 1, 0), n)  # np.clip, without its per-call cost
            hi = np.maximum(np.minimum(np.maximum(k2, 0), n), lo)
            mx = prefix_x[hi] - prefix_x[lo]
            m1 = (hi - lo).astype(float)
            mr = prefix_r[hi] - prefix_r[lo]
            mm = m1.copy()
            for k, w in ((k1, w1), (k2, w2)):
                ok = (k >= 0) & (k < n)
                kc = np.minimum(np.maximum(k, 0), n - 1)
                w = np.where(ok, w, 0.0)
                mx += w * x_perp[kc]
                m1 += w
                mr += w * ramp[kc]
                mm += w * w
            if baseline:
                mm = mm - m1 * m1 / n - mr * mr / n_ramp
            out = sxx - np.where(mm > 1e-12, mx * mx / np.where(mm > 1e-12, mm, 1.0), 0.0)
            width = ends - starts
            inside = (width > dt) & (width >= tp0 / TP_LEASH) & (width <= tp0 * TP_LEASH) & \
                (np.abs(starts - t00) <= tp0)
            return np.where(inside, out, np.inf)

        start, end = _scan_edges(sse_many, t0, t0 + tp, tp, dt)
        start, end = _zoom_edges(sse_many, start, end, step=max(0.3 * tp / 120, 0.5 * dt) * 2, tol=1e-7 * tp)
        tp_new, t0_new = end - start, start
        if not (math.isfinite(tp_new) and tp_new > dt) or sse((start, end)) > sse((t0, t0 + tp)):
            break
        A = np.column_stack([unit_samples(shape, tp_new, t0_new, tw, dt)] + extra)
        coef, *_ = np.linalg.lstsq(A, xw, rcond=None)
        ap_new = float(coef[0])
        best = (ap_new, tp_new, t0_new, idx)
        tp, t0 = tp_new, t0_new
        if _covers(idx, shape, tp, t0, dt, x.size):
            break
    return best


def _scan_edges(sse_many, start: float, end: float, tp: float, dt: float, sweeps: int = 2):
    """Move each edge of the rectangle to the best of a grid of positions around it.

    With background motion the sum of squares has a local minimum in almost every cell an edge
    crosses; a scan over +-0.15 Tp (at most 121 positions, half a cell apart when that fits) puts
    each edge in the right basin before the grids of :func:`_zoom_edges` close in.
    """
    half = max(0.15 * tp, 10 * dt)
    n = int(min(60, math.ceil(half / (0.5 * dt))))
    offsets = np.linspace(-half, half, 2 * n + 1)
    best = float(sse_many(np.array([start]), np.array([end]))[0])
    for _ in range(sweeps):
        moved = False
        for which in (0, 1):
            starts = start + offsets if which == 0 else np.full(offsets.size, start)
            ends = end + offsets if which == 1 else np.full(offsets.size, end)
            values = sse_many(starts, ends)
            k = int(np.argmin(values))
            if values[k] < best:
                best, start, end, moved = float(values[k]), float(starts[k]), float(ends[k]), True
        if not moved:
            break
    return start, end


def _zoom_edges(sse_many, start: float, end: float, step: float, tol: float):
    """Minimise over both edges on 21 x 21 grids that shrink fivefold around the best point.

    The grid spans +-10 steps; when the best point lies on the border the grid moves there at
    the same size, otherwise it shrinks, until the step is below ``tol`` (s).
    """
    offsets = np.arange(-10, 11)
    best = float(sse_many(np.array([start]), np.array([end]))[0])
    for _ in range(200):  # guard; a handful of levels are needed
        s_grid, e_grid = np.meshgrid(start + step * offsets, end + step * offsets, indexing="ij")
        values = sse_many(s_grid.ravel(), e_grid.ravel())
        k = int(np.argmin(values))
        i, j = divmod(k, offsets.size)
        improved = values[k] < best
        if improved:
            best, start, end = float(values[k]), float(s_grid.flat[k]), float(e_grid.flat[k])
        on_border = not (0 < i < offsets.size - 1 and 0 < j < offsets.size - 1)
        if improved and on_border:
            continue  # the minimum lies beyond this grid: move, same size
        if step < tol:
            break
        step /= 5.0
    return start, end
