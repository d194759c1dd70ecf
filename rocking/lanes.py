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
(``p dt`` within :data:`rocking.solver.PH_MAX`); :func:`rocking.simulate_many` uses it for those
(``rocking.solver._run_batch``) and the runs one by one, :func:`run_many`, for everything else.

Both ways are one compiled function, :func:`_kernel` (the engine's code is generated once for
every batch), which runs without the GIL: :func:`run_batch` spreads a large batch over threads
(``numba.get_num_threads()`` of them) instead of compiling ``parallel=True`` variants of it.
"""
from __future__ import annotations

import math

import numpy as np
from concurrent.futures import ThreadPoolExecutor

import numba
from numba import njit

from ._compiling import compiling_notice
from ._taylor_fixed import taylor_fixed
from ._taylor_lanes import ORDERS, lanes_step
from .engine import (HALF_PI, N_STAGES, NMAX, NODAL, OVERTURNED, REST, ROCKING, TAYLOR,
                     TAYLOR_EPS, WORK_SIZE, Dynamics, Forcing, Grid, Rocker, Settings,
                     Start, _first_crossing, _hermite, _step_peak, as_input, check_kind,
                     corner_sincos, energy_verdict, run_core)

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
    ``(n_rocking, n_live)``.  Two-pointer partitions: only lanes out of place move (a few per
    call: a lane changes state at an uplift, a return to rest or an overturning)."""
    i, m = 0, n_live
    while True:  # overturned lanes to the end
        while i < m and I[_STATUS, i] != OVERTURNED:
            i += 1
        while m > i and I[_STATUS, m - 1] == OVERTURNED:
            m -= 1
        if i >= m:
            break
        _swap(F, I, i, m - 1)
    i, k = 0, m
    while True:  # rocking lanes to the front
        while i < k and I[_STATUS, i] == ROCKING:
            i += 1
        while k > i and I[_STATUS, k - 1] != ROCKING:
            k -= 1
        if i >= k:
            break
        _swap(F, I, i, k - 1)
    return k, m


@njit(cache=True)
def _wake(uval, j, n_int, a, tan_a):
    """First interval from ``j`` on where a block at rest may uplift (an end of the interval
    above the threshold; the forcing is linear in between), ``n_int`` if none."""
    while j < n_int and abs(a * uval[j]) <= tan_a and abs(a * uval[j + 1]) <= tan_a:
        j += 1
    return j


@njit(cache=True)
def _turn(order, a, uval, j, ta, h, theta, omega, side, sa, ca, p, cf, kt, kw):
    """A step of a rocking lane whose ``omega`` changes sign inside it (a turning point) but whose
    ``theta`` keeps its side: as :func:`rocking.engine.run_core` takes it (the step's Taylor
    polynomial; the peak located on it), unless the block may touch zero inside the step (then
    ``ok`` is False and the engine takes the interval).  Returns ``(ok, theta, omega, sin, cos,
    peak)`` at the end of the step."""
    u0 = a * uval[j]
    u1 = a * (uval[j + 1] - uval[j])
    sn, cs = corner_sincos(theta, side, sa, ca)
    th2, wh2, s1, c1, flag = taylor_fixed(order, u0, u1, (p * h) ** 2, theta, omega * h, sn, cs,
                                          TAYLOR_EPS, cf)
    om2 = wh2 / h
    if flag == 0 or not (side * th2 > 0.0 and abs(th2) < HALF_PI):
        return False, 0.0, 0.0, 0.0, 1.0, 0.0
    c0, c1h, c2, c3 = _hermite(theta, omega, th2, om2, h)
    lo, _, _ = _first_crossing(c0, c1h, c2, c3, side, 0.0)
    if lo >= 0.0:
        return False, 0.0, 0.0, 0.0, 1.0, 0.0
    peak = _step_peak(Forcing(np.int64(NODAL), a, np.float64(1.0), np.float64(0.0)), uval, j, ta,
                      ta + h, ta, h, theta, omega, th2, om2, side,
                      Dynamics(p, sa, ca, np.bool_(False), np.int64(TAYLOR)), kt, kw, h, cf, order,
                      np.float64(0.0))
    return True, th2, om2, s1, c1, max(peak, abs(th2))


