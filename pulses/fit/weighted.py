"""Weighted (generalised) least squares of one pulse shape on a window of a record.

The background motion is taken as stationary noise whose covariance ``S`` is the circulant of a
power spectrum (:class:`pulses.fit.background.Background` estimates it from the record): weighting every
frequency of a residual by the inverse of the power there is generalised least squares, and the
weighted inner product of two sampled signals is ``u' S^-1 v``.  It is computed in the frequency
domain, on real FFTs of ``nfft`` points (the window zero-padded), with weights ``w`` per bin
(:func:`gram`).

:class:`WeightedWindow` holds one window of a record and gives the pieces of the weighted sum of
squares of a pulse ``(ap, Tp, t0)`` (amplitude in the record's units, period and time in s): the
sum profiled over the amplitude, the normal equations for Levenberg-Marquardt
(:func:`pulses.fit.lsq.levenberg_marquardt`), a scan over periods and whole-sample shifts, and the
search that combines them.  A straight-line baseline is fitted alongside in the same metric.
:func:`difference_covariance` gives the covariance of the difference of the plain and weighted
estimates, for Hausman's test of the pulse model (:func:`refine_weighted`).
"""
from __future__ import annotations

import math

import numpy as np
from scipy import fft as sfft

from ..shapes import shape_class
from .lsq import levenberg_marquardt
from .matching import BLAS_PRODUCT, _products
from .windows import TP_LEASH

#: record kept each side of the pulse by the weighted least squares: GLS_MARGIN s or
#: GLS_MARGIN_PERIODS periods if longer (enough for the baseline and the low frequencies a long
#: pulse needs; on the README's synthetic records 5 s either side did no better, and cost 9 % more)
GLS_MARGIN = 3.0
GLS_MARGIN_PERIODS = 1.0
#: the weighted estimate is refused when it differs from the plain one by more than noise
#: explains: Hausman's statistic (chi-square of 3 degrees of freedom under the model) above its
#: 99.9 % point
GLS_HAUSMAN = 16.27
#: periods scanned by the weighted search of a shape with corners before its descent, within a
#: factor GLS_SCAN_RANGE of the starting period; shifts within GLS_SHIFT Tp
GLS_SCAN = 9
GLS_SCAN_RANGE = 1.1
GLS_SHIFT = 0.1
#: the weighted descent stops when the weighted sum of squares falls by less than this share,
#: or after GLS_MAX_CALLS evaluations.  The sum is about the number of samples in the window
#: (thousands), so this is a fall of a few hundredths, where one standard deviation of the
#: estimates moves it by one; 1e-7 gave the same README tables, 2.5 % slower
GLS_FTOL = 1e-5
GLS_MAX_CALLS = 12
#: for a shape with corners (:meth:`pulses.Pulse.cornered`) the descent is restarted from the
#: best of a lattice of the pulse's two edges about where it stopped, GLS_LATTICE points per
#: sample, the width within GLS_LATTICE_SPAN points: weighted by the background's spectrum, the
#: corners pin the pulse to a fraction of a sample, and the objective has a kink at every sample
GLS_LATTICE = 4
GLS_LATTICE_SPAN = 4


def gram(U, Vw):
    """Weighted inner products ``u' S^-1 v`` of every row of ``U`` with every row of ``Vw``.

    Parameters
    ----------
    U : ndarray of complex, shape (k, nfft // 2 + 1)
        Real FFTs (``scipy.fft.rfft``, ``nfft`` points) of ``k`` sampled signals.
    Vw : ndarray of complex, shape (m, nfft // 2 + 1)
        Real FFTs of ``m`` signals already multiplied by the weights ``w`` of each bin.

    Returns
    -------
    ndarray, shape (k, m)
        ``sum(Re(U) Re(Vw) + Im(U) Im(Vw))`` over the bins (computed on the arrays' float views),
        which is ``u' S^-1 v`` when ``w`` are the weights of :meth:`pulses.fit.background.Background.weights`.
    """
    return _products(U.view(float), Vw.view(float))


