"""Section 2 of RESULTS.md: the linearised model's error against alpha, and where ``model="auto"`` switches."""
from __future__ import annotations

import math
import statistics

from benchmarks.common import fmt_e, log, per_call, steps_per_tp


def measure(quick, records):
    """Section 2: the linearised model's error against alpha (and its speed against the fast engine).

    ``records``: the real records (:func:`benchmarks.common.load_records`).  Returns plain data for
    :func:`benchmarks.results.linear_section`.
    """
    import rocking
    from pulses import G, make_pulse
    from rocking import Block
    from rocking.solver import LINEAR_ERROR_COEFF

    log("linear: error of the linearised model against alpha")
    p = 1.381
    tans = (0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5) if not quick else (0.01, 0.05, 0.2, 0.5)
    combos = [(1.0, 3.0), (2.0, 1.5), (4.0, 2.5)] if not quick else [(2.0, 1.5), (4.0, 2.5)]
    recs = records[:6] if not quick else records[:1]
    rows = []
    t_lin, t_fast = [], []
    for tan in tans:
        blk = Block.from_tan_alpha(p, tan)
        errs, wrong, n = [], 0, 0
        kinds = []  # (error, "pulse"/"record", label) per surviving case
        cases = []
        for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
            for ptp, ratio in combos:
                tp = ptp / p
                t0 = 0.0 if shape in ("rect", "sine") else 3.0 * tp
                cases.append(make_pulse(shape, ratio * G * tan, tp, t0))
        for rec in recs:
            cases.append(rec.scaled(1.5 * G * tan / rec.pga))
        for exc in cases:
            with steps_per_tp(400):  # the yardstick: fast at twice the default resolution
                truth = rocking.simulate(blk, exc, model="fast", history=False)
            lin = rocking.simulate(blk, exc, model="linear", history=False)
            n += 1
            if lin.overturned != truth.overturned:
                wrong += 1
            elif not truth.overturned:
                errs.append(abs(lin.max_rotation_ratio - truth.max_rotation_ratio))
                kinds.append((errs[-1], "record" if hasattr(exc, "dt") else "pulse",
                              getattr(exc, "name", None) if hasattr(exc, "dt") else repr(exc)))
        # one record and one pulse for speed
        exc = cases[5]
        t_lin.append(per_call(lambda: rocking.simulate(blk, exc, model="linear", history=False), 0.02, 3))
        t_fast.append(per_call(lambda: rocking.simulate(blk, exc, model="fast", history=False), 0.02, 3))
        alpha = blk.alpha
        emax = max(errs) if errs else math.nan
        ep = max([e for e, k, _ in kinds if k == "pulse"], default=math.nan)
        er = max([e for e, k, _ in kinds if k == "record"], default=math.nan)
        worst = max(kinds)[2] if kinds else ""
        rows.append(dict(tan=tan, alpha=alpha, n=n, wrong=wrong, emax=emax,
                         emed=statistics.median(errs) if errs else math.nan, coeff=emax / alpha**2,
                         cp=ep / alpha**2, cr=er / alpha**2, worst=worst))
        log(f"  tan alpha {tan}: max error {fmt_e(emax)}, error/alpha^2 {emax / alpha**2:.3g}, wrong {wrong}/{n}")
    # spot check against the reference at one slenderness
    blk = Block.from_tan_alpha(p, 0.05)
    exc = make_pulse("sine", 1.5 * G * 0.05, 2.0 / p)
    ref = rocking.simulate(blk, exc, model="reference", history=False)
    fst = rocking.simulate(blk, exc, model="fast", history=False)
    spot = abs(ref.max_rotation_ratio - fst.max_rotation_ratio)

    measured = max(r["coeff"] for r in rows if math.isfinite(r["coeff"]))
    return dict(rows=rows, measured_coeff=measured, coeff=LINEAR_ERROR_COEFF, t_lin=t_lin, t_fast=t_fast,
                spot=spot, combos=combos, n_records=len(recs))
