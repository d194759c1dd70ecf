"""Design for a site: what directions and fragility cost per pair, and what the default directions miss.

    PYTHONPATH=. python -m benchmarks.bench_site [--cost-pairs 1] [--heights 2.5 7.5] [--n 36]

1. Cost per pair (``pipeline run``'s own per-task function, ``pipeline.batch.record.process_record``,
   one process, no plots) for the default directions (two components, pulse direction and its
   normal), for ``--directions 36``, and for the default directions with ``--fragility``
   (critical scale of the column as it stands in each direction, up to 10).
2. Miss of the default set: on every pair of ``../shared/records/raw`` (paired by
   ``pulses.pair_files``), the governing design width (``rocking.required_width``, rule exact:
   the function the pipeline's design width comes from) over the default directions against
   that over the default directions plus 36 evenly spaced ones (every 5 deg).
"""
from __future__ import annotations

import argparse
import pathlib
import time

SHARED = pathlib.Path(__file__).resolve().parents[2] / "shared" / "records" / "raw"


def shared_pairs():
    import pulses

    files = sorted(str(p) for p in SHARED.glob("*.AT2")) + sorted(
        str(p) for p in (SHARED / "shahi_baker_examples").glob("*.AT2"))
    meta = {p: pulses.read_record(p).metadata for p in files}
    return pulses.pair_files(files, metadata=meta).pairs


def cost(pair, columns, n_even, fragility):
    from pipeline.batch import pairs
    from pipeline.batch.record import process_record
    from pipeline.batch.tasks import Options

    opts = Options(plots=False, fragility=fragility)
    tasks = pairs.pair_tasks([], [pair], "none", columns, opts, n_even, say=lambda m: None)
    t0, c0 = time.perf_counter(), time.process_time()
    out = [process_record(t) for t in tasks]
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    assert not any(o["failure"] for o in out), [o["failure"] for o in out if o["failure"]]
    return seconds, cpu, len(tasks)


def miss(pair, heights, n_even):
    import pulses
    import rocking
    from pipeline.batch import pairs

    first, second = pulses.read_pair(*pair)
    orient = pulses.classify_pulse(first, second).orientation
    default = pairs.directions(orient)
    full = pairs.directions(orient, n_even)
    out = []
    for H in heights:
        widths = {a: float(rocking.required_width(H, pulses.component(first, second, a), rule="exact").width)
                  for a, _ in full}
        wd = max(widths[a] for a, _ in default)
        a_full = max(widths, key=widths.get)
        out.append((H, wd, widths[a_full], a_full, orient))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cost-pairs", type=int, default=1, help="pairs timed for the cost (default 1)")
    ap.add_argument("--heights", type=float, nargs="+", default=[2.5, 7.5])
    ap.add_argument("--n", type=int, default=36)
    ap.add_argument("--skip-cost", action="store_true")
    ap.add_argument("--skip-miss", action="store_true")
    args = ap.parse_args(argv)
    from pipeline.batch.tasks import Column

    pairs = shared_pairs()
    print(f"{len(pairs)} pairs in {SHARED}")
    columns = (Column(7.5, 1.8), Column(2.5, 0.6))
    if not args.skip_cost:
        cost(pairs[0], columns, 0, False)  # warm-up: compilation caches, imports
        print("\ncost per pair (CPU s of one process: the machine may be shared), columns 7.5x1.8 and 2.5x0.6:")
        print(f"{'pair':46s} {'default':>14s} {'N=' + str(args.n):>14s} {'fragility':>14s}")
        for pair in pairs[:args.cost_pairs]:
            cells = []
            for n_even, frag in ((0, False), (args.n, False), (0, True)):
                s, c, k = cost(pair, columns, n_even, frag)
                cells.append(f"{c:7.1f} ({k:2d} dir)")
                print(f"  {'N=' + str(n_even) if n_even else 'default'}{' --fragility' if frag else ''}: "
                      f"{s:.1f} s wall, {c:.1f} s CPU for {k} directions", flush=True)
            print(f"{pathlib.Path(pair[0]).name + ' + ' + pathlib.Path(pair[1]).name:46s} " + " ".join(cells))
    if args.skip_miss:
        return
    print(f"\ngoverning design width: default directions vs default + {args.n} even (m)")
    print(f"{'pair':46s} {'H':>5s} {'default':>8s} {'all':>8s} {'miss %':>7s} {'at deg':>7s} {'pulse deg':>9s}")
    worst = 0.0
    for pair in pairs:
        for H, wd, wf, af, orient in miss(pair, args.heights, args.n):
            m = 100.0 * (wf - wd) / wf
            worst = max(worst, m)
            print(f"{pathlib.Path(pair[0]).name + ' + ' + pathlib.Path(pair[1]).name:46s} {H:5.2f} "
                  f"{wd:8.4f} {wf:8.4f} {m:7.2f} {af:7.1f} {orient % 180:9.1f}", flush=True)
    print(f"largest miss: {worst:.2f} %")


if __name__ == "__main__":
    main()
