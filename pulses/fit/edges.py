"""Least squares of a boxcar shape (the rectangular pulse): a search over its two edges, since
the sum of squares of a cell-averaged rectangle has a kink in every cell an edge crosses."""
from __future__ import annotations

import math

import numpy as np

from .matching import _dot
from .windows import TP_LEASH, covers, unit_samples


def refine_edges(x, t, dt, shape, best, window, baseline, tp0, t00):
    """Least squares for a boxcar shape (the rectangular pulse): a search over its two edges.

    The cell-averaged rectangle is piecewise linear in its edges, with a kink each time an edge
    crosses a cell boundary, and with background motion the sum of squares has a shallow local
    minimum in almost every cell: a gradient method stalls.  The edges are scanned one at a time
    over +-0.15 Tp, then both together on grids that shrink to 1e-7 Tp.  The amplitude (and
    the baseline) are solved linearly for each pair of edges, in O(1) from prefix sums
    (:class:`_EdgeCost`).
    """
    ap, tp, t0, _ = best
    for _ in range(3):
        idx = window(tp, t0)
        if idx.stop - idx.start < 6:
            break
        tw, xw = t[idx], x[idx]
        cost = _EdgeCost(tw, xw, dt, baseline, tp0, t00)
        start, end = _scan_edges(cost.many, t0, t0 + tp, tp, dt)
        start, end = _zoom_edges(cost.many, start, end, step=max(0.3 * tp / 120, 0.5 * dt) * 2, tol=1e-7 * tp)
        tp_new, t0_new = end - start, start
        if not (math.isfinite(tp_new) and tp_new > dt) or cost.one((start, end)) > cost.one((t0, t0 + tp)):
            break
        extra = [np.ones_like(tw), tw - cost.tc] if baseline else []
        A = np.column_stack([unit_samples(shape, tp_new, t0_new, tw, dt)] + extra)
        coef, *_ = np.linalg.lstsq(A, xw, rcond=None)
        ap_new = float(coef[0])
        best = (ap_new, tp_new, t0_new, idx)
        tp, t0 = tp_new, t0_new
        if covers(idx, shape, tp, t0, dt, x.size):
            break
    return best


class _EdgeCost:
    """The sum of squares left by a cell-averaged rectangle on the samples ``xw`` at times ``tw``
    (step ``dt``), as a function of its two edges (s), its amplitude and the straight-line
    baseline (with ``baseline``) solved linearly; trials whose width or start leave the leash
    around the match ``(tp0, t00)`` cost infinity in :meth:`many`."""

    def __init__(self, tw, xw, dt, baseline, tp0, t00):
        self.tw, self.dt, self.baseline, self.tp0, self.t00 = tw, dt, baseline, tp0, t00
        self.tc = float(tw.mean())
        n = self.n = tw.size
        ramp = self.ramp = tw - self.tc if baseline else np.zeros(n)
        # with the baseline (columns 1 and t - tc, orthogonal since tc is the mean time) projected
        # out, the amplitude and the remaining sum of squares follow from a few dot products
        self.n_ramp = _dot(ramp, ramp) or 1.0
        self.x_perp = xw - (xw.mean() + ramp * _dot(ramp, xw) / self.n_ramp if baseline else 0.0)
        self.sxx = _dot(self.x_perp, self.x_perp)
        self.prefix_x = np.concatenate([[0.0], np.cumsum(self.x_perp)])
        self.prefix_r = np.concatenate([[0.0], np.cumsum(ramp)])

    def one(self, edges) -> float:
        """The sum of squares with the edges ``(start, end)``."""
        # the cell-averaged rectangle is 1 on whole cells and a fraction on the two edge
        # cells, so its dot products with x, 1 and (t - tc) come from prefix sums in O(1)
        tw, dt, n, sxx = self.tw, self.dt, self.n, self.sxx
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
        mx = self.prefix_x[hi] - self.prefix_x[lo]
        m1 = float(hi - lo)
        mr = self.prefix_r[hi] - self.prefix_r[lo]
        mm = m1
        for k, w in parts:
            if 0 <= k < n:
                mx += w * self.x_perp[k]
                m1 += w
                mr += w * self.ramp[k]
                mm += w * w
        if self.baseline:  # squared norm of the pulse column after projecting out the baseline
            mm -= m1 * m1 / n + mr * mr / self.n_ramp
        if mm <= 1e-12:
            return sxx
        return sxx - mx * mx / mm

    def many(self, starts, ends) -> np.ndarray:
        """:meth:`one` for arrays of edge pairs (the scan's many trials at once)."""
        tw, dt, n, tp0 = self.tw, self.dt, self.n, self.tp0
        k1 = np.floor((starts - tw[0]) / dt + 0.5).astype(int)
        k2 = np.floor((ends - tw[0]) / dt + 0.5).astype(int)
        same = k1 == k2
        w1 = np.where(same, (ends - starts) / dt, (tw[0] + (k1 + 0.5) * dt - starts) / dt)
        w2 = np.where(same, 0.0, (ends - (tw[0] + (k2 - 0.5) * dt)) / dt)
        lo = np.minimum(np.maximum(k1 + 1, 0), n)  # np.clip, without its per-call cost
        hi = np.maximum(np.minimum(np.maximum(k2, 0), n), lo)
        mx = self.prefix_x[hi] - self.prefix_x[lo]
        m1 = (hi - lo).astype(float)
        mr = self.prefix_r[hi] - self.prefix_r[lo]
        mm = m1.copy()
        for k, w in ((k1, w1), (k2, w2)):
            ok = (k >= 0) & (k < n)
            kc = np.minimum(np.maximum(k, 0), n - 1)
            w = np.where(ok, w, 0.0)
            mx += w * self.x_perp[kc]
            m1 += w
            mr += w * self.ramp[kc]
            mm += w * w
        if self.baseline:
            mm = mm - m1 * m1 / n - mr * mr / self.n_ramp
        out = self.sxx - np.where(mm > 1e-12, mx * mx / np.where(mm > 1e-12, mm, 1.0), 0.0)
        width = ends - starts
        inside = (width > dt) & (width >= tp0 / TP_LEASH) & (width <= tp0 * TP_LEASH) & \
            (np.abs(starts - self.t00) <= tp0)
        return np.where(inside, out, np.inf)


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
