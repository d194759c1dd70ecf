"""Matching a record with a pulse shape over periods and times: an FFT-based wavelet transform.

For a shape ``w`` (unit amplitude, period ``Tp``) the transform of a record ``x`` sampled at
``t_i`` is the correlation

    c(tau, Tp) = sum_i x_i w((t_i - tau) / Tp),

the wavelet transform with the pulse as mother wavelet and ``Tp`` as scale.  The least-squares
amplitude of a pulse placed at ``tau`` is ``c / ||w||^2`` and the share of the record's energy it
explains is ``c^2 / (||w||^2 ||x||^2)``: the best match maximises that share.

The two Ricker shapes are PyWavelets' ``mexh`` (second derivative of a Gaussian) and ``gaus3``
(third derivative) at scale ``s``.  Their Tp follows from docs/theory.md section 3, not from pywt's rounded
``central_frequency`` (0.25 and 0.4):

- ``mexh``: ``psi(x) ~ (1 - x^2) exp(-x^2/2)``, ``x = t/s``; Eq. 7 is the same curve with
  ``x = sqrt(2) pi t / Tp``, so ``Tp = sqrt(2) pi s``.  Its Fourier amplitude
  ``~ f^2 exp(-Tp^2 f^2)`` peaks at ``f = 1/Tp``, as docs/theory.md section 3 requires (centre frequency
  ``1/(sqrt(2) pi) = 0.2251``, not 0.25: pywt's value gives Tp 10 % too low).
- ``gaus3``: ``psi(u) ~ d^3/du^3 exp(-u^2)``, ``u = t/s``; Eq. 8 is the same curve with
  ``u = x/sqrt(2) = 2 pi t / (sqrt(6) Tp)``, so ``Tp = 2 pi s / sqrt(6)``.  Its Fourier amplitude
  ``~ f^3 exp(-3 Tp^2 f^2 / 2)`` peaks at ``f = 1/Tp`` (centre frequency ``sqrt(6)/(2 pi) =
  0.3898``, not 0.4: 2.5 % too low).

The transform is computed in the frequency domain with the closed-form Fourier transforms of the
four shapes (one FFT of the record, one inverse FFT per period), keeping only the band the
shortest period needs, so the output is on a coarser time grid than the record.  This is the
coarse search; :mod:`pulses.fit.plain` refines the best match by least squares on the samples.
"""
from __future__ import annotations

import functools
import math

import numpy as np
from scipy import fft as sfft

from ..shapes import SHAPES, AntisymmetricRicker, SymmetricRicker, shape_class

#: Tp = MEXH_TP_PER_SCALE * s for PyWavelets' ``mexh`` at scale s (docs/theory.md section 3)
MEXH_TP_PER_SCALE = SymmetricRicker.pywt[1]
#: Tp = GAUS3_TP_PER_SCALE * s for PyWavelets' ``gaus3`` at scale s (docs/theory.md section 3)
GAUS3_TP_PER_SCALE = AntisymmetricRicker.pywt[1]
#: PyWavelets wavelet of each shape that has one, and its Tp per unit scale
PYWT_WAVELETS = {name: cls.pywt for name, cls in SHAPES.items() if cls.pywt is not None}


def _dot(a, b) -> float:
    """``sum(a * b)`` without BLAS: a multithreaded BLAS dot on long vectors (OpenBLAS uses
    threads above 10 000 samples) can stall for milliseconds on a busy machine."""
    return float(np.einsum("i,i->", a, b))


#: largest product :func:`_products` leaves to BLAS, in multiply-adds: half the size below which
#: OpenBLAS runs a matrix product on one thread (m n k = 262,144)
BLAS_PRODUCT = 131072


def _products(a, b) -> np.ndarray:
    """``a b'``: every row of ``a`` (shape ``(i, k)``) times every row of ``b`` (``(j, k)``).  BLAS
    up to :data:`BLAS_PRODUCT` multiply-adds (several times faster than ``einsum`` on a few rows),
    ``einsum`` beyond, where BLAS would start threads (see :func:`_dot`)."""
    if a.shape[0] * b.shape[0] * a.shape[-1] <= BLAS_PRODUCT:
        return a @ b.T
    return np.einsum("ik,jk->ij", a, b)


def _tp_per_scale(shape: str) -> float:
    cls = shape_class(shape)
    if cls.pywt is None:
        raise ValueError(f"pulse shape {shape!r} has no PyWavelets wavelet; those that do: "
                         f"{', '.join(PYWT_WAVELETS)}")
    return cls.pywt[1]


def tp_from_scale(shape: str, scale: float, dt: float = 1.0) -> float:
    """Pulse period Tp (s) of PyWavelets' ``mexh``/``gaus3`` at ``scale`` (in samples of ``dt`` s)."""
    return _tp_per_scale(shape) * scale * dt


