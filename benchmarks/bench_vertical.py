"""Speed and accuracy of the compiled core with vertical ground motion (issue 28, docs/theory.md
section 10), on the real three-component records of the shared PEER download.

    python benchmarks/bench_vertical.py [--repeat N] [--no-reference]

For each record (two horizontals and a vertical, read as :func:`pulses.check_triplet` reads them:
the vertical made upward, ``DWN`` negated) and each block, the first horizontal component is run
with and without its vertical by :func:`rocking.simulate` (the compiled engine: ``"fast"`` and
``"fast-vertical"``), with history (the default) and without.  Times are CPU seconds
(``time.process_time``) per call, the median of ``--repeat`` calls after one untimed call,
taken alternately so that both see the same load of the shared machine.  Printed: a markdown
table, the ratio with/without vertical per case, and (unless ``--no-reference``) the agreement
of the peak rotation with the independent reference integrator
(:func:`rocking.simulate_vertical_reference`, scipy DOP853 at rtol 1e-12) over the whole record,
in units of alpha, and whether the verdicts agree.
"""
from __future__ import annotations

import argparse
import pathlib
import statistics
import sys
import time

import pulses
import rocking
from rocking.reference_vertical import simulate_vertical_reference

DOWNLOAD = pathlib.Path(__file__).resolve().parents[2] / "shared" / "records" / "peer_download"
RECORDS = [("RSN77 San Fernando, Pacoima Dam (DWN)", "RSN77_SFERN_PUL164.AT2",
            "RSN77_SFERN_PUL254.AT2", "RSN77_SFERN_PULDWN.AT2"),
           ("RSN15 Kern County, Taft (UP)", "RSN15_KERN_TAF021.AT2", "RSN15_KERN_TAF111.AT2",
            "RSN15_KERN_TAF-UP.AT2"),
           ("RSN41 Lytle Creek, Wrightwood (DWN)", "RSN41_LYTLECR_ORR021.AT2",
            "RSN41_LYTLECR_ORR291.AT2", "RSN41_LYTLECR_ORRDWN.AT2")]
#: (height, width) m: a slender column that rocks hard, and stockier ones
BLOCKS = [(3.0, 0.45), (3.0, 0.3), (7.5, 1.8)]


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
    print("| record | block | history | horizontal only | with vertical | ratio |"
          + ("" if args.no_reference else " peak vs reference / alpha | verdicts agree |"))
    print("|---|---|---|---|---|---|" + ("" if args.no_reference else "---|---|"))
    ratios = []
    for name, h1, h2, v in RECORDS:
        hor, up = read(h1, h2, v)
        for hb in BLOCKS:
            block = rocking.Block.from_dimensions(*hb)
            for history in (True, False):
                t_h, t_v = [], []
                for _ in range(3):  # alternately, so that both see the same load
                    t_h.append(timed(lambda: rocking.simulate(block, hor, history=history),
                                     args.repeat))
                    t_v.append(timed(lambda: rocking.simulate(block, hor, vertical=up,
                                                              history=history), args.repeat))
                th, tv = min(t_h), min(t_v)
                ratios.append(tv / th)
                row = (f"| {name} | {hb[0]} x {hb[1]} m | {history} | {1e3 * th:.3f} ms | "
                       f"{1e3 * tv:.3f} ms | {tv / th:.2f} |")
                if not args.no_reference and history:
                    res = rocking.simulate(block, hor, vertical=up)
                    ref = simulate_vertical_reference(block, hor, up)
                    dev = abs(res.max_rotation - ref.max_rotation) / block.alpha
                    agree = (res.overturned, res.lifts_off) == (ref.overturned, ref.lifts_off)
                    row += (f" {dev:.1e} (overturns: {res.overturned}, max/alpha "
                            f"{res.max_rotation_ratio:.4f}) | {agree} |")
                elif not args.no_reference:
                    row += " | |"
                print(row, flush=True)
    print(f"\nratio with/without vertical: median {statistics.median(ratios):.2f}, "
          f"largest {max(ratios):.2f}")


if __name__ == "__main__":
    main()
