"""The scan-and-refine steps of the searches over a verdict (fails / survives) along an abscissa:
add points above the highest failure, find the brackets where the verdict changes, cut brackets
until narrow.  Many problems at once: ``evaluate(idx, xs)`` gives the failure verdicts of problems
``idx`` at abscissae ``xs`` (1-D arrays of equal length) in one batch.

Used by the minimum slenderness search (:func:`rocking.search._scan_refine`) and the critical
scale (:func:`rocking.fragility.critical_scale`).
"""
from __future__ import annotations

import numpy as np


def zone_points(evaluate, xs, fs, top, n_zone, zone_fraction, zone_rounds):
    """Scan densely just above each problem's highest failing point: ``n_zone`` points over
    ``zone_fraction`` of it, again while the highest failure moves up by more than half the zone.

    ``xs``, ``fs`` (lists, one sorted array of abscissae and verdicts per problem) get the new
    points in place; ``top``: each problem's last abscissa (points stay below it).  Returns
    ``(runs, calls)``."""
    runs = calls = 0
    todo = [i for i in range(len(xs)) if fs[i].any()]
    prev = {i: -np.inf for i in todo}
    for _ in range(zone_rounds):
        pi, px = [], []
        for i in todo:
            xf = xs[i][np.nonzero(fs[i])[0][-1]]
            hi = min(top[i], xf * (1.0 + zone_fraction))
            z = xf + (hi - xf) * np.arange(1, n_zone + 1) / n_zone
            z = z[z < top[i]]
            prev[i] = (xf, hi)
            pi.append(np.full(z.size, i))
            px.append(z)
        if not pi:
            break
        pi, px = np.concatenate(pi), np.concatenate(px)
        if not px.size:
            break
        pf = np.asarray(evaluate(pi, px), dtype=bool)
        runs += int(px.size)
        calls += 1
        nxt = []
        for i in todo:
            sel = pi == i
            xx = np.concatenate([xs[i], px[sel]])
            ff = np.concatenate([fs[i], pf[sel]])
            order = np.argsort(xx, kind="stable")
            xs[i], fs[i] = xx[order], ff[order]
            xf0, hi = prev[i]
            new_top = xs[i][np.nonzero(fs[i])[0][-1]]
            if new_top > xf0 + 0.5 * (hi - xf0) and hi < top[i]:
                nxt.append(i)
        todo = nxt
    return runs, calls


def brackets(xs, fs):
    """``(prob, lo, hi, flo, fhi)`` arrays: every change of verdict between neighbouring points of
    each problem (its index, the two abscissae and their verdicts), in order."""
    prob, lo, hi, flo, fhi = [], [], [], [], []
    for i in range(len(xs)):
        ch = np.nonzero(fs[i][1:] != fs[i][:-1])[0]
        prob.extend([i] * ch.size)
        lo.extend(xs[i][ch]), hi.extend(xs[i][ch + 1])
        flo.extend(fs[i][ch]), fhi.extend(fs[i][ch + 1])
    prob, lo, hi = np.array(prob, dtype=int), np.array(lo, dtype=float), np.array(hi, dtype=float)
    return prob, lo, hi, np.array(flo, dtype=bool), np.array(fhi, dtype=bool)


