"""Batch engine: many runs under one record, stepped together (lanes), in numba.

A design search or a spectrum runs one record against hundreds of blocks (or scalings).  One run's
Taylor step (:mod:`rocking._taylor_fixed`) is a chain of dependent operations, so the core mostly
waits on it; the runs of a batch are independent, so :func:`run_lanes` takes them
:data:`LANES` at a time and advances all the rocking ones over each sample interval with one loop
over lanes (:mod:`rocking._taylor_lanes`, the same arithmetic lane by lane, which the compiler turns
into SIMD instructions).  Only the common case is done there: a block rocking through a whole
interval with no turning point, impact or overturning, and with the series converged at the
chunk's order.  Everything else in an interval (uplift, impacts, Zeno sequences, peaks, a higher
order, overturning) is handed for that one interval and that one lane to the engine's own
:func:`rocking.engine.run_core`, so the model, its events and its accuracy are exactly those of
:func:`rocking.engine.run`.  The steps agree with a single run's to rounding (same formula, same
operations, at the same or a higher order).

For records (forcing linear between samples) on a uniform grid with one Taylor step per sample
(``p dt`` within :data:`rocking.solver.PH_MAX`); :func:`rocking.engine.run_many` uses it for those
and the per-run engine for everything else.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from ._taylor_lanes import ORDERS, lanes_step
from .engine import (HALF_PI, N_STAGES, NMAX, NODAL, OVERTURNED, REST, ROCKING, TAYLOR,
                     TAYLOR_EPS, corner_sincos, energy_verdict, run_core)

#: runs stepped together at most (a chunk; the rocking ones are kept first, so that one loop over
#: the first ``n_rocking`` lanes steps them all).  Measured per run and step at order 8: 45 ns for
#: one run, 15 ns for 8 lanes, 10.6 for 16, 7.9 for 32.
LANES = 32
#: intervals in a row in which a lower order sufficed for every rocking lane before it is lowered
LOW_RUN = 64

# rows of a chunk's float state (one column per lane)
_A, _Q, _SA, _CA, _TAN, _P, _ALPHA, _ETA, _TH, _OM, _SIDE, _SPHI, _CPHI, _REST, _MX = range(15)
_NF = 15
# rows of its integer state
_STATUS, _NIMP, _UP, _RUN, _WAKE = range(5)
_NI = 5


@njit(cache=True, inline="always")
def _swap(F, I, i, k):
    if i != k:
        for r in range(_NF):
            F[r, i], F[r, k] = F[r, k], F[r, i]
        for r in range(_NI):
            I[r, i], I[r, k] = I[r, k], I[r, i]


@njit(cache=True)
def _partition(F, I, n_live):
    """Reorder lanes ``0 .. n_live-1``: rocking first, then at rest, then overturned; returns
    ``(n_rocking, n_live)``."""
    k = 0
    for i in range(n_live):
        if I[_STATUS, i] == ROCKING:
            _swap(F, I, i, k)
            k += 1
    m = n_live
    i = k
    while i < m:
        if I[_STATUS, i] == OVERTURNED:
            m -= 1
            _swap(F, I, i, m)
        else:
            i += 1
    return k, m


@njit(cache=True)
def _wake(uval, j, n_int, a, tan_a):
    """First interval from ``j`` on where a block at rest may uplift (an end of the interval
    above the threshold; the forcing is linear in between), ``n_int`` if none."""
    while j < n_int and abs(a * uval[j]) <= tan_a and abs(a * uval[j + 1]) <= tan_a:
        j += 1
    return j


@njit(cache=True)
def _chunk(i0, i1, amp, uval, t_start, h, n_int, p, alpha, eta, zeno_tol, overturned, max_abs,
           n_impacts, uplifted, stats):
    """Runs ``i0 .. i1-1`` (at most :data:`LANES`) from rest over the whole record; results
    (after the energy rule at the end of the record) written at their indices."""
    n = i1 - i0
    F = np.zeros((_NF, n))
    I = np.zeros((_NI, n), dtype=np.int64)
    for i in range(n):
        k = i0 + i
        F[_A, i] = amp[k]
        F[_Q, i] = (p[k] * h) ** 2
        F[_SA, i] = math.sin(alpha[k])
        F[_CA, i] = math.cos(alpha[k])
        F[_TAN, i] = math.tan(alpha[k])
        F[_P, i], F[_ALPHA, i], F[_ETA, i] = p[k], alpha[k], eta[k]
        F[_CPHI, i] = 1.0
        F[_REST, i] = -np.inf
        I[_STATUS, i] = REST
        I[_RUN, i] = k
    a, q, theta, omega = F[_A], F[_Q], F[_TH], F[_OM]
    side, s_phi, c_phi = F[_SIDE], F[_SPHI], F[_CPHI]
    th1 = np.zeros(n)
    om1 = np.zeros(n)
    s1 = np.zeros(n)
    c1 = np.ones(n)
    flag = np.zeros(n, dtype=np.int64)
    work = np.zeros(2 * N_STAGES + 5 * (NMAX + 3))
    empty = np.zeros(0)
    order = ORDERS[2]
    n_low = 0
    n_rocking, n_live = 0, n
    next_wake = 0  # no lane at rest can uplift before this interval
    for j in range(n_int):
        if n_live == 0:
            break
        if n_rocking == 0 and j < next_wake:
            continue
        tb = t_start + (j + 1) * h
        stats[3] += 1
        if n_rocking > 0:
            lanes_step(order, n_rocking, uval[j], uval[j + 1] - uval[j], a, q, h, theta, omega,
                       s_phi, c_phi, TAYLOR_EPS, th1, om1, s1, c1, flag)
        raise_order = False
        all_low = n_rocking > 0
        changed = False
        wake_all = j >= next_wake
        if wake_all:
            next_wake = n_int
        for i in range(n_live):
            st = I[_STATUS, i]
            if st == ROCKING:
                f = flag[i]
                t2 = th1[i]
                w2 = om1[i]
                if f != 0 and omega[i] * w2 > 0.0 and side[i] * t2 > 0.0 and abs(t2) < HALF_PI:
                    theta[i] = t2
                    omega[i] = w2
                    s_phi[i] = s1[i]
                    c_phi[i] = c1[i]
                    if abs(t2) > F[_MX, i]:
                        F[_MX, i] = abs(t2)
                    if f != 2:
                        all_low = False
                    stats[0] += 1
                    continue
                if f == 0:
                    raise_order = True
                all_low = False
            else:  # at rest: the engine only where the block may uplift in this interval
                if not wake_all:
                    break  # lanes at rest come after the rocking ones
                if I[_WAKE, i] > j:
                    next_wake = min(next_wake, I[_WAKE, i])
                    continue
                if F[_REST, i] < tb:
                    w = _wake(uval, j, n_int, a[i], F[_TAN, i])
                    if w > j:
                        I[_WAKE, i] = w
                        next_wake = min(next_wake, w)
                        continue
            # something happens in this interval: the engine takes this lane through it
            stats[1 if st == ROCKING else 2] += 1
            (st2, th, om, _, m, ni, _, u, r) = run_core(
                NODAL, a[i], 1.0, 0.0, uval, empty, t_start, h, j, j + 1, 1, F[_P, i],
                F[_ALPHA, i], F[_ETA, i], theta[i], omega[i], F[_REST, i], False, zeno_tol,
                False, empty, empty, empty, empty, False, TAYLOR, work)
            if m > F[_MX, i]:
                F[_MX, i] = m
            I[_NIMP, i] += ni
            if u:
                I[_UP, i] = 1
            F[_REST, i] = r
            I[_STATUS, i] = st2
            changed = changed or st2 != st
            if st2 == ROCKING:
                theta[i] = th
                omega[i] = om
                if th != 0.0:
                    side[i] = 1.0 if th > 0.0 else -1.0
                else:
                    side[i] = 1.0 if om > 0.0 else -1.0
                s_phi[i], c_phi[i] = corner_sincos(th, side[i], F[_SA, i], F[_CA, i])
            else:
                theta[i] = 0.0
                omega[i] = 0.0
                side[i] = 0.0
                s_phi[i] = 0.0
                c_phi[i] = 1.0
                if st2 == REST:
                    I[_WAKE, i] = j + 1
                    next_wake = min(next_wake, j + 1)
        if changed:
            n_rocking, n_live = _partition(F, I, n_live)
        if raise_order and order < ORDERS[-1]:
            order += 2
            n_low = 0
        elif all_low:
            n_low += 1
            if n_low >= LOW_RUN and order > ORDERS[0]:
                order -= 2
                n_low = 0
        else:
            n_low = 0
    for i in range(n):
        k = I[_RUN, i]
        st = I[_STATUS, i]
        over = st == OVERTURNED
        peak = F[_MX, i]
        if st == ROCKING:
            over, pk = energy_verdict(theta[i], omega[i], F[_P, i], F[_ALPHA, i], F[_ETA, i],
                                      False)
            if pk > peak:
                peak = pk
        overturned[k] = over
        max_abs[k] = HALF_PI if over else peak
        n_impacts[k] = I[_NIMP, i]
        uplifted[k] = I[_UP, i] != 0


@njit(cache=True)
def _lanes_serial(amp, uval, t_start, h, n_int, p, alpha, eta, zeno_tol, overturned, max_abs,
                  n_impacts, uplifted, stats):
    n = p.shape[0]
    for c in range((n + LANES - 1) // LANES):
        _chunk(c * LANES, min(n, (c + 1) * LANES), amp, uval, t_start, h, n_int, p, alpha, eta,
               zeno_tol, overturned, max_abs, n_impacts, uplifted, stats[c])


@njit(cache=True, parallel=True)
def _lanes_parallel(amp, uval, t_start, h, n_int, p, alpha, eta, zeno_tol, overturned, max_abs,
                      n_impacts, uplifted, stats):
    n = p.shape[0]
    for c in prange((n + LANES - 1) // LANES):
        _chunk(c * LANES, min(n, (c + 1) * LANES), amp, uval, t_start, h, n_int, p, alpha, eta,
               zeno_tol, overturned, max_abs, n_impacts, uplifted, stats[c])


def run_lanes(amp, uval, t_start, h, n_int, p, alpha, eta, zeno_tol, parallel=False, stats=None):
    """Runs from rest of blocks ``p``, ``alpha``, ``eta`` (arrays) under the record ``amp * uval``
    (node values of ``ug''/g`` every ``h`` s from ``t_start``, ``n_int`` intervals), one Taylor
    step per interval, then the energy rule; no histories.

    Returns arrays ``overturned, max_abs_theta, n_impacts, uplifted`` (as
    :func:`rocking.engine.run_many`).
    """
    n = p.shape[0]
    out = (np.zeros(n, dtype=np.bool_), np.zeros(n), np.zeros(n, dtype=np.int64),
           np.zeros(n, dtype=np.bool_))
    fn = _lanes_parallel if parallel else _lanes_serial
    counts = np.zeros(((n + LANES - 1) // LANES, 4), dtype=np.int64)
    fn(np.ascontiguousarray(amp, dtype=float), uval, float(t_start), float(h), int(n_int),
       p, alpha, eta, float(zeno_tol), *out, counts)
    if stats is not None:
        stats += counts.sum(axis=0)
    return out
