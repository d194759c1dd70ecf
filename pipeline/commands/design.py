"""``pipeline design``: minimum slenderness by Eq. 31, Eq. 20, the envelope rule and exactly.

    pipeline design --block 7.5x1.8 --pulse sine --ap 0.71g --tp 0.8 [--json]
    pipeline design --height 7.5 --pulse sine --magnitude 7.0 [--vp 0.9]
"""
from __future__ import annotations

import json
import math
import sys

from ..args import ShapeNames, add_restitution_option, parse_acceleration
from ..values import ArgumentError, parse_column_block, parse_column_height, parse_friction, parse_positive, parse_restitution



def add_parser(subparsers):
    p = subparsers.add_parser(
        "design", help="minimum slenderness (Eq. 31, Eq. 20, envelope, exact) and required width",
        description="Minimum slenderness tan(alpha) of a column against a design pulse by Eq. 31, "
                    "Eq. 20, the envelope rule and exact time-history analysis; whether the block "
                    "is adequate by each; and the width its height requires (a fixed point, "
                    "since p depends on the width).")
    size = p.add_mutually_exclusive_group(required=True)
    size.add_argument("--block", help="HEIGHTxWIDTH in m, e.g. 7.5x1.8; cyl:HxD for a solid "
                                      "circular column of diameter D rocking in a plane")
    size.add_argument("--height", help="full height in m: report the required widths only "
                                       "(cyl:H for a circular column)")
    p.add_argument("--pulse", default="sine", choices=ShapeNames(), metavar="SHAPE",
                   help="pulse shape: %(choices)s (default sine)")
    p.add_argument("--ap", help="pulse amplitude, e.g. 0.71g or 6.96m/s2")
    p.add_argument("--tp", help="pulse period, s")
    p.add_argument("--magnitude", help="design for a near-fault scenario of this Mw (Eq. 6) "
                                       "instead of --ap/--tp")
    p.add_argument("--vp", default="0.9", help="scenario velocity amplitude, m/s (default 0.9)")
    p.add_argument("--lam", default="1.0", help="lambda of Eq. 20 (default 1)")
    p.add_argument("--criterion", default="overturn", choices=["overturn", "exceed"],
                   help="exact answer: failure is overturning (default) or |theta| > alpha")
    p.add_argument("--limit", metavar="R", default=None,
                   help="also the exact width for the performance level max|theta|/alpha <= R, "
                        "0 < R <= 1 (docs/design.md)")
    p.add_argument("--friction", metavar="MU",
                   help="judge the friction the column (and the exact design) needs under the "
                        "pulse against the base's coefficient MU; default: reported, not judged")
    add_restitution_option(p)
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    p.set_defaults(func=run)


def _limit(args):
    if args.limit is None:
        return None
    try:
        value = float(args.limit)
    except ValueError:
        raise ArgumentError(f"--limit: expected a number in (0, 1], got {args.limit!r}") from None
    if not 0.0 < value <= 1.0:
        raise ArgumentError(f"--limit (max|theta|/alpha) must lie in (0, 1], got {args.limit!r}")
    return value


def _print_restitution(eta, rules) -> None:
    """The line that says which restitution the exact rules used (none for Eq. 5)."""
    if eta is None:
        return
    print(f"Restitution: {eta.describe()} (eta the velocity ratio at impact, r = eta^2 the energy "
          "ratio); the exact rules use it, Eq. 31, Eq. 20 and the envelope do not depend on it"
          + (f"; a band: {rules['exact']['restitution_values_run']} values run, "
             f"{rules['exact']['restitution_governing']} governed the exact width"
             if "restitution_values_run" in rules["exact"] else ""))


def _eta_of(height, width, eta):
    """The block's velocity ratio at impact (a number), or ``"LOW-HIGH"`` over a band's ends."""
    import rocking
    from rocking import band

    if not band.is_band(eta):
        return rocking.Block.from_dimensions(height, width, band.plain(eta)).eta
    lo, hi = (rocking.Block.from_dimensions(height, width, v).eta for v in (eta.values(2)))
    return f"{lo:.4g}-{hi:.4g}"


def _eta_text(eta) -> str:
    return eta if isinstance(eta, str) else f"{eta:.3f}"


def _required_widths(rules, height, pulse, lam, criterion, eta, body=None) -> None:
    """Each rule's required width for the column's height (of ``body``'s shape) into ``rules`` (the
    exact rule with the restitution ``eta``; a band: how many values ran, which governed)."""
    import rocking

    for name in ("eq31", "eq20", "envelope", "exact"):
        w = rocking.required_width(height, pulse, rule=name, lam=lam, criterion=criterion,
                                   shape=pulse.shape, eta=eta if name == "exact" else None, body=body)
        rules.setdefault(name, {})
        rules[name].update({"required_width_m": w.width, "tan_alpha_at_width": w.tan_alpha,
                            "p_at_width": w.p, "iterations": w.iterations, "method": w.method})
        if w.restitution_values:
            rules[name].update(restitution_values_run=len(w.restitution_values),
                               restitution_governing=str(w.restitution_governing))


