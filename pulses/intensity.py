"""Intensity measures of a record: PGA, PGV and SA(T), the measures hazard curves are given in.

Short numpy functions with their units in their names' documentation, as pyrotd's are:

:func:`pga`
    Peak ground acceleration, g.
:func:`pgv`
    Peak ground velocity, cm/s (the unit of hazard curves of PGV), after the baseline correction
    of :mod:`pulses.fit.baseline`.
:func:`sa`
    5 %-damped pseudo-spectral acceleration ``omega^2 max|u|``, g, of a linear oscillator of
    period ``T`` from rest.  The oscillator is integrated exactly for a ground acceleration that is
    linear between samples (how every solver of the package reads a record): the exponential of the
    oscillator's matrix with a first-order hold, which is Nigam and Jennings' (1969) recurrence
    written as a second-order recursive filter (:func:`scipy.signal.lfilter`).
:func:`rotd`
    The same measures of a pair of horizontals at every rotation angle and their percentile over
    the angles (RotD50 by default: the measure of most current ground-motion models).
:func:`intensity`
    Any of them by the name a hazard curve gives (``"PGA"``, ``"PGV"``, ``"SA(1.0)"``).

The oscillator is followed past the record's end for one period of free vibration (its peak may
come after the ground has stopped), and where a record has fewer than :data:`PER_PERIOD` samples per
oscillator period its linear pieces are cut into as many substeps (the same ground motion,
sampled finely enough that the peak between two samples is missed by less than 0.05 %).

Examples
--------
>>> import numpy as np, pulses
>>> from pulses import intensity
>>> t = np.arange(0.0, 4.0, 0.005)
>>> rec = pulses.Record(0.3 * pulses.G * np.sin(2 * np.pi * t), 0.005)
>>> round(intensity.pga(rec), 4), intensity.parse_measure("sa(1)")
(0.3, ('SA', 1.0))
"""
from __future__ import annotations

import math
import re

import numpy as np

from .units import G

#: the measures and the units their values are given in (those of OpenQuake's and USGS's files)
UNITS = {"PGA": "g", "PGV": "cm/s", "SA": "g"}
#: damping of the spectral accelerations of hazard curves
DAMPING = 0.05
#: samples per oscillator period at least (finer substeps of the linear pieces below it)
PER_PERIOD = 100
#: rotation angles of :func:`rotd`, deg (1 deg apart: a percentile over them moves by < 0.1 %)
ANGLES = np.arange(0.0, 180.0, 1.0)

_SA = re.compile(r"^\s*(?:SA|PSA|SA_)\s*[\(\s]\s*([0-9.eE+-]+)\s*s?\s*\)?\s*$", re.IGNORECASE)
_USGS_SA = re.compile(r"^\s*SA(\d+)P(\d+)\s*$", re.IGNORECASE)


def parse_measure(text) -> tuple[str, float | None]:
    """``(name, period)`` of a measure as files and users write it: ``PGA``, ``PGV``, ``SA(1.0)``,
    ``SA(0.2)``, ``sa 1``, USGS's ``SA1P0`` and ``SA0P2``; period None for PGA and PGV.

    Raises
    ------
    ValueError
        A measure this package does not compute (one line, naming those it does).
    """
    s = str(text).strip()
    up = s.upper()
    if up in ("PGA", "PGV"):
        return up, None
    m = _USGS_SA.match(s)
    period = float(f"{m.group(1)}.{m.group(2)}") if m else None
    if m is None:
        m = _SA.match(s)
        if m:
            try:
                period = float(m.group(1))
            except ValueError:
                period = None
    if period is None or not (math.isfinite(period) and period > 0):
        raise ValueError(f"intensity measure {s!r}: expected PGA, PGV or SA(T) with the period T "
                         "in s (e.g. SA(1.0), or USGS's SA1P0)")
    return "SA", period


def measure_name(name: str, period: float | None = None) -> str:
    """The canonical name: ``PGA``, ``PGV`` or ``SA(1.0)`` (OpenQuake's spelling)."""
    return name if period is None else f"SA({period:g})" if "." in f"{period:g}" else f"SA({period:.1f})"


def _acc(record):
    return np.asarray(record.acc, dtype=float), float(record.dt)


def pga(record) -> float:
    """Peak ground acceleration of ``record`` (a :class:`pulses.Record`), g."""
    acc, _ = _acc(record)
    return float(np.max(np.abs(acc))) / G


def pgv(record) -> float:
    """Peak ground velocity of ``record``, cm/s (baseline-corrected, :func:`pulses.fit.baseline.pgv`)."""
    from .fit.baseline import pgv as peak_velocity

    acc, dt = _acc(record)
    return 100.0 * peak_velocity(acc, dt)


