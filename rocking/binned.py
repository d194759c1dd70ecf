"""The check above a record's search width laid out bin by bin, so that it is *separable in a
threshold* (docs/slivers.md, "The check above the search width").

The span ``(w, hi]`` above the search width ``w`` (``hi = min(check_span w, top)``, ``top`` the
no-uplift width; one span, no rounds) is cut into bins ``check_bin_width w`` wide.  Every width the check runs belongs to one bin,
and which widths a bin runs depends only on the search width, the seed and the verdicts and
``max|theta|/alpha`` of the widths run in that bin (the search's own included):

1. a first stage laid over the whole span as :func:`rocking.widths.check_widths` lays it (half of
   its widths uniform in ``log(B / w - 1)``, half uniform in ``B``, jittered), a deterministic
   function of ``w``, ``hi`` and the seed;
2. ``check_stages`` later stages: each bin gets ``floor(check_bin_runs q ** check_power + u)``
   widths, ``q = min(s / check_scale, 1)``, ``s`` the standard deviation of ``min(max|theta|/alpha,
   1)`` over the widths run so far in the bin (1 where one of them failed), ``u`` a uniform draw of
   the seed's per bin and stage: a fixed scale, not the span's largest bin, so that a bin's share
   does not depend on the others (the total varies from record to record; with a performance
   level R the ratios are over R, and :func:`rocking.widths._check_bins` divides the scale by R;
   ``check_bin_runs`` is scaled down where the search's runs alone promise more than
   ``check_budget``, :func:`budgeted`: the search is run whole in every direction);
3. a zoom stage: in each bin, around at most ``check_zoom_peaks`` surviving widths that came
   nearest to failing (``max|theta|/alpha >= check_zoom_ratio``, the largest first, peaks closer
   than two zoom widths counted once), ``check_zoom_points`` jittered widths within
   ``check_zoom_width`` relative, kept in the bin.

So, for any threshold ``T``, the widths the check runs in the bins above ``T``, and their verdicts,
are those a check of those bins alone runs (``SearchSettings.check_above``): a check above ``T``
runs the bins whose upper edge lies above ``T``, and the bins below them down to the first that
holds a width run at or below ``T`` (usually none more: the search's fine zone puts widths 0.05 %
apart in every bin up to 20 % above ``w``), so that the bracket above the widest failing width,
which the design width is refined in, is the full check's wherever it reaches above ``T``
(:func:`check`).
"""
from __future__ import annotations

import math

import numpy as np


def span_top(width, top, settings) -> float:
    """The top of the span (m): ``check_span`` times ``width`` or ``top``, whichever is smaller
    (one span: no rounds)."""
    return float(min(float(settings.check_span) * width, top))


def edges(width, hi, settings) -> np.ndarray:
    """The bins' edges (m, ascending) from ``width`` to ``hi``, ``check_bin_width width`` apart
    (the last bin cut at ``hi``); empty where the span is empty."""
    if not hi > width * (1.0 + settings.check_first):
        return np.zeros(0)
    k = max(1, math.ceil((hi / width - 1.0) / settings.check_bin_width - 1e-9))
    e = width * (1.0 + settings.check_bin_width * np.arange(k + 1))
    e[-1] = hi
    return e


def first_widths(width, hi, settings, seed) -> np.ndarray:
    """The first stage's widths (m, ascending) over ``(width, hi]``: ``check_runs (1 -
    check_follow)`` of them, laid out as :func:`rocking.widths.check_widths` says (which calls
    this with ``hi`` the span's top)."""
    n = int(settings.check_runs) - int(round(settings.check_follow * int(settings.check_runs)))
    if n <= 0 or not hi > width * (1.0 + settings.check_first):
        return np.zeros(0)
    rng = np.random.default_rng(seed)
    n_near = int(round(settings.check_near * n))

    def jittered(k):
        return (np.arange(k) + rng.random(k)) / k

    d_hi = hi / width - 1.0
    near = width * (1.0 + settings.check_first * (d_hi / settings.check_first) ** jittered(n_near))
    spread = width + (hi - width) * jittered(n - n_near)
    return np.sort(np.concatenate([near, spread]))


