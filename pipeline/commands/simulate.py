"""``pipeline simulate``: the rocking response of one column to a pulse or a record.

    pipeline simulate --block 7.5x1.8 --pulse sine --ap 0.71g --tp 0.8
    pipeline simulate --block 7.5x1.8 --record Rinaldi228.AT2 [--scale 1.2] [--plot h.png]

Prints the verdict, max|theta|/alpha, the impacts and which model answered; ``--json`` prints
the same as one JSON object, ``--csv`` writes the history, ``--plot`` draws rotation and angular
velocity against time (as the paper's Fig. 11).
"""
from __future__ import annotations

import json
import math
import sys

from ..args import ShapeNames, add_record_options, parse_acceleration, record_options
from ..values import ArgumentError, parse_scale, parse_column_block, parse_friction, parse_positive


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "simulate", help="rocking response of one column to a pulse or a record",
        description="Solve Housner's rocking block (docs/theory.md section 2) under a pulse or a full record "
                    "and report overturning, max|theta|/alpha, impacts and the model that answered.")
    p.add_argument("--block", required=True, help="HEIGHTxWIDTH in m, e.g. 7.5x1.8; cyl:HxD for a "
                                                  "solid circular column rocking in a plane")
    source = p.add_mutually_exclusive_group(required=True)
    source.add_argument("--pulse", choices=ShapeNames(), metavar="SHAPE",
                        help="pulse shape: %(choices)s (with --ap and --tp)")
    source.add_argument("--record", help="accelerogram file (AT2, SAC, MiniSEED, text, ...)")
    p.add_argument("--ap", help="pulse amplitude with its unit, e.g. 0.71g or 6.96m/s2 "
                                "(negative flips the polarity)")
    p.add_argument("--tp", help="pulse period, s")
    p.add_argument("--scale", default="1", help="factor on the record's acceleration (default 1)")
    p.add_argument("--model", default="auto", choices=["auto", "fast", "linear", "reference"],
                   help="solver model (default auto: the cheapest that meets --tol)")
    p.add_argument("--tol", default="1e-6", help="accepted error in max|theta|/alpha for auto")
    p.add_argument("--duration", help="length of history in s (default: the excitation; longer "
                                      "adds the free rocking after it)")
    p.add_argument("--eta", help="coefficient of restitution, the velocity ratio at impact (default Eq. 5)")
    p.add_argument("--restitution", metavar="VALUE",
                   help="the restitution as the design commands take it: a factor of Eq. 5 (0.97), "
                        "eta=V or r=V (the energy ratio); one value (a run has one restitution)")
    p.add_argument("--friction", metavar="MU",
                   help="judge the friction the response needs against the base's coefficient MU "
                        "(default: the demand is reported, not judged)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--csv", help="write the history t, theta, omega to this CSV file")
    p.add_argument("--plot", help="draw the rotation and angular velocity histories to this PNG")
    add_record_options(p)
    p.set_defaults(func=run)


def _excitation(args):
    import pulses

    if args.pulse:
        if args.ap is None or args.tp is None:
            raise ArgumentError("--pulse needs --ap (e.g. 0.71g) and --tp (s)")
        ap = parse_acceleration(args.ap)
        tp = parse_positive(args.tp, "--tp (s)")
        return pulses.make_pulse(args.pulse, ap, tp), f"{args.pulse} pulse ap={args.ap} tp={tp:g} s"
    scale = parse_scale(args.scale, "--scale", signed=True)  # the one rule for scales
    try:
        record = pulses.read_record(args.record, **record_options(args))
    except pulses.RecordError as exc:
        raise ArgumentError(str(exc)) from None
    label = f"record {record.name}" + (f" x {scale:g}" if scale != 1 else "")
    return (record.scaled(scale) if scale != 1 else record), label


