"""The Daubechies-4 wavelet as Shahi & Baker's classification uses it (:mod:`pulses.velocity`):
its continuous transform as MATLAB's legacy ``cwt(x, scales, 'db4')`` computes it, at every
sample (:func:`db4_cwt`), at one sample (:func:`cwt_point`) or over a stretch of samples
(:func:`cwt_at`, :class:`WindowedTransform`), and the wavelet drawn into a pulse (:func:`unit_wavelet`).

The integrated wavelet (``psi`` integrated on a 2^-10 grid) is resampled at each scale,
convolved with the signal, differentiated, its central part kept and multiplied by
``-sqrt(scale)``; here the convolution and the differentiation are one FFT convolution with
:func:`difference_filter`.  The filters are cached within byte budgets (:mod:`pulses.bytecache`).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pywt
from scipy import fft as sfft

from .bytecache import byte_lru

#: the mother wavelet (MATLAB name and PyWavelets name agree)
WAVELET = "db4"
#: centre frequency of db4 (MATLAB ``centfrq('db4')``: the peak of |FFT(psi)| over its support
#: of 7, at 5/7), so that a scale ``a`` has pseudo-period ``Tp = a dt / FC = 1.4 a dt``
FC = 5.0 / 7.0
#: precision (2^-PRECISION grid) of the integrated wavelet, MATLAB ``cwt``'s ``precis = 10``
PRECISION = 10
#: iterations of the wavelet drawn into the pulse, ``wavefun('db4', 4)`` in ``analyze_record.m``
PULSE_ITERATIONS = 4
#: bytes the caches of filters may hold (each): every filter of a 200 Hz record fits many times
#: over (51 coarse filters of at most 15,000 samples: 6 MB), while a 10 kHz record's, whose
#: longest filter has 750,000 samples, are recomputed rather than held by the gigabyte
FILTER_CACHE_BYTES = 64 * 2**20
#: bytes the cache of the coarse filters' spectra may hold: a 200 Hz record of 40 s needs 10 MB
SPECTRUM_CACHE_BYTES = 128 * 2**20
#: longest dot product handed to BLAS in one call: OpenBLAS (in NumPy's and SciPy's wheels)
#: spreads a dot product of more than 10,000 elements over threads, which stalls on a busy
#: machine (4 ms instead of 4 us measured); shorter pieces run on the calling thread, three
#: times faster than :func:`numpy.einsum`
DOT_PIECE = 8192
#: largest (outputs x input samples) for which a windowed transform is a direct convolution:
#: below it :func:`numpy.convolve` is cheaper than two FFTs
DIRECT_LIMIT = 100_000


@lru_cache(maxsize=None)
def _integrated_wavelet():
    """Integrated db4 wavelet on its grid (step 2^-10 over the support 0..7)."""
    int_psi, x = pywt.integrate_wavelet(pywt.Wavelet(WAVELET), precision=PRECISION)
    return int_psi, float(x[1] - x[0]), float(x[-1] - x[0])


def resampled_integral(scale: float) -> np.ndarray:
    """The integrated wavelet resampled at ``scale`` and reversed, as MATLAB's legacy ``cwt``:
    ``j = 1 + floor((0:a*xmax) / (a*step))``, ``f = fliplr(intpsi(j))``."""
    int_psi, step, xmax = _integrated_wavelet()
    j = (np.arange(int(math.floor(scale * xmax)) + 1) / (scale * step)).astype(int)
    j = j[j < int_psi.size]
    if j.size == 1:
        j = np.array([j[0], j[0]])
    return int_psi[j][::-1]


@byte_lru(FILTER_CACHE_BYTES)  # the coarse scales; the refined ones are kept by _point_filter
def difference_filter(scale: float) -> np.ndarray:
    """Filter ``g`` with ``conv(x, g) = diff(conv(x, f))``, ``f`` the :func:`resampled_integral`
    (``g = [f0, f1 - f0, ..., -f_last]``); read-only."""
    f = resampled_integral(scale)
    g = np.empty(f.size + 1)
    g[0] = f[0]
    g[1:-1] = np.diff(f)
    g[-1] = -f[-1]
    g.flags.writeable = False
    return g


def _offset(scale: float) -> int:
    """Index in ``conv(x, g)`` of the transform's sample 0: MATLAB keeps the central ``n``
    samples of ``diff(conv(x, f))`` (``wkeep1``), i.e. from ``floor((len(f) - 2) / 2)``, and
    ``diff(y)[k] = conv(x, g)[k + 1]``."""
    return _offset_of(difference_filter(scale).size)


def _offset_of(length: int) -> int:
    """:func:`_offset` of a filter ``g`` of ``length`` samples (``len(f) = length - 1``)."""
    return (length - 3) // 2 + 1


def db4_cwt_direct(x, scales) -> np.ndarray:
    """The db4 transform by direct convolution (:func:`numpy.convolve`): the reference for
    :func:`db4_cwt`, as MATLAB's legacy ``cwt(x, scales, 'db4')`` computes it.

    Returns an array (len(scales), len(x)).
    """
    x = np.asarray(x, dtype=float)
    out = np.empty((len(scales), x.size))
    for i, a in enumerate(scales):
        y = np.diff(np.convolve(x, resampled_integral(a)))
        start = (y.size - x.size) // 2
        out[i] = -math.sqrt(a) * y[start:start + x.size]
    return out


@byte_lru(SPECTRUM_CACHE_BYTES)
def _filter_spectrum(scale: float, size: int) -> np.ndarray:
    """``-sqrt(scale)`` times the FFT of size ``size`` of :func:`difference_filter`; read-only."""
    spectrum = sfft.rfft(difference_filter(scale), size) * (-math.sqrt(scale))
    spectrum.flags.writeable = False
    return spectrum


def db4_cwt(x, scales) -> np.ndarray:
    """Continuous wavelet transform with the db4 wavelet, MATLAB's legacy ``cwt(x, scales, 'db4')``.

    The integrated wavelet (``psi`` integrated on a 2^-10 grid) is resampled at each scale,
    convolved with the signal, differentiated, its central part kept and multiplied by
    ``-sqrt(scale)``; here the convolution and the differentiation are one FFT convolution
    with :func:`difference_filter`, on a grid just long enough that the kept part is exact.

    Parameters
    ----------
    x : array_like, shape (n,) or (m, n)
        Signal(s), uniformly sampled (scales are in samples).
    scales : sequence of float
        Scales, in samples.

    Returns
    -------
    numpy.ndarray, shape (len(scales), n) or (m, len(scales), n)
    """
    x = np.asarray(x, dtype=float)
    scales = tuple(float(a) for a in scales)
    out = np.empty(x.shape[:-1] + (len(scales), x.shape[-1]))
    for i, row in cwt_rows(x, scales):
        out[..., i, :] = row
    return out


def cwt_rows(x: np.ndarray, scales: tuple):
    """The rows of :func:`db4_cwt`, one scale at a time (in the order of their FFT sizes):
    pairs (index of the scale, transform of shape ``x.shape``), so that a caller can use each
    row while it is in the cache."""
    n = x.shape[-1]
    for size, members in _size_groups(scales, n):
        spectrum = sfft.rfft(x, size, axis=-1)
        product = np.empty_like(spectrum)
        for i in members:
            k = _offset(scales[i])
            np.multiply(spectrum, _filter_spectrum(scales[i], size), out=product)
            yield i, sfft.irfft(product, size, axis=-1)[..., k:k + n]


@lru_cache(maxsize=8)
def _size_groups(scales: tuple, n: int, groups: int = 4) -> tuple:
    """FFT sizes for the scales: circular convolution of size M equals the linear one on the
    kept samples when ``M >= n + len(g) - 1 - offset`` and ``M >= offset + n``; scales are put
    in up to ``groups`` runs sharing one size (one forward FFT of the signal per run)."""
    need = [sfft.next_fast_len(max(n + difference_filter(a).size - 1 - _offset(a), _offset(a) + n), real=True)
            for a in scales]
    order = sorted(range(len(scales)), key=lambda i: need[i])
    runs = [order[i * len(order) // groups:(i + 1) * len(order) // groups] for i in range(groups)]
    return tuple((max(need[i] for i in run), tuple(run)) for run in runs if run)


def _dot(a: np.ndarray, b: np.ndarray) -> float:
    """``sum(a * b)`` of two 1-D arrays, by BLAS in pieces of at most :data:`DOT_PIECE`."""
    if a.size <= DOT_PIECE:
        return float(np.dot(a, b))
    return float(sum(np.dot(a[i:i + DOT_PIECE], b[i:i + DOT_PIECE]) for i in range(0, a.size, DOT_PIECE)))


@byte_lru(FILTER_CACHE_BYTES)
def _point_filter(scale: float) -> tuple[int, np.ndarray, float]:
    """What the transform at one sample needs at ``scale``: (the :func:`_offset`, the
    :func:`difference_filter` reversed (read-only), ``-sqrt(scale)``)."""
    g = difference_filter.__wrapped__(scale)  # uncached: only the reversed copy is kept
    reverse = g[::-1].copy()
    reverse.flags.writeable = False
    return _offset_of(g.size), reverse, -math.sqrt(scale)


def cwt_point(x: np.ndarray, scales, at: int) -> np.ndarray:
    """The db4 transform of ``x`` at sample ``at`` for each of ``scales`` (one dot product each,
    over the samples of ``x`` the filter meets)."""
    out = np.empty(len(scales))
    n = x.size
    for i, a in enumerate(scales):
        offset, gr, factor = _point_filter(a)
        hi = at + offset + 1  # x indices at + offset - (G - 1) .. at + offset
        lo = hi - gr.size
        x_lo, x_hi = max(lo, 0), min(hi, n)
        out[i] = factor * _dot(x[x_lo:x_hi], gr[x_lo - lo:x_hi - lo]) if x_hi > x_lo else 0.0
    return out


class WindowedTransform:
    """The db4 transform at one scale over output samples ``start..stop-1`` of signals that are
    zero outside input samples ``lo..hi-1``.

    Only the stretch of the filter those outputs and inputs meet is used (zero-extended where
    it runs past the filter's ends), so the work scales with ``(stop - start) + (hi - lo)``
    rather than with the filter's length ``7 scale``: for long scales the filter is longer than
    the record.  Output ``q`` is ``conv(seg, part)[q + len(seg) - 1]``, the 'valid' part of a
    linear convolution; a circular one of size ``>= len(part)`` has it exact.
    """

    def __init__(self, scale: float, start: int, stop: int, lo: int, hi: int):
        k, reverse, self.factor = _point_filter(scale)
        g = reverse[::-1]
        self.lo = max(lo, start + k - (g.size - 1))  # inputs the outputs see
        self.hi = min(hi, stop + k)
        self.width = stop - start
        size = self.hi - self.lo
        if size <= 0:
            self.part = None
            return
        first = start + k - self.hi + 1  # filter index of the first output and the last input
        self.part = np.zeros(self.width + size - 1)
        a, b = max(first, 0), min(first + self.part.size, g.size)
        if b > a:
            self.part[a - first:b - first] = g[a:b]
        self.direct = self.width * size < DIRECT_LIMIT
        if not self.direct:
            self.fft_size = sfft.next_fast_len(self.part.size, real=True)
            self.spectrum = sfft.rfft(self.part, self.fft_size) * self.factor

    def __call__(self, piece: np.ndarray, at: int) -> np.ndarray:
        """Transform of the signal equal to ``piece`` from sample ``at`` on (zero elsewhere)."""
        if self.part is None:
            return np.zeros(self.width)
        a, b = max(at, self.lo), min(at + piece.size, self.hi)
        if b <= a:
            return np.zeros(self.width)
        size = self.hi - self.lo
        if a == self.lo and b == self.hi:
            seg = piece[a - at:b - at]
        else:
            seg = np.zeros(size)
            seg[a - self.lo:b - self.lo] = piece[a - at:b - at]
        if self.direct:
            return self.factor * np.convolve(seg, self.part, mode="valid")
        y = sfft.irfft(sfft.rfft(seg, self.fft_size) * self.spectrum, self.fft_size)
        return y[size - 1:size - 1 + self.width]


def cwt_at(x: np.ndarray, scale: float, start: int, stop: int) -> np.ndarray:
    """The db4 transform of ``x`` at one scale, samples ``start..stop-1`` only (exact: the
    convolution of the stretch of ``x`` those samples see)."""
    return WindowedTransform(scale, start, stop, 0, x.size)(x, 0)


@lru_cache(maxsize=None)
def _pulse_wavelet():
    _, psi, x = pywt.Wavelet(WAVELET).wavefun(level=PULSE_ITERATIONS)
    return psi, x


@byte_lru(FILTER_CACHE_BYTES)
def unit_wavelet(scale: float) -> tuple[int, np.ndarray]:
    """The db4 wavelet at ``scale`` on samples, centred on sample 0, linearly interpolated from
    the ``wavefun('db4', 4)`` grid (zero outside its support) as ``analyze_record.m`` draws it:
    (first sample, relative to the centre; values), read-only."""
    psi, x = _pulse_wavelet()
    centre = 0.5 * (x[0] + x[-1])
    first = int(math.ceil((x[0] - centre) * scale))
    k = np.arange(first, int(math.floor((x[-1] - centre) * scale)) + 1)
    values = np.interp(k / scale + centre, x, psi)
    values.flags.writeable = False
    return first, values