def most_runs(width, hi, settings) -> int:
    """The most widths the check can run over ``(width, hi]``: the first stage, and in every bin
    ``check_bin_runs`` a later stage and ``check_zoom_peaks check_zoom_points`` in the zoom."""
    k = edges(width, hi, settings).size - 1
    per_bin = int(settings.check_stages) * int(math.floor(settings.check_bin_runs)) \
        + int(settings.check_zoom_peaks) * int(settings.check_zoom_points)
    return first_widths(width, hi, settings, 0).size + max(k, 0) * per_bin


def bin_of(e, widths) -> np.ndarray:
    """The bin of each width (-1 below the span or at its foot, ``len(e) - 1`` above it)."""
    return np.searchsorted(e, np.asarray(widths, dtype=float), side="left") - 1


def follow_widths(e, on, widths, ratio, failed, settings, seed, stage) -> np.ndarray:
    """One later stage's widths (m, ascending) in the bins ``on`` (bool per bin), each bin's count
    from its own runs (``widths``, ``ratio``, ``failed``) against the fixed scale."""
    k = e.size - 1
    most = int(math.ceil(settings.check_bin_runs)) + 1
    rng = np.random.default_rng([seed, stage])
    u = rng.random(k)                       # drawn for every bin: a bin's draws never depend on
    v = rng.random((k, most))               # which other bins run
    alloc = np.floor(settings.check_bin_runs * weights(e, widths, ratio, failed, settings) + u).astype(int)
    alloc[~on] = 0
    # strata (e_j, e_j+1]: a width on a lower edge would belong to the bin below
    x = [e[j] + (e[j + 1] - e[j]) * (np.arange(a) + 1.0 - v[j, :a]) / a
         for j, a in enumerate(alloc) if a > 0]
    return np.sort(np.concatenate(x)) if x else np.zeros(0)


def weights(e, widths, ratio, failed, settings) -> np.ndarray:
    """Each bin's ``q ** check_power`` from its own runs (``widths``, ``ratio``, ``failed``)."""
    k = e.size - 1
    idx = bin_of(e, widths)
    inside = (idx >= 0) & (idx < k)
    idx = idx[inside]
    ratio = np.minimum(np.asarray(ratio, dtype=float)[inside], 1.0)
    failed = np.asarray(failed, dtype=bool)[inside]
    count = np.bincount(idx, minlength=k)
    mean = np.bincount(idx, weights=ratio, minlength=k) / np.maximum(count, 1)
    var = np.bincount(idx, weights=ratio * ratio, minlength=k) / np.maximum(count, 1) - mean * mean
    spread = np.where(count >= 2, np.sqrt(np.maximum(var, 0.0)), 0.0)
    q = np.minimum(spread / settings.check_scale, 1.0)
    q[np.bincount(idx[failed], minlength=k) > 0] = 1.0
    return q ** settings.check_power


def budgeted(e, seen, settings):
    """``settings`` with ``check_bin_runs`` scaled down where the search's own runs (run whole in
    every direction, so still separable) promise more than ``check_budget`` widths to the later
    stages: a record irregular everywhere gets the budget, not 20 widths a stage in every bin."""
    if settings.check_budget <= 0 or e.size < 2:
        return settings
    expected = int(settings.check_stages) * settings.check_bin_runs * weights(e, *seen, settings).sum()
    if expected <= settings.check_budget:
        return settings
    return settings.replace(check_bin_runs=settings.check_bin_runs * settings.check_budget / expected)


