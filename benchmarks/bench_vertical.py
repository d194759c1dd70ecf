"""Speed and accuracy of the compiled core with vertical ground motion (issue 28, docs/theory.md
section 10), on the real three-component records of the shared PEER download.

    python benchmarks/bench_vertical.py [--repeat N] [--no-reference]

For each record (two horizontals and a vertical, read as :func:`pulses.check_triplet` reads them:
the vertical made upward, ``DWN`` negated) and each block (3 m tall: 0.45 m wide, and widths
whose ``tan(alpha)`` is 0.35 and 0.7 of the record's PGA/g, so that every block rocks), the first
horizontal component is run with and without its vertical by :func:`rocking.simulate` (the
compiled engine: ``"fast"`` and ``"fast-vertical"``), with history (the default) and without.
The vertical changes the motion (more or fewer impacts, earlier or no overturning), so the ratio
of these two times mixes the cost of the vertical code path with that of a different motion; the
second table isolates the code path: a constant vertical of 0.3 g against the similar block
(``p sqrt(1.3)`` under ``ag / 1.3``, docs/theory.md section 10), the same motion computed both
ways.  The third table times batches (``rocking.simulate_many``) of 256 widths with and without
the vertical (the vertical batch runs one by one; the horizontal one in lanes).  Times are CPU
seconds (``time.process_time``) per call, the median of ``--repeat`` calls
after one untimed call, best of three rounds taken alternately so that both see the same load of
the shared machine.  Printed: markdown tables with the ratios, and (unless ``--no-reference``)
the agreement of the peak rotation with the independent reference integrator
(:func:`rocking.simulate_vertical_reference`, scipy DOP853 at rtol 1e-12) over the whole record,
in units of alpha, and whether the verdicts agree.
"""
from __future__ import annotations

import argparse
import math
import pathlib
import statistics
import sys
import time

import numpy as np

import pulses
import rocking
from rocking.reference_vertical import simulate_vertical_reference

DOWNLOAD = pathlib.Path(__file__).resolve().parents[2] / "shared" / "records" / "peer_download"
RECORDS = [("RSN77 San Fernando, Pacoima Dam (DWN)", "RSN77_SFERN_PUL164.AT2",
            "RSN77_SFERN_PUL254.AT2", "RSN77_SFERN_PULDWN.AT2"),
           ("RSN15 Kern County, Taft (UP)", "RSN15_KERN_TAF021.AT2", "RSN15_KERN_TAF111.AT2",
            "RSN15_KERN_TAF-UP.AT2"),
           ("RSN41 Lytle Creek, Castaic (DWN)", "RSN41_LYTLECR_ORR021.AT2",
            "RSN41_LYTLECR_ORR291.AT2", "RSN41_LYTLECR_ORRDWN.AT2")]


def blocks(hor):
    """The blocks of one record (see the module docstring)."""
    pga = float(np.max(np.abs(hor.acc))) / pulses.G
    return [(3.0, 0.45)] + [(3.0, round(3.0 * f * pga, 4)) for f in (0.35, 0.7)]


def read(h1, h2, v):
    d = pulses.peer.PeerDownload(DOWNLOAD)
    first, _, up = pulses.check_triplet(d.read_component(h1), d.read_component(h2),
                                        d.read_component(v))
    return first, up


