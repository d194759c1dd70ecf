"""The design rules in a row of ``pipeline run``: Eq. 31 for the governing pulse, the envelope rule,
and the exact minimum slenderness, each applied to the column as it stands and designed for its
height, and the Eq. 31 and envelope designs verified under the full record.

Every number comes from :mod:`rocking` by its public names: the governing pulse and its Eq. 31
width (:func:`rocking.governing_pulse`, the widest fixed-point width over the shapes that fit),
the envelope width (:func:`rocking.required_width`, rule ``envelope``, the widest over the shapes
that fit), the closed forms (:func:`rocking.eq31`, :func:`rocking.envelope_rule`) and the exact
minimum slenderness (:func:`rocking.min_slenderness_batch`).  Each design is verified by a run
under the full record (:func:`pipeline.batch.margin.simulate`: a restitution band's most
demanding value).
"""
from __future__ import annotations

import math

from . import margin, memo
from .fitted import to_g
from ..reports.columns import Columns, FLAG, TEXT
from ..reports.shapes import _shape_key as shape_key, SHAPE_NAMES


AS_STANDS_DESIGN_COLUMNS = Columns(
    ("width_m", "m", "Full width B of the column as it stands (blank for `--height`)."),
    ("tan_alpha", "-", "Slenderness tan(alpha) = B/H of the column as it stands."),
    ("alpha_deg", "deg", "Slenderness angle alpha = atan(B/H)."),
    ("p_rad_s", "rad/s", "Frequency parameter p = sqrt(3 g / (4 R)), R = sqrt((H/2)^2 + (B/2)^2)."),
    ("p_tp", "-", "p x Tp of the best-fitting pulse (dimensionless)."),
    ("eq31_tan_alpha", "-", "Eq. 31 minimum tan(alpha) = (ap/g) pTp / (1 + pTp) for the best-fitting "
                            "pulse at the column's p."),
    ("envelope_tan_alpha", "-", "Minimum tan(alpha) by the envelope rule (`rocking.envelope_rule`, "
                                "conservative for every realisable shape) for the best-fitting pulse."),
    ("exact_tan_alpha", "-", "Exact minimum tan(alpha) for the best-fitting pulse at the column's p: the "
                             "smallest slenderness that survives the pulse at that and every larger "
                             "slenderness (time-history analysis, `rocking.min_slenderness`)."),
)


def as_stands_design(col, block, best, exact) -> dict:
    """The :data:`AS_STANDS_DESIGN_COLUMNS` of a column as it stands (blank for a height only):
    its slenderness and what each rule asks of it for the best-fitting pulse ``best``."""
    import rocking

    if block is None:
        return AS_STANDS_DESIGN_COLUMNS.blank()
    p = block.p
    return AS_STANDS_DESIGN_COLUMNS.row({
        "width_m": col.width, "tan_alpha": block.tan_alpha,
        "alpha_deg": math.degrees(block.alpha), "p_rad_s": p, "p_tp": p * best.tp,
        "eq31_tan_alpha": float(rocking.eq31(best.ap, best.tp, p)),
        "envelope_tan_alpha": float(rocking.envelope_rule(best.ap, best.tp, p, shape=best.shape)),
        "exact_tan_alpha": exact[(best.shape, block)],
    })


GOVERNING_COLUMNS = Columns(
    ("governing_shape", "-", "Shape of the governing pulse (the rule is stated in `columns.md`).", TEXT),
    ("governing_ap_g", "g", "Amplitude of the governing pulse, signed."),
    ("governing_tp_s", "s", "Period of the governing pulse."),
    ("governing_eq31_tan_alpha", "-", "Eq. 31 minimum tan(alpha) for the governing pulse at the column's p."),
)


def governing_fields(gov, block) -> dict:
    """The :data:`GOVERNING_COLUMNS` of the governing pulse ``gov`` (at the column's p where it
    stands, ``block``)."""
    import rocking

    return GOVERNING_COLUMNS.row({
        "governing_shape": gov.shape, "governing_ap_g": to_g(gov.ap), "governing_tp_s": gov.tp,
        "governing_eq31_tan_alpha": None if block is None else float(rocking.eq31(gov.ap, gov.tp, block.p)),
    })