def _pulse(args):
    import pulses

    if args.magnitude is not None:
        if args.ap is not None or args.tp is not None:
            raise ArgumentError("give either --magnitude or --ap/--tp, not both")
        try:
            mw = float(args.magnitude)
        except ValueError:
            raise ArgumentError(f"--magnitude: expected a number, got {args.magnitude!r}") from None
        if not (math.isfinite(mw) and 3.0 <= mw <= 9.5):
            raise ArgumentError(f"--magnitude must lie between 3 and 9.5, got {args.magnitude!r}")
        vp = parse_positive(args.vp, "--vp (m/s)")
        return pulses.design_pulse(mw, args.pulse, vp), f"scenario Mw {mw:g}, vp = {vp:g} m/s"
    if args.ap is None or args.tp is None:
        raise ArgumentError("give the pulse as --ap and --tp (or --magnitude)")
    ap = abs(parse_acceleration(args.ap))
    tp = parse_positive(args.tp, "--tp (s)")
    return pulses.make_pulse(args.pulse, ap, tp), "given pulse"


def _friction(block, height, width, body, pulse, mu) -> dict:
    """The friction the column as it stands and the exact design need under the pulse; with
    ``mu``, the verdicts and the narrowest width from the exact design up that does not slide."""
    import rocking
    from rocking.sliding import sliding_width

    out = {"mu": mu}
    design = rocking.Block.from_dimensions(height, width, body=body)
    for name, blk in (("block", block), ("exact_width", design)):
        if blk is None:
            continue
        need = rocking.friction_demand(rocking.simulate(blk, pulse), pulse)
        entry = need.as_dict()
        if mu is not None:
            check = need.judge(mu)
            entry.update(slides=check.slides, t_slide_s=check.t_slide if check.slides else None)
        out[name] = entry
    if mu is not None and out["exact_width"]["slides"]:
        found = sliding_width(height, pulse, width, mu, body=body)
        out["exact_width"].update(valid_width_m=found.width, reason=found.reason)
    return out


def _print_friction(friction, mu) -> None:
    for name, label in (("block", "the column as it stands"), ("exact_width", "the exact design")):
        f = friction.get(name)
        if f is None:
            continue
        line = (f"friction needed by {label}: up to {f['max_demand']:.4g} at t = "
                f"{f['t_max']:.3f} s")
        if f.get("uplift_demand") is not None:
            line += f" (at uplift {f['uplift_demand']:.4g})"
        if mu is not None:
            line += (f"; with friction {mu:g}: " + ("no sliding" if not f["slides"] else
                     f"SLIDES at t = {f['t_slide_s']:.3f} s, outside the rocking model"))
        print(line)
        if f.get("slides") and "valid_width_m" in f:
            w = f["valid_width_m"]
            print(f"  narrowest width from the exact design up that does not slide: {w:.4f} m"
                  if w is not None else f"  {f['reason']}")


def run(args) -> int:
    import rocking
    from pulses import G

    pulse, origin = _pulse(args)
    lam = parse_positive(args.lam, "--lam")
    limit = _limit(args)
    mu = parse_friction(args.friction)
    eta = parse_restitution(args.restitution)
    if args.block is not None:
        height, width, body = parse_column_block(args.block)
        block = rocking.Block.from_dimensions(height, width, body=body)
    else:
        (height, body), width, block = parse_column_height(args.height), None, None
    ap_g = abs(pulse.ap) / G
    out = {
        "pulse": {"shape": pulse.shape, "ap_g": ap_g, "ap_m_s2": abs(pulse.ap), "tp_s": pulse.tp,
                  "origin": origin},
        "height_m": height, "criterion": args.criterion,
        "body": rocking.Body.parse(body).describe(),
        "restitution": None if eta is None else str(eta),
    }
    rules = {} if block is None else _block_rules(out, block, pulse, args.criterion, lam, eta, body)
    _required_widths(rules, height, pulse, lam, args.criterion, eta, body)
    names = ["eq31", "eq20", "envelope", "exact"]
    if limit is not None:
        w = rocking.required_width(height, pulse, rule="exact", limit=limit, body=body, eta=eta)
        rules["level"] = {"limit": limit, "required_width_m": w.width, "tan_alpha_at_width": w.tan_alpha,
                          "p_at_width": w.p, "iterations": w.iterations, "method": w.method}
        if block is not None:
            rules["level"].update(min_tan_alpha=w.tan_alpha, adequate=bool(width >= w.width))
        names.append("level")
    out["rules"] = rules
    out["friction"] = _friction(block, height, rules["exact"]["required_width_m"], body, pulse, mu)
    if args.json:
        json.dump(out, sys.stdout, indent=2)
        print()
        return 0
    _print_rules(out, pulse, origin, block, eta, lam, limit, args.criterion, names, mu)
    return 0


