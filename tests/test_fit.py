"""The pulse fitter: scale-to-Tp conversion, the FFT wavelet transform, and accuracy.

Accuracy is measured on synthetic records (:mod:`pulses.fit.synthetic`) against the noise limit of
any least-squares pulse fit (:func:`pulses.fit.synthetic.least_squares_limit`): with band-limited
background motion (0.5-10 Hz) a short pulse sits inside the noise band, and no fit recovers it
better than that limit.  The issue's percentage floors are asserted where the limit allows them;
everywhere the scatter must stay at the limit and every miss must be a pulse that explains the
record at least as well as the true one (the search did not fail; the data are ambiguous).

Monte-Carlo counts are small (fixed seeds, a few seconds in all); docs/validation-fitting.md has
the full tables, from ``python benchmarks/fit_accuracy.py``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import pulses
from pulses import G, PulseFit, Record, fit_pulse, make_pulse
from pulses.fit.matching import (
    GAUS3_TP_PER_SCALE,
    MEXH_TP_PER_SCALE,
    Matcher,
    scale_from_tp,
    tp_from_scale,
    unit_energy,
    unit_spectrum,
)
from pulses.fit.synthetic import least_squares_limit, sampled_pulse, synthetic_record

from .conftest import SHARED_RECORDS, shared_record

#: every registered shape, the realisable ones first (the order the random cases below are drawn in)
SHAPES = tuple(sorted(pulses.SHAPES, key=lambda shape: not pulses.SHAPES[shape].realisable))
TPS = (0.2, 0.5, 1.0, 2.0, 5.0)
DT = 0.005


# -- scale to Tp (docs/theory.md section 3) -----------------------------------------------------------------
def _fourier_peak_period(shape, tp=1.0):
    """Period (s) at which the Fourier amplitude of the densely sampled pulse peaks."""
    dt = tp / 2000.0
    t = np.arange(-40 * tp, 40 * tp, dt)  # 80 Tp long: frequency step 1/(80 Tp)
    amp = np.abs(np.fft.rfft(make_pulse(shape, 1.0, tp, 0.0)(t)))
    f = np.fft.rfftfreq(t.size, dt)
    k = int(np.argmax(amp))
    # parabolic interpolation of the peak between bins
    a, b, c = amp[k - 1], amp[k], amp[k + 1]
    f_peak = f[k] + 0.5 * (a - c) / (a - 2 * b + c) * (f[1] - f[0])
    return 1.0 / f_peak


@pytest.mark.parametrize("shape", ["ricker-sym", "ricker-anti"])
def test_ricker_fourier_amplitude_peaks_at_tp(shape):
    # docs/theory.md section 3 defines Tp of the Rickers as the period of the Fourier-amplitude peak;
    # the FFT of the pulse (80 Tp window, parabolic peak) finds it to better than 1e-4
    assert _fourier_peak_period(shape, 1.3) == pytest.approx(1.3, rel=1e-4)


@pytest.mark.parametrize("shape,name,per_scale", [("ricker-sym", "mexh", MEXH_TP_PER_SCALE),
                                                    ("ricker-anti", "gaus3", GAUS3_TP_PER_SCALE)])
def test_pywt_wavelet_at_scale_is_the_pulse_of_period_tp(shape, name, per_scale):
    import pywt

    psi, x = pywt.ContinuousWavelet(name).wavefun(level=14)
    scale = 0.37  # any scale: psi(t / scale) must be the pulse with Tp = per_scale * scale
    tp = tp_from_scale(shape, scale)
    assert tp == pytest.approx(per_scale * scale, rel=1e-15)
    assert scale_from_tp(shape, tp) == pytest.approx(scale, rel=1e-15)
    pulse = make_pulse(shape, 1.0, tp, 0.0)(x * scale)
    k = np.argmax(np.abs(pulse))
    ratio = psi[k] / pulse[k]  # pywt normalises to unit energy and may flip the sign
    np.testing.assert_allclose(psi, ratio * pulse, atol=1e-9 * np.abs(psi).max())
    # pywt's rounded centre frequencies (0.25, 0.4) would give Tp 10 % and 2.5 % too low
    tp_pywt = scale / pywt.central_frequency(name)
    expected_low = {"mexh": 0.10, "gaus3": 0.025}[name]
    assert 1.0 - tp_pywt / tp == pytest.approx(expected_low, abs=0.003)


@pytest.mark.parametrize("shape", SHAPES)
def test_closed_form_spectra_match_the_fft_of_the_pulse(shape):
    # the transform uses closed-form Fourier transforms; compare with a fine FFT of the shape
    dt, tp = 1e-3, 1.0
    t = np.arange(-20.0, 20.0, dt)
    w = sampled_pulse(shape, 1.0, tp, 0.0, t, dt)
    f = np.fft.rfftfreq(t.size, dt)[:200]
    numeric = np.fft.rfft(w)[:200] * dt * np.exp(-2j * np.pi * f * t[0])
    closed = tp * unit_spectrum(shape, f * tp)
    # differences are aliasing of the spectral tails of the sampled pulse: 1/f for the rectangle
    # (1e-3), 1/f^2 for the one-sine with its kinks (1e-6), nothing visible for the Rickers
    atol = {"rect": 2e-3, "sine": 1e-5}.get(shape, 1e-9)
    np.testing.assert_allclose(numeric, closed, atol=atol)
    e = np.sum(w * w) * dt
    assert e == pytest.approx(unit_energy(shape) * tp, rel=2e-3 if shape == "rect" else 1e-6)


def test_transform_matches_pywavelets_cwt():
    import pywt

    rec = synthetic_record("ricker-sym", 3.0, 0.8, 6.0, 16.0, 0.01, noise=0.3, seed=4)
    tp = 0.8
    m = Matcher(rec.acc, rec.dt, tp_min=6 * rec.dt, tp_max=2.0)  # full band: output at every sample
    tau, c = m.transform("ricker-sym", [tp])
    ours = np.interp(rec.time, tau[tau >= 0], c[0][tau >= 0])
    ref, _ = pywt.cwt(rec.acc, [scale_from_tp("ricker-sym", tp, rec.dt)], "mexh", method="fft")
    # pywt samples its integrated wavelet on a grid, so agreement is to a correlation of 0.999
    rho = np.corrcoef(ours[100:-100], ref[0][100:-100])[0, 1]
    assert abs(rho) > 0.999


# -- accuracy without noise ------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("shape", SHAPES)
def test_noise_free_recovery(shape):
    rng = np.random.default_rng(11)
    for tp in TPS:
        duration = max(20.0, 8 * tp)
        t0 = rng.uniform(2.0 * tp, duration - 3.0 * tp)  # any arrival, not on the sample grid
        ap = rng.choice([-1.0, 1.0]) * rng.uniform(1.0, 8.0)
        fit = fit_pulse(synthetic_record(shape, ap, tp, t0, duration, DT))
        c = fit[shape]
        # the search and the scale-to-Tp conversion are exact: 1e-4 is the bar
        assert fit.best.shape == shape
        assert c.ap == pytest.approx(ap, rel=1e-4)
        assert c.tp == pytest.approx(tp, rel=1e-4)
        assert c.t0 == pytest.approx(t0, abs=1e-4 * tp)
        assert c.score == pytest.approx(1.0, abs=1e-6) and c.correlation == pytest.approx(1.0, abs=1e-6)
        assert c.polarity == (1 if ap > 0 else -1)


def test_second_weaker_pulse_and_baseline_drift():
    # a sine of 5 m/s^2, 1 s at 4.3 s; a symmetric Ricker of 40 % its amplitude at 13 s;
    # a baseline drift of 30 % of ap across the record.  The line fitted with the pulse absorbs
    # the drift and the second pulse lies outside the fit window: recovery to 1e-4 again
    rec = synthetic_record("sine", 5.0, 1.0, 4.3, 20.0, DT, second=("ricker-sym", 2.0, 0.6, 13.0),
                           drift=0.3)
    c = fit_pulse(rec).best
    assert c.shape == "sine"
    assert (c.ap, c.tp, c.t0) == pytest.approx((5.0, 1.0, 4.3), rel=1e-4)
    # the same with background motion at 15 %: still the stronger pulse, within the noise limit
    rec = synthetic_record("ricker-anti", -4.0, 1.5, 6.0, 25.0, DT, noise=0.15, seed=3,
                           second=("sine", 1.6, 0.8, 16.0), drift=0.3)
    c = fit_pulse(rec).best
    lim = least_squares_limit("ricker-anti", -4.0, 1.5, 6.0, 25.0, DT, 0.15)
    assert c.shape == "ricker-anti"
    assert abs(c.ap / -4.0 - 1) < 4 * lim["ap"] and abs(c.tp / 1.5 - 1) < 4 * lim["tp"]


# -- accuracy with background motion ----------------------------------------------------------------
def _cases(noise, tps, per_cell, seed, weighting="plain"):
    """Fit ``per_cell`` random records for every shape and Tp; yield one dict per case.

    The noise tests below hold the plain least squares (``weighting="plain"``) to their own
    objective and limit; the weighted ones are tested against the plain ones further down."""
    rng = np.random.default_rng(seed)
    out = []
    for tp in tps:
        duration = max(20.0, 8 * tp)
        for shape in SHAPES:
            for _ in range(per_cell):
                t0 = rng.uniform(2.0 * tp, duration - 3.0 * tp)
                ap = rng.choice([-1.0, 1.0]) * rng.uniform(2.0, 8.0)
                rec = synthetic_record(shape, ap, tp, t0, duration, DT, noise=noise, seed=rng)
                fit = fit_pulse(rec, weighting=weighting)
                c = fit[shape]
                t = np.arange(rec.npts) * DT
                truth = sampled_pulse(shape, ap, tp, t0, t, DT)
                r = rec.acc - truth
                true_score = 1.0 - (r @ r) / (rec.acc @ rec.acc)
                # the fitter's own objective on the fitted candidate's window: pulse plus best line
                window = slice(*(int(round(v / DT)) for v in c.fit_window))
                fitted = sampled_pulse(shape, c.ap, c.tp, c.t0, t, DT)
                objective = (_window_sse(rec.acc, fitted, t, window), _window_sse(rec.acc, truth, t, window))
                lim = least_squares_limit(shape, ap, tp, t0, duration, DT, noise)
                out.append(dict(shape=shape, tp=tp, fit=fit, cand=c, true_score=true_score, lim=lim,
                                objective=objective,
                                e_ap=c.ap / ap - 1, e_tp=c.tp / tp - 1, e_t0=(c.t0 - t0) / tp))
    return out


def _window_sse(x, p, t, window):
    """Sum of squares left in ``window`` after the pulse ``p`` and the best straight line."""
    lo, hi = max(window.start, 0), min(window.stop + 1, x.size)
    r = (x - p)[lo:hi]
    A = np.column_stack([np.ones(hi - lo), t[lo:hi]])
    coef, *_ = np.linalg.lstsq(A, r, rcond=None)
    r = r - A @ coef
    return float(r @ r)


def _share(cases, pred):
    return float(np.mean([bool(pred(c)) for c in cases]))


def _check_at_noise_limit(cases):
    for c in cases:
        # no search failure: on the fitter's own objective (pulse plus a straight line in the fit
        # window) the fitted pulse does at least as well as the true one, which least squares can
        # only beat; and the best candidate explains at least as much of the record's energy as
        # the true pulse, up to 0.1 % that the fitted line may hold instead of the pulse
        fitted, true = c["objective"]
        assert fitted <= true * (1 + 1e-9) + 1e-12, c
        assert c["fit"].best.score >= c["true_score"] - 1e-3, c
    for key, lim_key in (("e_ap", "ap"), ("e_tp", "tp"), ("e_t0", "t0")):
        z = np.array([c[key] / c["lim"][lim_key] for c in cases if c["shape"] != "rect"])
        # scatter at the least-squares noise limit: RMS of error / limit is 1 for an exact
        # least-squares fit; with ~50-80 cases its sampling error is ~10 %, so 1.35 is a 3.5-sigma bar
        assert math.sqrt(np.mean(z**2)) < 1.35, (key, math.sqrt(np.mean(z**2)))


@pytest.mark.slow
def test_noise_5_percent():
    # 3 records per shape and Tp (60 fits); the floors of the issue (ap and Tp within 3 % in 90 %
    # of cases) hold where the noise limit allows them: for Tp >= 2 s the limit is <= 1.3 %
    cases = _cases(0.05, TPS, 3, seed=5)
    long = [c for c in cases if c["tp"] >= 2.0]
    assert _share(long, lambda c: abs(c["e_ap"]) < 0.03 and abs(c["e_tp"]) < 0.03) >= 0.9
    assert _share(cases, lambda c: c["fit"].best.shape == c["shape"]) >= 0.95
    assert _share(cases, lambda c: abs(c["e_t0"]) < 0.05) >= 0.95
    _check_at_noise_limit(cases)


@pytest.mark.slow
def test_noise_15_percent():
    cases = _cases(0.15, TPS, 3, seed=15)
    long = [c for c in cases if c["tp"] >= 2.0]
    # Tp >= 2 s: limit <= 4 %, so within 5 % in 75 % and within 15 % in 90 % of cases
    assert _share(long, lambda c: abs(c["e_ap"]) < 0.05 and abs(c["e_tp"]) < 0.05) >= 0.75
    assert _share(long, lambda c: abs(c["e_ap"]) < 0.15 and abs(c["e_tp"]) < 0.15) >= 0.9
    assert _share([c for c in cases if c["tp"] >= 1.0], lambda c: c["fit"].best.shape == c["shape"]) >= 0.9
    assert _share(cases, lambda c: abs(c["e_t0"]) < 0.05) >= 0.95
    _check_at_noise_limit(cases)


@pytest.mark.slow
def test_noise_30_percent_shape():
    cases = _cases(0.30, (0.5, 1.0, 2.0, 5.0), 3, seed=30)
    # right shape in 90 % for Tp >= 1 s; at 0.5 s the shapes are ambiguous in this noise (docs/validation-fitting.md)
    assert _share([c for c in cases if c["tp"] >= 1.0], lambda c: c["fit"].best.shape == c["shape"]) >= 0.9
    for c in cases:  # every miss is a pulse that explains the record at least as well as the truth
        assert c["fit"].best.score >= c["true_score"] - 1e-3
        assert c["objective"][0] <= c["objective"][1] * (1 + 1e-9)


# -- weighted least squares ---------------------------------------------------------------------------
@pytest.mark.slow
def test_weighted_fit_pins_the_edges_in_a_band_the_readme_does_not_use():
    # 15 % background in 0.8-12 Hz (the tables of docs/validation-fitting.md use 0.5-10 and 0.1-25 Hz), pulses inside
    # the band; the same records fitted both ways.  The one-sine's and rectangle's edges carry
    # energy above the band where the background has almost none: weighted by the background's
    # spectrum, their Tp is pinned (limit 0.02-0.5 % against 1-5 % plain), so the RMS Tp error
    # must fall at least fivefold (measured: 0.10 % against 1.9 % plain, 19x).  Their ap is
    # pinned less: the rectangle's by its edges (limit 0.2 % against 2.5-4.6 % plain), the
    # one-sine's mostly by frequencies below the band, which the fitter's spectrum (2.5 s
    # segments) does not resolve (limit 3.6-4 % against 5-7.4 % plain): expected RMS ratio about
    # 0.5, measured 2.0 % against 4.2 % (0.48); with 12 cases the ratio's sampling error is about
    # 0.15, so the bar is 0.75
    rng = np.random.default_rng(812)
    edges = {"plain": [], "background": []}
    amplitudes = {"plain": [], "background": []}
    for tp in (0.5, 1.0):
        for shape in ("sine", "rect"):
            for _ in range(3):
                t0 = rng.uniform(2.0 * tp, 20.0 - 3.0 * tp)
                ap = rng.choice([-1.0, 1.0]) * rng.uniform(2.0, 8.0)
                rec = synthetic_record(shape, ap, tp, t0, 20.0, DT, noise=0.15, seed=rng, band=(0.8, 12.0))
                for weighting in edges:
                    c = fit_pulse(rec, weighting=weighting)[shape]
                    edges[weighting].append(c.tp / tp - 1)
                    amplitudes[weighting].append(c.ap / ap - 1)
    rms = {k: math.sqrt(np.mean(np.square(v))) for k, v in edges.items()}
    assert rms["background"] < 0.2 * rms["plain"], rms
    rms_ap = {k: math.sqrt(np.mean(np.square(v))) for k, v in amplitudes.items()}
    assert rms_ap["background"] < 0.75 * rms_ap["plain"], rms_ap


@pytest.mark.slow
def test_weighted_fit_of_short_cornered_pulses_in_a_wide_band():
    # 0.2 s one-sines and rectangles in 15 % background of 0.1-25 Hz (seeds docs/validation-fitting.md does not
    # use).  Above 25 Hz the weights are about 4000 times those in the band, so the corners pin
    # the pulse to a fraction of a sample, and the weighted objective has a kink each time an edge
    # crosses a sample: a descent alone stopped in one a sample or two from the optimum
    # (one-sine: Tp RMS 2.6 %, ap 7.9 %, worse than plain), the lattice of edges reaches it.
    # Measured on these 24 records: one-sine Tp RMS 0.10 % against 3.7 % plain (0.03), ap 3.8 %
    # against 6.6 % (0.57); rectangle ap 2.0 % against 6.1 % (0.33).  Bars: a tenth of plain for
    # the one-sine's Tp, 0.8 of plain for the ap (12 records a shape: the ratio's sampling error
    # is about 0.15)
    rng = np.random.default_rng(2025)
    errors = {(shape, w): [] for shape in ("sine", "rect") for w in ("plain", "background")}
    for shape in ("sine", "rect"):
        for _ in range(12):
            t0, ap = rng.uniform(2.0, 17.0), rng.choice([-1.0, 1.0]) * rng.uniform(2.0, 8.0)
            rec = synthetic_record(shape, ap, 0.2, t0, 20.0, DT, noise=0.15, seed=rng, band=(0.1, 25.0))
            for w in ("plain", "background"):
                c = fit_pulse(rec, weighting=w)[shape]
                errors[shape, w].append((c.ap / ap - 1, c.tp / 0.2 - 1))
    rms = {key: np.sqrt(np.mean(np.square(v), axis=0)) for key, v in errors.items()}
    assert rms["sine", "background"][1] < 0.1 * rms["sine", "plain"][1], rms
    for shape in ("sine", "rect"):
        assert rms[shape, "background"][0] < 0.8 * rms[shape, "plain"][0], rms


@pytest.mark.slow
def test_weighted_fit_of_a_low_passed_record_keeps_the_pulse():
    # Real records are low-pass filtered: above the filter's corner they hold neither background
    # nor a one-sine's corners or a rectangle's edges, and a fit weighted by the (tiny) power
    # there would shrink the pulse to hide its corners.  One-sines and rectangles with 15 %
    # background (0.1-25 Hz), the whole record then low-passed at 10 Hz (4th-order Butterworth,
    # zero phase; seeds docs/validation-fitting.md does not use): Hausman's test refuses the winner's weighted
    # fit, and the ranking guard keeps the weighting from overturning it, so the shape and ap stay
    # the plain fit's (measured on these 8: the plain fit answered every one).  Without the test
    # the fits shrank to 1-91 % of ap and every best shape became a Ricker.  Bar: shape right, ap
    # within 3 % of the plain fit's
    from scipy import signal

    sos = signal.butter(4, 10.0, fs=1.0 / DT, output="sos")
    rng = np.random.default_rng(31)
    for shape in ("sine", "rect"):
        for tp in (0.3, 1.0):
            for _ in range(2):
                t0, ap = rng.uniform(3.0, 15.0), rng.choice([-1.0, 1.0]) * rng.uniform(2.0, 8.0)
                rec = synthetic_record(shape, ap, tp, t0, 20.0, DT, noise=0.15, seed=rng, band=(0.1, 25.0))
                low = Record(signal.sosfiltfilt(sos, rec.acc), DT, name="low-passed")
                plain, weighted = fit_pulse(low, weighting="plain"), fit_pulse(low)
                assert weighted.best.shape == shape, (shape, tp, weighted)
                assert weighted[shape].ap == pytest.approx(plain[shape].ap, rel=0.03), (shape, tp)


@pytest.mark.slow
@pytest.mark.parametrize("shape", SHAPES)
def test_noise_free_recovery_weighted(shape):
    # without noise the plain fit leaves round-off (the rectangle's cell averages: not exactly
    # zero), outside the pulse nothing: the weighted fit must neither fail on that residual nor
    # move the exact fit (the bar, 1e-4), and the true shape explains all of the record
    rng = np.random.default_rng(12)
    for tp in (0.2, 1.0, 5.0):
        duration = max(20.0, 8 * tp)
        t0 = rng.uniform(2.0 * tp, duration - 3.0 * tp)
        ap = rng.choice([-1.0, 1.0]) * rng.uniform(1.0, 8.0)
        fit = fit_pulse(synthetic_record(shape, ap, tp, t0, duration, DT), weighting="background")
        c = fit[shape]
        assert fit.best.shape == shape
        assert (c.ap, c.tp) == pytest.approx((ap, tp), rel=1e-4) and c.t0 == pytest.approx(t0, abs=1e-4 * tp)
        assert c.score == pytest.approx(1.0, abs=1e-6)


def test_background_spectrum_leaves_out_the_pulse():
    from pulses.fit.background import Background
    from pulses.fit.synthetic import band_noise

    # 15 % background (0.5-10 Hz) plus the error of a plain fit of a 0.5 s one-sine at 8 s (ap 5 %
    # and Tp 3 % off): its corners put power at 15-30 Hz, where the background has little.  From
    # the whole residual the power there comes out 46 % too high; with the segments over the
    # pulse left out it is the background's own (Welch over the 12 of 15 segments left: measured
    # 3 % above the estimate from the background alone; the bar, 10 %, is below the
    # contamination and above the loss of three segments' averaging)
    t = np.arange(4001) * DT
    noise = band_noise(t.size, DT, 0.75, np.random.default_rng(3))
    misfit = sampled_pulse("sine", 5.0, 0.5, 8.0, t, DT) - sampled_pulse("sine", 5.25, 0.485, 8.0, t, DT)

    def high(b):
        return b.power[(b.freq > 15) & (b.freq < 30)].mean()

    alone = high(Background(noise, DT))
    assert high(Background(noise + misfit, DT)) > 1.3 * alone
    assert high(Background(noise + misfit, DT, skip=(7.75, 8.75))) == pytest.approx(alone, rel=0.1)


@pytest.mark.parametrize("nseg", [16, 17, 250, 251, 500])
def test_segment_periodograms_are_scipys_spectrogram(nseg):
    """The background's periodograms are scipy.signal.spectrogram's (Hann, half overlap, constant
    detrend, density), computed without importing scipy.signal.  The two differ only in the
    rounding of the window, the mean and the scale: measured 2e-15 of each periodogram's peak
    and 6e-13 relative on every bin above 1e-6 of it (the zero bin of a segment less its mean is
    round-off itself); asserted at 1e-13 and 1e-11."""
    from scipy import signal

    from pulses.fit.background import segment_periodograms

    rng = np.random.default_rng(7)
    records = [rng.standard_normal(n) for n in (nseg, nseg + 1, 1001, 4000)]
    records.append(synthetic_record("sine", 5.0, 1.0, 7.3, 20.0, 0.005, noise=0.15, seed=1).acc)
    rinaldi = SHARED_RECORDS / "Rinaldi228.AT2"
    if rinaldi.is_file():
        records.append(pulses.read_record(rinaldi).acc)
    for x in records:
        f_ref, _, p_ref = signal.spectrogram(x, fs=1.0 / 0.005, window="hann", nperseg=nseg, noverlap=nseg // 2,
                                             detrend="constant")
        f, p = segment_periodograms(x, 0.005, nseg)
        assert p.shape == p_ref.shape
        assert f == pytest.approx(f_ref, rel=1e-15, abs=0.0)
        peak = p_ref.max(axis=0)
        assert np.all(np.abs(p - p_ref) <= 1e-13 * peak)
        above = p_ref[1:] > 1e-6 * peak
        assert p[1:][above] == pytest.approx(p_ref[1:][above], rel=1e-11, abs=0.0)


def test_a_fit_does_not_import_scipy_signal():
    """scipy.signal (and the scipy.stats it imports) takes over a second to import cold."""
    import subprocess
    import sys

    code = ("import sys, numpy as np, pulses; t = np.arange(0.0, 10.0, 0.01); "
            "rec = pulses.Record(pulses.make_pulse('sine', 5.0, 1.0, 2.0)(t) + 0.3 * np.sin(7.0 * t), 0.01); "
            "assert pulses.fit_pulse(rec).weighting == 'background'; print('scipy.signal' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.slow
def test_weighted_score_of_long_pulses():
    # 5 s pulses in 40 s records, 30 % background in 0.5-10 Hz (seeds docs/validation-fitting.md does not use).
    # Weighted by the inverse of the background's spectrum, the record's energy is almost all
    # below 0.5 Hz, where a 5 s pulse has its energy and the background none: the true shape,
    # fitted to its noise limit (0.02-0.04 % on ap and Tp), explains nearly all of it (measured
    # 0.93-0.999) and ranks first.  The metric is a Fourier transform of the record, tapered at
    # its ends: removing the line through the end samples instead put an offset of the noise's
    # size at 0 Hz, where the weights are largest, and ranked a 15 s Ricker first
    rng = np.random.default_rng(505)
    for shape in SHAPES:
        for _ in range(2):
            t0 = rng.uniform(10.0, 25.0)
            ap = rng.choice([-1.0, 1.0]) * rng.uniform(2.0, 8.0)
            rec = synthetic_record(shape, ap, 5.0, t0, 40.0, DT, noise=0.3, seed=rng)
            fit = fit_pulse(rec, weighting="background")
            assert fit.best.shape == shape and fit.best.score > 0.9, (shape, fit)
    x = rec.acc
    # the share of the record's weighted energy that the record itself explains is all of it
    from pulses.fit.background import Background

    assert Background(x - fit.best.pulse(np.arange(x.size) * DT), DT).explained(x, {"x": x})["x"] == 1.0


def test_weighted_limit_is_below_the_plain_one():
    from pulses.fit.synthetic import weighted_least_squares_limit

    for shape in SHAPES:
        for tp in (0.5, 2.0):
            plain = least_squares_limit(shape, 5.0, tp, 8.0, 20.0, DT, 0.15)
            weighted = weighted_least_squares_limit(shape, 5.0, tp, 8.0, 20.0, DT, 0.15)
            # weighting by the inverse of the noise's spectrum cannot do worse than plain least
            # squares (Gauss-Markov; the weighted problem also uses more record around the pulse)
            assert weighted["ap"] <= plain["ap"] * 1.001 and weighted["tp"] <= plain["tp"] * 1.001, (shape, tp)
            if shape in ("sine", "rect"):
                # their edges put energy above 10 Hz, where the 0.5-10 Hz background has none
                assert weighted["tp"] < 0.2 * plain["tp"], (shape, tp)


def test_weighting_option():
    rec = synthetic_record("sine", 5.0, 1.0, 7.3, 20.0, DT, noise=0.15, seed=1)
    with pytest.raises(pulses.FitError, match="weighting"):
        fit_pulse(rec, weighting="inverse")
    plain, weighted = fit_pulse(rec, weighting="plain")["sine"], fit_pulse(rec, weighting="background")["sine"]
    # 15 % background: the plain fit's Tp is 1 % off here; the weighted one within 0.1 %
    assert abs(weighted.tp - 1.0) < 0.001 < abs(plain.tp - 1.0)
    # the weighted least squares are the default, and a fit says which least squares answered
    default = fit_pulse(rec)
    assert default.weighting == "background" and default["sine"].tp == weighted.tp
    assert fit_pulse(rec, weighting="plain").weighting == "plain"
    assert default.to_frame()["weighting"].eq("background").all() and default.as_dict()["weighting"] == "background"


# -- the record's own numbers, and the real records ------------------------------------------------
def test_pga_pgv_duration_of_a_one_sine_with_offset():
    ap, tp = 4.0, 1.2
    rec = synthetic_record("sine", ap, tp, 5.0, 20.0, 0.002)
    offset = Record(rec.acc + 0.05, rec.dt)  # a constant baseline error of 0.05 m/s^2
    fit = fit_pulse(offset)
    # one-sine velocity: ap Tp / (2 pi) (1 - cos), peak ap Tp / pi; the zero-final-velocity
    # correction removes the offset exactly; the trapezoidal rule errs by O((dt/Tp)^2) = 3e-6
    assert fit.pgv == pytest.approx(ap * tp / math.pi, rel=1e-4)
    assert fit.pga == pytest.approx(ap + 0.05, rel=1e-9)
    assert fit.duration == pytest.approx(20.0)


def test_rinaldi_one_sine_matches_the_paper():
    rec = pulses.read_record(shared_record("Rinaldi228.AT2"))
    fit = fit_pulse(rec)
    sine = fit["sine"]
    # paper: one-sine 0.71 g, 0.8 s; the issue allows 7 % on ap and 5 % on Tp
    assert abs(sine.ap_g) == pytest.approx(0.71, rel=0.07)
    assert sine.tp == pytest.approx(0.8, rel=0.05)
    # the symmetric Ricker fits too (about 0.9 g, 1.0 s): every candidate is reported
    sym = fit["ricker-sym"]
    assert abs(sym.ap_g) == pytest.approx(0.9, rel=0.07) and sym.tp == pytest.approx(1.0, rel=0.05)
    assert len(fit.candidates) == 4 and [c.rank for c in fit.candidates] == [1, 2, 3, 4]
    assert fit.candidates == sorted(fit.candidates, key=lambda c: -c.score)
    old = fit_pulse(pulses.read_record(shared_record("NGA_no_1063_RRS228.AT2")))["sine"]
    assert abs(old.ap_g) == pytest.approx(0.71, rel=0.07) and old.tp == pytest.approx(0.8, rel=0.05)


def test_result_objects():
    rec = synthetic_record("ricker-sym", -3.0, 0.9, 8.0, 20.0, DT)
    fit = fit_pulse(rec, shapes=["ricker-sym", "sine"])
    assert isinstance(fit, PulseFit) and len(fit.candidates) == 2
    best = fit.best
    assert best.shape == "ricker-sym" and best.polarity == -1 and best.ap_g == pytest.approx(-3.0 / G)
    assert best.lp == pytest.approx(3.0 * 0.9**2)
    assert best.arrival == pytest.approx(8.0 - 0.45)
    assert isinstance(best.pulse, pulses.SymmetricRicker)
    assert best.pulse(np.array([8.0]))[0] == pytest.approx(-3.0)
    frame = fit.to_frame()
    assert list(frame["shape"]) == ["ricker-sym", "sine"] and frame["best"].tolist() == [True, False]
    for col in ("ap_m_s2", "ap_g", "tp_s", "t0_s", "polarity", "lp_m", "score", "correlation",
                "pga_g", "pgv_m_s", "duration_s"):
        assert col in frame.columns
    with pytest.raises(ValueError, match="unknown pulse shape"):
        fit_pulse(rec, shapes=["triangle"])


# -- pipeline fit ----------------------------------------------------------------------------------------
@pytest.mark.slow
def test_pipeline_fit_table_csv_json_plot(tmp_path, capsys):
    import json

    import pandas as pd

    from pipeline.cli import main

    rec = synthetic_record("ricker-anti", -0.4 * G, 1.1, 6.0, 20.0, 0.01, noise=0.05, seed=8)
    rec.name, rec.metadata = "demo", {"station": "SYN"}
    sac = pulses.write_sac(rec, tmp_path / "demo.sac")
    csv = tmp_path / "fit.csv"
    assert main(["fit", sac, "--csv", str(csv), "--plot", str(tmp_path / "plots")]) == 0
    text = capsys.readouterr().out
    assert "ricker-anti" in text and "1*" in text
    frame = pd.read_csv(csv)
    assert len(frame) == 4 and frame.loc[frame["best"], "shape"].item() == "ricker-anti"
    best = frame[frame["best"]].iloc[0]
    # 5 % noise at Tp 1.1 s: the noise limit is ~2 % on ap and ~1 % on Tp; 8 % is 4 sigma
    assert best["ap_g"] == pytest.approx(-0.4, rel=0.08) and best["tp_s"] == pytest.approx(1.1, rel=0.05)
    assert (tmp_path / "plots" / "demo.sac.png").is_file()
    assert main(["fit", sac, "--json", "--shapes", "sine", "ricker-anti"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert [c["shape"] for c in data[0]["candidates"]][0] == "ricker-anti" and len(data[0]["candidates"]) == 2
    # the weighted least squares by default, the plain ones on request; the CSV says which answered
    assert frame["weighting"].eq("background").all() and "background least squares" in text
    assert main(["fit", sac, "--weighting", "plain", "--csv", str(csv)]) == 0
    assert pd.read_csv(csv)["weighting"].eq("plain").all() and "plain least squares" in capsys.readouterr().out
    with pytest.raises(SystemExit) as stop:  # argparse's choices: one line, status 2
        main(["fit", sac, "--weighting", "inverse"])
    assert stop.value.code == 2
    assert main(["fit", sac, "--shapes", "triangle"]) == 2
    with pytest.raises(SystemExit):  # the help lists the registered shapes, read from the registry
        main(["fit", "--help"])
    help_text = "".join(capsys.readouterr().out.split())  # argparse wraps lines, even inside names
    assert all(name in help_text for name in pulses.SHAPES)
    assert main(["fit", str(tmp_path / "missing.AT2"), sac]) == 1  # one bad file: reported, others fitted
    captured = capsys.readouterr()
    assert "no such file" in captured.err and "ricker-anti" in captured.out


# -- the shape registry ----------------------------------------------------------------------------------
@pytest.mark.parametrize("shape", SHAPES)
def test_shape_slope_and_extrema(shape):
    cls = pulses.SHAPES[shape]
    lo, hi = cls.support_tau
    tau = np.linspace(lo, hi, 2001)[1:-1]
    h = 1e-6
    # central differences of the formula: error O(h^2 unit''') ~ 1e-10 against slopes of order 10
    numeric = (cls.unit(tau + h) - cls.unit(tau - h)) / (2 * h)
    np.testing.assert_allclose(cls.slope(tau), numeric, atol=1e-7)
    for x in cls.extrema_tau:  # an extremum: zero slope, and no larger value within 1e-3 Tp
        assert abs(float(cls.slope(np.array([x]))[0])) < 1e-12
        around = np.abs(cls.unit(np.array([x - 1e-3, x + 1e-3])))
        assert np.all(around <= abs(float(cls.unit(np.array([x]))[0])))
    pulse = cls(2.0, 1.5, 0.3)
    # the arrival is half a period before the centre: t0 for rect and sine, t0 - Tp/2 for the Rickers
    assert pulse.arrival == pytest.approx(0.3 - (0.75 if shape.startswith("ricker") else 0.0))


def test_unknown_shape_fails_loudly():
    from pulses.fit.matching import unit_spectrum as spectrum
    from pulses.fit.windows import unit_samples

    for call in (lambda: pulses.make_pulse("triangle", 1.0, 1.0), lambda: pulses.shape_class("triangle"),
                 lambda: unit_samples("triangle", 1.0, 0.0, np.zeros(3), 0.01),
                 lambda: spectrum("triangle", np.zeros(3)), lambda: tp_from_scale("sine", 1.0),
                 lambda: fit_pulse(synthetic_record("sine", 1.0, 1.0, 5.0, 20.0, DT), shapes=["triangle"])):
        with pytest.raises(ValueError):
            call()


class _Gaussian(pulses.Pulse):
    """A shape defined only here: ``exp(-pi tau^2)``, Fourier transform ``exp(-pi nu^2)``."""

    shape = "gauss-test"
    support_tau = (-3.0, 3.0)
    centre_tau = 0.0
    window_tau = (-1.0, 1.0)
    fit_tau = (-2.0, 2.0)
    energy = 1.0 / math.sqrt(2.0)  # integral exp(-2 pi tau^2)

    @staticmethod
    def unit(tau):
        return np.exp(-np.pi * tau**2)

    @staticmethod
    def slope(tau):
        return -2.0 * np.pi * tau * np.exp(-np.pi * tau**2)

    @staticmethod
    def spectrum(nu):
        return np.exp(-np.pi * np.asarray(nu, dtype=float) ** 2) + 0j


def test_a_new_shape_is_one_class(monkeypatch):
    # matching, refinement and results ask the shape, never its name: a shape registered in
    # SHAPES is fitted like the others, to the noise-free bar of 1e-4
    monkeypatch.setitem(pulses.SHAPES, _Gaussian.shape, _Gaussian)
    rec = synthetic_record("gauss-test", -3.0, 1.3, 8.2, 20.0, DT)
    c = fit_pulse(rec, shapes=["gauss-test", "sine"]).best
    assert c.shape == "gauss-test" and isinstance(c.pulse, _Gaussian)
    assert (c.ap, c.tp, c.t0) == pytest.approx((-3.0, 1.3, 8.2), rel=1e-4)
    assert c.arrival == pytest.approx(8.2 - 0.65)


# -- bad input ----------------------------------------------------------------------------------------
@pytest.mark.parametrize("tp_range,words", [((0, 0), "0 < shortest <= longest"), ((-1, 5), "0 < shortest"),
                                            ((5, 1), "shortest <= longest"), ((float("nan"), 2), "finite"),
                                            ((0.005, 2), "more than two samples"), ((0.5, 1e9), "exceeds"),
                                            (3.0, "two periods")])
def test_bad_tp_range_is_a_one_line_value_error(tp_range, words):
    rec = synthetic_record("sine", 5.0, 1.0, 7.3, 20.0, DT)
    with pytest.raises(pulses.FitError, match=words) as err:
        fit_pulse(rec, tp_range=tp_range)
    assert isinstance(err.value, ValueError) and "\n" not in str(err.value)


def test_records_with_nothing_to_fit_or_too_large_are_refused():
    rec = synthetic_record("sine", 5.0, 1.0, 7.3, 20.0, DT, noise=0.15, seed=1)
    for bad, words in ((Record(np.zeros(4001), DT), "zero everywhere"), (rec.scaled(1e300), "too large")):
        with pytest.raises(pulses.FitError, match=words) as err:
            fit_pulse(bad)
        assert isinstance(err.value, ValueError) and "\n" not in str(err.value)
    # the fit is linear in the record: scaled by 2^500 or 2^-900 (exact in binary floating point,
    # far beyond where sums of squares would overflow or underflow) it is the same fit, scaled
    base = fit_pulse(rec).best
    for k in (500, -900):
        c = fit_pulse(rec.scaled(2.0**k)).best
        assert (c.shape, c.tp, c.t0, c.score) == (base.shape, base.tp, base.t0, base.score)
        assert c.ap == base.ap * 2.0**k


# -- a shape's fit does not depend on the other shapes asked for (issue 24) -----------------------
SHARED_AT2 = ["Rinaldi228.AT2", "Rinaldi318.AT2", "NGA_no_1063_RRS228.AT2", "RSN1084_NORTHR_SCS052.AT2",
              "RSN1084_NORTHR_SCS142.AT2", "RSN125_FRIULI.A_A-TMZ000.AT2", "RSN15_KERN_TAF021.AT2",
              "RSN181_IMPVALL.H_H-E06140.AT2", "RSN181_IMPVALL.H_H-E06230.AT2", "RSN30_PARKF_C05085.AT2",
              "RSN68_SFERN_PEL090.AT2", "RSN6_IMPVALL.I_I-ELC180.AT2", "RSN77_SFERN_PUL164.AT2",
              "RSN879_LANDERS_LCN260.AT2", "RSN879_LANDERS_LCN345.AT2"]


@pytest.mark.slow
@pytest.mark.parametrize("name", SHARED_AT2)
def test_a_shapes_fit_is_the_same_whichever_shapes_are_asked(name):
    """``fit_pulse(r, shapes=[s])`` gave Rinaldi 228's one-sine as 0.652 g, 0.891 s while the sine
    of ``fit_pulse(r)`` was 0.676 g, 0.82 s: the weighted fit's background was estimated around
    the best plain pulse among the shapes asked.  It is estimated once per record now, so every
    number of a shape's candidate is the same (exactly: the same operations) either way."""
    record = pulses.read_record(shared_record(name))
    whole = fit_pulse(record)
    fields = ("ap", "tp", "t0", "score", "correlation", "fit_window")
    for shape in pulses.SHAPES:
        alone = fit_pulse(record, shapes=[shape])
        assert alone.weighting == whole.weighting
        assert [getattr(alone[shape], f) for f in fields] == [getattr(whole[shape], f) for f in fields], shape
    if name == "Rinaldi228.AT2":  # the numbers
        assert whole["sine"].ap_g == pytest.approx(0.676, abs=5e-4) and whole["sine"].tp == pytest.approx(0.82, abs=5e-3)
    pair = fit_pulse(record, shapes=["rect", "sine"])
    assert [c.shape for c in pair.candidates] == sorted(["rect", "sine"], key=lambda s: -whole[s].score)


