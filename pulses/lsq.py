"""Small dense least squares for the pulse fitter (:mod:`pulses.fit`, :mod:`pulses.weighted`).

- :func:`levenberg_marquardt`: minimise a sum of squares of a few unknowns (three: ``ap``, ``Tp``,
  ``t0``) inside a box, from the normal equations the caller computes;
- :func:`normal_equations`: those normal equations from a residual and its Jacobian;
- :func:`baseline_projector`: the removal of a straight-line baseline ``c0 + c1 (t - tc)`` from
  samples, which fits the baseline alongside a pulse (variable projection).

Everything here is plain numpy; a general solver (``scipy.optimize.least_squares``) finds the same
minima (``tests/test_weighted.py``) but costs far more per call on three unknowns.
"""
from __future__ import annotations

import numpy as np

from .cwt import _dot


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
        ``p -> (sum of squares, J'J, J'r)`` with ``J = dr/dp`` (:func:`normal_equations`; for
        weighted least squares the weighted products, :meth:`pulses.weighted.WeightedWindow.normal`).
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
    for _ in range(max_iter):
        diag = np.diag(A).copy()
        diag[diag <= 0] = 1.0
        while True:
            step = np.linalg.solve(A + lam * np.diag(diag), -g)
            trial = p + step
            if max_calls is not None and calls >= max_calls:
                return p, cost
            if np.all(trial >= lower) and np.all(trial <= upper):
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
        small_step = bool(np.all(np.abs(step) <= xtol * scale))
        small_gain = cost - cost_trial <= ftol * cost
        p, cost, A, g = trial, cost_trial, A_trial, g_trial
        if small_step or small_gain:
            break
    return p, cost
