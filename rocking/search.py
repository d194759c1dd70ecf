"""What the exact design searches share: their settings, the batch solver call, and the generic
transition finder (scan, then bracketed refinement of every verdict change).

Overturning is not monotonic in either the amplitude or the slenderness, so every exact answer is
found by a scan fine enough to see the islands (denser just above the highest failure) followed by
bracketed refinement of every verdict change found (vectorised: all brackets of all problems are
cut together, one batch-solver call per step).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from . import scan
from .block import Block

#: failure criteria: which verdict of the solver counts as failure
CRITERIA = ("overturn", "exceed")


@dataclass(frozen=True)
class SearchSettings:
    """Settings of the exact design searches (a value: pass a changed copy, ``replace(...)``).

    Pulses (minimum slenderness, critical amplitudes, a pulse's search width): ``n_scan``
    uniformly spaced scan points plus a geometric tail of ``n_tail`` points towards zero (the
    smallest uniform point divided by 2, 4, ... ``2**n_tail``); above the highest failing point
    found, ``zone_points`` more points over ``zone_fraction`` of its value, repeated while failures
    keep turning up in the zone's upper half (at most ``zone_rounds`` times: failure slivers just
    above the main boundary of long pulses are thinner than the coarse step; ``python
    benchmarks/bench_design.py --brute`` checks the result against a 3000-point brute-force scan,
    agreement 5e-4 relative on 240 hard cases); brackets cut in ``ksection`` parts per step
    (fewer batch calls than bisection) until narrower than ``rtol`` relative.

    Records (the search width, :func:`rocking.widths.record_width`): ``record_scan`` widths
    geometric from ``top record_low`` to the no-uplift width ``top`` (neighbours 3.3 % apart with
    the defaults), plus a tail of ``record_tail`` widths halving towards zero
    (``record_spacing="uniform"``: ``record_scan`` uniform widths up to ``top``, the former scan,
    kept to compare in benchmarks/bench_design.py).  The fine zone above each candidate answer
    ``w``: every width of the fixed grid ``top (1 + record_fine)^-k`` in
    ``(w, w (1 + record_fine_span)]`` is run (0.05 % apart: failing slivers of real records are
    often thinner than 0.2 %, and lie up to ~25 % above the main transition; README "Design" has
    the measurements), from its widest width down in batches (one batch of the batch engine's
    lanes per core): the grid's blocks of ``record_chunk`` indices ``k``, fixed on the grid, so
    that a level's and its overturning design's searches run the same batches where their zones
    overlap; stopping at the first batch with a failure.  An optional extra
    zone (``record_zone_points``, off by default: the fine zone covers it) of widths ``w (1 + d)``,
    ``d`` geometric from ``record_zone_first`` to ``record_zone_fraction``;
    ``record_zone_first / 4`` is also the bisection tolerance of candidates.  Above the
    candidate, every gap between scanned widths wider than ``record_gap`` (relative) is halved
    while either end came within ``record_near`` of tipping (``max|theta|/alpha >=
    record_near``: isolated failing bands of real records sit where the block nearly overturns);
    at most ``record_rounds`` rounds (a failure found above the candidate moves it up).

    The check in rounds above a record's search width ``w`` (``check_layout="rounds"``, the former
    default; docs/slivers.md;
    :func:`rocking.widths.check_widths`, :func:`rocking.widths.follow_widths`): ``check_runs``
    widths from ``w`` to ``check_span`` times ``w`` or the no-uplift width, whichever is smaller,
    jittered (one random width in each of equal strata; seeded from the record, so a re-run gives
    the same widths; none on the search's grid).  A first stage: a share ``check_near`` of its
    widths uniform in ``log(B / w - 1)`` from ``check_first`` up (failing slivers cluster just
    above ``w``), the rest uniform in ``B``.  Then ``check_stages`` stages share ``check_follow``
    of the runs, each spread over ``check_bins`` equal bins of the span in proportion to
    ``q**check_power``, ``q`` the standard deviation of ``min(max|theta|/alpha, 1)`` over the
    widths run so far in the bin, the search's own widths above ``w`` included (over the largest
    bin's), 1 in a bin where a width failed:
    failing slivers far above ``w`` are points where the response jumps, and they lie where it
    is irregular from one width to the next, not where the block rocks hardest (on the shared
    records the ratio next to a failing width is often that of the smooth surroundings, 0.3-0.6,
    while the bin's spread is among the span's largest).  The last stage (a share
    ``check_zoom`` of ``check_runs``, taken from the later stages' share) zooms in: around the
    surviving widths of the span that came nearest to failing (the largest
    ``max|theta|/alpha``), ``check_zoom_points`` jittered widths each within
    ``check_zoom_width`` relative (failing slivers come in clusters flanked by widths that rock
    nearly as hard; :func:`rocking.widths.zoom_widths`).  0 runs switch the check off; so does
    ``check_above`` (m; a pair's design width found in other directions, pipeline/batch/passes.py) at
    or above ``min(check_span ** check_rounds w, no-uplift width)``, the widest width the
    rounds could reach (each round's span is at most ``check_span`` times the width the round
    before left): such a check could not find a failing width above it; and so are the rounds
    left after one where that holds from the width it left.  The
    sizes were chosen from
    ``benchmarks/bench_slivers.py`` (its tables are in docs/slivers.md).

    ``check_layout="bins"`` (the default; :mod:`rocking.binned`, docs/slivers.md, "A check
    separable in a threshold"): one span ``(w, min(check_span w, top)]`` cut into bins
    ``check_bin_width w`` wide.  The first stage as above; then ``check_stages`` stages giving
    each bin ``floor(check_bin_runs q**check_power + u)`` widths, ``q`` its spread over the fixed
    ``check_scale`` (at most 1; 1 where a width in it failed), ``u`` a seeded uniform draw; then a
    zoom around at most ``check_zoom_peaks`` surviving widths of each bin with
    ``max|theta|/alpha >= check_zoom_ratio``.  Where the search's own runs (``check_budget`` > 0)
    promise the later stages more than ``check_budget`` widths (``check_stages check_bin_runs
    sum(q**check_power)`` over the bins, from the search's runs alone), ``check_bin_runs`` is scaled
    down to it: a record irregular everywhere gets the budget.  A bin's widths depend only on its
    own runs and the search's, so
    ``check_above`` runs only the bins above it (and below it down to the first with a width run
    at or below it), and gives exactly the full check's widths, verdicts and design width above it
    (pipeline/batch/passes.py).  The number of runs varies from record to record (only the first
    stage's, ``check_runs (1 - check_follow)``, is fixed); ``check_zoom`` and ``check_rounds``
    belong to the rounds layout (``check_layout="rounds"``, the former default, described above).

    The design width: where the check finds a failing width above the search's answer, the
    bracket above the widest failing width (up to the next width run, which survived) is bisected
    to ``design_rtol`` relative, and its surviving end is the design width
    (:attr:`rocking.widths.RequiredWidth.width`).  Under a record it is then raised to the
    narrowest number of ``design_digits`` significant digits at or above it that survives (run
    there; a failure there is bracketed and bisected in turn), so that the width as the reports
    print it (6 digits) is a width that was run and survived: a width 1e-6 above a failing one
    can print below it.  The rounds layout runs ``check_rounds`` rounds sharing
    ``check_runs``, each above the design width the rounds before it left (its span starts
    there).  ``check_seed``: the check's seed (None: made
    from the record's samples and the column, so a re-run gives the same widths).
    """

    n_scan: int = 64
    n_tail: int = 10
    zone_points: int = 160
    zone_fraction: float = 0.15
    zone_rounds: int = 4
    ksection: int = 8
    rtol: float = 1e-9
    record_scan: int = 128
    record_low: float = 1.0 / 64
    record_tail: int = 4
    record_spacing: str = "geometric"
    record_fine: float = 5e-4
    record_fine_span: float = 0.2
    record_zone_points: int = 0
    record_zone_first: float = 1e-3
    record_zone_fraction: float = 0.15
    record_gap: float = 0.01
    record_near: float = 0.6
    record_rounds: int = 12
    record_chunk: int = 32
    check_runs: int = 1500
    check_span: float = 1.5
    check_near: float = 0.5
    check_first: float = 1e-4
    check_follow: float = 0.8
    check_stages: int = 5
    check_bins: int = 100
    check_power: float = 3.0
    design_rtol: float = 1e-6
    design_digits: int = 6
    check_seed: int | None = None
    check_rounds: int = 2
    check_above: float = 0.0
    check_zoom: float = 0.3
    check_zoom_points: int = 4
    check_zoom_width: float = 2e-4
    check_layout: str = "bins"
    check_bin_width: float = 0.005
    check_scale: float = 0.07
    check_bin_runs: float = 20.0
    check_zoom_ratio: float = 0.9
    check_zoom_peaks: int = 2
    check_budget: float = 0.0

    def __post_init__(self):
        for name in ("n_scan", "ksection", "record_scan", "record_chunk"):
            if getattr(self, name) < 1 + (name == "ksection"):
                raise ValueError(f"SearchSettings.{name} is too small: {getattr(self, name)!r}")
        if self.check_runs < 0:
            raise ValueError(f"SearchSettings.check_runs must be 0 or more, got {self.check_runs!r}")
        if not self.check_span > 1.0:
            raise ValueError(f"SearchSettings.check_span must be above 1, got {self.check_span!r}")
        if not 0.0 <= self.check_near <= 1.0:
            raise ValueError(f"SearchSettings.check_near must be in [0, 1], got {self.check_near!r}")
        if not 0.0 < self.check_first < self.check_span - 1.0:
            raise ValueError("SearchSettings.check_first must be in (0, check_span - 1), got "
                             f"{self.check_first!r}")
        if not 0.0 <= self.check_follow < 1.0 or self.check_bins < 1 or self.check_stages < 1:
            raise ValueError("SearchSettings.check_follow must be in [0, 1), check_bins and "
                             f"check_stages at least 1, got {self.check_follow!r}, "
                             f"{self.check_bins!r}, {self.check_stages!r}")
        if not (0.0 <= self.check_zoom < self.check_follow or self.check_zoom == 0.0) \
                or self.check_zoom_points < 0 or not 0.0 < self.check_zoom_width < 1.0:
            raise ValueError("SearchSettings.check_zoom must be in [0, check_follow), "
                             "check_zoom_points 0 or more, check_zoom_width in (0, 1), got "
                             f"{self.check_zoom!r}, {self.check_zoom_points!r}, "
                             f"{self.check_zoom_width!r}")
        if self.check_layout not in ("rounds", "bins") or not 0.0 < self.check_bin_width \
                or not self.check_scale > 0.0 or self.check_bin_runs < 0 or self.check_zoom_peaks < 0 \
                or self.check_budget < 0:
            raise ValueError("SearchSettings.check_layout must be 'rounds' or 'bins', check_bin_width "
                             "and check_scale positive, check_bin_runs and check_zoom_peaks 0 or more, "
                             f"got {self.check_layout!r}, {self.check_bin_width!r}, "
                             f"{self.check_scale!r}, {self.check_bin_runs!r}, {self.check_zoom_peaks!r}")
        if self.check_rounds < 1:
            raise ValueError(f"SearchSettings.check_rounds must be at least 1, got {self.check_rounds!r}")
        if not (isinstance(self.design_digits, int) and 1 <= self.design_digits <= 15):
            raise ValueError(f"SearchSettings.design_digits must be a whole number in [1, 15], got "
                             f"{self.design_digits!r}")
        if not 0.0 < self.design_rtol < 1.0:
            raise ValueError(f"SearchSettings.design_rtol must be in (0, 1), got {self.design_rtol!r}")
        if not self.rtol > 0:
            raise ValueError(f"SearchSettings.rtol must be positive, got {self.rtol!r}")
        if self.record_spacing not in ("geometric", "uniform"):
            raise ValueError("SearchSettings.record_spacing must be 'geometric' or 'uniform', "
                             f"got {self.record_spacing!r}")

    @property
    def check_reach(self) -> float:
        """How far above the search width ``w`` the check looks, over ``w`` (before the no-uplift
        width cuts it): one span, ``check_span``, for the binned layout; ``check_span **
        check_rounds`` for the rounds (each round's span is at most ``check_span`` times the width
        the round before left)."""
        if self.check_layout == "bins":
            return float(self.check_span)
        return float(self.check_span) ** int(self.check_rounds)

    def replace(self, **changes) -> "SearchSettings":
        """A copy with ``changes``; ``None`` values are ignored (keyword arguments left unset)."""
        changes = {k: v for k, v in changes.items() if v is not None}
        return dataclasses.replace(self, **changes) if changes else self


#: the settings used when none are given
DEFAULT_SETTINGS = SearchSettings()


def _batch(blocks, excitation, scales=None, *, grid=False, model="fast", until_final=False):
    """Call :func:`rocking.simulate_many` (looked up at call time: the solver is a sibling module);
    ``until_final``: its runs stop once their verdicts and peaks are final."""
    import rocking

    if model in ("fast", "linear"):
        return rocking.simulate_many(blocks, excitation, scales, grid=grid, model=model,
                                     until_final=until_final)
    # any other model (the slow "reference" yardstick): one simulate() per run
    blocks = [blocks] if isinstance(blocks, Block) else list(blocks)
    scales = np.atleast_1d(np.asarray(1.0 if scales is None else scales, dtype=float))
    if grid:
        shape = (len(blocks), scales.size)
        pairs = [(b, s) for b in blocks for s in scales]
    else:
        idx_b, idx_s = np.broadcast_arrays(np.arange(len(blocks)), np.arange(scales.size))
        shape = idx_b.shape
        pairs = [(blocks[i], scales[j]) for i, j in zip(idx_b.ravel(), idx_s.ravel())]
    runs = [rocking.simulate(b, excitation.scaled(float(s)), model=model, history=False)
            for b, s in pairs]

    class _Result:
        pass

    res = _Result()
    for name in ("overturned", "exceeded_alpha", "max_rotation", "max_rotation_ratio"):
        res.__dict__[name] = np.array([getattr(r, name) for r in runs]).reshape(shape)
    return res


def check_limit(limit):
    """``limit`` as a float in (0, 1], or None (overturning); ValueError otherwise."""
    if limit is None:
        return None
    try:
        value = float(limit)
    except (TypeError, ValueError):
        raise ValueError(f"limit must be a number in (0, 1] (max|theta|/alpha), got {limit!r}") from None
    if not 0.0 < value <= 1.0:
        raise ValueError(f"limit must lie in (0, 1] (max|theta|/alpha), got {limit!r}")
    return value


def _failed(result, criterion, limit=None):
    """Failure verdicts of a batch: ``limit`` R (a performance level) fails a run whose
    ``max|theta|/alpha`` exceeds R (or that overturned); without it, ``criterion`` decides."""
    if limit is not None:
        return (np.asarray(result.overturned, dtype=bool)
                | (np.asarray(result.max_rotation_ratio, dtype=float) > limit))
    if criterion == "overturn":
        return np.asarray(result.overturned, dtype=bool)
    return np.asarray(result.exceeded_alpha, dtype=bool) | np.asarray(result.overturned, dtype=bool)


def _check_criterion(criterion):
    if criterion not in CRITERIA:
        raise ValueError(f"criterion must be one of {CRITERIA}, got {criterion!r}")


def _peak(excitation) -> float:
    """Peak absolute ground acceleration of a pulse or a record, m/s^2."""
    if hasattr(excitation, "pga"):
        return float(excitation.pga)
    return abs(float(excitation.ap))


@dataclass
class _Scan:
    """Outcome of a scan-and-refine over many independent 1-D problems."""

    brackets: list         # per problem: list of (lo, hi, fail_lo, fail_hi), refined, ascending
    runs: int              # number of solver runs
    calls: int             # number of batch-solver calls


def _scan_refine(evaluate, x, settings, known=None, zone=True, refine="all", max_iter=100):
    """Scan every problem on its abscissae ``x`` and refine every verdict change.

    ``evaluate(idx, xs)`` returns the failure verdicts of problems ``idx`` at abscissae ``xs``
    (1-D arrays of equal length) in one batch.  ``known`` is an optional boolean mask of scan
    points whose verdict is known to be "survive" without running (e.g. above the uplift limit).
    With ``zone`` the region just above each problem's highest failing point is scanned densely
    (``settings.zone_points`` points over ``settings.zone_fraction``).  Brackets are then cut in
    ``settings.ksection`` parts per step, all together, until narrower than ``settings.rtol``
    relative; where a step reveals more than one change inside a bracket the highest is followed
    (so the top fail-to-survive transition is always the highest one found).  ``refine="top"``
    refines only each problem's top fail-to-survive bracket (``pipeline run``, which needs only
    the answer); the other changes are then reported at scan resolution.  ``ksection=2``
    (bisection) needs about half the runs of the default in twice as many batch calls: cheaper
    when only a few problems are refined at once.
    """
    n_zone, rtol = int(settings.zone_points), settings.rtol
    x = np.asarray(x, dtype=float)
    n_prob, n_pts = x.shape
    fail = np.zeros(x.shape, dtype=bool)
    run = np.ones(x.shape, dtype=bool) if known is None else ~np.asarray(known, dtype=bool)
    idx, col = np.nonzero(run)
    runs, calls = int(idx.size), 0
    if idx.size:
        fail[idx, col] = evaluate(idx, x[idx, col])
        calls += 1
    xs = [x[i] for i in range(n_prob)]
    fs = [fail[i] for i in range(n_prob)]
    if zone:
        r, c = scan.zone_points(evaluate, xs, fs, x[:, -1], n_zone, settings.zone_fraction, settings.zone_rounds)
        runs, calls = runs + r, calls + c
    # brackets: every change of verdict between neighbouring scan points
    prob, lo, hi, flo, fhi = scan.brackets(xs, fs)
    if refine == "top":
        # only the last fail->survive change of each problem; the rest stay at scan resolution
        top_mask = np.zeros(prob.size, dtype=bool)
        for i in np.unique(prob):
            cand = np.nonzero((prob == i) & flo & ~fhi)[0]
            if cand.size:
                top_mask[cand[-1]] = True
        rough = ~top_mask
        done_p, done_lo, done_hi = [prob[rough]], [lo[rough]], [hi[rough]]
        done_flo, done_fhi = [flo[rough]], [fhi[rough]]
        prob, lo, hi, flo, fhi = prob[top_mask], lo[top_mask], hi[top_mask], flo[top_mask], fhi[top_mask]
    else:
        done_p, done_lo, done_hi, done_flo, done_fhi = [], [], [], [], []
    done, rest, r, c = scan.ksect(evaluate, (prob, lo, hi, flo, fhi), int(settings.ksection), rtol, max_iter)
    runs, calls = runs + r, calls + c
    parts = [d0 + d + [x] for d0, d, x in zip((done_p, done_lo, done_hi, done_flo, done_fhi), done, rest)]
    cat = lambda parts, dt: np.concatenate(parts).astype(dt) if parts else np.zeros(0, dt)
    prob, lo, hi = cat(parts[0], int), cat(parts[1], float), cat(parts[2], float)
    flo, fhi = cat(parts[3], bool), cat(parts[4], bool)
    order = np.lexsort((lo, prob))
    brackets = [[] for _ in range(n_prob)]
    for m in order:
        brackets[prob[m]].append((float(lo[m]), float(hi[m]), bool(flo[m]), bool(fhi[m])))
    return _Scan(brackets=brackets, runs=runs, calls=calls)


def _scan_points(top, n_scan, n_tail):
    """Scan abscissae on ``(0, top]``: a geometric tail towards 0, then ``n_scan`` uniform points."""
    top = np.asarray(top, dtype=float)[:, None]
    uniform = np.arange(1, n_scan + 1) / n_scan
    tail = uniform[0] * 2.0 ** -np.arange(n_tail, 0, -1)
    return top * np.concatenate([tail, uniform])[None, :]

