"""Fitting acceleration pulses to a record (docs/theory.md section 3; Vassiliou & Makris 2011).

For every candidate shape (rectangular, one-sine, symmetric and antisymmetric Ricker):

1. **Match** the record with the shape over periods and times: the wavelet transform with the
   pulse as mother wavelet (:mod:`pulses.fit.matching`), on a log-spaced grid of periods.  The best match
   maximises the share of the record's energy explained by a pulse of least-squares amplitude.
2. **Refine** ``ap``, ``Tp`` and ``t0`` by least squares on the record's samples inside a window
   around the pulse (Levenberg-Marquardt with the analytic Jacobian; for the rectangle a grid
   search over its two edges, :mod:`pulses.fit.edges`; :mod:`pulses.fit.plain`).  A straight-line baseline is fitted
   together with the pulse inside the window (``baseline=True``), so slow drift of the record
   does not bias the pulse; it is not part of the pulse and not counted in its score.
3. **Weight** (the default, ``weighting="background"``; ``"plain"`` stops after step 2, for
   comparison): the background's spectrum is estimated from the record
   (:class:`pulses.fit.background.Background`), first away from the best plain fit's pulse, then
   from the residual of that shape's fit weighted by the first estimate
   (:func:`pulses.fit.background.estimate_background`); every other shape is refit by least
   squares weighted by the inverse of the second (generalised least squares,
   :func:`pulses.fit.weighted.refine_weighted`), each weighted fit kept unless the record departs
   from the pulse model (Hausman's test, :func:`pulses.fit.weighted.difference_covariance`), and
   the candidates are ranked by the share of the record's energy they explain in the same metric
   (:func:`_weighted`; the plain fit answers where the record does not support the weighting,
   ``PulseFit.weighting``).

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

import numpy as np

from ..record import Record
from ..shapes import SHAPES, make_pulse, shape_class
from .background import estimate_background
from .baseline import pgv as _pgv
from .baseline import significant_duration
from .matching import Matcher, _dot, unit_energy
from .plain import refine, scored
from .results import Candidate, PulseFit
from .weighted import refine_weighted
from .windows import TP_LEASH, pulse_window

#: shapes fitted by default (every registered shape), in the order they are reported on ties
DEFAULT_SHAPES = tuple(SHAPES)
#: ratio between neighbouring periods of the coarse grid.  Half a step (3 %) off the true period,
#: the matched filter still explains 99.8 % of a Ricker's and 97 % of a rectangle's energy, so
#: the search lands in the right basin and least squares does the rest
GRID_RATIO = 1.06
#: for the antisymmetric shapes, a match of the other polarity is refined too when it explains
#: at least this share of what the best match explains
SECOND_START = 0.85


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
        record itself (generalised least squares, :class:`~pulses.fit.background.Background`), and rank the candidates
        by the share of the record's energy they explain in that metric.  More accurate ap and
        Tp, and the shape right more often, on synthetic records with band-limited background
        motion; about twice the cost of the plain fit (docs/validation-fitting.md, "Accuracy on synthetic records").
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
    fits = _plain_fits(x, t, dt, matcher, tps, fitted, energy, baseline)
    # the share of energy explained, in the metric of the least squares used
    scores, weighted_scores = _plain_scores(x, fits, energy), None
    if weighting == "background":
        fits, weighted_scores = _weighted(x, t, dt, fits, scores, energy, baseline, shapes)
        scores = scores if weighted_scores is None else weighted_scores
    ranked = _ranked(record, x, t, amplitude, {shape: fits[shape] for shape in shapes}, scores)
    return PulseFit(record.name, ranked, record.pga, _pgv(record.acc, dt), record.duration,
                    significant_duration(record.acc, dt), "plain" if weighted_scores is None else "background")


def _plain_fits(x, t, dt, matcher, tps, shapes, energy, baseline) -> dict:
    """The best plain fit of each shape from its starts (:func:`_coarse`): shape -> ``(match,
    (ap, Tp, t0, window), samples)``."""
    fits = {}
    for shape in shapes:
        score = -np.inf
        for start in _coarse(matcher, shape, tps, t[-1]):
            trial = refine(x, t, dt, shape, *start, baseline)
            s, p_trial = scored(x, t, dt, shape, trial, energy)
            if s > score:
                score, fits[shape] = s, (start, trial, p_trial)
    return fits


def _ranked(record, x, t, amplitude, fits, scores) -> list:
    """The :class:`Candidate` of each fit (``fits`` on the normalised samples ``x`` of ``record``
    at times ``t`` from its first sample; ``amplitude`` the normalisation), best score first."""
    dt = record.dt
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
    return ranked


def _weighted(x, t, dt, fits, plain_scores, energy, baseline, wanted=None):
    """The weighted least squares of the ``wanted`` shapes (default: all) from their plain fits
    (``fits``: shape -> ``(match, trial, samples)``, every shape of :data:`DEFAULT_SHAPES` at
    least), and their scores: the share of the record's energy each explains in the weighted
    metric; the plain fits and None where the weighting is not used.

    Whether it is used, and the background's spectrum, come from every shape of ``fits`` (the
    best plain fit among them): a shape's weighted fit is the same whichever are ``wanted``.

    It is not used where the record has no background to weight by (the plain fit explains it
    to round-off), nor where it would overturn the plain ranking although the plain winner's own
    weighted refit was refused (:func:`pulses.fit.background.estimate_background`): then the weighted metric rests on
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
    background, best_fit, accepted = estimate_background(x, t, dt, best, fits[best], energy, baseline)
    if background is None:
        return fits, None

    def refit(shape):
        match, trial, _ = fits[shape]
        if shape == best:
            return (match, *best_fit)
        trial = refine_weighted(x, t, dt, shape, match, trial, background, baseline)
        return (match, trial, scored(x, t, dt, shape, trial, energy)[1])

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