def difference_covariance(U, B, w, nfft):
    """Covariance of the difference of the plain and weighted estimates of ``(ap, Tp, t0)``.

    Linearised, plain least squares scatter as ``(J'J)^-1 J'SJ (J'J)^-1`` and weighted ones as
    ``(J'S^-1 J)^-1``; the weighted estimate being the efficient one, their difference has the
    difference of these covariances (Hausman), which lets the caller tell noise from a pulse
    model the record does not follow.

    Parameters
    ----------
    U : ndarray of complex, shape (3, nfft // 2 + 1)
        Real FFTs of the pulse's derivatives with respect to ``ap``, ``Tp`` and ``t0`` at the plain
        estimate (record units per unit of ``ap``, per s, per s).
    B : ndarray of complex, shape (2, nfft // 2 + 1), or None
        Real FFTs of the baseline's columns ``1`` and ``t - tc`` (None without a baseline).
    w : ndarray, shape (nfft // 2 + 1,)
        Weights of the bins, the inverse of the noise's spectrum (:func:`gram`).
    nfft : int
        Length of the FFTs.

    Returns
    -------
    ndarray, shape (3, 3), or None
        The covariance, in the units of ``(ap, Tp, t0)`` squared per unit of noise power; None
        where it cannot be computed (singular or not finite).
    """
    J = U if B is None else np.concatenate([U, B])
    plain = np.full(w.size, 2.0 / nfft)  # the same sums unweighted: interior bins count twice
    plain[0] = 1.0 / nfft
    if nfft % 2 == 0:
        plain[-1] = 1.0 / nfft
    try:
        weighted = np.linalg.inv(gram(J, J * w))
        plain_inv = np.linalg.inv(gram(J, J * plain))
    except np.linalg.LinAlgError:
        return None
    plain_cov = plain_inv @ gram(J, J * (plain**2 / w)) @ plain_inv
    difference = (plain_cov - weighted)[:3, :3]
    return difference if np.all(np.isfinite(difference)) else None


