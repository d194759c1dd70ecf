"""CPU of ``rocking.required_width`` on one record, this checkout against another version, side by
side, and their answers compared.

    python benchmarks/bench_required_width.py --baseline ../base [--rounds 3] [--only RSN77_SFERN_PUL164]

``--baseline``: a checkout of the version compared with, its compiled core built in place (``git
worktree add ../base 7dcc58d && cd ../base && python setup.py build_ext --inplace``, or its own
``pip install -e .``); it runs with the same Python as this checkout, first on the path.  The
records are those of ``bench_design_width.py`` (31 real records of ``../shared/records``), the
column 7.5 m high, ``rule="exact"``, overturning and ``limit=0.5``.  Each version runs in a process
of its own, the two alternately, ``--rounds`` times (the machine may be shared): for each record
and criterion the least CPU seconds (``time.process_time``, one thread) of the rounds, each round
the best of two calls after a warm-up.  Printed: per record the CPU of both and their ratio, the
design widths of both, then the median ratio per criterion and how many design widths, search
widths and widest failing widths are equal, or within 1e-6 relative.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
LEVEL = 0.5
HEIGHT = 7.5

CHILD = r'''
import json, sys, time
import pulses, rocking
from rocking import lanes
lanes.set_threads(1)
out = {}
for path in sys.argv[2:]:
    rec = pulses.read_record(path)
    for name, kw in (("overturning", {}), ("limit", {"limit": float(sys.argv[1])})):
        rocking.required_width(7.5, rec, rule="exact", **kw)           # warm (and the memo)
        best = None
        for _ in range(2):
            t = time.process_time()
            r = rocking.required_width(7.5, rec, rule="exact", **kw)
            t = time.process_time() - t
            best = t if best is None else min(best, t)
        out[path + "|" + name] = dict(cpu=best, width=r.width, search=r.search_width,
                                      widest=r.widest_failing_width, runs=r.total_runs)
print(json.dumps(out))
'''


def record_paths():
    sys.path.insert(0, str(HERE))
    from bench_design_width import record_paths as paths

    return [str(p) for p in paths()]


def child(root, paths):
    env = dict(os.environ, PYTHONPATH=str(root), OPENBLAS_NUM_THREADS="1")
    done = subprocess.run([sys.executable, "-c", CHILD, str(LEVEL), *paths], env=env,
                          cwd=str(root), capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(done.stderr[-3000:])
    return json.loads(done.stdout.strip().splitlines()[-1])


def close(a, b, rel=1e-6):
    if a is None or b is None:
        return a is None and b is None
    return abs(a - b) <= rel * max(abs(a), abs(b))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=True)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--only", help="comma-separated record names (stems)")
    args = ap.parse_args(argv)
    paths = record_paths()
    if args.only:
        paths = [p for p in paths if pathlib.Path(p).stem in args.only.split(",")]
    builds = {"this": ROOT, "baseline": pathlib.Path(args.baseline).resolve()}
    best = {}
    for _ in range(args.rounds):
        for name, root in builds.items():
            for key, row in child(root, paths).items():
                keep = best.setdefault(key, {}).setdefault(name, row)
                keep["cpu"] = min(keep["cpu"], row["cpu"])
    for crit in ("overturning", "limit"):
        ratios, same, near, same_search, same_widest = [], 0, 0, 0, 0
        print(f"\n{crit if crit == 'overturning' else f'limit={LEVEL}'}: record, CPU this / baseline (s), "
              "ratio, design width this / baseline (m)")
        keys = [k for k in best if k.endswith("|" + crit)]
        for key in keys:
            a, b = best[key]["this"], best[key]["baseline"]
            ratios.append(a["cpu"] / b["cpu"])
            same += a["width"] == b["width"]
            near += close(a["width"], b["width"])
            same_search += close(a["search"], b["search"])
            same_widest += close(a["widest"], b["widest"])
            print(f"  {pathlib.Path(key.split('|')[0]).stem:32s} {a['cpu']:.3f} / {b['cpu']:.3f}  "
                  f"{ratios[-1]:.3f}  {a['width']:.6f} / {b['width']:.6f}")
        print(f"{crit}: median CPU ratio {statistics.median(ratios):.3f} over {len(ratios)} records "
              f"(min {min(ratios):.3f}, max {max(ratios):.3f}); design widths equal on {same}, "
              f"within 1e-6 on {near}; search widths within 1e-6 on {same_search}; widest failing "
              f"widths within 1e-6 on {same_widest}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