def scale_from_tp(shape: str, tp: float, dt: float = 1.0) -> float:
    """PyWavelets scale (in samples of ``dt`` s) of the Ricker shape with period ``tp`` (s)."""
    return tp / (_tp_per_scale(shape) * dt)


def unit_spectrum(shape: str, nu):
    """Fourier transform of the unit-amplitude, unit-period shape at frequency ``nu`` (cycles/Tp).

    Convention ``W(nu) = integral w(tau) exp(-2 pi i nu tau) d tau`` with the shape's time origin
    (arrival for ``rect``/``sine``, centre for the Rickers); a shape of period ``Tp`` has
    transform ``Tp W(f Tp)`` (:meth:`pulses.Pulse.spectrum`).
    """
    return shape_class(shape).spectrum(nu)


def unit_energy(shape: str) -> float:
    """``integral w(tau)^2 d tau`` of the unit shape (the squared norm of a pulse is ``ap^2 Tp`` times it)."""
    return shape_class(shape).energy


#: highest frequency kept, in cycles per Tp of the shortest period: above it the Ricker spectra
#: are below 1e-3 of their peak (rect and sine keep their slowly decaying sinc tails out of
#: the coarse search, which is all this transform is for)
BAND_CYCLES = 3.0
#: octaves of matching kernels kept (:func:`_band`): about 6 octaves by 4 shapes make a record's,
#: each of 12 periods by up to ~1,000 bins of 16 bytes and ~2,000 output points (a 60 s record)
BANDS_KEPT = 32
#: zero padding after the record, in longest periods: the circular correlation must not wrap a
#: pulse's support round to the other end.  The Ricker wavelets fall below 1e-8 of their peak
#: 1.5 Tp from the centre, so 1.5 Tp is enough for the matching (it is only the coarse search)
PAD_PERIODS = 1.5


