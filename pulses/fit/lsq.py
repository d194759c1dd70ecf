"""Small dense least squares for the pulse fitter (:mod:`pulses.fit.plain`, :mod:`pulses.fit.weighted`).

- :func:`levenberg_marquardt`: minimise a sum of squares of a few unknowns (three: ``ap``, ``Tp``,
  ``t0``) inside a box, from the normal equations the caller computes;
- :func:`normal_equations`: those normal equations from a residual and its Jacobian;
- :func:`pulse_normal_equations`: the same for a pulse of one shape on a window of a record,
  the baseline projected out, its products formed on the pulse's support;
- :func:`baseline_projector`: the removal of a straight-line baseline ``c0 + c1 (t - tc)`` from
  samples, which fits the baseline alongside a pulse (variable projection).

Everything here is plain numpy; a general solver (``scipy.optimize.least_squares``) finds the same
minima (``tests/test_weighted.py``) but costs far more per call on three unknowns.
"""
from __future__ import annotations

import numpy as np

from .matching import _dot, _products

#: :func:`pulse_normal_equations` takes the sum of squares of the residual from its products with
#: the record, ``xp'xp - 2 ap m'P xp + ap^2 m'P m``, which loses ``xp'xp / r'r`` of its relative
#: precision to cancellation: where that would be more than 1e4 (a relative 1e-12, a thousandth
#: of the step the descent stops on, ``ftol``), from the residual itself
COST_EXPLICIT = 1e-4


def baseline_projector(tw, baseline: bool):
    """The removal of the least-squares straight-line baseline from samples on times ``tw``.

    Parameters
    ----------
    tw : ndarray, shape (n,)
        Sample times, s.
    baseline : bool
        Whether a baseline is fitted; if False the returned function returns its argument.

    Returns
    -------
    callable
        ``project(v)`` for ``v`` of shape ``(n,)`` or ``(k, n)`` (each row projected): ``v`` minus
        its least-squares fit by ``1`` and ``t - tc`` (``tc`` the mean time, which makes the two
        columns orthogonal), in the units of ``v``.  It is the orthogonal projector on the
        complement of those two columns: idempotent, and zero on any straight line.
    """
    ramp = tw - float(tw.mean())
    ramp_norm = _dot(ramp, ramp) or 1.0

    def project(v):
        if not baseline:
            return v
        v = v - v.mean(axis=-1, keepdims=True)
        if v.ndim == 1:
            return v - ramp * (_dot(v, ramp) / ramp_norm)
        return v - np.outer(np.einsum("ij,j->i", v, ramp), ramp / ramp_norm)

    return project


def normal_equations(residual_and_jacobian):
    """The normal equations of a least-squares problem, for :func:`levenberg_marquardt`.

    Parameters
    ----------
    residual_and_jacobian : callable
        ``p -> (r, J)``: the residual ``r`` (shape ``(n,)``) at the unknowns ``p`` (shape ``(k,)``)
        and its Jacobian ``J = dr/dp`` (shape ``(n, k)``).

    Returns
    -------
    callable
        ``p -> (||r||^2, J'J, J'r)``.
    """

    def normal(p):
        r, J = residual_and_jacobian(p)
        return _dot(r, r), np.einsum("ij,ik->jk", J, J), np.einsum("ij,i->j", J, r)

    return normal


def pulse_normal_equations(cls, xp, tw, dt: float, baseline: bool):
    """The normal equations of the plain least squares of a pulse of one shape on a window of a
    record, a straight-line baseline fitted alongside (projected out), for :func:`levenberg_marquardt`.

    Parameters
    ----------
    cls : type
        The shape's class (:func:`pulses.shape_class`): its ``support_columns``.
    xp : ndarray, shape (n,)
        The record's samples in the window, the baseline projected out (:func:`baseline_projector`).
    tw : ndarray, shape (n,)
        Their times, s (uniform, step ``dt``).
    dt : float
        Sampling step, s.
    baseline : bool
        Whether the baseline is fitted (else nothing is projected out).

    Returns
    -------
    callable
        ``p -> (||r||^2, J'J, J'r)`` at ``p = (ap, Tp, t0)`` (record units, s, s; the products as
        nested lists of floats), with
        ``r = xp - ap P m`` the residual, ``m`` the unit pulse sampled on ``tw``, ``P`` the
        projector of :func:`baseline_projector` and ``J = dr/dp``: :func:`normal_equations` of that
        residual and Jacobian, to round-off.

    Notes
    -----
    ``P`` is the orthogonal projector on the complement of ``1`` and ``t - tc``, so with ``C`` the
    unit pulse and its derivatives (rows), ``s`` their sums and ``q`` their products with
    ``t - tc``, ``(P C)(P C)' = C C' - s s' / n - q q' / ||t - tc||^2``, and ``(P C) r = C r``
    (``r`` lies in P's range): both need ``C`` on the pulse's support only, where it is not zero.
    The residual itself is formed on the whole window, so that its sum of squares keeps its
    relative precision when the pulse explains nearly all of the record.
    """
    n = tw.size
    ramp = tw - float(tw.mean())
    ramp_norm = _dot(ramp, ramp) or 1.0
    xx = _dot(xp, xp)
    # the columns the unit pulse and its derivatives are multiplied with, in one product
    others = np.stack((xp, np.ones(n), ramp)) if baseline else xp[None]

    def normal(p):
        a, tp, t0 = float(p[0]), max(float(p[1]), 1e-9), float(p[2])
        k, C = cls.support_columns(tp, t0, tw, dt)
        # the 3 x 3 arithmetic in Python floats: cheaper than numpy's per-call cost at this size
        products = _products(C, np.concatenate((C, others[:, k]))).tolist()
        cx = [row[3] for row in products]
        if baseline:
            s, q = [row[4] for row in products], [row[5] for row in products]
            G = [[row[j] - (s[i] * (s[j] / n) + q[i] * (q[j] / ramp_norm)) for j in range(3)]
                 for i, row in enumerate(products)]
        else:
            G = [row[:3] for row in products]
        cr = [cx[i] - a * G[i][0] for i in range(3)]  # C r = C xp - a (P C) m, r lying in P's range
        cost = xx - a * (cx[0] + cr[0])
        if cost < COST_EXPLICIT * xx:  # little left of the record: the sum of squares from r itself
            pm = np.zeros(n)
            pm[k] = C[0]
            if baseline:
                pm -= s[0] / n + ramp * (q[0] / ramp_norm)
            r = xp - a * pm
            cost = _dot(r, r)
        d = (1.0, a, a)  # the derivatives' columns of J scale with the amplitude
        return (cost, [[G[i][j] * (d[i] * d[j]) for j in range(3)] for i in range(3)],
                [-d[i] * cr[i] for i in range(3)])

    return normal


