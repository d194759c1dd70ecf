"""Section 4 of RESULTS.md, the pulse fitter: time against record length, error against noise and Tp."""
from __future__ import annotations

import subprocess

from benchmarks.common import RECORDS_DIR, log, timed


def measure(quick):
    """Section 4: the fitter's speed (``bench_fit.run``), its accuracy against noise and Tp
    (``fit_accuracy.cases``), its CPU per call on real records against the fit before issue 34
    (``bench_fit_records.run``; None where git cannot give that version) and the fit of Rinaldi
    228.  Returns plain data for :func:`benchmarks.results.fit_section`.
    """
    log("fit: speed (benchmarks/bench_fit.py)")
    from benchmarks import bench_fit, fit_accuracy

    sp = bench_fit.run(repeat=10 if quick else 20)
    log(f"  20 s, 200 Hz, all shapes: {sp['fit_all_shapes_20s_200Hz_ms_median']:.1f} ms")
    log("fit: accuracy against noise and Tp (benchmarks/fit_accuracy.py)")
    n = 2 if quick else 4
    noises = (0.0, 0.05, 0.15, 0.30)
    tps = (0.5, 2.0) if quick else (0.2, 0.5, 1.0, 2.0, 5.0)
    table = []  # one row per (noise, Tp), then the pooled row of each noise level (tp None)
    acc = {}
    for k, noise in enumerate(noises):
        pooled = []
        for j, tp in enumerate(tps):
            rows = fit_accuracy.cases(noise, tp, n, seed=1000 * k + j)
            pooled += rows
            table.append(dict(noise=noise, tp=tp, summary=fit_accuracy.summarise(rows)))
        s = fit_accuracy.summarise(pooled)
        acc[noise] = s
        table.append(dict(noise=noise, tp=None, summary=s))
        log(f"  noise {noise:.0%}: {len(pooled)} fits, within 5 %: {100 * s['5']:.0f} %, right shape {100 * s['shape']:.0f} %")

    log("fit: CPU per call on real records against the fit before issue 34 (benchmarks/bench_fit_records.py)")
    from benchmarks import bench_fit_records

    try:
        records = bench_fit_records.run(rounds=1 if quick else 3)
        log(f"  median {records['this_all_s'] * 1e3:.1f} ms per call, {records['ratio_all']:.2f}x faster")
    except (OSError, subprocess.CalledProcessError) as exc:  # no git, or the revision is not in this clone
        log(f"  skipped: {exc}")
        records = None

    rinaldi = None
    path = RECORDS_DIR / "Rinaldi228.AT2"
    if path.is_file():
        import pulses

        rec = pulses.read_record(path)
        fit, sec = timed(lambda: pulses.fit_pulse(rec))
        sine = fit["sine"]
        rinaldi = (sine.ap_g, sine.tp, fit.best.shape, sec)
    return dict(speed=sp, accuracy=table, n=n, rinaldi=rinaldi, records=records)