def timed(f, repeat):
    f()
    out = []
    for _ in range(repeat):
        t0 = time.process_time()
        f()
        out.append(time.process_time() - t0)
    return statistics.median(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=15)
    ap.add_argument("--no-reference", action="store_true")
    args = ap.parse_args(argv)
    if not DOWNLOAD.is_dir():
        sys.exit(f"bench_vertical: the shared PEER download is absent ({DOWNLOAD})")
    print("| record | block | history | horizontal only (impacts) | with vertical (impacts) | ratio |"
          + ("" if args.no_reference else " peak vs reference / alpha | overturns (core / reference) "
             "| max/alpha | verdicts agree |"))
    print("|---|---|---|---|---|---|" + ("" if args.no_reference else "---|---|---|---|"))
    ratios, same = [], []
    cases = []
    for name, h1, h2, v in RECORDS:
        hor, up = read(h1, h2, v)
        for hb in blocks(hor):
            cases.append((name, hor, up, hb))
            block = rocking.Block.from_dimensions(*hb)
            for history in (True, False):
                th, tv = pair(lambda: rocking.simulate(block, hor, history=history),
                              lambda: rocking.simulate(block, hor, vertical=up, history=history),
                              args.repeat)
                ratios.append(tv / th)
                res = rocking.simulate(block, hor, vertical=up)
                ho = rocking.simulate(block, hor)
                row = (f"| {name} | {hb[0]} x {hb[1]} m | {history} | {1e3 * th:.3f} ms "
                       f"({ho.n_impacts}) | {1e3 * tv:.3f} ms ({res.n_impacts}) | {tv / th:.2f} |")
                if not args.no_reference and history:
                    ref = simulate_vertical_reference(block, hor, up)
                    dev = abs(res.max_rotation - ref.max_rotation) / block.alpha
                    agree = (res.overturned, res.lifts_off) == (ref.overturned, ref.lifts_off)
                    row += (f" {dev:.1e} | {res.overturned} / {ref.overturned} | "
                            f"{res.max_rotation_ratio:.4f} | {agree} |")
                elif not args.no_reference:
                    row += " | | | |"
                print(row, flush=True)
    print(f"\nratio with/without vertical: median {statistics.median(ratios):.2f}, "
          f"largest {max(ratios):.2f}\n")
    print("The same motion both ways: a constant vertical of 0.3 g against the similar block\n")
    print("| record | block | history | similar block, horizontal only | block with 0.3 g vertical "
          "| ratio |")
    print("|---|---|---|---|---|---|")
    c = 0.3 * pulses.G
    for name, hor, up, hb in cases:
        block = rocking.Block.from_dimensions(*hb)
        const = pulses.Record(np.full(hor.npts, c), hor.dt)
        similar = rocking.Block(block.p * math.sqrt(1.0 + c / pulses.G), block.alpha, block.eta)
        scaled = hor.scaled(pulses.G / (pulses.G + c))
        for history in (True, False):
            th, tv = pair(lambda: rocking.simulate(similar, scaled, history=history, model="fast"),
                          lambda: rocking.simulate(block, hor, vertical=const, history=history),
                          args.repeat)
            same.append(tv / th)
            print(f"| {name} | {hb[0]} x {hb[1]} m | {history} | {1e3 * th:.3f} ms | "
                  f"{1e3 * tv:.3f} ms | {tv / th:.2f} |", flush=True)
    print(f"\nratio, the same motion: median {statistics.median(same):.2f}, largest {max(same):.2f}")
    print("\nBatches: 256 widths of 3 m tall columns (0.3 to 3 m, geometric), one thread\n")
    print("| record | horizontal only (lanes) | horizontal only (one by one) | with vertical | ratio |")
    print("|---|---|---|---|---|")
    for name, h1, h2, v in RECORDS:
        hor, up = read(h1, h2, v)
        widths = [rocking.Block.from_dimensions(3.0, float(w)) for w in np.geomspace(0.3, 3.0, 256)]
        t_l, t_v = pair(lambda: rocking.simulate_many(widths, hor, threads=1),
                        lambda: rocking.simulate_many(widths, hor, vertical=up, threads=1), 3)
        t_o = timed(lambda: rocking.simulate_many(widths, hor, threads=1, lanes=False), 3)
        print(f"| {name} | {1e3 * t_l:.1f} ms | {1e3 * t_o:.1f} ms | {1e3 * t_v:.1f} ms | "
              f"{t_v / t_l:.2f} |", flush=True)


def pair(f_h, f_v, repeat):
    """Best of three rounds of the medians of ``f_h`` and ``f_v``, taken alternately."""
    t_h, t_v = [], []
    for _ in range(3):
        t_h.append(timed(f_h, repeat))
        t_v.append(timed(f_v, repeat))
    return min(t_h), min(t_v)


if __name__ == "__main__":
    main()
