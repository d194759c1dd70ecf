"""The background motion's power spectrum, estimated from a record and its plain fit, as the
weights of the weighted least squares (:mod:`pulses.fit.weighted`)."""
from __future__ import annotations

import numpy as np
from scipy import fft as sfft

from .plain import scored
from .weighted import refine_weighted
from .windows import pulse_window

#: length (s) of the segments over which the background's spectrum is averaged: at least
#: SEGMENT s and SEGMENT_PERIODS periods of the best plain fit
SEGMENT = 2.5
SEGMENT_PERIODS = 2.5
#: the segments that overlap the best plain pulse's window widened by this many of its periods
#: on each side are left out of the background's spectrum (:class:`Background`): there the
#: residual holds the plain fit's own error, whose corners reach frequencies where the
#: background has almost no power.  Half a period beyond the window holds the true pulse where
#: the plain fit is off by its noise limit (t0 within 5 % of Tp in 86 % of the README's cases at
#: 30 % noise, Tp within 15 % in 76 %)
SKIP_PERIODS = 0.5
#: length (s) over which the record is tapered to zero at each end for the weighted score
SCORE_TAPER = 1.0
#: white noise added to the background's spectrum, as a share of its mean power: bounds the
#: weight of frequencies where the background has (almost) no power
LOADING = 1e-3


def segment_periodograms(x, dt: float, nseg: int):
    """Periodograms of the half-overlapping Hann segments of ``x``: Welch's estimate before the
    average.

    Segments of ``nseg`` samples every ``nseg - nseg // 2``, each less its mean, times the
    periodic Hann window ``w_k = (1 - cos(2 pi k / nseg)) / 2``; one-sided power spectral density
    ``2 |rfft|^2 dt / sum(w^2)`` (the zero and, for an even ``nseg``, the Nyquist bins not doubled),
    in the units of ``x`` squared per Hz.  These are ``scipy.signal.spectrogram(x, 1 / dt,
    "hann", nseg, nseg // 2, detrend="constant")``'s (density scaling), computed without
    importing ``scipy.signal`` (half a second or more on a cold start: it imports ``scipy.stats``).

    Parameters
    ----------
    x : ndarray, shape (n,)
        Samples, ``n >= nseg``.
    dt : float
        Sampling step, s.
    nseg : int
        Samples per segment.

    Returns
    -------
    freq : ndarray, shape (nseg // 2 + 1,)
        Frequencies, Hz.
    power : ndarray, shape (nseg // 2 + 1, number of segments)
        One periodogram per column, segments in time order.
    """
    x = np.asarray(x, dtype=float)
    step = nseg - nseg // 2
    segments = np.lib.stride_tricks.sliding_window_view(x, nseg)[::step]
    window = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(nseg) / nseg)
    spectra = sfft.rfft(window * (segments - segments.mean(axis=-1, keepdims=True)), axis=-1)
    power = (spectra.real**2 + spectra.imag**2) * (dt / float(np.sum(window * window)))
    power[:, 1:(None if nseg % 2 else -1)] *= 2.0
    return sfft.rfftfreq(nseg, dt), power.T