def levenberg_marquardt(normal, p, scale, lower, upper, xtol=1e-10, ftol=1e-9, max_iter=100,
                        max_calls=None):
    """Minimise a sum of squares ``||r(p)||^2`` by Levenberg-Marquardt with Marquardt's scaling.

    A small dense solver (a few unknowns) without the per-call overhead of a general one.  Steps
    that leave the box ``[lower, upper]`` are refused like steps that increase the sum of squares:
    the box is a leash that keeps the answer near its start, not a constraint the solver slides
    along; where the minimum in the box lies on its border, it stops at the border, short of
    that minimum (``tests/test_weighted.py``).

    Parameters
    ----------
    normal : callable
        ``p -> (sum of squares, J'J, J'r)`` (arrays or nested lists) with ``J = dr/dp``
        (:func:`normal_equations`; :func:`pulse_normal_equations`; for weighted least squares the
        weighted products, :meth:`pulses.fit.weighted.WeightedWindow.normal`).
    p : ndarray, shape (k,)
        Start, inside the box.
    scale : ndarray, shape (k,)
        Typical size of each unknown, in its units: the step test below is relative to it.
    lower, upper : ndarray, shape (k,)
        The box (``-inf``/``inf`` where unbounded).
    xtol : float, optional
        Stop when every component of a step is below ``xtol * scale``.
    ftol : float, optional
        Stop when an accepted step lowers the sum of squares by less than ``ftol`` of it.
    max_iter : int, optional
        Most accepted steps.
    max_calls : int, optional
        Most evaluations of ``normal`` (default: no limit).

    Returns
    -------
    p : ndarray, shape (k,)
        The unknowns where it stopped.
    cost : float
        The sum of squares there.

    Raises
    ------
    numpy.linalg.LinAlgError
        Where the damped normal equations are singular.
    """
    cost, A, g = normal(p)
    calls = 1
    lam = 1e-3
    p = np.asarray(p, dtype=float)
    step_tol = (xtol * np.asarray(scale, dtype=float)).tolist()
    lower, upper = (np.zeros(p.shape) + lower).tolist(), (np.zeros(p.shape) + upper).tolist()
    for _ in range(max_iter):
        A_rows = A.tolist() if isinstance(A, np.ndarray) else A
        minus_g = [-v for v in (g.tolist() if isinstance(g, np.ndarray) else g)]
        diag = [1.0 if row[i] <= 0 else row[i] for i, row in enumerate(A_rows)]
        while True:
            step = _solve_small([[v + lam * diag[i] if i == j else v for j, v in enumerate(row)]
                                 for i, row in enumerate(A_rows)], minus_g)
            trial = p + step
            if max_calls is not None and calls >= max_calls:
                return p, cost
            if all(lo <= v <= hi for v, lo, hi in zip(trial.tolist(), lower, upper)):
                cost_trial, A_trial, g_trial = normal(trial)
                calls += 1
            else:
                cost_trial = np.inf
            if cost_trial <= cost:
                lam = max(lam / 10.0, 1e-12)
                break
            lam *= 4.0
            if lam > 1e12:
                return p, cost
        small_step = all(abs(v) <= tol for v, tol in zip(step, step_tol))
        small_gain = cost - cost_trial <= ftol * cost
        p, cost, A, g = trial, cost_trial, A_trial, g_trial
        if small_step or small_gain:
            break
    return p, cost


def _solve_small(M, b):
    """``x`` with ``M x = b`` for a few unknowns (lists of floats; ``M`` overwritten): Gaussian
    elimination with partial pivoting, without numpy's per-call cost on a 3 x 3 system.

    Raises
    ------
    numpy.linalg.LinAlgError
        Where a pivot is zero (``M`` singular).
    """
    n = len(b)
    b = list(b)
    for c in range(n):
        r = c
        for i in range(c + 1, n):
            if abs(M[i][c]) > abs(M[r][c]):
                r = i
        if M[r][c] == 0.0:
            raise np.linalg.LinAlgError("singular matrix")
        if r != c:
            M[c], M[r], b[c], b[r] = M[r], M[c], b[r], b[c]
        pivot = M[c]
        for i in range(c + 1, n):
            f = M[i][c] / pivot[c]
            if f != 0.0:
                row = M[i]
                for j in range(c + 1, n):
                    row[j] -= f * pivot[j]
                b[i] -= f * b[c]
    x = [0.0] * n
    for i in range(n - 1, -1, -1):
        x[i] = (b[i] - sum(M[i][j] * x[j] for j in range(i + 1, n))) / M[i][i]
    return np.array(x)