def _block_rules(out, block, pulse, criterion, lam, eta, body) -> dict:
    """What each rule asks of the column as it stands (``out`` gets the block's facts and the
    exact answer's transitions and islands): ``{rule: {"min_tan_alpha", "adequate"}}``."""
    import rocking

    p = block.p
    exact = rocking.min_slenderness(pulse, p, criterion=criterion, body=body, eta=eta)
    values = {
        "eq31": rocking.eq31(pulse.ap, pulse.tp, p),
        "eq20": rocking.eq20(pulse.ap, pulse.tp, p, lam),
        "envelope": rocking.envelope_rule(pulse.ap, pulse.tp, p, pulse.shape),
        "exact": exact.tan_alpha,
    }
    height, width = block.height, block.width
    out["envelope_shape"] = pulse.shape
    out["block"] = {"height_m": height, "width_m": width, "p_rad_s": p,
                    "tan_alpha": block.tan_alpha, "alpha_deg": math.degrees(block.alpha),
                    "eta": _eta_of(height, width, eta), "pTp": p * pulse.tp}
    if exact.band is not None:
        out["exact_restitution_governing"] = str(exact.eta)
    out["exact_transitions"] = list(exact.transitions)
    out["exact_safe_islands"] = [list(s) for s in exact.safe_islands]
    return {name: {"min_tan_alpha": value, "adequate": bool(block.tan_alpha >= value)}
            for name, value in values.items()}


def _print_rules(out, pulse, origin, block, eta, lam, limit, criterion, names, mu) -> None:
    """The command's answer as text: the pulse, the block, a line per rule, friction, notes."""
    import rocking
    from pulses import G

    rules, height = out["rules"], out["height_m"]
    ap_g = abs(pulse.ap) / G
    print(f"Pulse: {pulse.label}, ap = {ap_g:.4g} g ({abs(pulse.ap):.4g} m/s2), "
          f"Tp = {pulse.tp:.4g} s ({origin})")
    if block is not None:
        b = out["block"]
        print(f"Block: {height:g} x {b['width_m']:g} m, p = {b['p_rad_s']:.4g} rad/s, tan(alpha) = "
              f"{b['tan_alpha']:.4g} (alpha = {b['alpha_deg']:.3g} deg), eta = {_eta_text(b['eta'])}, "
              f"pTp = {b['pTp']:.4g}")
    _print_restitution(eta, rules)
    labels = {"eq31": "Eq. 31", "eq20": f"Eq. 20 (lambda={lam:g})",
              "envelope": f"envelope ({pulse.shape})",
              "exact": f"exact ({criterion})",
              "level": f"exact (level {limit:g})" if limit is not None else ""}
    head = f"{'rule':<22}"
    if block is not None:
        head += f"{'min tan(alpha)':>15}  {'adequate':>8}"
    head += f"  {'required width (m)':>19} for H = {height:g} m"
    print(head)
    for name in names:
        r = rules[name]
        line = f"{labels[name]:<22}"
        if block is not None:
            line += f"{r['min_tan_alpha']:>15.4f}  {'yes' if r['adequate'] else 'NO':>8}"
        line += f"  {r['required_width_m']:>19.4f}"
        print(line)
    _print_friction(out["friction"], mu)
    if block is not None and out["exact_safe_islands"]:
        isl = ", ".join(f"{lo:.4f}-{hi:.4f}" for lo, hi in out["exact_safe_islands"])
        print(f"safe islands below the exact minimum (tan alpha): {isl}")
    print("Required widths solve B = H tan(alpha_min(p(B))), p depending on B; "
          "exact: smallest width surviving at it and every larger width"
          + (f"; level: max|theta|/alpha <= {limit:g} there." if limit is not None else "."))
    lo, hi = rocking.design.ENVELOPE_RANGE["ap/g"]
    ptp_lo, ptp_hi = rocking.design.ENVELOPE_RANGE["pTp"]
    ptps = [rules["envelope"]["p_at_width"] * pulse.tp]
    if block is not None:
        ptps.append(block.p * pulse.tp)
    if not (lo <= ap_g <= hi) or any(not (ptp_lo <= x <= ptp_hi) for x in ptps):
        print(f"note: the envelope rule was derived for {ptp_lo:g} <= pTp <= {ptp_hi:g} and "
              f"{lo:g} <= ap/g <= {hi:g}; outside that range rely on the exact answer.")
