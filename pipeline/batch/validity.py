"""Where the rocking model holds, in ``pipeline run`` (docs/theory.md, "Friction"; docs/validity.md):
which model answered each row (the body, the restitution) and whether the responses it reports
stay inside it: the friction they need against ``--friction MU``, and lift-off with a vertical.

Without ``--friction`` the friction demand is reported, not judged.  With it, a response whose
demand exceeds ``MU`` slides (outside the model) and the row says when; a design width is valid
only where the column at that width does not slide, and the row gives the narrowest width from it
up that does not (``rocking.sliding_width``), or says that none does.
"""
from __future__ import annotations

from ..reports.columns import Columns, FLAG, TEXT

VALIDITY_COLUMNS = Columns(
    ("body", "-", "The body that rocks: `rectangular` (`--block HxW`), `cylinder (planar rocking)` "
                  "(`--block cyl:HxD`: a solid circular column of diameter D rocking in a plane, "
                  "no wobbling or rolling; docs/theory.md, \"Bodies\").", TEXT),
    ("impact_rule", "-", "The restitution the responses used, in words: `Eq. 5` (Housner's rule "
                         "for the body, the largest for which it rocks; the cylinder's own rule for "
                         "a cylinder), a factor of it (`0.97 x Eq. 5`) or the value given "
                         "(`--restitution`, whose text is in `restitution`).", TEXT),
    ("eta", "-", "The velocity ratio at impact eta of the column as it stands (the energy ratio "
                 "is r = eta^2); blank for `--height`."),
    ("design_eta", "-", "eta of the column at its design width (Eq. 5 follows the width)."),
    ("friction_demand", "-", "The largest friction coefficient the column as it stands needs to "
                             "rock without sliding under the full record: max |F_x|/F_z over the "
                             "response (rocking, resting and the impulses at impacts; with a "
                             "vertical, gravity is g + uv''; docs/theory.md, \"Friction\")."),
    ("friction_demand_t_s", "s", "When that largest demand arises."),
    ("friction_at_uplift", "-", "The demand at the column's first uplift from rest (Shenton's "
                                "boundary between rocking and slide-rock for the rectangular "
                                "block); blank where it never uplifts."),
    ("impulse_ratio", "-", "Horizontal over vertical impulse of each impact, (1 - eta)/((1 + eta) "
                           "tan(alpha)), of the column as it stands; blank where it has no impact."),
    ("min_normal_force", "-", "Smallest vertical force on the base of the column as it stands over "
                              "its weight m g (at or below 0 the column leaves the ground)."),
    ("eq31_width_friction_demand", "-", "The largest friction demand of the Eq. 31 design under "
                                        "the full record."),
    ("design_friction_demand", "-", "The largest friction demand of the column at its design "
                                    "width under the full record (with the vertical, where the "
                                    "row has one)."),
    ("design_min_normal_force", "-", "Smallest base normal force over the weight at the design "
                                     "width."),
    ("friction_mu", "-", "`--friction MU`: the friction coefficient of the base the demands are "
                         "judged against; blank: not judged."),
    ("slides", "-", "With `--friction`: the column as it stands needs more than MU at some "
                    "instant: it slides, which the rocking model does not describe (its verdict "
                    "is then not a verdict).", FLAG),
    ("t_slide_s", "s", "When the column as it stands first needs more than MU."),
    ("eq31_width_slides", "-", "With `--friction`: the Eq. 31 design slides.", FLAG),
    ("design_slides", "-", "With `--friction`: the column at its design width slides: the design "
                           "width is not valid (see `friction_width_m`).", FLAG),
    ("design_t_slide_s", "s", "When the column at its design width first needs more than MU."),
    ("friction_width_m", "m", "With `--friction` where the design width slides: the narrowest "
                              "width from the design width up at which the column does not slide "
                              "(and so the valid design width); blank where none does "
                              "(`validity` says why) or where the design width holds."),
    ("validity", "-", "Which model answered and its checks, in words: the body, the restitution, "
                      "friction (demand, and with `--friction` passed or failed and when), "
                      "lift-off with the vertical (passed, failed and when, or no vertical).", TEXT),
)


def _need(block, record, up):
    """The friction demand of ``block`` under ``record`` (with the vertical ``up``), and the
    response (its ``lifts_off`` where a vertical was used)."""
    import rocking

    res = rocking.simulate(block, record, vertical=up)
    return rocking.friction_demand(res, record, vertical=up), res