class WeightedWindow:
    """The weighted least squares of one pulse shape on one window of a record.

    Parameters
    ----------
    cls : type
        The shape's class (:func:`pulses.shape_class`): its ``sampled``,
        ``sampled_with_derivatives``, ``support_tau``, ``centre_tau`` and ``cornered``.
    xw : ndarray, shape (n,)
        The record's samples in the window (any acceleration units; ``ap`` comes out in them).
    tw : ndarray, shape (n,)
        Their times, s (uniform, step ``dt``).
    dt : float
        Sampling step, s.
    weights : callable
        ``nfft -> w``: the weights of the ``nfft // 2 + 1`` bins of a real FFT of ``nfft``
        points (:meth:`pulses.fit.background.Background.weights`).
    baseline : bool
        Fit a straight-line baseline ``c0 + c1 (t - tc)`` alongside the pulse.
    tp : float
        The period the search starts near, s: it sets how far the whole-sample shifts of
        :meth:`scan` reach (:data:`GLS_SHIFT`).

    Notes
    -----
    The window is zero-padded to ``nfft = scipy.fft.next_fast_len(n)`` points and the metric is
    circular over them.  The record's and the baseline's weighted spectra are computed once;
    every pulse tried costs one FFT of its samples (and derivatives), built on its support only.
    """

    def __init__(self, cls, xw, tw, dt, weights, baseline, tp):
        self.cls, self.tw, self.dt, self.baseline = cls, tw, dt, baseline
        self.t_first = float(tw[0])
        self.nfft = nfft = sfft.next_fast_len(tw.size, real=True)
        self.w = w = weights(nfft)
        X = sfft.rfft(xw, nfft)
        self.Xw = Xw = X * w  # every product is with one weighted side
        # the pulse and its derivatives vanish outside its support: computed there only
        self.sup_lo, self.sup_hi = cls.support_tau
        self.xx = float(gram(X[None], Xw[None])[0, 0])
        if baseline:
            self.B = B = sfft.rfft(np.stack((np.ones_like(tw), tw - float(tw.mean()))), nfft, axis=-1)
            Bw = B * w
            self.BB_inv = np.linalg.inv(gram(B, Bw))
            self.BX = gram(B, Xw[None])[:, 0]
            self.xx -= float(self.BX @ self.BB_inv @ self.BX)
        # the record's and the baseline's weighted spectra, stacked: one product with the columns
        self.fixed = np.concatenate((Xw[None], Bw)) if baseline else Xw[None]
        # each candidate pulse's best whole-sample shift from the weighted cross-correlation (one
        # inverse FFT per candidate, all at once; baseline left out)
        self.shifts = np.fft.fftfreq(nfft, 1.0 / nfft)  # sample shift of each lag of the correlation
        self.k_near = np.flatnonzero(np.abs(self.shifts) <= max(2, int(GLS_SHIFT * tp / dt)))
        # irfft counts the interior bins twice, which the weights already do
        self.half = np.where((np.arange(w.size) == 0) | (2 * np.arange(w.size) == nfft), 1.0, 0.5)
        self.Xw_half = Xw * self.half
        # computed on first use by the scans: the record whitened in time, irfft(Xw_half) nfft,
        # and the circulant's kernel (:meth:`norms`)
        self.whitened = self.kernel = None

    def support(self, tp_, t0_):
        """Slice of the window's samples where the pulse ``(tp_, t0_)`` (s) may be non-zero."""
        return self.cls.support_slice(tp_, t0_, self.t_first, self.dt, self.tw.size)

    # columns are built zero-padded to the FFT's length, which spares the FFT a padded copy
    def sampled(self, tp_, t0_):
        """The unit pulse ``(tp_, t0_)`` on the window, zero-padded: shape ``(1, nfft)``."""
        out = np.zeros((1, self.nfft))
        k = self.support(tp_, t0_)
        out[0, k] = self.cls.sampled(tp_, t0_, self.tw[k], self.dt)
        return out

    def sampled_with_derivatives(self, tp_, t0_):
        """The unit pulse and its derivatives with respect to ``tp`` and ``t0`` (per s),
        zero-padded: shape ``(3, nfft)``."""
        out = np.zeros((3, self.nfft))
        k, columns = self.cls.support_columns(tp_, t0_, self.tw, self.dt)
        out[:, k] = columns
        return out

    def products(self, cols):
        """Weighted ``u'v`` among the columns ``cols`` (shape ``(k, nfft)``; overwritten) and with
        the record, the baseline projected out: ``(UU, UX)``, lists of floats of shapes ``(k, k)``
        and ``(k,)`` (the small algebra in Python floats: cheaper than numpy calls at this size)."""
        U = sfft.rfft(cols, axis=-1, overwrite_x=True)
        k = U.shape[0]
        UF = gram(U, np.concatenate((U * self.w, self.fixed))).tolist()  # columns, record, baseline
        UU, UX = [row[:k] for row in UF], [row[k] for row in UF]
        if self.baseline:  # less (UB BB^-1) UB' and (UB BB^-1) BX
            (b00, b01), (b10, b11) = self.BB_inv.tolist()
            bx0, bx1 = self.BX.tolist()
            for i, row in enumerate(UF):
                c0, c1 = row[k + 1] * b00 + row[k + 2] * b10, row[k + 1] * b01 + row[k + 2] * b11
                UU[i] = [UU[i][j] - (c0 * UF[j][k + 1] + c1 * UF[j][k + 2]) for j in range(k)]
                UX[i] -= c0 * bx0 + c1 * bx1
        return UU, UX

    def profiled(self, tp_, t0_):
        """``(cost, ap)``: the weighted sum of squares of the record less the pulse ``(tp_, t0_)``
        of least-squares amplitude ``ap`` (record units), and that amplitude."""
        UU, UX = self.products(self.sampled(tp_, t0_))
        return self.xx - UX[0] ** 2 / max(UU[0][0], 1e-300), UX[0] / max(UU[0][0], 1e-300)

    def normal(self, p):
        """The normal equations at ``p = (ap, tp, t0)`` for :func:`pulses.fit.lsq.levenberg_marquardt`:
        ``(r'S^-1 r, J'S^-1 J, J'S^-1 r)`` with ``r`` the residual and ``J = dr/dp`` (nested lists
        of floats)."""
        a = float(p[0])
        UU, UX = self.products(self.sampled_with_derivatives(max(p[1], 1e-9), p[2]))
        d = (1.0, a, a)
        ur = [UX[i] - a * UU[i][0] for i in range(3)]  # u' S^-1 r for r = x - a m
        cost = self.xx - 2.0 * a * UX[0] + a * a * UU[0][0]
        return (cost, [[UU[i][j] * (d[i] * d[j]) for j in range(3)] for i in range(3)],
                [-d[i] * ur[i] for i in range(3)])

    def difference_covariance(self, ap, tp_, t0_):
        """:func:`difference_covariance` at the plain estimate ``(ap, tp_, t0_)`` on this window."""
        U = sfft.rfft(self.sampled_with_derivatives(tp_, t0_), axis=-1) * np.array([[1.0], [ap], [ap]])
        return difference_covariance(U, self.B if self.baseline else None, self.w, self.nfft)

    def scan(self, tps, t0s, reach=None):
        """The best of the pulses ``(tps, t0s)`` (arrays, s), each moved by its best whole-sample
        shift, by the weighted gain ``(u'S^-1 x)^2 / u'S^-1 u``: its ``(tp, t0)``.

        The shifts are within ``reach`` samples (default: :data:`GLS_SHIFT` of the window's
        period, at least 2).  ``u'S^-1 x`` for ``u`` moved by ``m`` samples is the circular
        cross-correlation at lag ``m`` of ``u`` with the record whitened (``irfft(Xw)``, in time):
        for short pulses and few shifts summed over the pulses' support, with ``u'S^-1 u`` from
        ``u``'s autocorrelation, whose transform is as short as twice the support
        (:meth:`norms`); otherwise by one transform of each pulse over the window."""
        tw, dt, nfft = self.tw, self.dt, self.nfft
        # every candidate sampled at once, over the union of their supports
        a = max(0, int(math.floor((np.min(t0s + self.sup_lo * tps) - tw[0]) / dt)) - 1)
        b = max(a, min(tw.size, int(math.ceil((np.max(t0s + self.sup_hi * tps) - tw[0]) / dt)) + 2))
        cols = self.cls.sampled(tps[:, None], t0s[:, None], tw[a:b], dt)
        lags = self.shifts[self.k_near].astype(int) if reach is None else np.arange(-reach, reach + 1)
        if cols.size * lags.size <= BLAS_PRODUCT:  # short pulses, few shifts: sums in time
            mm = self.norms(cols)
            if self.whitened is None:
                self.whitened = sfft.irfft(self.Xw_half, nfft) * nfft
            corr = _products(cols, self.whitened[(np.arange(a, b)[None] + lags[:, None]) % nfft])
        else:  # one transform of each candidate and one inverse transform for all its shifts
            padded = np.zeros((len(tps), nfft))
            padded[:, a:b] = cols
            M = sfft.rfft(padded, axis=-1, overwrite_x=True)
            mm = np.einsum("ik,ik->i", M.view(float), (M * self.w).view(float))
            corr = sfft.irfft(self.Xw_half * M.conj(), nfft, axis=-1)[:, lags % nfft] * nfft
        j = np.argmax(np.abs(corr), axis=1)
        gain = corr[np.arange(j.size), j] ** 2 / np.maximum(mm, 1e-300)
        i = int(np.argmax(gain))
        return tps[i], t0s[i] + lags[j[i]] * dt

    def norms(self, cols):
        """``u'S^-1 u`` of each row ``u`` of ``cols`` (shape ``(k, m)``: samples on ``m`` consecutive
        samples of the window, zero elsewhere).

        ``sum(w |U|^2)`` over the bins is ``nfft sum_l h_l R_l``, with ``R`` the autocorrelation of
        ``u`` and ``h = irfft(w_half)`` the circulant's kernel: ``R`` vanishes beyond ``m - 1``
        lags, so it is computed by transforms of about ``2 m`` points instead of ``nfft``."""
        m = cols.shape[1]
        if 2 * m - 1 > self.nfft:  # no shorter than the window's own transform
            U = sfft.rfft(cols, self.nfft, axis=-1)
            return np.einsum("ik,ik->i", U.view(float), (U * self.w).view(float))
        if self.kernel is None:  # h_0 and 2 h_l for l > 0: R is even
            self.kernel = sfft.irfft(self.w * self.half, self.nfft) * self.nfft
            self.kernel[1:] *= 2.0
        n = sfft.next_fast_len(2 * m - 1, real=True)
        F = sfft.rfft(cols, n, axis=-1)
        R = sfft.irfft(F.real**2 + F.imag**2, n, axis=-1)[:, :m]
        return _products(R, self.kernel[None, :m])[:, 0]

    def descent(self, tp_, t0_, lower, upper):
        """``(p, cost)``: Levenberg-Marquardt from ``(tp_, t0_)`` and its profiled amplitude, inside
        the box ``[lower, upper]`` of ``(ap, tp, t0)`` (:data:`GLS_FTOL`, :data:`GLS_MAX_CALLS`)."""
        _, ap_ = self.profiled(tp_, t0_)
        return levenberg_marquardt(self.normal, np.array([ap_, tp_, t0_]),
                                   scale=np.array([abs(ap_) or 1.0, tp_, tp_]),
                                   ftol=GLS_FTOL, max_calls=GLS_MAX_CALLS, lower=lower, upper=upper)

    def search(self, tp, t0, lower, upper):
        """``(p, cost)``: the weighted least squares ``p = (ap, tp, t0)`` from ``(tp, t0)`` (s)
        inside the box ``[lower, upper]``, and its weighted sum of squares.

        The descent from ``(tp, t0)``; for a shape with corners from the best of a scan of the
        period (:data:`GLS_SCAN`), then again from the best of a lattice of the pulse's edges
        (:data:`GLS_LATTICE`), whichever ends lower."""
        cls, dt = self.cls, self.dt
        if not cls.cornered():
            return self.descent(tp, t0, lower, upper)
        # a scan of the period about the start, the pulse's centre kept, then the descent
        tps = tp * np.exp(np.linspace(-math.log(GLS_SCAN_RANGE), math.log(GLS_SCAN_RANGE), GLS_SCAN))
        p_new, cost = self.descent(*self.scan(tps, t0 + cls.centre_tau * (tp - tps)), lower, upper)
        # the descent stops in the first kink it meets, a sample or two from the optimum:
        # a lattice of both edges about where it stopped, then the descent from its best
        lo_, hi_ = cls.support_tau
        widths, starts = (v.ravel() for v in np.meshgrid(
            (hi_ - lo_) * p_new[1] + dt * np.arange(-GLS_LATTICE_SPAN, GLS_LATTICE_SPAN + 1) / GLS_LATTICE,
            p_new[2] + lo_ * p_new[1] + dt * (np.arange(GLS_LATTICE) / GLS_LATTICE - 0.5)))
        tps = widths / (hi_ - lo_)
        p_lattice, cost_lattice = self.descent(*self.scan(tps, starts - lo_ * tps, reach=2), lower, upper)
        if cost_lattice < cost:
            p_new, cost = p_lattice, cost_lattice
        return p_new, cost