class Background:
    """The background motion's power spectrum, estimated from a residual, as least-squares weights.

    Welch's average of periodograms of the residual (Hann segments of :data:`SEGMENT` s, half
    overlapping; below two of its frequency steps no lower than there), plus :data:`LOADING`
    times its mean: white noise that bounds the weight of
    frequencies where the background has almost no power.  Segments that overlap the interval
    ``skip`` (s from the first sample; the pulse) are left out, unless that leaves no power.
    Weighting each frequency of a residual by the inverse of this power is generalised least
    squares (the noise's covariance taken as the circulant of this spectrum).
    """

    def __init__(self, resid, dt: float, segment: float = None, skip=None):
        resid = np.asarray(resid, dtype=float)
        self.dt = float(dt)
        segment = SEGMENT if segment is None else segment
        nseg = int(min(resid.size, max(16, round(segment / dt))))
        # Welch's estimate, one periodogram per segment so that some can be left out
        self.freq, periodograms = segment_periodograms(resid, dt, nseg)
        keep = np.ones(periodograms.shape[1], dtype=bool)
        if skip is not None:
            starts = np.arange(keep.size) * (nseg - nseg // 2) * dt
            keep = (starts + (nseg - 1) * dt < skip[0]) | (starts > skip[1])
        power = periodograms[:, keep].mean(axis=1) if keep.any() else np.zeros(self.freq.size)
        if not np.any(power > 0):  # nothing left, or only round-off of an exact fit there
            power = periodograms.mean(axis=1)
        # below two frequency steps the segments (their means removed) cannot measure the
        # power: it is taken as no lower than there
        low = self.freq < 2.0 / (nseg * dt)
        if np.any(low) and not np.all(low):
            power[low] = np.maximum(power[low], power[np.argmin(low)])
        self.power = power + LOADING * float(np.mean(power))

    @property
    def usable(self) -> bool:
        """Whether the spectrum has finite, positive power everywhere (weights to divide by)."""
        return bool(np.all(np.isfinite(self.power) & (self.power > 0)))

    def weights(self, nfft: int) -> np.ndarray:
        """Weights of the ``nfft // 2 + 1`` bins of a real FFT of ``nfft`` points such that
        ``sum(w * Re(U conj(V)))`` is ``u' S^-1 v`` (``S`` the background's covariance, circulant)."""
        f = np.arange(nfft // 2 + 1) / (nfft * self.dt)
        w = 2.0 / (nfft * np.interp(f, self.freq, self.power * (0.5 / self.dt)))
        w[0] *= 0.5
        if nfft % 2 == 0:
            w[-1] *= 0.5
        return w

    def explained(self, x, pulses: dict) -> dict:
        """Share of the weighted energy of the samples ``x`` that each pulse (samples on the same
        times, by name) explains: ``1 - r' S^-1 r / x' S^-1 x`` with ``r = x - p``.

        The metric is circular (a Fourier transform of the record): ``x`` and ``r`` are tapered
        to zero over :data:`SCORE_TAPER` s at each end first (half a Hann window), so that the
        jump from the record's last sample back to its first, which the weights would see as
        motion at every frequency, does not count, and a pulse cannot gain by cancelling it.
        """
        nfft = sfft.next_fast_len(x.size, real=True)
        w = self.weights(nfft)
        m = max(1, min(x.size // 4, int(round(SCORE_TAPER / self.dt))))
        taper = np.ones(x.size)
        ramp = 0.5 - 0.5 * np.cos(np.pi * (np.arange(m) + 0.5) / m)
        taper[:m], taper[-m:] = ramp, ramp[::-1]

        def energy(v):
            V = sfft.rfft(v * taper, nfft)
            return float(np.sum(w * (V.real**2 + V.imag**2)))

        xx = energy(x)
        return {name: 1.0 - energy(x - p) / xx for name, p in pulses.items()}


def estimate_background(x, t, dt, shape, fit, energy, baseline):
    """The background's spectrum (:class:`Background`) from the record and its best plain fit
    ``fit = (match, trial, samples)`` of ``shape``, and that shape's weighted fit with the first
    estimate, as ``((ap, Tp, t0, window), samples)``, and whether that refit was accepted (else
    it is the plain fit: :func:`pulses.fit.weighted.refine_weighted`); ``(None, None, False)`` if the residual has
    no power to weight by.

    Two passes.  The plain fit's residual holds its own error where the pulse is, and a
    one-sine's or a rectangle's corners put that error at frequencies where the background has
    almost no power: the first estimate leaves out the segments near the pulse
    (:data:`SKIP_PERIODS`).  The best shape is refit with it; that fit's error being much
    smaller, the spectrum is estimated again from the whole of its residual, which counts the
    background where it is strongest too: around the pulse, on a real record; the other shapes
    are refit with this second estimate (on Rinaldi 228, with the first one the one-sine's Tp
    would move 4 % from the plain fit's, with the second 2 %).  Segments of
    :data:`SEGMENT` s or :data:`SEGMENT_PERIODS` plain periods if longer, to resolve the
    spectrum down to the pulse's own frequencies.
    """
    match, trial, p = fit
    _, tp, t0, _ = trial
    segment = max(SEGMENT, SEGMENT_PERIODS * tp)
    lo, hi = pulse_window(shape, tp, t0)
    first = Background(x - p, dt, segment, skip=(lo - SKIP_PERIODS * tp, hi + SKIP_PERIODS * tp))
    if not first.usable:
        return None, None, False
    refit = refine_weighted(x, t, dt, shape, match, trial, first, baseline)
    samples = p if refit is trial else scored(x, t, dt, shape, refit, energy)[1]
    second = Background(x - samples, dt, segment)
    return (second if second.usable else first), (refit, samples), refit is not trial