def _restitution_words(restitution, body) -> str:
    """The restitution a row's runs used, in words: Eq. 5 (a factor of it), or the body's rule."""
    rule = "Eq. 5" if body.is_rectangular else f"Housner's rule for the {body.kind}"
    if restitution is None or restitution.is_housner:
        return rule
    return restitution.describe().replace("Eq. 5", rule)


def fields(col, block, record, up, design, gamma, mu, eq31_block, cache, restitution=None):
    """The :data:`VALIDITY_COLUMNS` of one row, and the curves of its friction figure
    ``[(label, FrictionDemand)]``; ``design``: the row's :class:`rocking.RequiredWidth`,
    ``cache``: the record's (a height's design is judged once); ``restitution``: the run's
    ``--restitution`` (None: the body's own impact rule)."""
    from rocking.bodies import Body

    body = Body.parse(col.body)
    curves, values = [], dict.fromkeys(VALIDITY_COLUMNS.names)
    values.update(body=body.describe(), impact_rule=_restitution_words(restitution, body),
                  friction_mu=mu)
    lift = []
    if block is not None:
        need, res = _need(block, record, up)
        values.update(eta=block.eta, friction_demand=need.max_demand,
                      friction_demand_t_s=need.t_max, friction_at_uplift=need.uplift_demand,
                      impulse_ratio=need.impulse_ratio if need.impacts.size else None,
                      min_normal_force=need.min_normal)
        curves.append((f"as it stands, {col.width:.3g} m", need))
        lift.append(("as it stands", res))
        if mu is not None:
            check = need.judge(mu)
            values.update(slides=check.slides, t_slide_s=check.t_slide)
    key = ("design", col.height, col.body)
    if key not in cache:
        cache[key] = _design(col, design, record, up, gamma, mu, eq31_block)
    d = cache[key]
    values.update(d["values"])
    curves.append((f"design width, {float(design.width):.3g} m", d["need"]))
    lift.append(("design width", d["res"]))
    values["validity"] = _words(values, body, lift, up, d.get("reason"))
    return VALIDITY_COLUMNS.row(values), curves


def _design(col, design, record, up, gamma, mu, eq31_block) -> dict:
    """The design width's (and the Eq. 31 design's) friction demand and verdicts."""
    from rocking.sliding import sliding_width

    width = float(design.width)
    block = design.block  # with the restitution the design was made with (a band: the value that governed)
    need, res = _need(block, record, up)
    need31, _ = _need(eq31_block, record, up)
    values = {"design_eta": block.eta, "design_friction_demand": need.max_demand,
              "design_min_normal_force": need.min_normal,
              "eq31_width_friction_demand": need31.max_demand}
    out = {"need": need, "res": res, "values": values}
    if mu is not None:
        check = need.judge(mu)
        values.update(design_slides=check.slides, design_t_slide_s=check.t_slide,
                      eq31_width_slides=need31.judge(mu).slides)
        if check.slides:
            eta = design.restitution_governing if design.restitution_values else design.eta
            found = sliding_width(col.height, record, width, mu, body=col.body,
                                  cap_mass_ratio=gamma, eta=eta, vertical=up)
            values["friction_width_m"] = found.width
            out["reason"] = found.reason
    return out


def _words(values, body, lift, up, reason) -> str:
    """The ``validity`` cell."""
    parts = [f"body: {body.describe()}", f"restitution: {values['impact_rule']}"]
    mu = values["friction_mu"]
    demand = values["design_friction_demand"]
    if values["friction_demand"] is not None:
        demand = max(demand, values["friction_demand"])
    if mu is None:
        parts.append(f"friction: needs up to {demand:.3g} (not judged: no --friction)")
    else:
        failed = [(who, values[k]) for who, k in (("as it stands", "t_slide_s"),
                                                   ("at the design width", "design_t_slide_s"))
                  if values[k.replace("t_slide_s", "slides")]]
        if not failed:
            parts.append(f"friction: passed (needs up to {demand:.3g} <= mu {mu:g})")
        else:
            said = "; ".join(f"slides {who} at {t:.3g} s" for who, t in failed)
            parts.append(f"friction: FAILED (mu {mu:g}): {said}, outside the model")
            if values["design_slides"]:
                w = values["friction_width_m"]
                parts.append(f"narrowest width that does not slide {w:.4g} m" if w is not None
                             else (reason or "no width from the design width up holds"))
    if up is None:
        parts.append("lift-off: no vertical")
    else:
        off = [(who, r.t_lift_off) for who, r in lift if getattr(r, "lifts_off", False)]
        parts.append("lift-off with the vertical: FAILED: " + "; ".join(
            f"{who} leaves the ground at {t:.3g} s" for who, t in off) if off else
            "lift-off with the vertical: passed")
    return "; ".join(parts)
