"""The pulse fitter's least squares, part by part, against independent dense references.

:mod:`pulses.fit.weighted` computes generalised least squares in the frequency domain: a noise whose
covariance is the circulant of a power spectrum ``P`` (over the FFT's ``nfft`` points) weights a
residual's bins by ``1 / P``.  The references here build the same covariance as a dense matrix
(``C = circulant(ifft(P))``, ``C^-1 = circulant(ifft(1 / P))``), whiten with its Cholesky factor and
solve with :func:`numpy.linalg.lstsq` or :func:`scipy.optimize.least_squares`; the window is shorter
than ``nfft`` (zero-padded), so the metric on the window's samples is ``C^-1[:n, :n]``.
:mod:`pulses.fit.lsq`'s Levenberg-Marquardt and baseline projector are checked the same way.

Tolerances: the FFT sums and the dense products are two roundings of the same double-precision
sums over a few hundred samples with a spectrum spanning a factor 10 (condition numbers below
1e4), so agreements are asserted to 1e-9 relative where no iteration is involved.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import fft as sfft
from scipy import linalg, optimize

from pulses import shape_class
from pulses.fit.background import Background
from pulses.fit.lsq import baseline_projector, levenberg_marquardt, normal_equations
from pulses.fit.weighted import WeightedWindow, difference_covariance, gram

DT = 0.01
N = 397  # window samples; the FFT pads them to 400 points (5-smooth), so padding is exercised


def spectrum(nfft):
    """A red noise spectrum over the ``nfft // 2 + 1`` bins of a real FFT: 10 at low
    frequencies falling to 1 (any positive spectrum would do)."""
    k = np.arange(nfft // 2 + 1)
    return 1.0 + 9.0 / (1.0 + (k / (0.05 * nfft)) ** 2)


def weights(nfft):
    """The bins' weights for :func:`spectrum`, as :meth:`pulses.fit.background.Background.weights` makes them:
    interior bins stand for two bins of the full FFT."""
    w = 2.0 / (nfft * spectrum(nfft))
    w[0] *= 0.5
    if nfft % 2 == 0:
        w[-1] *= 0.5
    return w


def full(half, nfft):
    """The full FFT's ``nfft`` values of a real signal's spectrum given on its ``nfft // 2 + 1`` bins."""
    return np.concatenate([half, half[1:(nfft + 1) // 2][::-1]])


def dense(nfft, n, power=None):
    """``(C^-1[:n, :n], C[:n, :n])`` of the circulant covariance with spectrum ``power`` (default
    :func:`spectrum`): the metric and the covariance on the first ``n`` of ``nfft`` points."""
    P = full(spectrum(nfft) if power is None else power, nfft)
    inverse = linalg.circulant(np.fft.ifft(1.0 / P).real)
    covariance = linalg.circulant(np.fft.ifft(P).real)
    return inverse[:n, :n], covariance[:n, :n]


@pytest.fixture(scope="module")
def window():
    """A record window: a symmetric Ricker of 0.8 s plus red noise and a drift (m/s^2)."""
    rng = np.random.default_rng(7)
    tw = 1.0 + DT * np.arange(N)
    cls = shape_class("ricker-sym")
    noise = np.cumsum(rng.normal(0.0, 0.05, N)) * 0.2 + rng.normal(0.0, 0.05, N)
    xw = 1.3 * cls.sampled(0.8, 3.0, tw, DT) + noise + 0.02 + 0.01 * tw
    return cls, tw, xw


# -- gram: the weighted inner product ---------------------------------------------------------------
def test_gram_is_the_dense_quadratic_form():
    rng = np.random.default_rng(1)
    nfft = 400
    u, v = rng.normal(size=(3, nfft)), rng.normal(size=(2, nfft))
    got = gram(sfft.rfft(u), sfft.rfft(v) * weights(nfft))
    inverse, _ = dense(nfft, nfft)
    np.testing.assert_allclose(got, u @ inverse @ v.T, rtol=1e-9, atol=1e-12 * np.abs(got).max())


def test_background_weights_make_gram_the_inverse_of_its_spectrum():
    """:meth:`Background.weights` follow the convention the dense reference assumes: the metric is
    the inverse of the circulant covariance whose eigenvalues are the two-sided power ``P / (2 dt)``
    at each bin's frequency (the estimate interpolated there)."""
    rng = np.random.default_rng(2)
    bg = Background(rng.normal(size=2000), DT, segment=1.0)
    nfft = 256
    f = np.arange(nfft // 2 + 1) / (nfft * DT)
    inverse, _ = dense(nfft, nfft, np.interp(f, bg.freq, bg.power * (0.5 / DT)))
    u, v = rng.normal(size=(2, nfft)), rng.normal(size=(2, nfft))
    got = gram(sfft.rfft(u), sfft.rfft(v) * bg.weights(nfft))
    np.testing.assert_allclose(got, u @ inverse @ v.T, rtol=1e-9, atol=1e-12 * np.abs(got).max())


# -- the weighted window -------------------------------------------------------------------------------
def dense_gls(cls, tw, xw, tp, t0, baseline=True):
    """``(ap, cost)`` of the pulse ``(tp, t0)`` by generalised least squares on whitened data:
    ``C^-1 = L L'`` (Cholesky), ``min ||L'(x - A b)||`` with :func:`numpy.linalg.lstsq`."""
    nfft = sfft.next_fast_len(tw.size, real=True)
    inverse, _ = dense(nfft, tw.size)
    L = np.linalg.cholesky(inverse)
    cols = [cls.sampled(tp, t0, tw, DT)] + ([np.ones_like(tw), tw - tw.mean()] if baseline else [])
    A = np.column_stack(cols)
    coef, *_ = np.linalg.lstsq(L.T @ A, L.T @ xw, rcond=None)
    r = L.T @ (xw - A @ coef)
    return coef[0], float(r @ r)


@pytest.mark.parametrize("baseline", [True, False])
def test_profiled_amplitude_and_cost_are_generalised_least_squares(window, baseline):
    cls, tw, xw = window
    gls = WeightedWindow(cls, xw, tw, DT, weights, baseline, 0.8)
    assert gls.nfft == 400 > N
    for tp, t0 in ((0.8, 3.0), (0.7, 3.05), (1.1, 2.9)):
        cost, ap = gls.profiled(tp, t0)
        ap_ref, cost_ref = dense_gls(cls, tw, xw, tp, t0, baseline)
        assert ap == pytest.approx(ap_ref, rel=1e-9)
        assert cost == pytest.approx(cost_ref, rel=1e-9)


def dense_cost(cls, tw, xw, p):
    """Weighted sum of squares of the record less the pulse ``p = (ap, tp, t0)``, the baseline
    solved for (dense GLS with the pulse column subtracted)."""
    nfft = sfft.next_fast_len(tw.size, real=True)
    inverse, _ = dense(nfft, tw.size)
    L = np.linalg.cholesky(inverse)
    B = np.column_stack([np.ones_like(tw), tw - tw.mean()])
    y = xw - p[0] * cls.sampled(p[1], p[2], tw, DT)
    coef, *_ = np.linalg.lstsq(L.T @ B, L.T @ y, rcond=None)
    r = L.T @ (y - B @ coef)
    return float(r @ r)


def test_normal_equations_of_the_window(window):
    """``normal(p)``: the cost is the dense one, ``J'S^-1 r`` is half its gradient (central
    differences: truncation ~h^2 times third derivatives, below 1e-6 of the gradient here) and
    ``J'S^-1 J`` is the dense Gauss-Newton matrix with the baseline projected out in the metric."""
    cls, tw, xw = window
    gls = WeightedWindow(cls, xw, tw, DT, weights, True, 0.8)
    p = np.array([1.1, 0.75, 3.04])
    cost, A, g = gls.normal(p)
    assert cost == pytest.approx(dense_cost(cls, tw, xw, p), rel=1e-9)
    h = np.array([1e-5, 1e-6, 1e-6])
    grad = np.array([(dense_cost(cls, tw, xw, p + h[i] * e) - dense_cost(cls, tw, xw, p - h[i] * e)) / (2 * h[i])
                     for i, e in enumerate(np.eye(3))])
    np.testing.assert_allclose(g, 0.5 * grad, rtol=1e-5, atol=1e-6 * np.abs(grad).max())
    # Gauss-Newton: J = -d(a m)/dp; projected off the baseline in the metric M = C^-1
    inverse, _ = dense(gls.nfft, N)
    m, d_tp, d_t0 = cls.sampled_with_derivatives(p[1], p[2], tw, DT)
    J = -np.column_stack([m, p[0] * d_tp, p[0] * d_t0])
    B = np.column_stack([np.ones_like(tw), tw - tw.mean()])
    Jp = J - B @ np.linalg.solve(B.T @ inverse @ B, B.T @ inverse @ J)
    np.testing.assert_allclose(A, Jp.T @ inverse @ Jp, rtol=1e-9, atol=1e-12 * np.abs(A).max())


@pytest.mark.parametrize("shape, tp, t0", [("ricker-sym", 0.8, 3.0), ("sine", 0.9, 2.2)])
def test_search_finds_the_minimum_scipy_finds(shape, tp, t0):
    """:meth:`WeightedWindow.search` against :func:`scipy.optimize.least_squares` on the whitened
    residual (pulse and baseline, 5 unknowns, the same box), from a start 8 % off in Tp.  The
    descent stops when the cost falls by less than GLS_FTOL = 1e-5 of it (or after 12 calls), so
    its cost is asserted within 1e-4 of scipy's and the pulse within 1 % in ap and Tp and 1 % of Tp in t0
    (the standard errors here are several per cent)."""
    rng = np.random.default_rng(11)
    cls = shape_class(shape)
    tw = DT * np.arange(N)
    nfft = sfft.next_fast_len(N, real=True)
    inverse, covariance = dense(nfft, N)
    noise = np.linalg.cholesky(covariance) @ rng.normal(size=N) * 0.05
    xw = 1.2 * cls.sampled(tp, t0, tw, DT) + noise + 0.03
    lower, upper = np.array([-np.inf, tp / 1.5, t0 - tp]), np.array([np.inf, tp * 1.5, t0 + tp])
    gls = WeightedWindow(cls, xw, tw, DT, weights, True, tp)
    p, cost = gls.search(1.08 * tp, t0, lower, upper)
    L = np.linalg.cholesky(inverse)
    B = np.column_stack([np.ones_like(tw), tw - tw.mean()])

    def residual(q):
        return L.T @ (xw - q[0] * cls.sampled(q[1], q[2], tw, DT) - B @ q[3:])

    ref = optimize.least_squares(residual, [1.0, tp, t0, 0.0, 0.0], x_scale=[1.0, tp, tp, 0.1, 0.1],
                                 bounds=(np.r_[lower, -np.inf, -np.inf], np.r_[upper, np.inf, np.inf]),
                                 xtol=1e-12, ftol=1e-12)
    ref_cost = 2.0 * ref.cost
    assert cost == pytest.approx(ref_cost, rel=1e-4)
    assert cost >= ref_cost * (1 - 1e-9)  # scipy's is the minimum: the search cannot beat it
    assert p[0] == pytest.approx(ref.x[0], rel=0.01)
    assert p[1] == pytest.approx(ref.x[1], rel=0.01)
    assert p[2] == pytest.approx(ref.x[2], abs=0.01 * tp)
    assert abs(p[1] - tp) < 0.1 * tp  # and it is the pulse, not another minimum


# -- the covariance of the difference (Hausman) ------------------------------------------------------
@pytest.mark.parametrize("shape, n, baseline", [("ricker-sym", N, True), ("ricker-sym", 400, True),
                                               ("ricker-sym", N, False), ("rect", N, False)])
def test_difference_covariance_against_dense_matrices(shape, n, baseline):
    """``(J'J)^-1 J' C J (J'J)^-1 - (J' C^-1 J)^-1`` for the pulse's derivatives (and the
    baseline), from dense matrices; without padding (``n == nfft``) the metric is exactly the
    inverse covariance, and by Gauss-Markov the difference is positive semi-definite.  The
    rectangle, unlike the Rickers, has a mean, which the zero-frequency bin carries."""
    cls = shape_class(shape)
    tw = DT * np.arange(n)
    nfft = sfft.next_fast_len(n, real=True)
    ap, tp, t0 = 1.3, 0.8, 2.0
    m, d_tp, d_t0 = cls.sampled_with_derivatives(tp, t0, tw, DT)
    J = np.column_stack([m, ap * d_tp, ap * d_t0] + ([np.ones_like(tw), tw - tw.mean()] if baseline else []))
    U = sfft.rfft(J[:, :3].T, nfft, axis=-1)
    B = sfft.rfft(J[:, 3:].T, nfft, axis=-1) if baseline else None
    got = difference_covariance(U, B, weights(nfft), nfft)
    inverse, covariance = dense(nfft, n)
    JJ_inv = np.linalg.inv(J.T @ J)
    expected = (JJ_inv @ J.T @ covariance @ J @ JJ_inv - np.linalg.inv(J.T @ inverse @ J))[:3, :3]
    np.testing.assert_allclose(got, expected, rtol=1e-8, atol=1e-10 * np.abs(expected).max())
    if n == nfft:
        assert np.linalg.eigvalsh(0.5 * (got + got.T)).min() >= -1e-9 * np.abs(got).max()
    # the window's method is the same computation at its plain estimate (the pulse sampled on
    # its support only: the same numbers up to round-off)
    gls = WeightedWindow(cls, ap * m, tw, DT, weights, baseline, tp)
    np.testing.assert_allclose(gls.difference_covariance(ap, tp, t0), got, rtol=1e-9,
                               atol=1e-12 * np.abs(got).max())


def test_difference_covariance_refuses_a_singular_problem():
    nfft = 64
    U = np.zeros((3, nfft // 2 + 1), dtype=complex)  # a pulse that is not there
    assert difference_covariance(U, None, weights(nfft), nfft) is None


# -- Levenberg-Marquardt -----------------------------------------------------------------------------
def decay_problem():
    """A small nonlinear problem: ``y = a exp(-b t) + c`` sampled at 50 times, with a fixed
    perturbation so that the minimum is not a zero residual."""
    t = np.linspace(0.0, 4.0, 50)
    y = 2.0 * np.exp(-1.3 * t) + 0.4 + 0.01 * np.sin(7.0 * t)

    def residual(q):
        return q[0] * np.exp(-q[1] * t) + q[2] - y

    def jacobian(q):
        e = np.exp(-q[1] * t)
        return np.column_stack([e, -q[0] * t * e, np.ones_like(t)])

    return residual, jacobian


def solve(residual, jacobian, start, lower, upper):
    """:func:`levenberg_marquardt` with tight tolerances, and the number of its evaluations."""
    calls = []
    normal = normal_equations(lambda q: (residual(q), jacobian(q)))

    def counted(q):
        calls.append(q)
        return normal(q)

    p, cost = levenberg_marquardt(counted, start, scale=np.ones(3), lower=lower, upper=upper,
                                  xtol=1e-14, ftol=1e-15)
    return p, cost, len(calls)


@pytest.mark.parametrize("b_range, b_start", [((0.0, 5.0), 0.5), ((0.0, 5.0), 4.0), ((1.28, 1.32), 1.319)])
def test_levenberg_marquardt_against_scipy_with_bounds(b_range, b_start):
    """The minimum of ``y = a exp(-b t) + c`` inside the box ``b_range`` of ``b``: from both sides,
    and in a box so narrow (``b`` at 1.3068) that steps leaving it are refused on the way.  scipy's
    trust-region reflective solver with tight tolerances gives the reference; the minimum is well
    conditioned (the Jacobian's columns are far from parallel), so 1e-8 relative in the unknowns
    is orders above both solvers' stopping tolerances and far below any wrong answer."""
    residual, jacobian = decay_problem()
    lower, upper = np.array([-np.inf, b_range[0], -np.inf]), np.array([np.inf, b_range[1], np.inf])
    start = np.array([1.0, b_start, 0.0])
    p, cost, calls = solve(residual, jacobian, start, lower, upper)
    ref = optimize.least_squares(residual, start, jac=jacobian, bounds=(lower, upper),
                                 xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.all(p >= lower) and np.all(p <= upper)
    assert cost == pytest.approx(2.0 * ref.cost, rel=1e-9)
    np.testing.assert_allclose(p, ref.x, rtol=1e-8)
    np.testing.assert_allclose(p, [2.0, 1.3, 0.4], rtol=0.02)  # near the generating values
    assert calls < 100


def test_levenberg_marquardt_stays_in_the_box():
    """Where the unbounded minimum (b = 1.31) lies outside the box (b <= 1), every step that leaves
    the box is refused: the answer is inside, lower than the start, and not below the minimum in
    the box (scipy's).  The box is a leash, not a constraint it slides along: it stops on the
    border short of that minimum (here 2.5 % above its cost)."""
    residual, jacobian = decay_problem()
    lower, upper = np.array([-np.inf, 0.0, -np.inf]), np.array([np.inf, 1.0, np.inf])
    start = np.array([1.0, 0.5, 0.0])
    p, cost, _ = solve(residual, jacobian, start, lower, upper)
    ref = optimize.least_squares(residual, start, jac=jacobian, bounds=(lower, upper),
                                 xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.all(p >= lower) and np.all(p <= upper)
    assert p[1] == pytest.approx(1.0, abs=1e-6)
    assert 2.0 * ref.cost * (1 - 1e-12) <= cost < 0.1 * float(residual(start) @ residual(start))


def test_levenberg_marquardt_respects_max_calls():
    residual, jacobian = decay_problem()
    calls = []

    def normal(q):
        calls.append(1)
        return normal_equations(lambda v: (residual(v), jacobian(v)))(q)

    levenberg_marquardt(normal, np.array([1.0, 0.5, 0.0]), scale=np.ones(3), lower=np.full(3, -np.inf),
                        upper=np.full(3, np.inf), max_calls=3)
    assert len(calls) == 3


def test_normal_equations_are_the_products():
    rng = np.random.default_rng(3)
    r, J = rng.normal(size=20), rng.normal(size=(20, 3))
    cost, A, g = normal_equations(lambda p: (r, J))(None)
    assert cost == pytest.approx(r @ r, rel=1e-12)
    np.testing.assert_allclose(A, J.T @ J, rtol=1e-12)
    np.testing.assert_allclose(g, J.T @ r, rtol=1e-12)


# -- the baseline projector ------------------------------------------------------------------------
def test_projector_removes_the_straight_line_and_nothing_else():
    """Against ``I - Q Q'`` (``Q`` from the QR factorisation of the columns 1 and t): the same
    orthogonal projector, so idempotent, zero on straight lines, the identity on what is
    orthogonal to them."""
    rng = np.random.default_rng(4)
    tw = 3.0 + DT * np.arange(120)
    project = baseline_projector(tw, True)
    Q, _ = np.linalg.qr(np.column_stack([np.ones_like(tw), tw]))
    reference = np.eye(tw.size) - Q @ Q.T
    v = rng.normal(size=tw.size)
    np.testing.assert_allclose(project(v), reference @ v, atol=1e-12)
    np.testing.assert_allclose(project(project(v)), project(v), atol=1e-12)
    assert np.abs(project(0.7 - 2.5 * tw)).max() < 1e-11
    w = reference @ v  # orthogonal to both columns
    np.testing.assert_allclose(project(w), w, atol=1e-12)
    rows = rng.normal(size=(3, tw.size))
    np.testing.assert_allclose(project(rows), rows @ reference.T, atol=1e-12)
    assert baseline_projector(tw, False)(v) is v
    assert math.isclose(float(project(v) @ tw), 0.0, abs_tol=1e-9)


# -- the fitter's fast paths against the plain formulas ----------------------------------------------
@pytest.mark.parametrize("shape", ["rect", "sine", "ricker-sym", "ricker-anti"])
def test_support_columns_are_sampled_with_derivatives(shape):
    """Computed on the support only, the same values bit for bit (the same operations), zero
    elsewhere, for pulses inside, across the ends of and outside a window."""
    cls = shape_class(shape)
    tw = 2.0 + 0.005 * np.arange(3000)
    for tp, t0 in ((0.7, 3.0), (2.3, 1.0), (1.1, 16.5), (0.3, 10.0017), (1.0, 30.0), (1.0, -10.0)):
        k, columns = cls.support_columns(tp, t0, tw, 0.005)
        placed = np.zeros((3, tw.size))
        placed[:, k] = columns
        assert np.array_equal(placed, np.stack(cls.sampled_with_derivatives(tp, t0, tw, 0.005)))
        assert np.array_equal(cls.sampled_on_grid(tp, t0, tw, 0.005), cls.sampled(tp, t0, tw, 0.005))


@pytest.mark.parametrize("shape", ["sine", "ricker-sym", "ricker-anti"])
@pytest.mark.parametrize("baseline", [True, False])
@pytest.mark.parametrize("noise", [0.1, 1e-9])
def test_pulse_normal_equations_are_those_of_the_projected_residual(shape, baseline, noise):
    """:func:`pulses.fit.lsq.pulse_normal_equations` (products on the pulse's support, the projector
    applied algebraically) against :func:`normal_equations` of the residual ``xp - ap P m`` and its
    Jacobian formed on the whole window.  Two roundings of the same sums over ~400 samples:
    ``J'J`` to 1e-10 of its largest entry, ``J'r`` to 1e-12 of ``||J|| ||xp||`` (near the exact fit its
    entries are differences of products that large).  With noise 1e-9 the pulse explains all but
    1e-18 of the record and the cost comes from the residual itself (COST_EXPLICIT): still 1e-10
    relative."""
    from pulses.fit.lsq import pulse_normal_equations

    cls = shape_class(shape)
    rng = np.random.default_rng(5)
    tw = 1.0 + DT * np.arange(N)
    xw = 1.3 * cls.sampled(0.8, 3.0, tw, DT) + noise * rng.normal(size=N) + 0.02 + 0.01 * tw
    project = baseline_projector(tw, baseline)
    xp = project(xw)

    def residual_and_jacobian(p):
        cols = project(np.stack(cls.sampled_with_derivatives(p[1], p[2], tw, DT)))
        cols[1:] *= p[0]
        return xp - p[0] * cols[0], -cols.T

    fast = pulse_normal_equations(cls, xp, tw, DT, baseline)
    reference = normal_equations(residual_and_jacobian)
    for p in (np.array([1.3, 0.8, 3.0]), np.array([1.1, 0.83, 2.97]), np.array([-0.4, 1.4, 4.6])):
        (cost, A, g), (cost_ref, A_ref, g_ref) = fast(p), reference(p)
        assert cost == pytest.approx(cost_ref, rel=1e-10)
        scale = np.abs(A_ref).max()
        np.testing.assert_allclose(np.array(A), A_ref, rtol=0, atol=1e-10 * scale)
        np.testing.assert_allclose(np.array(g), g_ref, rtol=0, atol=1e-12 * math.sqrt(scale * (xp @ xp)))


def test_small_solve_is_numpys():
    """Gaussian elimination with partial pivoting against LAPACK's on the damped normal
    equations' sizes (3 and 5 unknowns, condition numbers up to ~1e6): 1e-9 relative; a singular
    system raises numpy's LinAlgError."""
    from pulses.fit.lsq import _solve_small

    rng = np.random.default_rng(2)
    for k in (3, 5):
        for scale in (1.0, 1e3):
            J = rng.normal(size=(20, k)) * np.logspace(0, math.log10(scale), k)
            M, b = J.T @ J, rng.normal(size=k)
            np.testing.assert_allclose(_solve_small(M.tolist(), b.tolist()), np.linalg.solve(M, b), rtol=1e-9)
    with pytest.raises(np.linalg.LinAlgError):
        _solve_small([[1.0, 2.0, 3.0], [2.0, 4.0, 6.0], [0.0, 1.0, 1.0]], [1.0, 1.0, 1.0])


@pytest.mark.parametrize("shape, tp", [("sine", 0.5), ("rect", 0.6), ("ricker-sym", 1.0)])
def test_weighted_norms_and_scan_paths(shape, tp, window, monkeypatch):
    """``u'S^-1 u`` from autocorrelations of twice the support (:meth:`WeightedWindow.norms`)
    against :func:`gram` of the full transforms: 1e-12 relative (two roundings of sums of ~100
    products).  The scan's two ways (sums in time for short pulses, a transform of each pulse
    otherwise, forced here by a zero BLAS_PRODUCT) pick the same pulse and shift."""
    import pulses.fit.weighted as weighted

    cls = shape_class(shape)
    _, tw, xw = window
    gls = WeightedWindow(cls, xw, tw, DT, weights, True, tp)
    tps = tp * np.exp(np.linspace(-0.1, 0.1, 9))
    t0s = 3.0 + cls.centre_tau * (tp - tps)
    a = 20
    cols = cls.sampled(tps[:, None], t0s[:, None], tw[a:a + 150], DT)
    padded = np.zeros((tps.size, gls.nfft))
    padded[:, a:a + 150] = cols
    U = sfft.rfft(padded, axis=-1)
    reference = np.einsum("ik,ik->i", U.view(float), (U * gls.w).view(float))
    np.testing.assert_allclose(gls.norms(cols), reference, rtol=1e-12)
    short = gls.scan(tps, t0s)
    monkeypatch.setattr(weighted, "BLAS_PRODUCT", 0)
    assert gls.scan(tps, t0s) == pytest.approx(short, rel=1e-12)
