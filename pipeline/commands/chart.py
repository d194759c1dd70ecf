"""``pipeline chart``: Fig. 8, the exact minimum tan(alpha) against ap/g for several pTp; or,
with ``--heights``, the width a column needs against its height for one pulse under every rule.

    pipeline chart --pulse all [--csv chart.csv] [--plot chart.png] [--block 7.5x1.8 --ap 0.5g --tp 1]
    pipeline chart --heights 3:15 --pulse sine --ap 0.5g --tp 1 [--block 7.5x1.8] [--plot w.png]
"""
from __future__ import annotations

import time

from ..args import ShapeNames, add_restitution_option, parse_acceleration
from ..values import ArgumentError, parse_column_block, parse_positive, parse_restitution


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
    p.add_argument("--heights", help="LOW:HIGH[:N] or comma-separated heights in m: the width "
                                      "against height for the pulse of --pulse/--ap/--tp under every rule")
    p.add_argument("--ap", help="your pulse's amplitude, e.g. 0.5g or 4.9m/s2 (with --tp)")
    p.add_argument("--tp", help="your pulse's period, s (with --ap)")
    p.add_argument("--block", help="your column HEIGHTxWIDTH in m, e.g. 7.5x1.8 (cyl:HxD: a "
                                   "circular one; with --heights every width is of its shape): "
                                   "marked on the chart")
    p.add_argument("--csv", help="write the table to this CSV file")
    p.add_argument("--plot", help="write the chart to this PNG file")
    add_restitution_option(p)
    p.set_defaults(func=run)


def _heights(text):
    parts = str(text).split(":")
    if len(parts) in (2, 3):
        lo, hi = (float(_floats(v, "--heights")[0]) for v in parts[:2])
        n = int(_floats(parts[2], "--heights")[0]) if len(parts) == 3 else 13
        if not (lo < hi and 2 <= n <= 200):
            raise ArgumentError(f"--heights: need LOW < HIGH and 2..200 points, got {text!r}")
        return [lo + (hi - lo) * k / (n - 1) for k in range(n)]
    return _floats(text, "--heights")


def _your_pulse(args):
    """``(shape, ap, tp)`` from --pulse/--ap/--tp, or None when neither --ap nor --tp is given."""
    if args.ap is None and args.tp is None:
        return None
    if args.ap is None or args.tp is None:
        raise ArgumentError("--ap and --tp go together (your pulse's amplitude and period)")
    if args.pulse == "all":
        from pulses import SHAPES

        names = list(SHAPES)
        raise ArgumentError(f"--ap/--tp need one pulse shape: --pulse {', '.join(names[:-1])} or {names[-1]}")
    return args.pulse, parse_acceleration(args.ap, signed=False), parse_positive(args.tp, "--tp")


def run(args) -> int:
    import rocking
    from rocking.spectrum import CHART_APG, CHART_PTP

    from ..reports.outpaths import check_file_options

    check_file_options(args, "chart")
    pulse = _your_pulse(args)
    column = parse_column_block(args.block) if args.block else None
    eta = parse_restitution(args.restitution)
    if args.heights:
        if pulse is None:
            raise ArgumentError("--heights needs your pulse: --pulse SHAPE --ap AMPLITUDE --tp PERIOD")
        return _run_heights(args, _heights(args.heights), pulse, column, eta)
    shapes = ShapeNames().names() if args.pulse == "all" else [args.pulse]
    ptp = _floats(args.ptp, "--ptp") if args.ptp else CHART_PTP
    apg = _floats(args.apg, "--apg") if args.apg else CHART_APG
    start = time.perf_counter()
    frame = rocking.slenderness_chart(shapes, ptp, apg, criterion=args.criterion, eta=eta)
    elapsed = time.perf_counter() - start
    print(f"Exact minimum tan(alpha) ({args.criterion}) for {len(shapes)} shape(s) x {len(ptp)} pTp "
          f"x {len(apg)} ap/g in {elapsed:.1f} s; ratio = exact / Eq. 31 (> 1: Eq. 31 unconservative)")
    if eta is not None:
        print(f"restitution {eta.describe()}" + (f": a band, {_band_values()} values run at each point, "
                                                 "the largest tan(alpha) kept (restitution_governing)"
                                                 if eta.is_band else ""))
    print(f"{'shape':<12} {'pTp':>6} {'max ratio':>10} {'at ap/g':>8} {'min ratio':>10} "
          f"{'islands':>8}")
    for (shape, x), sub in frame.groupby(["shape", "pTp"], sort=False):
        k = sub["ratio"].idxmax()
        print(f"{shape:<12} {x:>6g} {sub['ratio'].max():>10.3f} {sub.loc[k, 'ap_over_g']:>8.3g} "
              f"{sub['ratio'].min():>10.3f} {int((sub['islands'] > 0).sum()):>8d}")
    from ..reports.outpaths import figure_png, write_output

    if args.csv:
        write_output(args.csv, frame.to_csv(index=False), "csv")
        print(f"wrote {args.csv}")
    if args.plot:
        mark = _mark(pulse, column)
        write_output(args.plot, figure_png(lambda buf: rocking.plot_chart(frame, buf, mark=mark)), "png")
        print(f"wrote {args.plot}")
    return 0


def _mark(pulse, column):
    """Your pulse and column as a point of Fig. 8: ``(shape, pTp, ap/g, tan alpha)``."""
    if pulse is None or column is None:
        return None
    import rocking
    from pulses import G

    shape, ap, tp = pulse
    block = rocking.Block.from_dimensions(column[0], column[1], body=column[2])
    return shape, block.p * tp, ap / G, block.tan_alpha


def _band_values() -> int:
    from rocking.band import BAND_VALUES

    return BAND_VALUES


def _run_heights(args, heights, pulse, column, eta=None) -> int:
    import pulses

    from ..reports.outpaths import figure_png, write_output
    from ..reports.figures.chart import RULES, width_figure, widths_by_height

    shape, ap, tp = pulse
    start = time.perf_counter()
    body = None if column is None else column[2]
    frame = widths_by_height(pulses.make_pulse(shape, ap, tp), heights, body=body, eta=eta)
    elapsed = time.perf_counter() - start
    title = f"{shape} pulse, ap = {ap / pulses.G:.3g} g, Tp = {tp:g} s: width a column needs"
    print(f"{title}, by rule, {len(heights)} heights in {elapsed:.1f} s (m)")
    table = frame.pivot(index="height_m", columns="rule", values="width_m")[list(RULES)]
    print(f"{'height':>8} " + " ".join(f"{r:>9}" for r in table.columns))
    for h, row in table.iterrows():
        print(f"{h:>8.4g} " + " ".join(f"{v:>9.3f}" for v in row))
    if column is not None:
        h, b, _ = column
        import rocking

        need = rocking.required_width(h, pulses.make_pulse(shape, ap, tp), rule="exact",
                                      body=body, eta=eta).width
        print(f"your column {h:g} x {b:g} m: the exact rule asks for {need:.3f} m "
              + ("(it is wide enough)" if b >= need else "(it is too narrow)"))
    if args.csv:
        write_output(args.csv, frame.to_csv(index=False), "csv")
        print(f"wrote {args.csv}")
    if args.plot:
        fig = width_figure(frame, title, None if column is None else column[:2])
        write_output(args.plot, figure_png(lambda buf: fig.savefig(buf, format="png", dpi=110)), "png")
        print(f"wrote {args.plot}")
    return 0
