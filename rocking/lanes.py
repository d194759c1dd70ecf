"""Batch engine: many runs under one record, stepped together (lanes), compiled.

A design search or a spectrum runs one record against hundreds of blocks (or scalings).  One run's
Taylor step (``rocking/_taylor_fixed.pxi``) is a chain of dependent operations, so the core mostly
waits on it; the runs of a batch are independent, so :func:`run_lanes` takes them :data:`LANES`
at a time and advances all the rocking ones over each sample interval with one loop over lanes
(``rocking/_taylor_lanes.h``, generated C: the same arithmetic lane by lane, which the compiler
turns into SIMD instructions).  The events of an interval (turning points and their peaks,
impacts with the restitution and the rest of the interval, the hops of a block coming to rest and
the Zeno rest that ends them) are taken in the lanes too, for all the lanes with one in a pass
(``rocking_events_N``): located on the polynomial of the lane's step, as the engine's own
``run_core`` (``rocking/_core.pyx``) locates them, with the same model, so the answers agree with
:func:`rocking.engine.run`'s to rounding (the operations differ; near the verge of overturning a
rounding can change a verdict, as between any two machines).  What the pass cannot settle (an
uplift from rest, overturning, a Zeno rest followed by an uplift in the same interval, a root or
a step that needs more than the chunk's order) is handed for that one interval and that one
lane to ``run_core``; :data:`STATS` counts both.

For records (forcing linear between samples) on a uniform grid with one Taylor step per sample
(``p dt`` within :data:`rocking.solver.PH_MAX`); :func:`rocking.simulate_many` uses it for those
(``rocking.solver._run_batch``) and the runs one by one, :func:`run_many`, for everything else.

Both ways are one compiled function, ``rocking._core.kernel``, which runs without the GIL:
:func:`run_batch` spreads a large batch over Python threads (:func:`get_threads` of them; worker
processes that already share the cores set 1 with :func:`set_threads`).
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from . import _core
from .engine import NODAL, TAYLOR, as_input, check_kind

#: runs stepped together at most (a chunk; the rocking ones are kept first, so that one loop over
#: the first ``n_rocking`` lanes steps them all); compiled into ``rocking/_core.pyx``
LANES = 32
#: intervals in a row in which a lower order sufficed for every rocking lane before it is lowered
LOW_RUN = 2
#: counts a batch in lanes keeps (``stats`` of :func:`run_batch`), in this order: rocking steps
#: kept in lanes, turning points and impacts taken in lanes (``rocking_events_N``), intervals
#: handed to the engine for rocking lanes, for lanes at rest, and for rocking lanes whose order
#: was too low; then the rocking intervals the events' pass left to the engine, by why
STATS = ("kept", "turns", "engine", "rest", "impacts", "low", "overturning", "zeno_uplift", "root",
         "rest_order", "many_events")
#: batches at least this large are spread over threads (:func:`run_batch`): on small batches (and
#: on a busy machine) starting the work on other threads costs more than the work itself
PARALLEL_MIN_RUNS = 256
#: runs per task of a batch run one by one over threads (a task is one call of the kernel)
TASK_RUNS = 16

_pools = {}
_threads = None  # set_threads; None: one per CPU this process may use


def _cpus() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not on Linux
        return os.cpu_count() or 1


def get_threads() -> int:
    """Threads that share a large batch by default (:func:`set_threads`; else one per CPU this
    process may use)."""
    return _threads if _threads is not None else _cpus()


def set_threads(n: int | None) -> None:
    """Set how many threads share a large batch by default (1: the calling thread only, as worker
    processes that already share the cores want; None: one per CPU)."""
    global _threads
    _threads = None if n is None else max(1, int(n))


def _pool(threads):
    if threads not in _pools:
        _pools[threads] = ThreadPoolExecutor(max_workers=threads,
                                             thread_name_prefix="rocking-batch")
    return _pools[threads]


def run_batch(lanes, kind, amp, tp, t0, uval, nodes, t_start, h, n_int, n_sub, p, alpha, eta,
              linear, zeno_tol, method=TAYLOR, threads=None, stats=None, vval=None,
              until_final=False):
    """Runs from rest of blocks ``p``, ``alpha``, ``eta`` (arrays) scaled by ``amp`` (array), then
    the energy rule; no histories.  ``lanes``: stepped together (records on a uniform grid with one
    Taylor step per sample, ``n_sub == 1``), else one by one (any grid, model or method).

    ``threads``: how many threads share the batch (default :func:`get_threads` for batches of at
    least :data:`PARALLEL_MIN_RUNS` runs, else 1; 1 runs it on the calling thread).  ``stats``
    (integers, lanes only) is incremented by the counts of :data:`STATS` (as many of them as it
    holds, at least 4).

    ``vval``: node values of the vertical ground motion, scaled as the record (``1 + amp * vval`` =
    ``1 + av/g``; one by one only, docs/theory.md section 10); then a fifth array is returned, the
    lift-off time of each run (nan where none).

    ``until_final`` (lanes only): each run stops once its verdict and its peak ``max|theta|``
    can no longer change (an energy bound on what the rest of the record can give it,
    ``rocking._core._finals``): the same verdicts and peaks as run to the end, less work, and
    ``n_impacts`` counts the impacts up to where it stopped (what a design search needs).

    Returns arrays ``overturned, max_abs_theta, n_impacts, uplifted``.
    """
    check_kind(kind)
    n = p.shape[0]
    out = (np.zeros(n, dtype=np.bool_), np.zeros(n), np.zeros(n, dtype=np.int64),
           np.zeros(n, dtype=np.bool_))
    if threads is None:
        threads = get_threads() if n >= PARALLEL_MIN_RUNS else 1
    threads = max(1, int(threads))
    if lanes:
        size = LANES
    else:
        size = n if threads == 1 else TASK_RUNS
    starts = range(0, n, max(size, 1))
    counts = np.zeros((len(starts), len(STATS)), dtype=np.int64)
    f64 = as_input
    # the flags as bytes (the same memory as the boolean results)
    results = (out[0].view(np.uint8), out[1], out[2], out[3].view(np.uint8))
    args = (int(kind), f64(amp), float(tp), float(t0), f64(uval), f64(nodes), float(t_start),
            float(h), int(n_int), np.ascontiguousarray(n_sub, dtype=np.int64), f64(p), f64(alpha),
            f64(eta), bool(linear), float(zeno_tol), int(method)) + results

    extra, kw = (), {}
    if until_final and lanes:
        kw["rest_u"] = rest_of_record(uval, h, n_int)
    if vval is not None:
        t_lift = np.full(n, np.nan)
        extra = (f64(vval), t_lift)
        out = out + (t_lift,)

    def task(k):
        i0 = starts[k]
        _core.kernel(bool(lanes), i0, min(n, i0 + size), *args, counts[k], *extra, **kw)

    if threads == 1 or len(starts) <= 1:
        for k in range(len(starts)):
            task(k)
    else:
        list(_pool(min(threads, len(starts))).map(task, range(len(starts))))
    if stats is not None:
        stats += counts.sum(axis=0)[:len(stats)]
    return out


def rest_of_record(uval, h, n_int):
    """The integral of ``|u|`` from each node ``j`` to the end (``n_int`` intervals of ``h`` s,
    ``u`` linear between the node values ``uval``: at most the trapezoid of ``|u|``), rounded
    up by a part in 1e12 (the sum's own rounding)."""
    a = np.abs(np.asarray(uval[:n_int + 1], dtype=float))
    out = np.zeros(n_int + 1)
    out[:-1] = np.cumsum((0.5 * h * (a[:-1] + a[1:]))[::-1])[::-1]
    return out * (1.0 + 1e-12)


def run_lanes(amp, uval, t_start, h, n_int, p, alpha, eta, zeno_tol, threads=None, stats=None,
              until_final=False):
    """Runs from rest of blocks ``p``, ``alpha``, ``eta`` (arrays) under the record ``amp * uval``
    (node values of ``ug''/g`` every ``h`` s from ``t_start``, ``n_int`` intervals), one Taylor
    step per interval, then the energy rule; no histories (:func:`run_batch` in lanes).

    ``until_final``: each run stops once its verdict and peak are final (:func:`run_batch`).

    Returns arrays ``overturned, max_abs_theta, n_impacts, uplifted`` (as :func:`run_many`).
    """
    n_sub = np.ones(np.shape(p)[0], dtype=np.int64)
    return run_batch(True, NODAL, amp, 1.0, 0.0, uval, np.zeros(0), t_start, h, n_int, n_sub, p,
                     alpha, eta, False, zeno_tol, TAYLOR, threads, stats,
                     until_final=until_final)


def run_many(kind, amp, tp, t0, uval, nodes, t_start, h_uniform, n_int, n_sub, p, alpha, eta,
             linear, zeno_tol, method=TAYLOR, threads=None):
    """:func:`rocking.engine.run` for many blocks/amplitudes at once (arrays ``amp``, ``p``,
    ``alpha``, ``eta``, ``n_sub`` of equal length), one by one, then the energy rule; no
    histories (:func:`run_batch`).

    Returns arrays ``overturned, max_abs_theta, n_impacts, uplifted``.
    """
    return run_batch(False, kind, amp, tp, t0, uval, nodes, t_start, h_uniform, n_int, n_sub, p,
                     alpha, eta, linear, zeno_tol, method, threads)
