"""Synthetic accelerograms with a known pulse, for testing the fitter and measuring its accuracy.

A synthetic record is a pulse of given shape, amplitude, period and time, plus optionally

- band-limited background motion: Gaussian white noise through a zero-phase 4th-order
  Butterworth band-pass (default 0.5-10 Hz, where strong ground motion carries most of its
  high-frequency energy), scaled so that its RMS over the whole record is ``noise * |ap|``;
- a second, weaker pulse;
- a baseline drift: a straight line in acceleration, ``drift * |ap| * (t / T - 1/2)``.

The pulse is sampled at the sample times (the rectangular pulse as its average over each
sample's cell, from its antiderivative, so that its edges are defined below ``dt``).
"""
from __future__ import annotations

import numpy as np
from scipy import signal

from .record import Record
from .shapes import make_pulse

#: default band of the background motion, Hz
NOISE_BAND = (0.5, 10.0)


def sampled_pulse(shape: str, ap: float, tp: float, t0: float, t, dt: float) -> np.ndarray:
    """Samples of a pulse at times ``t`` (s): point values, cell averages for ``rect``."""
    t = np.asarray(t, dtype=float)
    if shape == "rect":
        def antiderivative(s):
            return ap * np.clip(s - t0, 0.0, tp)
        return (antiderivative(t + 0.5 * dt) - antiderivative(t - 0.5 * dt)) / dt
    return make_pulse(shape, ap, tp, t0)(t)


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