def refine_weighted(x, t, dt, shape, match, start, background, baseline):
    """Generalised least squares ``(ap, Tp, t0, window)`` from a plain least-squares ``start``.

    The residual over the pulse and :data:`GLS_MARGIN` s (or :data:`GLS_MARGIN_PERIODS`) of
    record each side is weighted by the inverse of the background's spectrum
    (:class:`pulses.fit.background.Background`), in the frequency domain, the straight-line baseline fitted alongside
    in the same metric (:meth:`WeightedWindow.search`: for a shape with corners
    a scan of the period and a lattice of the pulse's edges around Levenberg-Marquardt; for a
    smooth shape, whose weighted minimum lies in the plain one's basin, the descent from
    ``start``).  ``start`` is returned when nothing beats it on the weighted objective, or when
    the two estimates differ by more than noise of the estimated spectrum explains
    (:func:`difference_covariance`, Hausman's test).  By Gauss-Markov, under
    that spectrum the weighted estimate scatters less than the plain one,
    whatever the shape and period; it is used wherever the record follows the model.
    """
    cls = shape_class(shape)
    ap, tp, t0, _ = start
    lo, hi = cls.fit_tau
    margin = max(GLS_MARGIN, GLS_MARGIN_PERIODS * tp)
    i0 = max(0, int(math.floor((t0 + lo * tp - margin) / dt)))
    i1 = min(x.size, int(math.ceil((t0 + hi * tp + margin) / dt)) + 1)
    idx = slice(i0, i1)
    gls = WeightedWindow(cls, x[idx], t[idx], dt, background.weights, baseline, tp)
    difference = gls.difference_covariance(ap, tp, t0)
    if difference is None:
        return start
    start_cost, _ = gls.profiled(tp, t0)
    _, tp0, t00 = match
    try:
        p_new, cost = gls.search(tp, t0, lower=np.array([-np.inf, tp0 / TP_LEASH, t00 - tp0]),
                                 upper=np.array([np.inf, tp0 * TP_LEASH, t00 + tp0]))
    except np.linalg.LinAlgError:
        return start
    ap_new, tp_new, t0_new = (float(v) for v in p_new)
    if not all(map(math.isfinite, (ap_new, tp_new, t0_new))) or tp_new <= 2 * dt or \
            cost > start_cost * (1 + 1e-12):
        return start
    # the record must follow the pulse model where the weights look: on a record whose
    # background was filtered away above some frequency, a rectangle's or one-sine's edges are
    # not in the record either, and a weighted fit would shrink the pulse to hide them.  Under
    # the model the two estimates differ only by noise of known covariance (Hausman's test)
    d = np.array([ap_new - ap, tp_new - tp, t0_new - t0])
    if float(d @ np.linalg.pinv(difference) @ d) > GLS_HAUSMAN:
        return start
    return (ap_new, tp_new, t0_new, idx)