def test_shapes_are_named_only_by_their_registry():
    # a new shape is one class in pulses (pulses.Pulse's notes): outside pulses/shapes.py no
    # module of pulses or pipeline compares a value with a shape's name or writes a list of
    # shapes by hand (a tuple, list, set or dict of two or more of their names or classes)
    import ast
    import pathlib

    names = set(pulses.SHAPES)
    classes = {cls.__name__ for cls in pulses.SHAPES.values()}

    def named(node):
        if isinstance(node, ast.Constant):
            return node.value in names
        return isinstance(node, (ast.Name, ast.Attribute)) and \
            (getattr(node, "id", None) or getattr(node, "attr", None)) in classes

    root = pathlib.Path(__file__).resolve().parents[1]
    found = []
    for package in ("pulses", "pipeline"):
        for path in sorted((root / package).rglob("*.py")):
            if path.relative_to(root).as_posix() in ("pulses/shapes.py", "pulses/__init__.py"):
                continue  # the registry, and the lazy table naming the public classes
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, ast.Compare) and any(named(n) for n in (node.left, *node.comparators)):
                    found.append(f"{path.name}:{node.lineno} compares with a shape")
                items = node.elts if isinstance(node, (ast.Tuple, ast.List, ast.Set)) else \
                    node.keys if isinstance(node, ast.Dict) else []
                if sum(named(n) for n in items if n is not None) >= 2:
                    found.append(f"{path.name}:{node.lineno} lists shapes by hand")
    assert len(names) == 4 and not found, found
