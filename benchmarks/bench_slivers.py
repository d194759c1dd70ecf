"""How big must the check above the search width be?  Its findings against a dense grid.

    python benchmarks/bench_slivers.py            # ~20 min on 2 busy cores; needs ../shared
    python benchmarks/bench_slivers.py --quick    # the 15 top-level records, one seed
    python benchmarks/bench_slivers.py --variants "near + stages (default)"   # one layout
    python benchmarks/bench_slivers.py --variants "near + stages (default)" --ns 800,1500 \
        --seeds 8 --only RSN879_LANDERS_LCN345,RSN159_1,RSN250_1,RSN6_2,RSN77_2
    python benchmarks/bench_slivers.py --figure docs/slivers_barcode.png
    python benchmarks/bench_slivers.py --variants "near + stages (default)" --ns 1500 --seeds 8 --height 12

The search width ``w`` (``rocking.required_width(H, record, rule="exact").search_width``) is followed by a
check of ``check_runs`` jittered widths above it (docs/slivers.md).  For every real record of
../shared/records/raw (or ``$ROCKING_RECORDS``; the top level and its sub-folders), column height
7.5 m, this script runs

- the reference: an independent dense grid of ``DENSE`` linear widths in ``(w, min(2 w, top)]``
  (``top``: the no-uplift width);
- the check with ``N`` runs (``NS``), with a share ``q`` of them concentrated just above ``w``
  (``NEARS``: 0 all uniform, 1 all log-spaced in ``B / w - 1``), for ``SEEDS`` seeds each;

and prints, per ``(q, N)``: on the records where the dense grid finds a failing width more than
1 % above ``w``, on how many (of all seeds) the check's widest failing width is at least
``1.01 w``, and on how many it found none; on every record where the dense grid finds any
failure, how often the check finds one; the median ratio ``(widest found - w) / (dense widest -
w)``.  It also prints the search's own runs per record (today's cost, the 4x budget's
base).  The tables in docs/validation-slivers.md are this script's output.
"""
from __future__ import annotations

import json
import os
import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

RECORDS = pathlib.Path(os.environ.get("ROCKING_RECORDS", ROOT.parent / "shared" / "records" / "raw"))
HEIGHT = 7.5
DENSE = 6000
NS = (50, 100, 200, 400, 800, 1500)
#: layouts of the check (rocking.search.SearchSettings fields): "uniform" all in B, "near" half of
#: them log-spaced just above w, "all near", and the default, a fifth placed so (half near) and
#: four fifths over five later stages where the widths run so far (the search's included) vary
#: most or failed
VARIANTS = {"uniform": dict(check_near=0.0, check_follow=0.0),
            "near": dict(check_near=0.5, check_follow=0.0),
            "all near": dict(check_near=1.0, check_follow=0.0),
            "near + stages (default)": {},
            # the later stages' rule varied one setting at a time (docs/validation-slivers.md)
            "power 2": dict(check_power=2.0), "power 4": dict(check_power=4.0),
            "50 bins": dict(check_bins=50), "200 bins": dict(check_bins=200),
            "10 stages": dict(check_stages=10), "first stage 1/3": dict(check_follow=2.0 / 3.0),
            "first stage 1/4": dict(check_follow=0.75)}
NEARS = tuple(VARIANTS)
SEEDS = (1, 2)


def _run(record, widths):
    import rocking

    blocks = [rocking.Block.from_dimensions(HEIGHT, float(b)) for b in widths]
    res = rocking.simulate_many(blocks, record)
    return np.asarray(res.overturned, dtype=bool), np.asarray(res.max_rotation_ratio, dtype=float)


def _verdicts(record, widths):
    return _run(record, widths)[0]


def _check(record, v, seen, top, layout, n, seed):
    """The package's check (``rocking.widths``) with these sizes above the search width of ``v``."""
    import dataclasses

    import rocking
    from rocking import widths as rw

    res = dataclasses.replace(v)
    settings = rocking.search.SearchSettings(check_runs=n, **layout)
    x, f, _ = rw._add_check(res, top, lambda x: _run(record, x), settings, seed, seen)
    return (float(f.mean()) if x.size else 0.0), (float(x[f].max()) if f.any() else None)


def measure(paths, seeds=SEEDS, ns=NS, nears=NEARS):
    """One dict per record: ``w``, ``runs`` (the search's), the dense grid's failing
    widths, and per ``(near, n, seed)`` the check's share and widest failing width."""
    import pulses
    import rocking
    from pulses import G
    from rocking import widths as rw
    out = []
    cache = os.environ.get("BENCH_SLIVERS_DENSE")        # an earlier run's JSON: its dense grids
    cached = {r["record"]: r for r in json.loads(pathlib.Path(cache).read_text())} if cache else {}
    for path in paths:
        record = pulses.read_record(path)
        t = time.perf_counter()
        top = HEIGHT * (record.pga / G)       # as required_width computes it, to the last bit
        # the search as required_width runs it, keeping its widths (the check's later stages
        # measure the spread over them too)
        v, seen = rw._record_search(HEIGHT, top, lambda x: _run(record, x), criterion="overturn",
                                    eta=None, settings=rocking.search.SearchSettings(check_runs=0))
        t_search = time.perf_counter() - t
        w = v.width
        hi = min(2.0 * w, top)
        old = cached.get(pathlib.Path(path).stem)
        if old is not None and old["w"] == w:
            dense_fail, t_dense = old["dense_fail"], old["t_dense"]
        else:
            x = np.linspace(w, hi, DENSE + 1)[1:]
            t = time.perf_counter()
            f = _verdicts(record, x)
            t_dense = time.perf_counter() - t
            dense_fail = x[f].tolist()
        row = dict(record=pathlib.Path(path).stem, w=w, top=top, runs=v.runs, t_search=t_search,
                   t_dense=t_dense, dense_fail=dense_fail, checks={})
        for q in nears:
            for n in ns:
                for s in seeds:
                    row["checks"][f"{q}/{n}/{s}"] = _check(record, v, seen, top, VARIANTS[q], n, s)
        out.append(row)
        dense = (max(row["dense_fail"]) / w - 1) * 100 if row["dense_fail"] else 0.0
        print(f"{row['record']:28s} w {w:.4f} m, search {v.runs} runs {t_search:.1f} s, dense "
              f"{len(row['dense_fail'])} failing, widest +{dense:.2f} % ({t_dense:.1f} s)", flush=True)
    return out


