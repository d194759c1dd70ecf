"""This checkout's design answers against another version's, on the 62 cases of
``bench_design_width.py``: what moved, by how much, and whether the guarantees still hold.

    python benchmarks/bench_answers.py --baseline ../base [--cache DIR] [--only NAME,...]

``--baseline``: a checkout of the version compared with, its compiled core built in place; each
version runs in a process of its own (the two at once), the same Python, its checkout first on the
path.  For every case (31 real records, columns 7.5 m and 6 m; 60 once a record's duplicate counts
once) each version computes:

- the overturning design ``rocking.required_width(H, record, rule="exact")`` with the check's seed
  set to each of ``record`` (the package's own) and 1..7 (``SearchSettings.check_seed``): its
  design width ``W`` and search width ``w``;
- the level designs ``limit=0.5`` and ``limit=0.2`` as ``pipeline run --limit`` computes them
  (``pipeline.batch.record.design_width``): the design width ``W_R`` and the level's search width;
- an independent dense grid of ``bench_design_width.DENSE`` linear widths in ``(w0, min(3 w0,
  top)]`` (``w0``: 0.5.0's search width, as ``bench_design_width.py``), run by that version's
  engine: a miss of a seed is a case whose grid fails more than 1 % above its ``W``.

Printed: the cases where a level's design width or search width, or the overturning search width,
moved by more than 1e-6 relative (and whether a transition lies within that distance: the two
versions' runs near it disagree, which rounding decides), each seed's misses of each version
against both dense grids (counted once per record's samples, as ``bench_design_width.py``), and
the overturning design widths of this version outside the spread of the baseline's eight seeds.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
SEEDS = (None, 1, 2, 3, 4, 5, 6, 7)
LEVELS = (0.5, 0.2)

CHILD = r'''
import json, pathlib, sys
here, root, cache = sys.argv[1], sys.argv[2], sys.argv[3]
sys.path.insert(0, here)
import bench_design_width as bdw
sys.path.insert(0, root)              # this version's package first (bdw put its own checkout in)
import numpy as np
import pulses, rocking
from rocking import lanes
from rocking.search import DEFAULT_SETTINGS
from pipeline.batch.record import design_width
lanes.set_threads(1)
seeds = json.loads(sys.argv[4]); levels = json.loads(sys.argv[5]); only = set(json.loads(sys.argv[6]))
out = []
for path in bdw.record_paths():
    if only and path.stem not in only:
        continue
    record = pulses.read_record(str(path))
    for H in bdw.HEIGHTS:
        row = dict(record=path.stem, key=bdw.samples_key(record), height=H)
        for s in seeds:
            r = rocking.required_width(H, record, rule="exact",
                                       settings=DEFAULT_SETTINGS.replace(check_seed=s))
            row[f"W_{s}"], row["w"] = r.width, r.search_width
        for R in levels:
            lv = design_width(record, None, H, 0.0, R, DEFAULT_SETTINGS)
            row[f"WR_{R}"], row[f"wR_{R}"] = lv.width, lv.search_width
        w0 = rocking.required_width(H, record, rule="exact", settings=bdw._baseline()).search_width
        fx = bdw.dense_failures(H, record, w0, H * record.pga / pulses.G, cache)
        row["w0"], row["dense_widest"] = w0, (float(fx.max()) if fx.size else None)
        row["dense"] = [float(x) for x in fx]
        out.append(row)
        print(json.dumps({"done": path.stem, "H": H}), file=sys.stderr, flush=True)
print(json.dumps(out))
'''


def child(root, cache, only):
    env = dict(os.environ, PYTHONPATH=str(root), OPENBLAS_NUM_THREADS="1")
    seeds = [s for s in SEEDS]
    done = subprocess.run([sys.executable, "-c", CHILD, str(HERE), str(root), str(cache),
                           json.dumps(seeds), json.dumps(list(LEVELS)), json.dumps(only)],
                          env=env, cwd=str(root), capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(done.stderr[-3000:])
    return json.loads(done.stdout.strip().splitlines()[-1])


def rel(a, b):
    return abs(a - b) / max(abs(a), abs(b))


def misses(rows, dense_of, seed):
    """Cases (once per record's samples) whose dense grid fails above 1.01 W of ``seed``."""
    seen = {}
    for r in rows:
        fx = dense_of[(r["key"], r["height"])]
        k = (r["key"], r["height"])
        seen[k] = seen.get(k, False) or bool(fx and max(fx) > 1.01 * r[f"W_{seed}"])
    return sum(seen.values()), len(seen)


def report(this, base):
    key = lambda r: (r["record"], r["height"])
    b_of = {key(r): r for r in base}
    rows = [(r, b_of[key(r)]) for r in this if key(r) in b_of]
    lines = [f"{len(rows)} cases compared"]
    for name in ["w"] + [f"WR_{R}" for R in LEVELS] + [f"wR_{R}" for R in LEVELS]:
        moved = [(a, b) for a, b in rows if rel(a[name], b[name]) > 1e-6]
        lines.append(f"- {name}: within 1e-6 relative on {len(rows) - len(moved)} of {len(rows)}"
                     + "".join(f"; {a['record']} {a['height']:g} m {b[name]:.7g} -> {a[name]:.7g}"
                               f" ({(a[name] / b[name] - 1):+.2e})" for a, b in moved))
    grids = {"this version's grid": {(r["key"], r["height"]): r["dense"] for r in this},
             "the baseline's grid": {(r["key"], r["height"]): r["dense"] for r in base}}
    for gname, dense in grids.items():
        for vname, vrows in (("this", this), ("baseline", base)):
            counts = [misses(vrows, dense, s)[0] for s in SEEDS]
            n = misses(vrows, dense, SEEDS[0])[1]
            lines.append(f"- misses of {vname} on {gname} ({n} cases), seeds record, 1..7: "
                         f"{', '.join(map(str, counts))}; mean {sum(counts) / len(counts):.2f}")
    out = []
    for a, b in rows:
        spread = [b[f"W_{s}"] for s in SEEDS]
        lo, hi = min(spread), max(spread)
        bad = [s for s in SEEDS if not lo * (1 - 1e-6) <= a[f"W_{s}"] <= hi * (1 + 1e-6)]
        if bad:
            got = ", ".join(format(a["W_" + str(s)], ".6g") for s in bad)
            out.append(f"{a['record']} {a['height']:g} m: seeds {bad} ({got}) "
                       f"outside [{lo:.6g}, {hi:.6g}]")
    lines.append(f"- overturning design widths outside the baseline's 8-seed spread: {len(out)} of "
                 f"{len(rows)} cases" + "".join("; " + x for x in out))
    same = sum(all(a[f"W_{s}"] == b[f"W_{s}"] for s in SEEDS) for a, b in rows)
    lines.append(f"- overturning design widths equal to the last bit on all 8 seeds: {same} of {len(rows)} cases")
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=True)
    ap.add_argument("--cache", default=None, help="folder for the dense grids (one per version)")
    ap.add_argument("--only", default="", help="comma-separated record names")
    ap.add_argument("--save", default=None, help="write both versions' rows to this JSON file")
    args = ap.parse_args(argv)
    only = [x for x in args.only.split(",") if x]
    cache = pathlib.Path(args.cache or (pathlib.Path.home() / ".cache" / "rocking-bench-answers"))
    builds = {"this": ROOT, "baseline": pathlib.Path(args.baseline).resolve()}
    with ThreadPoolExecutor(2) as pool:
        res = dict(zip(builds, pool.map(lambda kv: child(kv[1], cache / kv[0], only), builds.items())))
    if args.save:
        pathlib.Path(args.save).write_text(json.dumps(res), encoding="utf-8")
    print("\n".join(report(res["this"], res["baseline"])))
    return 0


if __name__ == "__main__":
    sys.exit(main())
