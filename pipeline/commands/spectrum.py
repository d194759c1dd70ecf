"""``pipeline spectrum``: the overturning spectrum of Fig. 5.

    pipeline spectrum --alpha 14deg --pulse sine [--grid 200x200] --csv out.csv --plot out.png
    pipeline spectrum --block 7.5x1.8 --pulse sine --ap 0.5g --tp 1 --plot out.png   # your column marked
"""
from __future__ import annotations

import math
import re
import time

from ..args import ShapeNames, add_restitution_option, parse_acceleration, parse_angle
from ..values import ArgumentError, parse_column_block, parse_positive, parse_restitution



def _range(text, what):
    m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*[:,]\s*([0-9.eE+-]+)\s*", str(text))
    try:
        lo, hi = float(m.group(1)), float(m.group(2))
    except (AttributeError, ValueError):
        raise ArgumentError(f"{what}: expected LOW:HIGH, got {text!r}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and 0 < lo < hi):
        raise ArgumentError(f"{what}: need 0 < LOW < HIGH, got {text!r}")
    return lo, hi


def _grid(text):
    m = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", str(text))
    if not m or int(m.group(1)) < 2 or int(m.group(2)) < 2 or int(m.group(1)) * int(m.group(2)) > 4_000_000:
        raise ArgumentError(f"--grid expects NWxNA with 2..2000 points each, e.g. 200x200; got {text!r}")
    return int(m.group(1)), int(m.group(2))


def add_parser(subparsers):
    p = subparsers.add_parser(
        "spectrum", help="overturning spectrum (Fig. 5) of a block slenderness under a pulse shape",
        description="Survive / overturn over omega_p/p (x) and ap/(g tan alpha) (y) for blocks of "
                    "slenderness alpha under one pulse shape (the paper's Fig. 5), from the batch "
                    "solver and the similarity law.")
    p.add_argument("--alpha", help="slenderness: 14deg, 0.244rad or tan0.25 (default: --block's)")
    p.add_argument("--block", help="your column HEIGHTxWIDTH in m, e.g. 7.5x1.8 (its slenderness; "
                                    "cyl:HxD a circular one, with its impact rule; with --ap and "
                                    "--tp, marked on the plot)")
    p.add_argument("--ap", help="your pulse's amplitude, e.g. 0.5g (with --block and --tp)")
    p.add_argument("--tp", help="your pulse's period, s (with --block and --ap)")
    p.add_argument("--pulse", default="sine", choices=ShapeNames(), metavar="SHAPE",
                   help="pulse shape: %(choices)s (default sine)")
    p.add_argument("--grid", default="200x200", help="points along omega_p/p x ap/(g tan alpha)")
    p.add_argument("--wp-range", default="0.5:12", help="omega_p/p range LOW:HIGH (default 0.5:12)")
    p.add_argument("--ap-range", default="1:6", help="ap/(g tan alpha) range (default 1:6)")
    p.add_argument("--csv", help="write the grid (long format) to this CSV file")
    p.add_argument("--plot", help="write the spectrum plot to this PNG file")
    add_restitution_option(p)
    p.set_defaults(func=run)


def run(args) -> int:
    import numpy as np

    import rocking

    from ..reports.outpaths import check_file_options

    check_file_options(args, "spectrum")
    if args.alpha is None and args.block is None:
        raise ArgumentError("give the slenderness: --alpha 14deg, or your column with --block 7.5x1.8")
    block = None
    if args.block:
        height, width, body = parse_column_block(args.block)
        block = rocking.Block.from_dimensions(height, width, body=body)
    alpha = parse_angle(args.alpha) if args.alpha else block.alpha
    mark = _mark(args, block)
    nw, na = _grid(args.grid)
    w0, w1 = _range(args.wp_range, "--wp-range")
    a0, a1 = _range(args.ap_range, "--ap-range")
    start = time.perf_counter()
    eta = parse_restitution(args.restitution)
    if block is not None and not block.body.is_rectangular and not args.alpha:
        # a circular column's impact rule differs from Eq. 5: its own eta at its alpha (a factor
        # given multiplies that rule)
        if eta is not None and eta.is_band:
            raise ArgumentError("--restitution: a band goes with a rectangular column's spectrum; give "
                                "one value for a circular column")
        eta = rocking.Block.from_dimensions(block.height, block.width, eta, body=block.body).eta
    spec = rocking.overturning_spectrum(alpha, args.pulse, np.linspace(w0, w1, nw),
                                        np.linspace(a0, a1, na), eta=eta)
    elapsed = time.perf_counter() - start
    n = spec.overturned.size
    islands = spec.safe_islands()
    shown = (f"{spec.eta:.3f}" if not spec.band_runs else
             f"{eta.describe()} (a band: {spec.band_runs} values run, a point overturns where any does)")
    print(f"Overturning spectrum: {args.pulse} pulse, alpha = {math.degrees(alpha):.4g} deg "
          f"(tan {math.tan(alpha):.4g}), eta = {shown}; {nw} x {na} points in "
          f"{elapsed:.2f} s")
    print(f"overturn: {int(spec.overturned.sum())} of {n} points; |theta| > alpha without "
          f"overturning: {int((spec.exceeded_alpha & ~spec.overturned).sum())}; safe-island "
          f"points (survive above an overturning amplitude): {int(islands.sum())}")
    mins = spec.minimum_overturning()
    print(f"{'omega_p/p':>10}  {'min overturning ap/(g tan alpha)':>33}")
    for i in np.unique(np.linspace(0, nw - 1, min(nw, 8)).astype(int)):
        v = mins[i]
        print(f"{spec.wp_over_p[i]:>10.3f}  {('> %.3g' % a1) if np.isnan(v) else ('%.4g' % v):>33}")
    from ..reports.outpaths import figure_png, write_output

    if args.csv:
        write_output(args.csv, spec.to_frame().to_csv(index=False), "csv")
        print(f"wrote {args.csv}")
    if args.plot:
        write_output(args.plot, figure_png(lambda buf: spec.plot(buf, mark=mark)), "png")
        print(f"wrote {args.plot}")
    return 0


def _mark(args, block):
    """Your column under your pulse as a point of the spectrum, ``(omega_p/p, ap/(g tan alpha))``."""
    if args.ap is None and args.tp is None:
        return None
    if args.ap is None or args.tp is None or block is None:
        raise ArgumentError("--ap and --tp mark your pulse with your column: give --block, --ap and --tp")
    from pulses import G

    ap, tp = parse_acceleration(args.ap, signed=False), parse_positive(args.tp, "--tp")
    return 2 * math.pi / (block.p * tp), ap / (G * block.tan_alpha)