@njit(cache=True, inline="always")  # one caller, _kernel: compiled once, there
def _chunk(i0, i1, amp, uval, t_start, h, n_int, p, alpha, eta, zeno_tol, overturned, max_abs,
           n_impacts, uplifted, stats):
    """Runs ``i0 .. i1-1`` (at most :data:`LANES`) from rest over the whole record; results
    (after the energy rule at the end of the record) written at their indices.

    ``stats`` (4 integers) counts steps kept in lanes, turning points taken in lanes, and
    intervals handed to the engine for rocking lanes and for lanes at rest.
    """
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
    a, theta, omega = F[_A], F[_TH], F[_OM]
    side, s_phi, c_phi, peak = F[_SIDE], F[_SPHI], F[_CPHI], F[_MX]
    bad = np.zeros(n, dtype=np.int64)
    work = np.zeros(WORK_SIZE)
    kt = work[:N_STAGES]
    kw = work[N_STAGES:2 * N_STAGES]
    cf = np.zeros(NMAX + 3)
    empty = np.zeros(0)
    # constants passed to compiled functions as np.int64 / np.bool_: a bare constant is typed as
    # a literal, and numba would compile those functions once more for it.  The rows that
    # lanes_step reads and writes: it takes the whole state, one array rather than eight views
    # (numba counts a reference to every array a compiled function is given, at every interval)
    rows = (np.int64(_A), np.int64(_Q), np.int64(_TH), np.int64(_OM), np.int64(_SIDE),
            np.int64(_SPHI), np.int64(_CPHI), np.int64(_MX))
    grid = Grid(t_start, h, np.int64(1))
    settings = Settings(np.bool_(False), np.int64(TAYLOR), zeno_tol, np.bool_(False),
                        np.bool_(False))
    order = np.int64(ORDERS[2])
    n_low = 0
    n_rocking, n_live = np.int64(0), n
    next_wake = 0  # no lane at rest can uplift before this interval
    for j in range(n_int):
        if n_live == 0:
            break
        if n_rocking == 0 and j < next_wake:
            continue
        ta = t_start + j * h
        tb = t_start + (j + 1) * h
        n_bad = 0
        all_low = False
        if n_rocking > 0:
            n_bad, n_two = lanes_step(order, n_rocking, uval[j], uval[j + 1] - uval[j], F,
                                      rows, h, TAYLOR_EPS, bad)
            stats[0] += n_rocking - n_bad
            all_low = n_two == n_rocking
        wake_all = j >= next_wake
        if n_bad > 0 or wake_all:  # lanes that need attention in this interval
            raise_order = False
            changed = False
            if wake_all:
                next_wake = n_int
            for i in range(n_rocking if not wake_all else n_live):
                st = I[_STATUS, i]
                if st == ROCKING:
                    b = bad[i]
                    if b == 0:
                        continue
                    if b == 2:
                        raise_order = True
                    elif omega[i] * side[i] > 0.0:
                        # moving away from zero and turning back: the peak, in the lane
                        ok, th, om, sn, cs, pk = _turn(order, a[i], uval, j, ta, h, theta[i],
                                                      omega[i], side[i], F[_SA, i], F[_CA, i],
                                                      F[_P, i], cf, kt, kw)
                        if ok:
                            theta[i], omega[i], s_phi[i], c_phi[i] = th, om, sn, cs
                            if pk > peak[i]:
                                peak[i] = pk
                            stats[1] += 1
                            continue
                else:  # at rest: the engine only where the block may uplift in this interval
                    if I[_WAKE, i] > j:
                        next_wake = min(next_wake, I[_WAKE, i])
                        continue
                    if F[_REST, i] >= tb:  # at rest after a Zeno sequence until then
                        next_wake = min(next_wake, j + 1)
                        continue
                    w = _wake(uval, j, n_int, a[i], F[_TAN, i])
                    if w > j:
                        I[_WAKE, i] = w
                        next_wake = min(next_wake, w)
                        continue
                # something happens in this interval: the engine takes this lane through it
                stats[2 if st == ROCKING else 3] += 1
                (st2, th, om, _, m, ni, _, u, r) = run_core(
                    Forcing(np.int64(NODAL), a[i], np.float64(1.0), np.float64(0.0)), uval, grid,
                    empty, Rocker(F[_P, i], F[_ALPHA, i], F[_ETA, i]), settings,
                    Start(j, theta[i], omega[i], F[_REST, i]), j + 1, empty, empty, empty, empty,
                    work)
                if m > peak[i]:
                    peak[i] = m
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
                continue
        if all_low:
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
        pk = peak[i]
        if st == ROCKING:
            over, pk2 = energy_verdict(theta[i], omega[i], F[_P, i], F[_ALPHA, i], F[_ETA, i],
                                       np.bool_(False))
            if pk2 > pk:
                pk = pk2
        overturned[k] = over
        max_abs[k] = HALF_PI if over else pk
        n_impacts[k] = I[_NIMP, i]
        uplifted[k] = I[_UP, i] != 0


