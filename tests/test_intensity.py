"""Intensity measures of records (pulses.intensity) against independent references: closed forms
of a linear oscillator, a general-purpose ODE integration of the same oscillator, and pyrotd
(frequency domain) where it is installed."""
from __future__ import annotations

import math

import numpy as np
import pytest

import pulses
from pulses import intensity as im

from .conftest import shared_record


def test_step_of_acceleration_closed_form():
    # a constant ground acceleration a from rest: u peaks at (a / w^2)(1 + exp(-zeta pi / sqrt(1 -
    # zeta^2))) at the first half period, so SA = a (1 + exp(...)); the input is linear between
    # samples (constant), so the recursion is exact and only the peak's sampling is approximate
    # (100 samples a period at least: cos(pi/100) -> 5e-4 at most)
    a = 0.3
    rec = pulses.Record(np.full(4001, a * pulses.G), 0.005)
    for period in (0.2, 1.0, 3.0):
        for zeta in (0.0, 0.05):
            exact = a * (1.0 + math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta * zeta)))
            assert im.sa(rec, period, zeta) == pytest.approx(exact, rel=5e-4)


def _rk4(acc, dt, periods, zeta, sub=40):
    """The oscillators of ``periods`` by classical Runge-Kutta, ``sub`` fixed steps per sample
    (steps end on the samples, where the piecewise-linear ground motion has its kinks)."""
    w = 2 * np.pi / np.asarray(periods)
    h = dt / sub
    y = np.zeros((2, w.size))
    out = np.zeros((acc.size, w.size))

    def f(y, a):
        return np.array([y[1], -a - 2 * zeta * w * y[1] - w * w * y[0]])

    for n in range(acc.size - 1):
        a0, a1 = acc[n], acc[n + 1]
        for k in range(sub):
            s0, s1 = k / sub, (k + 1) / sub
            am = a0 + (a1 - a0) * 0.5 * (s0 + s1)
            k1 = f(y, a0 + (a1 - a0) * s0)
            k2 = f(y + 0.5 * h * k1, am)
            k3 = f(y + 0.5 * h * k2, am)
            k4 = f(y + h * k3, a0 + (a1 - a0) * s1)
            y = y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        out[n + 1] = y[0]
    return out


def test_displacement_matches_runge_kutta():
    # the oscillator under a real record against a fixed-step Runge-Kutta integration of the same
    # piecewise-linear ground motion (40 steps a sample: its error, (h w)^4 per step, is below
    # 1e-7 of the peak): the recursion is exact at the samples, so they agree to 1e-6
    rec = pulses.read_record(shared_record("Rinaldi228.AT2"))
    periods = (0.1, 1.0, 3.0)
    ref = _rk4(rec.acc[:800], rec.dt, periods, 0.05)
    for j, period in enumerate(periods):
        u = im.displacement(rec.acc[:800], rec.dt, period, 0.05)
        assert np.max(np.abs(u - ref[:, j])) < 1e-6 * np.max(np.abs(ref[:, j]))


def test_sa_peak_after_the_record_ends():
    # a long-period oscillator keeps moving after a short record: its peak comes in free vibration
    rec = pulses.read_record(shared_record("Rinaldi228.AT2"))
    on_record = (2 * math.pi / 5.0) ** 2 * np.max(np.abs(im.displacement(rec.acc, rec.dt, 5.0))) / pulses.G
    assert im.sa(rec, 5.0) >= on_record


@pytest.mark.parametrize("name", ["RSN77_SFERN_PUL164.AT2", "RSN1084_NORTHR_SCS052.AT2"])
def test_sa_against_pyrotd(name):
    pyrotd = pytest.importorskip("pyrotd", reason="pyrotd not installed (a test-only reference)")
    rec = pulses.read_record(shared_record(name))
    periods = np.array([0.2, 0.5, 1.0, 2.0])
    # pyrotd works in the frequency domain: the record padded with zeros (else its circular
    # convolution wraps the free vibration round), resampled to 20 times each oscillator's frequency;
    # it interpolates between samples band-limited where this package takes them as linear: 1 %
    padded = np.concatenate([rec.acc, np.zeros(rec.npts + int(20 / rec.dt))]) / pulses.G
    ref = pyrotd.calc_spec_accels(rec.dt, padded, 1 / periods, 0.05, max_freq_ratio=20)["spec_accel"]
    assert im.sa(rec, periods) == pytest.approx(ref, rel=1e-2)


def test_pga_pgv_rotd():
    rec = pulses.read_record(shared_record("RSN77_SFERN_PUL164.AT2"))
    assert im.pga(rec) == pytest.approx(np.max(np.abs(rec.acc)) / pulses.G)
    from pulses.fit.baseline import pgv

    assert im.pgv(rec) == pytest.approx(100 * pgv(rec.acc, rec.dt))
    # the same component twice: the rotated motion is sqrt(2) cos(theta - 45 deg) times it, so
    # RotD100 is sqrt(2) PGA and RotD0 is 0 (at 135 deg)
    assert im.rotd(rec, rec, "PGA", 100) == pytest.approx(math.sqrt(2) * im.pga(rec), rel=1e-9)
    zero = pulses.Record(np.zeros(rec.npts), rec.dt)
    # one component and nothing at right angles: RotD100 is the component's own PGA
    assert im.rotd(rec, zero, "PGA", 100) == pytest.approx(im.pga(rec), rel=1e-12)
    assert im.rotd(rec, zero, "SA(1.0)", 100) == pytest.approx(im.sa(rec, 1.0), rel=1e-12)


def test_measure_names():
    assert im.parse_measure("SA1P0") == ("SA", 1.0)
    assert im.parse_measure("SA0P2") == ("SA", 0.2)
    assert im.parse_measure("sa(0.3)") == ("SA", 0.3)
    assert im.parse_measure("pgv") == ("PGV", None)
    assert im.measure_name("SA", 1.0) == "SA(1.0)"
    with pytest.raises(ValueError, match="PGA, PGV or SA"):
        im.parse_measure("MMI")
