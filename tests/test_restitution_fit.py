"""rocking.fit_restitution: the restitution from a free-rocking record, on responses the package
simulates with a known restitution (sampled as a test would: a zero ground motion of the test's
sampling interval carries the block from its release tilt), with and without noise."""
from __future__ import annotations


import numpy as np
import pytest

import pulses
import rocking


def _free_rocking(eta, dt=0.005, seconds=15.0, width=0.25, body=None):
    block = rocking.Block.from_dimensions(1.0, width, eta, body=body)
    still = pulses.Record(np.zeros(int(seconds / dt)), dt)
    res = rocking.simulate(block, still, theta0=0.8 * block.alpha)
    return block, res.t, res.theta


@pytest.mark.parametrize("eta", [0.6, 0.85, 0.95, 0.99])
@pytest.mark.parametrize("body", [None, "cylinder"])
def test_noise_free_peaks_give_the_restitution(eta, body):
    block, t, theta = _free_rocking(eta, body=body, seconds=40.0 if eta > 0.98 else 15.0)
    fit = rocking.fit_restitution(t, theta, block.alpha)
    # the peaks' heights from quartic fits at 200 Hz: measured errors below 3e-6
    assert fit.eta == pytest.approx(eta, abs=1e-5)
    assert fit.r == pytest.approx(eta**2, abs=2e-5) and fit.n >= 2
    assert fit.values == pytest.approx(eta, abs=1e-4)


@pytest.mark.parametrize("eta", [0.85, 0.95])
def test_noise_free_impacts_give_the_restitution(eta):
    block, t, theta = _free_rocking(eta, dt=0.001)
    fit = rocking.fit_restitution(t, theta, method="impacts")
    assert fit.method == "impacts" and fit.n >= 5
    assert fit.eta == pytest.approx(eta, abs=2e-4)   # measured 1.5e-5 at 1 kHz, 6e-4 at 200 Hz


@pytest.mark.parametrize("eta, share", [(0.85, 0.002), (0.95, 0.002), (0.85, 0.01), (0.95, 0.01)])
def test_noise_and_the_stated_uncertainty(eta, share):
    block, t, theta = _free_rocking(eta)
    rng = np.random.default_rng(7)
    sigma = share * block.alpha
    errors, stds = [], []
    for _ in range(20):
        fit = rocking.fit_restitution(t, theta + rng.normal(0.0, sigma, theta.size), block.alpha)
        errors.append(fit.eta - eta)
        stds.append(fit.eta_std)
    errors, stds = np.array(errors), np.array(stds)
    # the standard error describes the scatter: rms error within 2x the mean standard error
    # (measured 1.0-1.6x; the noise lifts the smallest peaks a little, a bias of about one std)
    assert np.sqrt(np.mean(errors**2)) <= 2.0 * np.mean(stds)
    assert abs(np.mean(errors)) <= 1.5 * np.mean(stds) + 1e-5
    assert np.all(np.abs(errors) < 0.01)


def test_the_fit_as_a_design_input():
    block, t, theta = _free_rocking(0.9)
    fit = rocking.fit_restitution(t, theta, block.alpha)
    band = fit.as_restitution()
    assert band.kind == "eta" and band.is_band
    assert band.low == pytest.approx(fit.eta - 2 * fit.eta_std, rel=1e-12)
    assert band.high == pytest.approx(fit.eta + 2 * fit.eta_std, rel=1e-12)
    one = fit.as_restitution(band=None)
    assert one.eta_at(block.alpha) == pytest.approx(0.9, abs=1e-5)
    assert fit.factor(block.alpha) == pytest.approx(0.9 / rocking.eta_housner(block.alpha), rel=1e-4)


def test_bad_input_is_refused_in_one_line():
    block, t, theta = _free_rocking(0.9)
    for kwargs, match in ((dict(), "alpha"), (dict(alpha=0.2, method="x"), "method")):
        with pytest.raises(ValueError, match=match):
            rocking.fit_restitution(t, theta, **kwargs)
    with pytest.raises(ValueError, match="same length"):
        rocking.fit_restitution(t[:-1], theta, 0.2)
    with pytest.raises(ValueError, match="peaks above the noise"):
        rocking.fit_restitution(t[:50], theta[:50], block.alpha)