@functools.lru_cache(maxsize=BANDS_KEPT)
def _band(shape: str, nfft: int, dt: float, bins: int, tp_max: float, t_end: float, tps: bytes):
    """What matching ``shape`` at one octave of periods needs besides the record: a function of
    the record's length and step only, kept (:data:`BANDS_KEPT`) for the next record of the
    same length, such as the next direction of a pair.  Read-only arrays.

    Parameters
    ----------
    shape : str
        The shape.
    nfft : int
        Length of the record's (padded) transform; ``bins`` of its bins are kept (:class:`Matcher`).
    dt : float
        Sampling step, s.
    tp_max : float
        Longest period matched, s (the padding).
    t_end : float
        Time of the record's last sample, s.
    tps : bytes
        The octave's periods, s (float64).

    Returns
    -------
    m : int
        Bins of the band the shortest period needs.
    n_out : int
        Points of the inverse transform (the octave's time grid).
    kernels : ndarray of complex, shape (len(tps), m)
        ``conj`` of the DFT of the sampled unit shape at each period.
    tau : ndarray, shape (n_out,)
        Time of the shape's origin at each output point, s (past the padded end: negative).
    allowed : ndarray of bool, shape (len(tps), n_out)
        Whether the pulse's centre lies inside the record there.
    norm : ndarray, shape (len(tps), 1)
        ``||w||^2`` of the sampled unit shape at each period.
    """
    group = np.frombuffer(tps)
    tps = group[:, None]
    m = int(math.ceil(BAND_CYCLES / group[0] * nfft * dt)) + 1
    m = max(2, min(m, bins))
    n_out = min(sfft.next_fast_len(2 * (m - 1), real=True), nfft)
    m = min(m, n_out // 2 + 1)
    freq = np.arange(m) / (nfft * dt)
    kernels = np.conj(tps / dt * unit_spectrum(shape, freq[None, :] * tps))
    period = nfft * dt
    tau = np.arange(n_out) * (period / n_out)
    tau = np.where(tau > period - PAD_PERIODS * tp_max, tau - period, tau)
    centre = shape_class(shape).centre_tau * tps
    allowed = (tau[None, :] >= -centre) & (tau[None, :] <= t_end - centre)
    norm = unit_energy(shape) * tps / dt
    for a in (kernels, tau, allowed, norm):
        a.flags.writeable = False
    return m, n_out, kernels, tau, allowed, norm


class Matcher:
    """The FFT of one record, ready to be matched against shapes at many periods.

    Parameters
    ----------
    acc : ndarray
        Samples (m/s^2).
    dt : float
        Sampling interval (s).
    tp_max : float
        Longest period that will be asked for (s): sets the zero padding against wrap-around.
    tp_min : float
        Shortest period (s): sets the band kept and the output time step.
    """

    def __init__(self, acc, dt: float, tp_min: float, tp_max: float):
        acc = np.asarray(acc, dtype=float)
        self.dt = float(dt)
        self.n = acc.size
        pad = int(math.ceil(PAD_PERIODS * tp_max / dt)) + 1
        self.nfft = sfft.next_fast_len(self.n + pad, real=True)
        spectrum = sfft.rfft(acc, self.nfft)
        f_keep = min(BAND_CYCLES / tp_min, 0.5 / dt)
        m = int(math.ceil(f_keep * self.nfft * dt)) + 1
        m = min(m, spectrum.size)
        self.n_out = sfft.next_fast_len(2 * (m - 1), real=True) if m > 1 else 2
        self.n_out = min(self.n_out, self.nfft)
        m = min(m, self.n_out // 2 + 1)
        self.spectrum = spectrum[:m]
        self.freq = np.arange(m) / (self.nfft * dt)
        self.period = self.nfft * dt
        self.dtau = self.period / self.n_out
        self.energy = _dot(acc, acc)
        self.tp_max = float(tp_max)

    def transform(self, shape: str, tps) -> tuple[np.ndarray, np.ndarray]:
        """Correlation ``c(tau, Tp)`` for every period in ``tps``.

        Returns
        -------
        tau : ndarray, shape (n_out,)
            Time of the shape's origin (arrival or centre), s from the first sample; values past
            the padded end wrap to negative times.
        c : ndarray, shape (len(tps), n_out)
            ``sum_i x_i w((t_i - tau)/Tp)`` (units of the samples).
        """
        tps = np.asarray(tps, dtype=float)[:, None]
        w_hat = tps / self.dt * unit_spectrum(shape, self.freq[None, :] * tps)  # DFT of sampled w
        c = sfft.irfft(self.spectrum[None, :] * np.conj(w_hat), self.n_out, axis=1) * (self.n_out / self.nfft)
        k = np.arange(self.n_out)
        tau = k * self.dtau
        tau = np.where(tau > self.period - PAD_PERIODS * tps.max() - self.dtau, tau - self.period, tau)
        return tau, c

    def explained(self, shape: str, tps) -> tuple[np.ndarray, np.ndarray]:
        """Signed share of the record's energy explained by the best-amplitude pulse at each (Tp, tau).

        ``c |c| / (||w||^2 ||x||^2)``: its absolute value is the share, its sign the polarity.
        """
        tau, c = self.transform(shape, tps)
        norm = unit_energy(shape) * np.asarray(tps, dtype=float)[:, None] / self.dt
        return tau, c * np.abs(c) / (norm * max(self.energy, 1e-300))

    def best_match(self, shape: str, tps, t_end: float):
        """Best ``(signed share, Tp, tau)`` of each polarity over the periods ``tps`` (s) and times.

        Periods are taken an octave at a time, each with the band (and so the time grid) its
        shortest period needs: a long period is matched on a coarse time grid, which keeps the
        cost proportional to the record length and almost independent of the period range.
        Allowed times: the pulse's centre (:attr:`pulses.Pulse.centre_tau`) inside the record:
        the centre of a Ricker, at least half of a rectangular or one-sine pulse.

        Returns
        -------
        polarities : list of (float, float, float)
            The best positive and the best negative match, the better first.
        octaves : list of (float, float, float)
            The best match (either polarity) of each octave of periods, the better first.
        """
        tps = np.sort(np.asarray(tps, dtype=float))
        best = {1: (0.0, float(tps[0]), 0.0), -1: (-0.0, float(tps[0]), 0.0)}
        octaves = []
        start = 0
        while start < tps.size:
            stop = int(np.searchsorted(tps, 2.0 * tps[start], side="left"))
            stop = max(stop, start + 1)
            group = tps[start:stop]
            m, n_out, kernels, tau, allowed, norm = _band(shape, self.nfft, self.dt, self.spectrum.size,
                                                          self.tp_max, float(t_end), group.tobytes())
            c = sfft.irfft(self.spectrum[None, :m] * kernels, n_out, axis=1) * (n_out / self.nfft)
            share = c * np.abs(c) / (norm * max(self.energy, 1e-300))
            masked = np.where(allowed, share, 0.0)
            in_octave = []
            for sign, k in ((1, int(np.argmax(masked))), (-1, int(np.argmin(masked)))):
                i, j = divmod(k, masked.shape[1])
                match = (float(share[i, j]), float(group[i]), float(tau[j]))
                in_octave.append(match)
                if sign * masked[i, j] > abs(best[sign][0]):
                    best[sign] = match
            octaves.append(max(in_octave, key=lambda b: abs(b[0])))
            start = stop
        by_size = lambda b: -abs(b[0])  # noqa: E731
        return sorted(best.values(), key=by_size), sorted(octaves, key=by_size)
