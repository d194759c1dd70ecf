"""Synthetic accelerograms with a known pulse, for testing the fitter and measuring its accuracy.

A synthetic record is a pulse of given shape, amplitude, period and time, plus optionally

- band-limited background motion: Gaussian white noise through a zero-phase 4th-order
  Butterworth band-pass (default 0.5-10 Hz, where strong ground motion carries most of its
  high-frequency energy), scaled so that its RMS over the whole record is ``noise * |ap|``;
- a second, weaker pulse;
- a baseline drift: a straight line in acceleration, ``drift * |ap| * (t / T - 1/2)``.

The pulse is sampled at the sample times (the rectangular pulse as its average over each
sample's cell, so that its edges are defined below ``dt``), as the fitter samples it.
"""
from __future__ import annotations

import numpy as np
from scipy import signal

from ..record import Record
from ..shapes import make_pulse, shape_class

#: default band of the background motion, Hz
NOISE_BAND = (0.5, 10.0)


def sampled_pulse(shape: str, ap: float, tp: float, t0: float, t, dt: float) -> np.ndarray:
    """Samples of a pulse at times ``t`` (s): point values, cell averages for ``rect``
    (:meth:`pulses.Pulse.sampled`)."""
    make_pulse(shape, ap, tp, t0)  # checks the name and the values
    return ap * shape_class(shape).sampled(tp, t0, np.asarray(t, dtype=float), dt)


def band_noise(n: int, dt: float, rms: float, rng, band=NOISE_BAND) -> np.ndarray:
    """Gaussian noise band-passed to ``band`` (Hz) with the given RMS."""
    if rms == 0.0:
        return np.zeros(n)
    nyq = 0.5 / dt
    lo, hi = band[0] / nyq, min(band[1] / nyq, 0.99)
    sos = signal.butter(4, [lo, hi], btype="bandpass", output="sos")
    white = rng.standard_normal(n + 2000)
    noise = signal.sosfiltfilt(sos, white)[1000:1000 + n]
    return noise * (rms / np.sqrt(np.mean(noise**2)))


def synthetic_record(shape: str, ap: float, tp: float, t0: float, duration: float, dt: float = 0.005,
                     noise: float = 0.0, seed=None, band=NOISE_BAND, second=None,
                     drift: float = 0.0) -> Record:
    """A record made of a known pulse and optional background motion, second pulse and drift.

    Parameters
    ----------
    shape, ap, tp, t0 :
        The pulse (``ap`` in m/s^2, ``tp`` and ``t0`` in s; see :func:`pulses.make_pulse`).
    duration : float
        Record length, s.
    dt : float
        Sampling interval, s.
    noise : float
        RMS of the background motion as a fraction of ``|ap|``.
    seed : int or numpy Generator, optional
        Random seed of the background motion.
    band : (float, float)
        Band of the background motion, Hz.
    second : tuple, optional
        ``(shape, ap, tp, t0)`` of a second pulse.
    drift : float
        Baseline drift: a straight line from ``-drift |ap| / 2`` to ``+drift |ap| / 2``.

    Returns
    -------
    pulses.Record
        With ``metadata["truth"] = {"shape", "ap", "tp", "t0"}``.
    """
    rng = seed if isinstance(seed, np.random.Generator) else np.random.default_rng(seed)
    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    acc = sampled_pulse(shape, ap, tp, t0, t, dt)
    acc = acc + band_noise(n, dt, noise * abs(ap), rng, band)
    if second is not None:
        acc = acc + sampled_pulse(*second, t, dt)
    if drift:
        acc = acc + drift * abs(ap) * (t / t[-1] - 0.5)
    truth = {"shape": shape, "ap": ap, "tp": tp, "t0": t0}
    return Record(acc, dt, name=f"synthetic-{shape}", metadata={"truth": truth, "units": "m/s2",
                                                                  "warnings": []})