def table(rows, seeds=SEEDS, ns=NS, nears=NEARS):
    """Markdown lines: one row per (near share, N)."""
    far = [r for r in rows if r["dense_fail"] and max(r["dense_fail"]) > 1.01 * r["w"]]
    anyf = [r for r in rows if r["dense_fail"]]
    lines = [f"{len(rows)} records, height {HEIGHT} m; dense grid: {DENSE} linear widths in "
             f"(w, min(2w, no-uplift width)]; it finds failing widths above w on {len(anyf)} records, "
             f"more than 1 % above w on {len(far)} ({', '.join(r['record'] for r in far)}). "
             f"Each check size run with {len(seeds)} seeds: counts are over records x seeds.",
             "",
             "| layout | N | far records: widest >= 1.01 w | far records: none found "
             "| records with a dense failure: check finds one | median (widest - w) / (dense widest - w) "
             "| median failing share (records with a dense failure) |",
             "|---|---|---|---|---|---|---|"]
    for q in nears:
        for n in ns:
            ge = none = found = 0
            ratios, shares = [], []
            for r in anyf:
                dw = max(r["dense_fail"]) - r["w"]
                for s in seeds:
                    share, widest = r["checks"][f"{q}/{n}/{s}"]
                    shares.append(share)
                    found += widest is not None
                    ratios.append(0.0 if widest is None else (widest - r["w"]) / dw)
                    if r in far:
                        ge += widest is not None and widest >= 1.01 * r["w"]
                        none += widest is None
            nf, na = len(far) * len(seeds), len(anyf) * len(seeds)
            lines.append(f"| {q} | {n} | {ge}/{nf} | {none}/{nf} | {found}/{na} | "
                         f"{np.median(ratios):.2f} | {np.median(shares):.4f} |")
    runs = np.array([r["runs"] for r in rows])
    lines += ["", f"The search's own runs: {runs.min()}-{runs.max()} runs per record, median "
              f"{np.median(runs):.0f} (4x: {4 * np.median(runs):.0f})."]
    return lines


def figure(path, name="RSN879_LANDERS_LCN345.AT2", n=6000):
    """docs/slivers_barcode.png: the verdict against the width for one record, on ``n`` linear
    widths from 0.6 to 1.6 times the search width and the check's own widths."""
    import pulses
    import rocking
    from pipeline.reports.figures.widths import widths_figure_png

    record = pulses.read_record(RECORDS / name)
    v = rocking.required_width(HEIGHT, record, rule="exact")
    w = v.search_width
    x = np.concatenate([np.linspace(0.6 * w, 1.6 * w, n), v.check_widths])
    f = np.concatenate([_verdicts(record, x[:n]), v.check_failed])
    pathlib.Path(path).write_bytes(widths_figure_png(
        f"{pathlib.Path(name).stem}, column height {HEIGHT} m", w, x, f))
    print(f"{path}: search width {w:.4f} m, design width {v.width:.4f} m, check: share {v.failing_share:.4f}, widest "
          f"failing {v.widest_failing_width} m")


def main(argv=None):
    global HEIGHT
    argv = sys.argv[1:] if argv is None else argv
    quick = "--quick" in argv
    if "--height" in argv:         # e.g. --height 12: another column height (m)
        HEIGHT = float(argv[argv.index("--height") + 1])
    if not RECORDS.is_dir():
        print(f"no records at {RECORDS} (set $ROCKING_RECORDS)")
        return 1
    if "--figure" in argv:
        figure(argv[argv.index("--figure") + 1])
        return 0
    paths = sorted(RECORDS.glob("*.AT2")) + ([] if quick else sorted(RECORDS.glob("*/*.AT2")))
    seeds = SEEDS[:1] if quick else SEEDS
    if "--seeds" in argv:          # e.g. --seeds 8: seeds 1..8
        seeds = tuple(range(1, int(argv[argv.index("--seeds") + 1]) + 1))
    if "--only" in argv:           # e.g. --only RSN159_1,RSN6_2: these records (file stems) only
        only = set(argv[argv.index("--only") + 1].split(","))
        paths = [p for p in paths if p.stem in only]
    ns = NS
    if "--ns" in argv:             # e.g. --ns 800,1500
        ns = tuple(int(n) for n in argv[argv.index("--ns") + 1].split(","))
    nears = NEARS
    if "--variants" in argv:       # e.g. --variants "near + stages (default)"
        nears = tuple(argv[argv.index("--variants") + 1].split(","))
    rows = measure(paths, seeds=seeds, nears=nears, ns=ns)
    dump = pathlib.Path(os.environ.get("BENCH_SLIVERS_JSON", "")) if os.environ.get("BENCH_SLIVERS_JSON") else None
    if dump:
        dump.write_text(json.dumps(rows))
    print("\n".join(table(rows, seeds=seeds, nears=nears, ns=ns)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
