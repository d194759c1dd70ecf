"""Cost of ``rocking.critical_scale`` per record, and the collapse fragility of two columns.

    python benchmarks/bench_fragility.py            # about a minute; real records need ../shared
    python benchmarks/bench_fragility.py --brute    # also a 1000-factor brute scan per case

For every PEER record at the top of ../shared/records/raw (or $ROCKING_RECORDS) and two columns
(the 7.5 x 1.8 m column of docs/theory.md section 1 and a slender 2.5 x 0.5 m one) plus the 7.5 x 1.8 m
columns as a frame with a beam twice their mass (``cap_mass_ratio=2``), it times
``critical_scale(block, record, up_to=10)`` (default settings, the compiled solver warmed up
first), prints the time and solver runs per record (median, min, max), and the lognormal fit
over the suite (median critical scale and PGA, dispersion).  With ``--brute`` it also runs a
brute scan of 1000 factors uniform over 0.2-5 and reports how the answers compare (the unit
test's check, on every record).
"""
from __future__ import annotations

import argparse
import pathlib
import statistics
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

COLUMNS = [("7.5 x 1.8 m column", 7.5, 1.8, 0.0), ("2.5 x 0.5 m column", 2.5, 0.5, 0.0),
           ("7.5 x 1.8 m frame, gamma 2", 7.5, 1.8, 2.0)]
UP_TO = 10.0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--brute", action="store_true", help="compare with 1000-factor brute scans")
    args = ap.parse_args(argv)

    import pulses
    import rocking
    from pulses import G

    sys.path.insert(0, str(HERE))
    from common import RECORDS_DIR

    paths = sorted(RECORDS_DIR.glob("*.AT2")) if RECORDS_DIR.is_dir() else []
    if not paths:
        print(f"no records at {RECORDS_DIR} (../shared beside the checkout, or $ROCKING_RECORDS)")
        return 1
    records = [pulses.read_record(p) for p in paths]
    warm = rocking.Block.from_dimensions(7.5, 1.8)
    rocking.critical_scale(warm, records[0], up_to=2.0)     # compile (cached after the first run)
    print(f"{len(records)} records from {RECORDS_DIR}; critical_scale(..., up_to={UP_TO:g}), "
          f"default settings\n")
    for label, h, b, gamma in COLUMNS:
        block = rocking.Block.from_dimensions(h, b, cap_mass_ratio=gamma)
        times, runs, results, brute = [], [], [], []
        for rec in records:
            t = time.perf_counter()
            cs = rocking.critical_scale(block, rec, up_to=UP_TO)
            times.append(time.perf_counter() - t)
            runs.append(cs.runs)
            results.append(cs)
            if args.brute:
                ks = np.linspace(0.2, 5.0, 1000)
                t = time.perf_counter()
                over = np.asarray(rocking.simulate_many(block, rec, ks).overturned)
                dt = time.perf_counter() - t
                first = ks[np.argmax(over)] if over.any() else None
                brute.append((dt, first, ks[1] - ks[0], cs.scale))
        print(f"{label}: per record {statistics.median(times) * 1e3:.0f} ms median "
              f"({min(times) * 1e3:.0f}-{max(times) * 1e3:.0f}), solver runs "
              f"{statistics.median(runs):.0f} median ({min(runs)}-{max(runs)}), "
              f"{statistics.median([len(r.islands) for r in results]):.0f} islands median")
        for path, cs, t in zip(paths, results, times):
            k = "none" if cs.scale is None else f"{cs.scale:.4f}"
            pga = "" if cs.scale is None else f" = {cs.scale * cs.pga / G:.3f} g"
            print(f"    {path.name:34s} k {k:>7s}{pga:10s} islands {len(cs.islands):3d}  "
                  f"runs {cs.runs:5d}  {t * 1e3:6.0f} ms")
        try:
            fs = rocking.fragility(results)
            fp = rocking.fragility(results, measure="pga")
            print(f"  fragility over {fs.n} records ({int(np.sum(~np.isfinite(fs.values)))} did "
                  f"not overturn up to {UP_TO:g}x): median scale {fs.median:.3f}, beta "
                  f"{fs.beta:.3f}; median PGA {fp.median:.3f} g, beta {fp.beta:.3f}; "
                  f"P(overturn | 1.0 x record) = {fs.probability(1.0):.2f}")
        except ValueError as err:
            print(f"  fragility: {err}")
        if brute:
            dts = [d[0] for d in brute]
            both = [(f, s, c) for _, f, s, c in brute if f is not None and c is not None]
            above = [(c - f) / s for f, s, c in both]
            lower = sum(1 for f, s, c in both if c < f - s)
            higher = sorted(round(float(a), 2) for a in above if a > 1.0)
            print(f"  brute 1000 factors (0.2-5): {statistics.median(dts) * 1e3:.0f} ms median; "
                  f"critical_scale - first brute failure, in brute steps: higher by more than a "
                  f"step on {len(higher)} of {len(both)} {higher}; lower by more than a step on "
                  f"{lower} (slivers the brute scan stepped over)")
        print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
