"""Section 3 of RESULTS.md, cost growth: time against record length (10 s to 1 h) and against
blocks in a batch; the 100 x 100 spectrum grid; ``pipeline simulate`` cold start.
"""
from __future__ import annotations

import math
import statistics
import subprocess
import sys

import numpy as np

from benchmarks.common import (ROOT, USUAL_DEFAULT, blocks, fmt_t, headline_record, log, per_call, timed,
                               tstat)


def measure(quick):
    """Section 3: time against record length and blocks in a batch, the 100 x 100 spectrum grid,
    and ``pipeline simulate``'s cold start.  Returns plain data for :func:`benchmarks.results.cost_section`;
    times are :class:`benchmarks.common.TStat` (a float median with ``.best``).
    """
    import rocking
    from benchmarks.baseline import simulate_usual
    from pulses import G, Record, make_pulse

    blk = blocks()["Temple column 7.5x1.8 m"]
    log("cost: time against record length")
    # a 30 s chunk: Rinaldi 228 (or a synthetic record) at 200 Hz followed by 10 s of rest, tiled
    base = headline_record()
    chunk = np.concatenate([0.8 * base.acc, np.zeros(2000)])
    lengths = (10, 30, 120, 600, 3600) if not quick else (10, 30, 120, 600)
    usual_max = 120 if not quick else 30
    rows = []
    for L in lengths:
        n = int(L / 0.005) + 1
        acc = np.resize(chunk, n)
        rec = Record(acc, 0.005, name=f"{L} s")
        res, _ = timed(lambda: rocking.simulate(blk, rec, model="fast", history=False))
        tf = per_call(lambda: rocking.simulate(blk, rec, model="fast", history=False), budget=0.1, repeat=3)
        th = per_call(lambda: rocking.simulate(blk, rec, model="fast"), budget=0.1, repeat=3)
        tu = timed(lambda: simulate_usual(blk, rec, **USUAL_DEFAULT))[1] if L <= usual_max else math.nan
        rows.append(dict(L=L, npts=n, tf=tf, th=th, tu=tu, over=res.overturned, imp=res.n_impacts))
        log(f"  {L} s: fast {fmt_t(tf)}, with history {fmt_t(th)}, usual {fmt_t(tu)}")

    log("cost: blocks in a batch")
    pulse = make_pulse("sine", 0.5 * G, 1.0)
    rec20 = Record(0.8 * base.acc, 0.005)
    brows = []
    ns = (1, 10, 100, 1000, 10000) if not quick else (1, 10, 100, 1000)
    for N in ns:
        tans = np.linspace(0.05, 0.4, N) if N > 1 else np.array([0.2])
        bl = [rocking.Block.from_tan_alpha(blk.p, t) for t in tans]
        tp_ = per_call(lambda: rocking.simulate_many(bl, pulse), budget=0.1, repeat=3)
        tr_ = per_call(lambda: rocking.simulate_many(bl, rec20), budget=0.1, repeat=3) if N <= 2000 else math.nan
        brows.append(dict(N=N, tp=tp_, tr=tr_))
        log(f"  {N} blocks: pulse {fmt_t(tp_)}, record {fmt_t(tr_)}")

    log("cost: the 100 x 100 overturning-spectrum grid")
    alpha = math.radians(14.0)
    wp, ratio = np.linspace(0.5, 12.0, 100), np.linspace(1.0, 6.0, 100)
    rocking.overturning_spectrum(alpha, "sine", wp[:2], ratio[:2])
    spec = {}
    for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
        ts = [timed(lambda: rocking.overturning_spectrum(alpha, shape, wp, ratio))[1]
              for _ in range(3 if not quick else 1)]
        spec[shape] = tstat(ts)
        log(f"  {shape}: {spec[shape]:.2f} s")
    from rocking import lanes

    threads = lanes.get_threads()
    spec1 = {}
    try:
        lanes.set_threads(1)
        for shape in ("sine", "ricker-sym"):
            ts = [timed(lambda: rocking.overturning_spectrum(alpha, shape, wp, ratio))[1]
                  for _ in range(3 if not quick else 1)]
            spec1[shape] = tstat(ts)
            log(f"  {shape}, one thread: {spec1[shape]:.2f} s")
    finally:
        lanes.set_threads(threads)

    log("cost: `pipeline simulate` cold start")
    cold = None
    cmd = [sys.executable, "-m", "pipeline", "simulate", "--block", "7.5x1.8", "--pulse", "sine",
           "--ap", "0.71g", "--tp", "0.8"]
    probe = subprocess.run(cmd, capture_output=True, text=True, cwd=str(ROOT))
    if probe.returncode == 0:
        tc = [timed(lambda: subprocess.run(cmd, capture_output=True, text=True, cwd=str(ROOT)))[1]
              for _ in range(3 if quick else 5)]
        ti = [timed(lambda: subprocess.run([sys.executable, "-c", "import rocking, pulses"],
                                           capture_output=True, cwd=str(ROOT)))[1] for _ in range(3)]
        tpy = [timed(lambda: subprocess.run([sys.executable, "-c", "pass"], capture_output=True))[1]
               for _ in range(3)]
        cold = dict(t=statistics.median(tc), tmin=min(tc), imp=statistics.median(ti), py=statistics.median(tpy),
                    out=probe.stdout.strip().splitlines()[1].strip() if probe.stdout.count("\n") >= 1 else "")
        log(f"  cold start {cold['t']:.2f} s (import rocking+pulses {cold['imp']:.2f} s, bare python {cold['py']:.2f} s)")
    else:
        log("  `pipeline simulate` not available: " + (probe.stderr.strip().splitlines() or ["?"])[-1])
    return dict(length=rows, batch=brows, spectrum=spec, spectrum_1thread=spec1, cold=cold, record=base.name,
                usual_max=usual_max, threads=threads, parallel_min=lanes.PARALLEL_MIN_RUNS,
                n_spectrum=3 if not quick else 1,
                n_cold=3 if quick else 5)