@njit(cache=True, nogil=True)
def _kernel(lanes, i0, i1, kind, amp, tp, t0, uval, nodes, t_start, h, n_int, n_sub, p, alpha, eta,
            linear, zeno_tol, method, overturned, max_abs, n_impacts, uplifted, stats):
    """Runs ``i0 .. i1-1`` of a batch from rest, then the energy rule; results written at their
    indices.  ``lanes``: stepped together (:func:`_chunk`, at most :data:`LANES` runs; a record
    on a uniform grid, one Taylor step per sample), else one by one with
    :func:`rocking.engine.run_core`.

    The one compiled entry of every batch (both ways in one function: the engine's code is
    generated once for both), without the GIL: :func:`run_batch` spreads calls over threads.
    """
    if lanes:
        _chunk(i0, i1, amp, uval, t_start, h, n_int, p, alpha, eta, zeno_tol, overturned, max_abs,
               n_impacts, uplifted, stats)
        return
    work = np.zeros(WORK_SIZE)
    empty = np.zeros(0)
    settings = Settings(linear, method, zeno_tol, np.bool_(False), np.bool_(False))
    start = Start(np.int64(0), np.float64(0.0), np.float64(0.0), np.float64(-np.inf))
    for i in range(i0, i1):
        st, th, om, _, mx, ni, _, up, _ = run_core(
            Forcing(kind, amp[i], tp, t0), uval, Grid(t_start, h, n_sub[i]), nodes,
            Rocker(p[i], alpha[i], eta[i]), settings, start, n_int, empty, empty, empty, empty,
            work)
        if st == OVERTURNED:
            over = True
        elif st == ROCKING:
            over, peak = energy_verdict(th, om, p[i], alpha[i], eta[i], linear)
            if peak > mx:
                mx = peak
        else:
            over = False
        overturned[i] = over
        max_abs[i] = HALF_PI if over else mx
        n_impacts[i] = ni
        uplifted[i] = up


#: batches at least this large are spread over threads (:func:`run_batch`): on small batches (and
#: on a busy machine) starting the work on other threads costs more than the work itself
PARALLEL_MIN_RUNS = 256
#: runs per task of a batch run one by one over threads (a task is one call of :func:`_kernel`)
TASK_RUNS = 16

_pools = {}


def _pool(threads):
    if threads not in _pools:
        _pools[threads] = ThreadPoolExecutor(max_workers=threads,
                                             thread_name_prefix="rocking-batch")
    return _pools[threads]


