"""The plain fit of one shape: ordinary least squares of ``ap``, ``Tp`` and ``t0`` near the match
it starts from (Levenberg-Marquardt with the analytic Jacobian; a boxcar shape by a search over
its edges, :mod:`pulses.fit.edges`), a straight-line baseline fitted alongside, and the share of
the record's energy a fit explains."""
from __future__ import annotations

import math

import numpy as np

from ..shapes import shape_class
from .edges import refine_edges
from .lsq import baseline_projector, levenberg_marquardt, pulse_normal_equations
from .matching import _dot
from .windows import TP_LEASH, covers, fit_window


def refine(x, t, dt, shape, ap0, tp0, t00, baseline):
    """Least-squares ``(ap, Tp, t0, window)`` near a starting guess; the guess if refinement fails.

    Levenberg-Marquardt on the samples inside the fit window, with the analytic Jacobian; the
    straight-line baseline ``c0 + c1 (t - tc)`` is fitted alongside when ``baseline`` is True
    (projected out: the residual and Jacobian are taken orthogonal to 1 and ``t - tc``).
    """

    def window(tp, t0):
        lo, hi = fit_window(shape, tp, t0)
        i0 = max(0, int(math.floor(lo / dt)))
        i1 = min(x.size, int(math.ceil(hi / dt)) + 1)
        return slice(i0, i1)

    best = (ap0, tp0, t00, None)
    cls = shape_class(shape)
    if cls.boxcar:
        return refine_edges(x, t, dt, shape, best, window, baseline, tp0, t00)
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
        if covers(idx, shape, tp, t0, dt, x.size):
            break
    return best


def scored(x, t, dt, shape, trial, energy):
    """Share of the record's energy a refined ``(ap, Tp, t0, window)`` explains, and its samples."""
    p = trial[0] * shape_class(shape).sampled_on_grid(trial[1], trial[2], t, dt)
    r = x - p
    return 1.0 - _dot(r, r) / energy, p