def shape_columns(shape: str) -> Columns:
    """The columns of one pulse shape (``sine``, ...), named ``<shape>_*`` (``-`` as ``_``)."""
    k = shape_key(shape)
    return Columns(
        (f"{k}_fits", "-", f"Whether the `{shape}` shape fits the record (see `shapes_fitting`); "
                           "blank when the shape was not tried (`--shapes`).", FLAG),
        (f"{k}_ap_g", "g", f"Amplitude of the best `{shape}` pulse, signed."),
        (f"{k}_tp_s", "s", f"Period of the best `{shape}` pulse."),
        (f"{k}_score", "-", f"Fit quality (score) of the best `{shape}` pulse."),
        (f"{k}_eq31_tan_alpha", "-", f"Eq. 31 minimum tan(alpha) for the `{shape}` pulse at the column's p."),
        (f"{k}_exact_tan_alpha", "-", f"Exact minimum tan(alpha) for the `{shape}` pulse at the column's "
                                      "p (only for shapes that fit)."),
        (f"{k}_eq31_width_m", "m", f"Width a column of this height needs by Eq. 31 for the `{shape}` "
                                   "pulse (fixed point in B; only for shapes that fit)."),
    )


SHAPE_COLUMNS = {shape: shape_columns(shape) for shape in SHAPE_NAMES}


def shape_fields(shape, candidate, fitting, block, exact, widths) -> dict:
    """The ``<shape>_*`` group: blank where the shape was not tried, does not fit, or (for the
    as-it-stands values) the column is only a height."""
    import rocking

    columns = SHAPE_COLUMNS[shape]
    if candidate is None:
        return columns.blank()
    c, k = candidate, shape_key(shape)
    eq31_width = None
    for w, f in widths:  # the fitting candidates of this shape (one per shape from the fitter)
        if f.shape == shape:
            eq31_width = w
    return columns.row({
        f"{k}_fits": any(c is f for f in fitting), f"{k}_ap_g": to_g(c.ap), f"{k}_tp_s": c.tp,
        f"{k}_score": c.score,
        f"{k}_eq31_tan_alpha": None if block is None else float(rocking.eq31(c.ap, c.tp, block.p)),
        f"{k}_exact_tan_alpha": None if block is None else exact.get((shape, block)),
        f"{k}_eq31_width_m": eq31_width,
    })


EQ31_DESIGN_COLUMNS = Columns(
    ("eq31_width_m", "m", "Width a column of this height needs by Eq. 31 for the governing pulse "
                          "(fixed point in B, since p depends on B; `rocking.required_width`, rule eq31)."),
    ("eq31_width_tan_alpha", "-", "tan(alpha) of the Eq. 31 design, eq31_width_m / height_m."),
    ("eq31_width_overturns", "-", "The Eq. 31 design overturns under the full record.", FLAG),
    ("eq31_width_max_theta_ratio", "-", "max|theta|/alpha of the Eq. 31 design under the full record."),
    ("eq31_width_model", "-", "Solver model that answered for the Eq. 31 design.", TEXT),
)


def eq31_fields(height, w31, res31) -> dict:
    """The :data:`EQ31_DESIGN_COLUMNS` of the Eq. 31 width ``w31`` and its response ``res31``."""
    return EQ31_DESIGN_COLUMNS.row({
        "eq31_width_m": w31, "eq31_width_tan_alpha": w31 / height,
        "eq31_width_overturns": bool(res31.overturned),
        "eq31_width_max_theta_ratio": float(res31.max_rotation_ratio),
        "eq31_width_model": str(res31.model),
    })


def design_fields(col, block, fit, fitting, by_shape, exact, governed) -> dict:
    """The rules' groups of a row: the column as it stands (:data:`AS_STANDS_DESIGN_COLUMNS`), the
    governing pulse's (``governed``, :func:`governing`) and each shape's (``by_shape``: the best
    candidate of each shape fitted)."""
    fields = as_stands_design(col, block, fit.best, exact)
    fields.update(governing_fields(governed.candidate, block))
    for shape in SHAPE_NAMES:
        fields.update(shape_fields(shape, by_shape.get(shape), fitting, block, exact, governed.widths))
    return fields


