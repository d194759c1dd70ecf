"""Could the width search's fine zone be thinned?  Where failing slivers sit, measured.

    python benchmarks/bench_fine_zone.py        # about a minute; real records need ../shared

The width search (``rocking.required_width(..., rule="exact")`` on a record) runs every width
0.05 % apart up to 20 % above its candidate (the *fine zone*, ~365 full-record runs of the ~530
per column), and that is most of what ``pipeline run`` costs.  A cheaper search would run a
coarser grid (every ``k``-th width) and fill in only the gaps next to a width that came near to
tipping (``max|theta|/alpha >= R``).  This script runs the whole fine zone at once on real records
(../shared/records/raw or $ROCKING_RECORDS, heights 3, 6, 7.5 and 12 m) and on the benchmark's
synthetic ones, and for every zone with a failure reports, per stride ``k``, the larger ``max|theta|/alpha`` of the two
coarse widths around its widest failing width: a refinement rule with ``R`` above that value
misses the failure (and answers narrower, unconservatively).  It also reports what share of the
zone such a rule would still run.
"""
from __future__ import annotations

import math
import pathlib
import sys
import tempfile
import time

import numpy as np

STRIDES = (4, 8, 16)
NEAR = (0.3, 0.5, 0.7)


def _zones(record, height):
    """Every batch of the fine zone of one width search: ``(widths, failed, ratio)``
    sorted widest first, with each width's index ``k`` on the grid ``top (1 + record_fine)^-k``
    (the search run with the whole zone in one batch, ``record_chunk`` unbounded, not stopped
    at its first failure; every batch logged)."""
    from pulses import G
    from rocking import search, widths

    settings = search.SearchSettings(record_chunk=sys.maxsize)
    fine = settings.record_fine
    top = height * record.pga / G
    log = []

    def evaluate(ws):
        res = search._batch([rocking_block(height, b) for b in ws], record)
        log.append((np.asarray(ws, dtype=float), np.asarray(res.overturned, dtype=bool),
                    np.asarray(res.max_rotation_ratio, dtype=float)))
        return log[-1][1], log[-1][2]

    widths._record_width(height, top, evaluate, criterion="overturn", eta=None, settings=settings)
    out = []
    for w, f, r in log:
        k = np.round(np.log(top / w) / math.log1p(fine)).astype(int)
        if w.size < 40 or not np.allclose(top * (1.0 + fine) ** -k.astype(float), w,
                                          rtol=1e-12, atol=0.0):
            continue                   # the scan, bisections and gap checks
        order = np.argsort(-w)
        out.append((w[order], f[order], r[order], k[order]))
    return out


def rocking_block(height, width):
    from rocking import Block

    return Block.from_dimensions(height, float(width))


def analyse(cases) -> dict:
    """``cases``: ``(name, record, height)``.  Returns the measurements (see the module doc)."""
    worst = {k: (math.inf, "") for k in STRIDES}
    missed = {(k, near): 0 for k in STRIDES for near in NEAR}
    share = {(k, near): [0, 0] for k in STRIDES for near in NEAR}
    n_zones = n_fail = n_runs = 0
    ratios = []
    t0 = time.process_time()
    for name, record, height in cases:
        for w, f, r, k in _zones(record, height):
            n_zones += 1
            n_runs += w.size
            ratios.append(r)
            for stride in STRIDES:
                coarse = np.nonzero(k % stride == 0)[0]
                if f.any():
                    j = int(np.nonzero(f)[0][0])          # the widest failing width
                    if k[j] % stride:
                        left, right = coarse[coarse < j], coarse[coarse > j]
                        ends = [r[left[-1]] if left.size else np.inf,
                                r[right[0]] if right.size else np.inf]
                        value = max(ends)
                        if value < worst[stride][0]:
                            worst[stride] = (value, f"{name} at {height:g} m")
                        for near in NEAR:
                            missed[(stride, near)] += value < near
                for near in NEAR:
                    n = coarse.size
                    for a, b in zip(coarse[:-1], coarse[1:]):
                        if max(r[a], r[b]) >= near:
                            n += b - a - 1
                    share[(stride, near)][0] += n
                    share[(stride, near)][1] += w.size
            n_fail += bool(f.any())
    ratios = np.concatenate(ratios) if ratios else np.zeros(0)
    return {
        "cases": len(cases), "fine_zones": n_zones, "zones_with_a_failure": n_fail,
        "runs_in_fine_zones": n_runs, "cpu_s": round(time.process_time() - t0, 1),
        "share_of_zone_runs_reaching_0.5": round(float(np.mean(ratios >= 0.5)), 3) if ratios.size else None,
        "lowest_neighbour_ratio_around_widest_failure": {
            f"every {k}th ({k * 0.05:.2g} % apart)": (round(float(v), 3), where) for k, (v, where) in worst.items()},
        "zones_whose_widest_failure_a_rule_misses": {
            f"k={k}, R={near}": int(n) for (k, near), n in missed.items()},
        "share_of_zone_still_run": {
            f"k={k}, R={near}": round(float(a / b), 3) if b else None for (k, near), (a, b) in share.items()},
    }


def cases():
    import pulses

    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
    from bench_pipeline import make_records
    from common import RECORDS_DIR

    out = []
    if RECORDS_DIR.is_dir():
        for path in sorted(RECORDS_DIR.rglob("*.AT2")):
            rec = pulses.read_record(path)
            out += [(path.stem, rec, h) for h in (3.0, 6.0, 7.5, 12.0)]
    else:
        print(f"({RECORDS_DIR} not found: synthetic records only)")
    with tempfile.TemporaryDirectory() as tmp:
        for path in make_records(tmp, 20, durations=[20.0, 25.0, 30.0, 35.0, 40.0]):
            rec = pulses.read_record(path)
            out += [(pathlib.Path(path).stem, rec, h) for h in (6.0, 7.5)]
    return out


def run() -> dict:
    result = analyse(cases())
    for key, value in result.items():
        print(f"{key}: {value}")
    return result


if __name__ == "__main__":
    run()