def run_batch(lanes, kind, amp, tp, t0, uval, nodes, t_start, h, n_int, n_sub, p, alpha, eta,
              linear, zeno_tol, method=TAYLOR, threads=None, stats=None):
    """Runs from rest of blocks ``p``, ``alpha``, ``eta`` (arrays) scaled by ``amp`` (array), then
    the energy rule; no histories.  ``lanes``: stepped together (records on a uniform grid with one
    Taylor step per sample, ``n_sub == 1``), else one by one (any grid, model or method).

    ``threads``: how many threads share the batch (default ``numba.get_num_threads()`` for
    batches of at least :data:`PARALLEL_MIN_RUNS` runs, else 1; 1 runs it on the calling thread,
    as worker processes that already share the cores want: ``numba.set_num_threads(1)`` there
    sets the default).  ``stats`` (4 integers, lanes only) is incremented as in :func:`_chunk`.

    Returns arrays ``overturned, max_abs_theta, n_impacts, uplifted``.
    """
    check_kind(kind)
    n = p.shape[0]
    out = (np.zeros(n, dtype=np.bool_), np.zeros(n), np.zeros(n, dtype=np.int64),
           np.zeros(n, dtype=np.bool_))
    if threads is None:
        threads = numba.get_num_threads() if n >= PARALLEL_MIN_RUNS else 1
    threads = max(1, int(threads))
    if lanes:
        size = LANES
    else:
        size = n if threads == 1 else TASK_RUNS
    starts = range(0, n, max(size, 1))
    counts = np.zeros((len(starts), 4), dtype=np.int64)
    f64 = as_input
    args = (int(kind), f64(amp), float(tp), float(t0), f64(uval), f64(nodes), float(t_start),
            float(h), int(n_int), np.ascontiguousarray(n_sub, dtype=np.int64), f64(p), f64(alpha),
            f64(eta), bool(linear), float(zeno_tol), int(method)) + out

    def task(k):
        i0 = starts[k]
        _kernel(bool(lanes), i0, min(n, i0 + size), *args, counts[k])

    if n:
        with compiling_notice(_kernel):
            task(0)
        if threads == 1 or len(starts) <= 2:
            for k in range(1, len(starts)):
                task(k)
        else:
            list(_pool(min(threads, len(starts) - 1)).map(task, range(1, len(starts))))
    if stats is not None:
        stats += counts.sum(axis=0)
    return out


def run_lanes(amp, uval, t_start, h, n_int, p, alpha, eta, zeno_tol, threads=None, stats=None):
    """Runs from rest of blocks ``p``, ``alpha``, ``eta`` (arrays) under the record ``amp * uval``
    (node values of ``ug''/g`` every ``h`` s from ``t_start``, ``n_int`` intervals), one Taylor
    step per interval, then the energy rule; no histories (:func:`run_batch` in lanes).

    Returns arrays ``overturned, max_abs_theta, n_impacts, uplifted`` (as :func:`run_many`).
    """
    n_sub = np.ones(np.shape(p)[0], dtype=np.int64)
    return run_batch(True, NODAL, amp, 1.0, 0.0, uval, np.zeros(0), t_start, h, n_int, n_sub, p,
                     alpha, eta, False, zeno_tol, TAYLOR, threads, stats)


def run_many(kind, amp, tp, t0, uval, nodes, t_start, h_uniform, n_int, n_sub, p, alpha, eta,
             linear, zeno_tol, method=TAYLOR, threads=None):
    """:func:`rocking.engine.run` for many blocks/amplitudes at once (arrays ``amp``, ``p``,
    ``alpha``, ``eta``, ``n_sub`` of equal length), one by one, then the energy rule; no
    histories (:func:`run_batch`).

    Returns arrays ``overturned, max_abs_theta, n_impacts, uplifted``.
    """
    return run_batch(False, kind, amp, tp, t0, uval, nodes, t_start, h_uniform, n_int, n_sub, p,
                     alpha, eta, linear, zeno_tol, method, threads)