def zoom_widths(e, on, widths, ratio, failed, settings, seed) -> np.ndarray:
    """The zoom stage's widths (m, ascending) in the bins ``on``: around each bin's surviving
    widths nearest to failing (above ``check_zoom_ratio``), kept in their bin."""
    k, m = e.size - 1, int(settings.check_zoom_points)
    d, most = settings.check_zoom_width, int(settings.check_zoom_peaks)
    widths, ratio = np.asarray(widths, dtype=float), np.asarray(ratio, dtype=float)
    idx = bin_of(e, widths)
    keep = (idx >= 0) & (idx < k) & ~np.asarray(failed, dtype=bool) & (ratio >= settings.check_zoom_ratio)
    rng = np.random.default_rng([seed, int(settings.check_stages) + 1])
    v = rng.random((k, most, m))
    out = []
    if m <= 0 or most <= 0:
        return np.zeros(0)
    for j in np.unique(idx[keep]):
        if not on[j]:
            continue
        sel = keep & (idx == j)
        peaks = []
        for b in widths[sel][np.argsort(-ratio[sel], kind="stable")]:
            if len(peaks) >= most:
                break
            if all(abs(b / p - 1.0) > 2.0 * d for p in peaks):
                peaks.append(float(b))
        for i, b in enumerate(peaks):
            x = b * (1.0 + d * (2.0 * (np.arange(m) + v[j, i]) / m - 1.0))
            out.append(x[(x > e[j]) & (x <= e[j + 1])])
    return np.sort(np.concatenate(out)) if out else np.zeros(0)


def _run_bins(e, on, first, evaluate, seen, settings, seed):
    """Every stage of the bins ``on``: ``(widths, failed, ratio)`` in the order run.  ``first``:
    the first stage's widths (all bins); ``seen``: the search's runs."""
    idx = bin_of(e, first)
    x = first[(idx >= 0) & (idx < on.size) & on[np.clip(idx, 0, on.size - 1)]]
    f, r = _evaluate(evaluate, x)
    sx, sf, sr = seen
    stages = int(settings.check_stages)
    for stage in range(1, stages + 2):
        allx, allf, allr = (np.concatenate([x, sx]), np.concatenate([f, sf]), np.concatenate([r, sr]))
        if stage <= stages:
            y = follow_widths(e, on, allx, allr, allf, settings, seed, stage)
        else:
            y = zoom_widths(e, on, allx, allr, allf, settings, seed)
        fy, ry = _evaluate(evaluate, y)
        x, f, r = np.concatenate([x, y]), np.concatenate([f, fy]), np.concatenate([r, ry])
    return x, f, r


def _evaluate(evaluate, x):
    if not x.size:
        return np.zeros(0, dtype=bool), np.zeros(0)
    f, r = evaluate(x)
    return np.asarray(f, dtype=bool), np.asarray(r, dtype=float)


def check(width, top, evaluate, seen, settings, seed, above=0.0):
    """The check above the search width ``width`` (m) in the bins above ``above`` (m; 0: every
    bin): ``(widths, failed, ratio)`` run, and the span's top (m).

    ``seen``: the search's runs ``(widths, failed, ratio)``.  The bins run are those whose upper
    edge lies above ``above``, and below them, one at a time, until the lowest bin run, or the
    search, has a width run in ``(its lower edge, above]``: then a widest failing width of the
    full check at or below ``above`` whose bracket reaches above ``above`` is one of those run.
    """
    hi = span_top(width, top, settings)
    e = edges(width, hi, settings)
    seen = tuple(np.asarray(v, dtype=dt) for v, dt in zip(seen, (float, bool, float)))
    if not e.size:
        return (np.zeros(0), np.zeros(0, dtype=bool), np.zeros(0)), hi
    first = first_widths(width, hi, settings, seed)
    settings = budgeted(e, seen, settings)
    k = e.size - 1
    lowest = int(np.searchsorted(e[1:], above, side="right"))   # first bin whose top is above
    on = np.zeros(k, dtype=bool)
    on[lowest:] = True
    out = _run_bins(e, on, first, evaluate, seen, settings, seed) if lowest < k else \
        (np.zeros(0), np.zeros(0, dtype=bool), np.zeros(0))
    while lowest > 0:
        foot = e[lowest]
        runs = np.concatenate([seen[0], out[0]])
        if np.any((runs > foot) & (runs <= above)):
            break
        lowest -= 1
        one = np.zeros(k, dtype=bool)
        one[lowest] = True
        more = _run_bins(e, one, first, evaluate, seen, settings, seed)
        out = tuple(np.concatenate([a, b]) for a, b in zip(out, more))
    return out, hi