def noise_autocovariance(n: int, dt: float, rms: float, band=NOISE_BAND) -> np.ndarray:
    """Autocovariance (lags 0..n-1, (m/s^2)^2) of :func:`band_noise` with the given RMS.

    The zero-phase filter applies the Butterworth response twice, so the noise power spectrum is
    ``|H(f)|^4`` times that of the white input.
    """
    nyq = 0.5 / dt
    lo, hi = band[0] / nyq, min(band[1] / nyq, 0.99)
    sos = signal.butter(4, [lo, hi], btype="bandpass", output="sos")
    nfft = 1 << int(np.ceil(np.log2(4 * n)))
    _, h = signal.sosfreqz(sos, worN=nfft // 2 + 1, whole=False)
    acov = np.fft.irfft(np.abs(h) ** 4, nfft)[:n]
    return acov * (rms**2 / acov[0])


def least_squares_limit(shape: str, ap: float, tp: float, t0: float, duration: float, dt: float,
                        noise: float, band=NOISE_BAND, baseline: bool = True) -> dict:
    """Standard deviations of ``ap``, ``Tp`` and ``t0`` that an exact least-squares fit of the
    true shape has under band-limited background motion (the noise limit of the method).

    Linearised about the true pulse, the least-squares estimate has covariance
    ``(J'J)^-1 J' S J (J'J)^-1`` with ``J`` the derivatives of the sampled pulse (and of the
    straight-line baseline fitted with it) over the fit window and ``S`` the covariance of the
    background motion: the scatter of any least-squares pulse fit, however good its search.

    Returns
    -------
    dict
        ``ap``, ``tp`` (relative standard deviations) and ``t0`` (standard deviation in Tp).
    """
    from .windows import fit_window, unit_samples_and_derivatives

    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    lo, hi = fit_window(shape, tp, t0)
    idx = slice(max(0, int(np.floor(lo / dt))), min(n, int(np.ceil(hi / dt)) + 1))
    tw = t[idx]
    m, d_tp, d_t0 = unit_samples_and_derivatives(shape, tp, t0, tw, dt)
    cols = [m, ap * d_tp, ap * d_t0]
    if baseline:
        cols += [np.ones_like(tw), tw - tw.mean()]
    J = np.column_stack(cols)
    acov = noise_autocovariance(tw.size, dt, noise * abs(ap), band)
    # S J by convolution with the symmetric autocovariance (Toeplitz product through the FFT)
    kernel = np.concatenate([acov[::-1], acov[1:]])
    SJ = np.column_stack([signal.fftconvolve(J[:, k], kernel, mode="same") for k in range(J.shape[1])])
    JtJ_inv = np.linalg.inv(J.T @ J)
    cov = JtJ_inv @ (J.T @ SJ) @ JtJ_inv
    sd = np.sqrt(np.diag(cov))
    return {"ap": sd[0] / abs(ap), "tp": sd[1] / tp, "t0": sd[2] / tp}


def weighted_least_squares_limit(shape: str, ap: float, tp: float, t0: float, duration: float, dt: float,
                                 noise: float, band=NOISE_BAND, baseline: bool = True) -> dict:
    """Standard deviations of ``ap``, ``Tp`` and ``t0`` that the weighted (generalised) least
    squares of :func:`pulses.fit_pulse` have under band-limited background motion, when the
    background's spectrum is known: the noise limit of ``weighting="background"``.

    As the fitter does, over the pulse and ``pulses.fit.weighted.GLS_MARGIN`` s each side, with the
    covariance of the background taken as the circulant of its spectrum ``S`` and the weights
    ``1 / (S + c mean(S))`` (``c = pulses.fit.background.LOADING``).  Linearised about the true pulse, the
    estimate has covariance ``(J'WJ)^-1 J'WSWJ (J'WJ)^-1``; without the loading (``c = 0``) it is
    ``(J'S^-1 J)^-1``, the Cramer-Rao bound, which no unbiased estimator beats.

    Returns
    -------
    dict
        ``ap``, ``tp`` (relative standard deviations) and ``t0`` (standard deviation in Tp).
    """
    from scipy import fft as sfft

    from .background import LOADING
    from .weighted import GLS_MARGIN

    cls = shape_class(shape)
    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    lo, hi = cls.fit_tau
    idx = slice(max(0, int(np.floor((t0 + lo * tp - GLS_MARGIN) / dt))),
                min(n, int(np.ceil((t0 + hi * tp + GLS_MARGIN) / dt)) + 1))
    tw = t[idx]
    m, d_tp, d_t0 = cls.sampled_with_derivatives(tp, t0, tw, dt)
    cols = [m, ap * d_tp, ap * d_t0]
    if baseline:
        cols += [np.ones_like(tw), tw - tw.mean()]
    nfft = sfft.next_fast_len(tw.size, real=True)
    U = sfft.rfft(np.stack(cols), nfft, axis=-1)
    # eigenvalues of the circulant covariance: the noise's power at each bin, averaging to its variance
    nyq = 0.5 / dt
    sos = signal.butter(4, [band[0] / nyq, min(band[1] / nyq, 0.99)], btype="bandpass", output="sos")
    _, h = signal.sosfreqz(sos, worN=np.arange(nfft // 2 + 1) / (nfft * dt), fs=1.0 / dt)
    power = np.abs(h) ** 4
    c = np.full(power.size, 2.0)
    c[0] = 1.0
    if nfft % 2 == 0:
        c[-1] = 1.0
    power *= (noise * abs(ap)) ** 2 / (np.sum(c * power) / nfft)
    weighted = power + LOADING * float(np.mean(power))

    def gram(w):
        return np.real(np.einsum("ik,jk->ij", U * (c * w / nfft), U.conj()))

    F_inv = np.linalg.inv(gram(1.0 / weighted))
    cov = F_inv @ gram(power / weighted**2) @ F_inv
    sd = np.sqrt(np.diag(cov))
    return {"ap": sd[0] / abs(ap), "tp": sd[1] / tp, "t0": sd[2] / tp}
