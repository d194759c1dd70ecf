"""The batch engine's lanes on columns near their design width (issue 34), two builds side by side.

    python benchmarks/bench_lanes.py [--build NAME=PATH ...] [--rounds N] [--records NAME ...]

``--build``: another checkout of the package with its compiled core built in place (e.g.
``git worktree add --detach /tmp/lanes-base main && cd /tmp/lanes-base && python setup.py
build_ext --inplace``), run with the same Python, first on its path; any number of them.  This
checkout is measured as ``this``.

For each real record (``../shared/records/raw``; RSN77 San Fernando, Rinaldi (RSN1063), Imperial
Valley RSN181, Landers RSN879 by default): the exact required width of a 7.5 m column
(``rocking.required_width(7.5, record, rule="exact")``, CPU seconds of the whole search), then 64
widths from 1.0 to 2.0 times its ``search_width`` (the columns a design search runs most: they
rock and impact all through the strong motion) in one ``rocking.simulate_many`` call (one thread):
CPU per run in lanes and one by one (``lanes=False``, the same answers), and the batch engine's
counts: rocking steps kept in lanes, turning points and impacts taken in lanes, intervals handed
to the one-run engine (of them, for a too low order), and the share of rocking intervals handed
over.  Each build runs in its own process, alternately, ``--rounds`` times (the machine is
shared); the best of the rounds' medians is printed, and a digest of every answer (verdicts,
peaks, impact counts) says whether the builds agree bit for bit.  (Impacts in lanes: builds that
count them, six counts; the package counts four, the rest printed 0.)

``--early-stop``: instead, what a compiled early stop of a performance level (a run stopped once
``max|theta|/alpha > R``) would skip in ``required_width(7.5, record, rule="exact", limit=R)``, R
= 0.3 and 0.6: the runs the design makes (the blocks ``rocking.widths`` hands to its batch
runner), each run again alone with its history; the work after ``R alpha`` is first passed (rocking samples,
and 15 per impact: an impact costs about 15-30 steps, benchmarks/lanes.md) over the design's.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
RECORDS = ROOT.parent / "shared" / "records" / "raw"
DEFAULT = ("RSN77_SFERN_PUL164.AT2", "NGA_no_1063_RRS228.AT2", "RSN181_IMPVALL.H_H-E06140.AT2",
           "RSN879_LANDERS_LCN260.AT2")

CHILD = r'''
import hashlib, json, pathlib, statistics, sys, time
import numpy as np
import pulses, rocking
from rocking import lanes, solver
out = {}
for path in map(pathlib.Path, sys.argv[1:]):
    rec = pulses.read_record(path)
    rocking.required_width(7.5, rec, rule="exact")  # warm
    c = time.process_time()
    w0 = rocking.required_width(7.5, rec, rule="exact").search_width
    t_design = time.process_time() - c
    blocks = [rocking.Block.from_dimensions(7.5, float(w)) for w in w0 * np.linspace(1.0, 2.0, 64)]
    row = {"design_s": t_design, "search_width": w0}
    for name, flag in (("lanes", True), ("single", False)):
        ts = []
        for _ in range(5):
            c = time.process_time()
            r = rocking.simulate_many(blocks, rec, threads=1, lanes=flag)
            ts.append(time.process_time() - c)
        row[name + "_ms_per_run"] = 1e3 * statistics.median(ts) / len(blocks)
        if flag:
            digest = hashlib.sha256()
            for a in (r.overturned, r.max_rotation, r.n_impacts, r.uplifted):
                digest.update(np.ascontiguousarray(a).tobytes())
            row["digest"] = digest.hexdigest()[:16]
    p = np.array([b.p for b in blocks]); alpha = np.array([b.alpha for b in blocks])
    eta = np.array([b.eta for b in blocks])
    g = solver._grid(rec, float(p.max()), False, None, solver._default_ph_max("taylor"))
    for n in (6, 4):  # a build that counts 4 (before issue 34) leaves the last two at 0
        stats = np.zeros(n, dtype=np.int64)
        try:
            lanes.run_lanes(np.full(p.size, g.amp), g.uval, g.t_start, g.h, g.n_int, p, alpha,
                            eta, solver.ZENO_TOL, threads=1, stats=stats)
            break
        except ValueError:
            continue
    row["stats"] = [int(x) for x in stats] + [0] * (6 - stats.size)
    out[path.name] = row
print(json.dumps(out))
'''


def child(python: str, base: str | None, records: list[str]) -> dict:
    env = dict(os.environ)
    if base:
        env["PYTHONPATH"] = base + os.pathsep + env.get("PYTHONPATH", "")
    done = subprocess.run([python, "-c", CHILD, *records], env=env, cwd=base or str(ROOT),
                          capture_output=True, text=True)
    if done.returncode:
        raise SystemExit(done.stderr)
    return json.loads(done.stdout.strip().splitlines()[-1])


def early_stop_share(records, limits=(0.3, 0.6)) -> None:
    """Print the share of a level design's work after its runs first pass the level."""
    import numpy as np

    import pulses
    import rocking
    from rocking import widths

    batch, seen = widths._batch, []

    def spy(blocks, *args, **kwargs):
        seen.extend(blocks)
        return batch(blocks, *args, **kwargs)

    widths._batch = spy
    try:
        for path in records:
            rec = pulses.read_record(path)
            for limit in limits:
                seen.clear()
                rocking.required_width(7.5, rec, rule="exact", limit=limit)
                total = after = 0.0
                n_over = 0
                for block in seen:
                    r = rocking.simulate(block, rec)
                    th = np.abs(r.theta)
                    impacts = np.asarray(r.impacts)
                    total += np.count_nonzero(th) + 15 * impacts.size
                    over = th > limit * block.alpha
                    if over.any():
                        k = int(np.argmax(over))
                        n_over += 1
                        after += np.count_nonzero(th[k:]) + 15 * np.count_nonzero(impacts > r.t[k])
                print(f"{pathlib.Path(path).stem}, limit {limit}: {len(seen)} runs, {n_over} pass "
                      f"the level; work after it is first passed: {after / total:.3f} of the design's")
    finally:
        widths._batch = batch


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--build", action="append", default=[], metavar="NAME=PATH",
                    help="another checkout of the package, built in place (repeatable)")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--records", nargs="*", default=list(DEFAULT))
    ap.add_argument("--early-stop", action="store_true",
                    help="the share of a level design's work an early stop would skip")
    args = ap.parse_args(argv)
    records = [str(RECORDS / r) for r in args.records]
    if args.early_stop:
        early_stop_share(records)
        return 0
    builds = dict(b.split("=", 1) for b in args.build)
    builds["this"] = None
    best: dict = {}
    for _ in range(args.rounds):
        for name, base in builds.items():
            for rec, row in child(sys.executable, base, records).items():
                keep = best.setdefault(name, {}).setdefault(rec, row)
                for key in ("design_s", "lanes_ms_per_run", "single_ms_per_run"):
                    keep[key] = min(keep[key], row[key])
    print("| record | build | required_width (s) | lanes ms/run | one by one ms/run | "
          "in lanes: steps, turns, impacts | to the engine (low order) | share | digest |")
    print("|---|---|---|---|---|---|---|---|---|")
    for rec in args.records:
        for name in builds:
            r = best[name][rec]
            kept, turns, rock, _, imp, low = r["stats"]
            share = rock / (kept + turns + imp + rock)
            print(f"| {rec.split('.')[0]} (w = {r['search_width']:.3f} m) | {name} | "
                  f"{r['design_s']:.3f} | {r['lanes_ms_per_run']:.3f} | "
                  f"{r['single_ms_per_run']:.3f} | {kept}, {turns}, {imp} | {rock} ({low}) | "
                  f"{share:.3f} | {r['digest']} |")
    same = all(len({best[b][r]["digest"] for b in builds}) == 1 for r in args.records)
    print(f"\nanswers bit for bit equal between the builds: {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