def ksect(evaluate, brackets, k, rtol, max_iter):
    """Cut every bracket in ``k`` parts per step, all together, until narrower than ``rtol``
    relative; where a step reveals more than one change inside a bracket the highest is followed.

    ``brackets``: ``(prob, lo, hi, flo, fhi)`` arrays.  Returns ``(done, rest, runs, calls)``:
    ``done`` five lists of the arrays of the brackets made narrow, step by step; ``rest`` the five
    arrays of those still wide after ``max_iter`` steps."""
    prob, lo, hi, flo, fhi = brackets
    done = ([], [], [], [], [])
    runs = calls = 0
    frac = np.arange(1, k) / k
    for _ in range(max_iter):
        narrow = (hi - lo) <= rtol * np.abs(hi)
        for part, arr in zip(done, (prob, lo, hi, flo, fhi)):
            part.append(arr[narrow])
        keep = ~narrow
        prob, lo, hi, flo, fhi = prob[keep], lo[keep], hi[keep], flo[keep], fhi[keep]
        if not prob.size:
            break
        mids = lo[:, None] + (hi - lo)[:, None] * frac[None, :]          # (n, k-1)
        vm = np.asarray(evaluate(np.repeat(prob, k - 1), mids.ravel()), dtype=bool)
        runs += int(vm.size)
        calls += 1
        pts = np.concatenate([lo[:, None], mids, hi[:, None]], axis=1)   # (n, k+1)
        ver = np.concatenate([flo[:, None], vm.reshape(-1, k - 1), fhi[:, None]], axis=1)
        change = ver[:, 1:] != ver[:, :-1]                              # (n, k)
        bi = np.arange(prob.size)
        bj = (k - 1) - np.argmax(change[:, ::-1], axis=1)               # highest change
        lo, hi = pts[bi, bj], pts[bi, bj + 1]
        flo, fhi = ver[bi, bj], ver[bi, bj + 1]
    return done, (prob, lo, hi, flo, fhi), runs, calls


class Points:
    """The points of one problem's scan: ``run(xs) -> (fails, nearness)`` gives the verdicts (and
    how near failure each survivor came, inf for a failure) at abscissae ``xs`` in one batch;
    ``first`` is a point known to survive without running.  Counts the runs and calls."""

    def __init__(self, run, first):
        self._run = run
        self._x, self._f, self._r = [np.array([first])], [np.zeros(1, dtype=bool)], [np.zeros(1)]
        self.runs = self.calls = 0

    def add(self, xs):
        """Run the points ``xs``; return their failure verdicts."""
        xs = np.atleast_1d(np.asarray(xs, dtype=float))
        f, near = self._run(xs)
        self.runs += xs.size
        self.calls += 1
        self._x.append(xs)
        self._f.append(f)
        self._r.append(near)
        return f

    def sorted(self):
        """``(x, fails, nearness)`` of every point run so far, by abscissa."""
        x, f, r = np.concatenate(self._x), np.concatenate(self._f), np.concatenate(self._r)
        order = np.argsort(x, kind="stable")
        return x[order], f[order], r[order]


def refine_gaps(pts, step, resolution, near, max_rounds) -> None:
    """Halve the gaps below the first failure (everywhere, if none), round after round: every gap
    wider than ``step`` (relative) where either end moved (nearness > 0), wider than ``resolution``
    where either end came within ``near`` of failing."""
    for _ in range(max_rounds):
        x, f, r = pts.sorted()
        end = np.nonzero(f)[0][0] if f.any() else x.size - 1
        x, r = x[:end + 1], r[:end + 1]
        gap = (x[1:] - x[:-1]) / x[1:]
        most = np.maximum(r[1:], r[:-1])
        m = np.nonzero(((gap > resolution) & (most >= near)) | ((gap > step) & (most > 0.0)))[0]
        if not m.size:
            break
        pts.add(0.5 * (x[m] + x[m + 1]))


def bisect(pts, lo, hi, rtol, fails_low):
    """Bisect the bracket ``lo < hi`` (its ends of different verdicts; ``fails_low``: the ``lo``
    end fails) by adding points to ``pts`` until narrower than ``rtol`` relative; the bracket."""
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if pts.add([mid])[0] == fails_low:
            lo = mid
        else:
            hi = mid
    return lo, hi


def bisect_first(pts, rtol) -> float:
    """Bisect the bracket below the lowest failure (the first point survives) until narrower than
    ``rtol`` relative; return its failing end."""
    x, f, _ = pts.sorted()
    j = np.nonzero(f)[0][0]
    lo, hi = x[j - 1], x[j]                    # x[0] survives, so j >= 1
    return float(bisect(pts, lo, hi, rtol, fails_low=False)[1])
