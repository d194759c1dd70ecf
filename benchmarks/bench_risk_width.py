"""Cost of the width for a target rate at a site: a 20-record suite, one column, ``--jobs 2``.

    python benchmarks/bench_risk_width.py              # a few minutes; real records need ../shared
    python benchmarks/bench_risk_width.py --jobs 1

The suite: the first 20 PEER records under ../shared/records/raw (or $ROCKING_RECORDS), each as
recorded (single components); the site: a power-law hazard curve of SA(1.0) s,
``lambda = 1e-4 x^-2.2`` per year from 0.005 g to 5 g at 25 points a decade; the column 7.5 m tall;
the target 2 % in 50 years (4.04e-4 per year), the restitution 0.95-1.05 x Eq. 5 drawn per record.
It prints the width found, its rate and the width just narrower (whose rate must be above the
target), the widths computed, the wall time and the cost per width scanned (one critical scale per
record each).  The floor: under 5 minutes on the development machine (2 cores) with ``--jobs 2``.
"""
from __future__ import annotations

import argparse
import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

N_RECORDS = 20
HEIGHT = 7.5
TARGET_POE = "2%/50"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--records", type=int, default=N_RECORDS)
    args = ap.parse_args(argv)

    import pulses
    from rocking.risk import HazardCurve
    from rocking.risk.site import assess
    from rocking.risk.suite import members

    sys.path.insert(0, str(HERE))
    from common import RECORDS_DIR

    paths = sorted(RECORDS_DIR.rglob("*.AT2"))[:args.records] if RECORDS_DIR.is_dir() else []
    if len(paths) < args.records:
        print(f"{len(paths)} records at {RECORDS_DIR}; {args.records} needed (../shared beside the checkout)")
        return 1
    x = np.geomspace(0.005, 5.0, 76)
    curve = HazardCurve("SA(1.0)", x, 1e-4 * x ** -2.2, units="g", source="power law")
    t0 = time.perf_counter()
    suite = members([pulses.read_record(p) for p in paths], curve.measure)
    t_read = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = assess(suite, curve, height=HEIGHT, target_poe=TARGET_POE, restitution="0.95:1.05",
                 jobs=args.jobs)
    wall = time.perf_counter() - t0
    t = res.target
    n = len(t.widths)
    print(f"{len(suite)} records ({RECORDS_DIR}), SA(1.0) power-law curve, column {HEIGHT:g} m, "
          f"target {TARGET_POE} ({t.target_rate:.3e}/yr), restitution 0.95-1.05 x Eq. 5, --jobs {args.jobs}")
    print(f"  records read and SA(1.0) of each: {t_read:.1f} s")
    print(f"  width for the target: {t.width:.4f} m, rate {t.rate:.3e}/yr (meets it: {t.rate <= t.target_rate})")
    print(f"  width just narrower:  {t.narrower_width:.4f} m, rate {t.narrower_rate:.3e}/yr "
          f"(above the target: {t.narrower_rate > t.target_rate})")
    print(f"  widths computed: {n} ({sum(w.stage == 'scan' for w in t.widths)} scanned, "
          f"{sum(w.stage == 'refine' for w in t.widths)} refining), critical scales: {t.runs}")
    print(f"  wall time: {wall:.1f} s; per width: {wall / n:.2f} s; per critical scale (record and "
          f"width): {wall / t.runs * args.jobs:.3f} s of a core")
    print(f"  under 5 minutes: {wall < 300}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