def run(args) -> int:
    import rocking

    from ..reports.outpaths import check_file_options

    check_file_options(args, "simulate", inputs=[getattr(args, "record", None)])

    height, width, body = parse_column_block(args.block)
    mu = parse_friction(args.friction)
    eta = None
    if args.eta is not None:
        eta = float(args.eta) if args.eta.replace(".", "", 1).isdigit() else math.nan
        if not (0.0 <= eta <= 1.0):
            raise ArgumentError(f"--eta must lie in [0, 1], got {args.eta!r}")
    if args.restitution is not None:
        from ..values import parse_restitution

        if args.eta is not None:
            raise ArgumentError("give --eta or --restitution, not both")
        eta = parse_restitution(args.restitution)
        if eta.is_band:
            raise ArgumentError(f"--restitution {args.restitution}: a run has one restitution; a band "
                                "goes with run, design, chart and spectrum (their answers cover it)")
    block = rocking.Block.from_dimensions(height, width, eta, body=body)
    excitation, label = _excitation(args)
    tol = parse_positive(args.tol, "--tol")
    duration = parse_positive(args.duration, "--duration (s)") if args.duration else None
    res = rocking.simulate(block, excitation, model=args.model, tol=tol, duration=duration)
    out = {
        "block": {"height_m": height, "width_m": width, "tan_alpha": block.tan_alpha,
                  "alpha_rad": block.alpha, "p_rad_s": block.p, "R_m": block.R, "eta": block.eta},
        "excitation": label,
        **res.summary(),
        "impact_times_s": [float(x) for x in res.impacts[:1000]],
    }
    need = rocking.friction_demand(res, excitation)
    out["block"]["body"] = block.body.describe()
    out["friction"] = need.as_dict()
    check = None if mu is None else need.judge(mu)
    if check is not None:
        out["friction"].update(mu=mu, slides=check.slides,
                               t_slide_s=None if not check.slides else check.t_slide, how=check.how)
    if args.csv:
        _write_history(args.csv, res)
    if args.plot:
        _plot(args.plot, res, block, label)
    if args.json:
        json.dump(out, sys.stdout, indent=2)
        print()
        return 0
    verdict = "OVERTURNS" if res.overturned else "survives"
    when = f" at t = {res.t_overturn:.3f} s" if math.isfinite(res.t_overturn) else ""
    print(f"{height:g} x {width:g} m column (tan(alpha) = {block.tan_alpha:.4g}, "
          f"p = {block.p:.4g} rad/s) under {label}:")
    print(f"  {verdict}{when}; max|theta|/alpha = {res.max_rotation_ratio:.4g} "
          f"(max|theta| = {res.max_rotation:.4g} rad)"
          + ("; |theta| exceeded alpha" if res.exceeded_alpha and not res.overturned else ""))
    print(f"  impacts: {res.n_impacts}; model: {res.model} (verdict by {res.verdict_by}); "
          f"body: {block.body.describe()}, eta = {block.eta:.4g}")
    print(f"  friction needed: up to {need.max_demand:.4g} at t = {need.t_max:.3f} s"
          + (f" (at uplift {need.uplift_demand:.4g})" if math.isfinite(need.uplift_demand) else "")
          + (f", impulse ratio at impacts {need.impulse_ratio:.4g}" if need.impacts.size else "")
          + f"; smallest normal force {need.min_normal:.4g} of the weight")
    if check is not None:
        print(f"  with friction {mu:g}: " + ("no sliding" if not check.slides else
              f"SLIDES at t = {check.t_slide:.3f} s ({check.how}): outside the rocking model"))
    return 0


def _write_history(path, res) -> None:
    import numpy as np

    import io

    from ..reports.outpaths import write_output

    data = np.column_stack([res.t, res.theta, res.omega])
    buf = io.StringIO()
    np.savetxt(buf, data, delimiter=",", header="t_s,theta_rad,omega_rad_s", comments="", fmt="%.10g")
    write_output(path, buf.getvalue(), "csv")


def _plot(path, res, block, label) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(8, 5.5))
    ax1.plot(res.t, res.theta / block.alpha, lw=1)
    for y in (-1, 1):
        ax1.axhline(y, color="0.6", lw=0.8, ls="--")
    ax1.set_ylabel(r"$\theta/\alpha$")
    ax1.set_title(f"{label}: {'overturns' if res.overturned else 'survives'}, "
                  f"max|θ|/α = {res.max_rotation_ratio:.3g} ({res.model})", fontsize=9)
    ax2.plot(res.t, res.omega / block.p, lw=1)
    ax2.set_ylabel(r"$\dot\theta/p$")
    ax2.set_xlabel("t (s)")
    fig.tight_layout()
    from ..reports.outpaths import figure_png, write_output

    data = figure_png(lambda buf: fig.savefig(buf, format="png", dpi=110, metadata={"Software": None}))
    plt.close(fig)
    write_output(path, data, "png")
