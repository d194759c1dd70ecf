"""How many values a restitution band must run: how often its interior governs on real records.

    python benchmarks/bench_restitution_band.py                    # ~10 min of CPU; needs ../shared
    python benchmarks/bench_restitution_band.py --bands 0.95:1.05 --heights 7.5 --limits 0.5,none --fine 17

For every real record of ../shared/records (those of ``bench_design_width.record_paths``, a
record's duplicate counted once), each column height, each band (factors of Eq. 5) and each level
(``pipeline run``'s default 0.5, as it computes it: ``overturning=True``; ``none``: the verge
alone), the design width of ``FINE`` single values evenly spaced over the band (ends included) is
computed.  The reference is the widest of them.  A band of ``n`` values (``n - 1`` dividing
``FINE - 1``: a subset of the fine values) answers the widest of its own; the table counts the
cases where it is below the reference (an interior value it did not run governs), by more than
0.5 % and 2 %, and the worst shortfall.  ``n = 2`` is the ends alone: how often the interior
governs at all.
"""
from __future__ import annotations

import argparse
import pathlib
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

#: single values run over each band (ends included); the subsets compared are those of SUBSETS
#: (``--fine 17``: 2, 3, 5, 9 against 17)
FINE = 9
SUBSETS = (2, 3, 5, 9)
BANDS = ("0.95:1.05", "0.67:1")
HEIGHTS = (7.5, 6.0)
LIMITS = ("0.5",)


def subsets(fine):
    """The band sizes whose values are among ``fine`` evenly spaced ones, ends included."""
    return tuple(n for n in (2, 3, 5, 9, 17, 33) if n <= fine and (fine - 1) % (n - 1) == 0)


def widths(height, record, band, limit):
    """The design widths (m) of the ``FINE`` values of ``band`` (rocking.required_width, one value
    at a time, as a band design runs each)."""
    import rocking

    level = None if limit == "none" else float(limit)
    over = None if level is None else True
    return [float(rocking.required_width(height, record, rule="exact", eta=v, limit=level,
                                         overturning=over).width)
            for v in band.values(FINE)]


def shortfalls(values):
    """``{n: (widest of n values - widest of all) / widest of all}`` for each n of SUBSETS."""
    top = max(values)
    out = {}
    for n in SUBSETS:
        step = (FINE - 1) // (n - 1)
        out[n] = max(values[::step]) / top - 1.0
    return out


def main(argv=None) -> int:
    global FINE, SUBSETS
    import pulses
    from rocking.restitution import Restitution

    from benchmarks.bench_design_width import record_paths, samples_key

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bands", default=",".join(BANDS))
    ap.add_argument("--heights", default=",".join(f"{h:g}" for h in HEIGHTS))
    ap.add_argument("--limits", default=",".join(LIMITS))
    ap.add_argument("--fine", type=int, default=FINE, help=f"values run per band (default {FINE})")
    args = ap.parse_args(argv)
    FINE, SUBSETS = args.fine, subsets(args.fine)
    bands = [Restitution.parse(b) for b in args.bands.split(",")]
    heights = [float(h) for h in args.heights.split(",")]
    limits = args.limits.split(",")
    records, seen = [], set()
    for path in record_paths():
        rec = pulses.read_record(path)
        key = samples_key(rec)
        if key not in seen:
            seen.add(key)
            records.append((path.stem, rec))
    start = time.perf_counter()
    print(f"{len(records)} records x {len(heights)} heights; {FINE} values per band")
    for limit in limits:
        for band in bands:
            rows = []
            for name, rec in records:
                for h in heights:
                    v = widths(h, rec, band, limit)
                    rows.append((name, h, v, shortfalls(v)))
            print(f"\nlevel {limit}, band {band} x Eq. 5 ({len(rows)} cases; {time.perf_counter() - start:.0f} s)")
            print("| values run | interior governs | below by > 0.5 % | below by > 2 % | worst |")
            print("|---:|---:|---:|---:|---:|")
            for n in SUBSETS[:-1]:
                short = [s[n] for _, _, _, s in rows]
                print(f"| {n} | {sum(x < 0 for x in short)} | {sum(x < -0.005 for x in short)} | "
                      f"{sum(x < -0.02 for x in short)} | {100 * min(short):+.1f} % |")
            for name, h, v, s in rows:
                if s[SUBSETS[-2]] < -0.005:
                    print(f"  {name} {h:g} m: widest at value {v.index(max(v)) + 1} of {FINE}; "
                          + ", ".join(f"{n} values {100 * s[n]:+.1f} %" for n in SUBSETS[:-1]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
