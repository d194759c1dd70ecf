"""Baseline correction used for the record's peak ground velocity (PGV).

A digitised accelerogram usually carries a small constant offset, which integrates into a
velocity that drifts linearly.  The correction used here is the simplest one that a reader can
check by hand: subtract from the acceleration the constant ``a0`` that brings the ground back to
rest at the end of the record (zero final velocity),

    a0 = v_raw(T) / T,     v(t) = integral_0^t (a(s) - a0) ds   (trapezoidal rule),

so a record that already ends at rest is left untouched (a one-sine or Ricker pulse has zero net
velocity change, so its PGV is exact).  It does not remove the slow drifts a full processing
(high-pass filtering) would; PEER NGA records are already processed that way.
"""
from __future__ import annotations

import numpy as np


def velocity(acc, dt: float) -> np.ndarray:
    """Ground velocity (m/s) from acceleration (m/s^2) by the trapezoidal rule, starting at rest."""
    acc = np.asarray(acc, dtype=float)
    v = np.empty_like(acc)
    v[0] = 0.0
    np.cumsum(0.5 * (acc[1:] + acc[:-1]) * dt, out=v[1:])
    return v


def baseline_offset(acc, dt: float) -> float:
    """The constant acceleration ``a0`` (m/s^2) whose removal makes the final velocity zero."""
    acc = np.asarray(acc, dtype=float)
    duration = (acc.size - 1) * dt
    return float(velocity(acc, dt)[-1] / duration) if duration > 0 else 0.0


def corrected_velocity(acc, dt: float) -> np.ndarray:
    """Velocity (m/s) after removing :func:`baseline_offset` from the acceleration."""
    acc = np.asarray(acc, dtype=float)
    return velocity(acc - baseline_offset(acc, dt), dt)


def pgv(acc, dt: float) -> float:
    """Peak ground velocity (m/s) after the baseline correction of this module."""
    return float(np.max(np.abs(corrected_velocity(acc, dt))))


def significant_duration(acc, dt: float, low: float = 0.05, high: float = 0.95) -> float:
    """Time (s) between 5 % and 95 % of the Arias intensity (``integral a^2 dt``), D5-95."""
    acc = np.asarray(acc, dtype=float)
    energy = np.cumsum(acc * acc)
    if energy[-1] <= 0:
        return 0.0
    energy /= energy[-1]
    return float((np.searchsorted(energy, high) - np.searchsorted(energy, low)) * dt)
