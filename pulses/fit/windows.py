"""Where a pulse is fitted and measured: its unit samples, the window of samples a least-squares
fit uses, the window its correlation is measured over, and the leash that keeps a refinement near
the match it started from (:mod:`pulses.fit.plain`, :mod:`pulses.fit.edges`,
:mod:`pulses.fit.weighted`)."""
from __future__ import annotations

import numpy as np

from ..shapes import shape_class

#: least squares refines the match, it does not replace it: Tp stays within this factor of the
#: matched period and t0 within one matched period of the matched time (with background motion
#: that reaches low frequencies, a free fit can trade a short pulse for a long swell of noise)
TP_LEASH = 1.5
#: least margin (s) of record kept on each side of the pulse by the refinement: the straight-line
#: baseline fitted with the pulse is pinned down by the motion around it, so that it does not
#: trade off against a short pulse
FIT_MARGIN = 1.0


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


def fit_window(shape: str, tp: float, t0: float) -> tuple[float, float]:
    """Interval (s) of samples used by the least-squares refinement: the pulse plus a margin."""
    margin = max(0.5 * tp, FIT_MARGIN)
    lo, hi = shape_class(shape).fit_tau
    return t0 + lo * tp - margin, t0 + hi * tp + margin


def covers(idx: slice, shape: str, tp: float, t0: float, dt: float, n: int) -> bool:
    """True if the samples ``idx`` hold the pulse with at least half the fit margin around it."""
    lo, hi = fit_window(shape, tp, t0)
    half = 0.5 * max(0.5 * tp, FIT_MARGIN)
    return (idx.start == 0 or idx.start * dt <= lo + half) and (idx.stop >= n or (idx.stop - 1) * dt >= hi - half)