def governing(fit, col, cap_mass_ratio, cache, key):
    """The governing pulse of ``fit`` for a column of ``col``'s height and body, and its Eq. 31 width
    (:func:`rocking.governing_pulse`: the widest over the shapes that fit), kept in ``cache`` under
    ``key`` (a height's)."""
    import rocking

    if key not in cache:
        cache[key] = rocking.governing_pulse(fit, col.height, cap_mass_ratio=cap_mass_ratio, body=col.body)
    return cache[key]


def eq31_design(height, width, record, options, draw, body="rectangular"):
    """``(block, result)`` of the Eq. 31 design ``width`` under the full record (a band: its most
    demanding value; ``draw``: with its history, for the figure)."""
    return margin.simulate(height, width, record, options, draw, body=body)


ENVELOPE_COLUMNS = Columns(
    ("envelope_width_m", "m", "Width a column of this height needs by the envelope rule "
                              "(`rocking.required_width`, rule envelope, with each fitting shape's "
                              "factor; fixed point in B): the widest over the shapes that fit."),
    ("envelope_width_overturns", "-", "The envelope design overturns under the full record.", FLAG),
)


def envelope_fields(height, record, fitting, options, cache, body="rectangular") -> dict:
    """The :data:`ENVELOPE_COLUMNS` of a column ``height`` tall (of ``body``'s shape): the envelope
    rule's width (:func:`rocking.required_width`, rule ``envelope``, with each fitting shape's
    factor: the widest) and whether it overturns under the full record; kept in ``cache`` (the
    record's) per height and body."""
    import rocking

    key = ("envelope", height) if body == "rectangular" else ("envelope", height, body)
    if key not in cache:
        g = options.cap_mass_ratio
        widths = [float(rocking.required_width(height, c.pulse, rule="envelope", shape=c.shape,
                                               cap_mass_ratio=g, body=body).width) for c in fitting]
        w = max(widths)
        res = margin.simulate(height, w, record, options, body=body)[1]
        cache[key] = ENVELOPE_COLUMNS.row({"envelope_width_m": w,
                                           "envelope_width_overturns": bool(res.overturned)})
    return dict(cache[key])


#: the parts a bracket of the exact minimum slenderness is cut into at each step (:func:`exact_by_shape`)
EXACT_KSECTION = 4


def exact_by_body(fitting, blocks, cap_mass_ratio=0.0, restitution=None) -> dict:
    """:func:`exact_by_shape` for the blocks of each body, by its own impact rule."""
    exact = {}
    for kind in dict.fromkeys(["rectangular"] + [b.body.kind for b in blocks]):
        exact.update(exact_by_shape(fitting, [b for b in blocks if b.body.kind == kind],
                                     cap_mass_ratio, kind, restitution))
    return exact


def exact_by_shape(fitting, blocks, cap_mass_ratio=0.0, body="rectangular", restitution=None) -> dict:
    """Exact minimum tan(alpha) of every fitting pulse for every block: ``{(shape, block): tan}``.

    One ``rocking.min_slenderness_batch`` call per shape covers all the blocks (the similarity law:
    only pTp and ap/g matter), which gives the same numbers as ``rocking.min_slenderness`` (to its
    1e-9 refinement): the same scan, but only the deciding transition refined, cut in four at each
    step (three runs a solver call: a pulse run is short, and a call's own cost, not the runs,
    decides; measured, 10 % less CPU than bisection on the pulses fitted to a real pair's
    directions, 40 % at pTp 2-4, answers within 1e-9 relative of it; the safe islands below it
    are not reported here).  ``restitution``: as the run's (a band: the answer covering it).
    """
    import rocking
    from pulses import G

    out = {}
    if not blocks:
        return out
    for c in fitting:
        p_tp = [b.p * c.tp for b in blocks]
        key = (c.shape, tuple(p_tp), abs(c.ap) / G, cap_mass_ratio)  # its every input
        if body != "rectangular":
            key += (body,)
        if restitution is not None:
            key += (str(restitution),)
        res = memo.remembered("slenderness", key, lambda: rocking.min_slenderness_batch(
            c.shape, p_tp, [abs(c.ap) / G] * len(blocks), refine="top", ksection=EXACT_KSECTION,
            cap_mass_ratio=cap_mass_ratio, body=body, eta=restitution))
        for b, r in zip(blocks, res):
            out[(c.shape, b)] = float(r.tan_alpha)
    return out
