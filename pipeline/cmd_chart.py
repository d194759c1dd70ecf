"""``pipeline chart``: Fig. 8, the exact minimum tan(alpha) against ap/g for several pTp.

    pipeline chart --pulse all [--csv chart.csv] [--plot chart.png]
"""
from __future__ import annotations

import time

from .args import ArgumentError, ShapeNames


def _floats(text, what):
    try:
        values = [float(v) for v in str(text).split(",") if v.strip()]
    except ValueError:
        raise ArgumentError(f"{what}: expected comma-separated numbers, got {text!r}") from None
    if not values or any(not (v > 0 and v < 1e6) for v in values):
        raise ArgumentError(f"{what}: expected positive numbers, got {text!r}")
    return values


def add_parser(subparsers):
    p = subparsers.add_parser(
        "chart", help="Fig. 8: exact minimum tan(alpha) vs ap/g for several pTp, with Eq. 31",
        description="Exact minimum slenderness (time-history analysis, scan + bracketed "
                    "refinement) against ap/g for several pTp and pulse shapes, beside Eq. 31 "
                    "(the paper's Fig. 8).")
    p.add_argument("--pulse", default="all", choices=ShapeNames("all"), metavar="SHAPE",
                   help="shape(s): %(choices)s (default all)")
    p.add_argument("--ptp", help="comma-separated pTp values (default 0.5,1,2,3,4,6,10,20)")
    p.add_argument("--apg", help="comma-separated ap/g values (default 20 from 0.075 to 1.5)")
    p.add_argument("--criterion", default="overturn", choices=["overturn", "exceed"])
    p.add_argument("--csv", help="write the table to this CSV file")
    p.add_argument("--plot", help="write the chart to this PNG file")
    p.set_defaults(func=run)


def run(args) -> int:
    import rocking
    from rocking.spectrum import CHART_APG, CHART_PTP

    from .outpaths import check_file_options

    check_file_options(args, "chart")

    shapes = ShapeNames().names() if args.pulse == "all" else [args.pulse]
    ptp = _floats(args.ptp, "--ptp") if args.ptp else CHART_PTP
    apg = _floats(args.apg, "--apg") if args.apg else CHART_APG
    start = time.perf_counter()
    frame = rocking.slenderness_chart(shapes, ptp, apg, criterion=args.criterion)
    elapsed = time.perf_counter() - start
    print(f"Exact minimum tan(alpha) ({args.criterion}) for {len(shapes)} shape(s) x {len(ptp)} pTp "
          f"x {len(apg)} ap/g in {elapsed:.1f} s; ratio = exact / Eq. 31 (> 1: Eq. 31 unconservative)")
    print(f"{'shape':<12} {'pTp':>6} {'max ratio':>10} {'at ap/g':>8} {'min ratio':>10} "
          f"{'islands':>8}")
    for (shape, x), sub in frame.groupby(["shape", "pTp"], sort=False):
        k = sub["ratio"].idxmax()
        print(f"{shape:<12} {x:>6g} {sub['ratio'].max():>10.3f} {sub.loc[k, 'ap_over_g']:>8.3g} "
              f"{sub['ratio'].min():>10.3f} {int((sub['islands'] > 0).sum()):>8d}")
    from .outpaths import figure_png, write_output

    if args.csv:
        write_output(args.csv, frame.to_csv(index=False), "csv")
        print(f"wrote {args.csv}")
    if args.plot:
        write_output(args.plot, figure_png(lambda buf: rocking.plot_chart(frame, buf)), "png")
        print(f"wrote {args.plot}")
    return 0