def _filter(period: float, damping: float, dt: float):
    """``(b, a)`` of the recursive filter from ground acceleration samples to the oscillator's
    relative displacement ``u`` (``u'' + 2 zeta w u' + w^2 u = -a``), exact for an acceleration
    linear between samples (first-order hold)."""
    from scipy.linalg import expm

    w = 2.0 * math.pi / period
    f = np.array([[0.0, 1.0], [-w * w, -2.0 * damping * w]])
    g = np.array([0.0, -1.0])
    # x' = F x + G a with a(t) = a_n + (a_{n+1} - a_n) s / dt: the augmented exponential gives
    # x_{n+1} = Phi x_n + G1 a_n + G2 (a_{n+1} - a_n)
    m = np.zeros((4, 4))
    m[:2, :2] = f
    m[:2, 2] = g
    m[2, 3] = 1.0 / dt
    e = expm(m * dt)
    phi, g1, g2 = e[:2, :2], e[:2, 2], e[:2, 3]
    b0, b1 = g1 - g2, g2                          # x_{n+1} = Phi x_n + b0 a_n + b1 a_{n+1}
    (p11, p12), (p21, p22) = phi
    # u = first state: U(z) = [z - p22, p12] (b0 + b1 z) A(z) / det(zI - Phi)
    num = np.array([b1[0], b0[0] - p22 * b1[0] + p12 * b1[1], -p22 * b0[0] + p12 * b0[1]])
    den = np.array([1.0, -(p11 + p22), p11 * p22 - p12 * p21])
    return num, den, b1


def displacement(acc, dt: float, period: float, damping: float = DAMPING) -> np.ndarray:
    """Relative displacement (m) of the oscillator of ``period`` (s) and ``damping`` under the
    ground acceleration samples ``acc`` (m/s^2), from rest, at the samples."""
    from scipy.signal import lfilter

    _check_oscillator(period, damping)
    acc = np.asarray(acc, dtype=float)
    b, a, b1 = _filter(float(period), float(damping), float(dt))
    u = lfilter(b, a, acc)
    # the filter starts as if the ground had ramped from 0 to acc[0] over one step before t = 0,
    # leaving the oscillator in the state b1 acc[0]; at rest instead: its free vibration removed
    d0, v0 = b1 * acc[0]
    if d0 or v0:
        w = 2.0 * math.pi / period
        wd = w * math.sqrt(1.0 - damping * damping)
        t = np.arange(acc.size) * dt
        u -= np.exp(-damping * w * t) * (d0 * np.cos(wd * t) + (v0 + damping * w * d0) / wd * np.sin(wd * t))
    return u


def _check_oscillator(period, damping) -> None:
    if not (math.isfinite(period) and period > 0):
        raise ValueError(f"SA: the period must be positive (s), got {period!r}")
    if not (0.0 <= damping < 1.0):
        raise ValueError(f"SA: the damping ratio must lie in [0, 1), got {damping!r}")


def oscillator_input(acc, dt: float, period: float):
    """``(samples, step)``: the ground acceleration the oscillator of ``period`` is driven by: the
    record's linear pieces cut into substeps where it has fewer than :data:`PER_PERIOD` samples
    per period, then one period of rest (free vibration after the record)."""
    acc = np.asarray(acc, dtype=float)
    k = max(1, math.ceil(PER_PERIOD * dt / period))
    if k > 1:
        fine = np.arange((acc.size - 1) * k + 1) / k
        acc = np.interp(fine, np.arange(acc.size), acc)
    step = dt / k
    return np.concatenate([acc, np.zeros(math.ceil(period / step))]), step


def sa(record, period, damping: float = DAMPING):
    """Pseudo-spectral acceleration ``(2 pi / T)^2 max|u|`` of ``record`` at ``period`` (s, one or
    an array), g; 5 % damped by default."""
    acc, dt = _acc(record)
    periods = np.atleast_1d(np.asarray(period, dtype=float))
    out = []
    for T in periods:
        x, step = oscillator_input(acc, dt, float(T))
        out.append((2.0 * math.pi / T) ** 2 * np.max(np.abs(displacement(x, step, T, damping))) / G)
    out = np.array(out)
    return float(out[0]) if np.ndim(period) == 0 else out


def _histories(record, name, period, damping):
    """The time history whose peak is the measure: acceleration (g), velocity (cm/s) or the
    oscillator's pseudo-acceleration ``w^2 u`` (g)."""
    from .fit.baseline import corrected_velocity

    acc, dt = _acc(record)
    if name == "PGA":
        return acc / G
    if name == "PGV":
        return 100.0 * corrected_velocity(acc, dt)
    x, step = oscillator_input(acc, dt, period)
    return (2.0 * math.pi / period) ** 2 * displacement(x, step, period, damping) / G


def rotd(first, second, measure="PGA", percentile: float = 50.0, damping: float = DAMPING) -> float:
    """RotD``percentile`` of a pair of horizontal components (records of one sampling, at right
    angles): the measure of ``a1 cos(theta) + a2 sin(theta)`` at every angle of :data:`ANGLES`, and
    that percentile over the angles (RotD50: their median; RotD100: the largest).  Units of the
    measure (g; PGV cm/s)."""
    name, period = parse_measure(measure)
    if abs(float(first.dt) - float(second.dt)) > 1e-9 * float(first.dt):
        raise ValueError("rotd: the two components must have the same sampling interval")
    n = min(first.npts, second.npts)
    h1 = _histories(first, name, period, damping)[:n]
    h2 = _histories(second, name, period, damping)[:n]
    th = np.radians(ANGLES)
    # the linear measures rotate with the motion: each angle's history is c h1 + s h2
    peaks = np.max(np.abs(np.outer(np.cos(th), h1) + np.outer(np.sin(th), h2)), axis=1)
    return float(np.percentile(peaks, percentile))


def intensity(record, measure, damping: float = DAMPING) -> float:
    """The measure (``"PGA"`` g, ``"PGV"`` cm/s, ``"SA(T)"`` g) of one component."""
    name, period = parse_measure(measure)
    if name == "PGA":
        return pga(record)
    if name == "PGV":
        return pgv(record)
    return sa(record, period, damping)
