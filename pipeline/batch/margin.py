"""What a design of ``pipeline run`` keeps in reserve, and the restitution it was made with: the
columns of the margin (the verge beside the design width, max|theta|/alpha at both) and of the
restitution (``--restitution``: a factor of Eq. 5, an ``eta`` or an ``r``, one value or a band),
and the runs of a column under every value of a band.

Both groups are written only where they apply: the margin's under a performance level (the
default, ``--limit 0.5``), the restitution's with ``--restitution``; with ``--limit none`` and no
``--restitution`` the reports have exactly the columns they had before either existed.
"""
from __future__ import annotations

from ..reports.columns import Columns, TEXT, WHOLE

#: the performance level a run designs for unless told otherwise (``--limit``): the paper's
#: dependable design, the peaks at or below alpha/2 (its section 5.3)
DEFAULT_LIMIT = 0.5

MARGIN_COLUMNS = Columns(
    ("design_max_theta_ratio", "-", "max|theta|/alpha of a column of the design width under the full "
                                    "record (a run of its own, `rocking.simulate`; with a restitution "
                                    "band the largest over its values; with a vertical component, the "
                                    "larger of the runs without and with it): at most `design_limit` "
                                    "where the level governs."),
    ("overturning_max_theta_ratio", "-", "max|theta|/alpha of a column of `overturning_width_m`, the "
                                         "verge (no margin), under the full record (as "
                                         "`design_max_theta_ratio`): 1 or more where the column passes "
                                         "its slenderness angle there and comes back."),
)

RESTITUTION_COLUMNS = Columns(
    ("restitution", "-", "`--restitution` as given: a factor of Eq. 5 (`0.97`: 0.97 times "
                         "Housner's eta at each width), `eta=V` (the velocity ratio at impact, the "
                         "same at every width) or `r=V` (the energy ratio, eta squared); `LOW:HIGH` "
                         "a band, whose design covers it.", TEXT),
    ("restitution_values_run", "-", "Single values of the restitution run for this row: 1, or for a "
                                    "band its values evenly spaced, ends included (`rocking.band.BAND_VALUES`).", WHOLE),
    ("restitution_governing", "-", "The value (as `restitution` states it) whose design width governs: "
                                   "the widest of the band's (the lowest restitution of equal widths).", TEXT),
    ("restitution_design_widths_m", "m", "Each value's design width, `value=width` and `;`-separated "
                                         "(for a band, in the order run); the design width is the widest.", TEXT),
    ("design_r", "-", "The energy ratio r = eta^2 at impact at the design width, for the value that "
                      "governs (`design_eta` squared)."),
)


def extra_columns(options) -> list:
    """The groups of columns this run's options add to every row, after the design width's (none
    with ``--limit none`` and no ``--restitution``)."""
    out = []
    if options.limit is not None:
        out.append(MARGIN_COLUMNS)
    if options.restitution is not None:
        out.append(RESTITUTION_COLUMNS)
    return out


def singles(options) -> list:
    """The single restitutions every block of the run is made with (``[None]``: Eq. 5)."""
    from rocking import band

    return band.singles(band.plain(options.restitution))


def worst(results):
    """The index of the most demanding of ``results`` (rocking results of one column under the
    values of a band): the first to overturn, else the largest max|theta|/alpha (the first of
    equals)."""
    def key(i):
        r = results[i]
        t = float(r.t_overturn) if r.overturned and r.t_overturn is not None else float("inf")
        return (not r.overturned, t, -float(r.max_rotation_ratio), i)

    return min(range(len(results)), key=key)


def blocks(height, width, options, body="rectangular") -> list:
    """The column ``height`` x ``width`` (m) of the run (its frame's cap mass ratio; its ``body``'s
    shape), one :class:`rocking.Block` per single restitution of :func:`singles`."""
    import rocking

    return [rocking.Block.from_dimensions(height, width, eta, cap_mass_ratio=options.cap_mass_ratio,
                                          body=body)
            for eta in singles(options)]


def simulate(height, width, record, options, history=False, vertical=None, body="rectangular"):
    """``(block, result)`` of a column ``height`` x ``width`` (m) under ``record``: with a band, the
    most demanding of its values (:func:`worst`); ``vertical``: the vertical record too."""
    import rocking

    blocks_ = blocks(height, width, options, body)
    kw = {} if vertical is None else {"vertical": vertical}
    results = [rocking.simulate(b, record, history=history, **kw) for b in blocks_]
    k = worst(results)
    return blocks_[k], results[k]


def ratio_at(height, width, record, up, options, body="rectangular"):
    """max|theta|/alpha of a column ``width`` wide under ``record`` (the largest over a band's
    values, and with a vertical ``up`` over the runs without and with it); None where ``width``
    is blank or 0."""
    if width is None or not width > 0:
        return None
    ratios = [float(simulate(height, width, record, options, body=body)[1].max_rotation_ratio)]
    if up is not None:
        ratios.append(float(simulate(height, width, record, options, vertical=up,
                                     body=body)[1].max_rotation_ratio))
    return max(ratios)


def margin_fields(height, designed, record, up, options, at_design=None) -> dict:
    """The :data:`MARGIN_COLUMNS` of a row whose design width is ``designed`` (a
    :class:`rocking.RequiredWidth`); ``at_design``: the ratio at the design width where already
    run (the figure's run)."""
    width = float(designed.width)
    verge = designed.overturning_width
    return MARGIN_COLUMNS.row({
        "design_max_theta_ratio": at_design if at_design is not None and up is None
        else ratio_at(height, width, record, up, options, designed.body),
        "overturning_max_theta_ratio": ratio_at(height, None if verge is None else float(verge),
                                                record, up, options, designed.body),
    })


def restitution_fields(height, designed, options) -> dict:
    """The :data:`RESTITUTION_COLUMNS` of a row whose design width is ``designed``."""
    import rocking
    from rocking import band

    given = options.restitution
    values = designed.restitution_values or (given,)
    widths = designed.restitution_widths or (float(designed.width),)
    gov = designed.restitution_governing if designed.restitution_values else given
    width = float(designed.width)
    eta = None
    if width > 0:
        eta = rocking.Block.from_dimensions(height, width, band.plain(gov),
                                            cap_mass_ratio=options.cap_mass_ratio, body=designed.body).eta
    return RESTITUTION_COLUMNS.row({
        "restitution": str(given), "restitution_values_run": len(values),
        "restitution_governing": str(gov),
        "restitution_design_widths_m": "; ".join(f"{v}={w:.6g}" for v, w in zip(values, widths)),
        "design_r": None if eta is None else eta * eta,
    })


def design_curves(H, designed, record, up, opts, margin_cache, draw, key=None) -> list:
    """The figure's curves of the design width (and under a level, of the verge beside it), and
    under a level the row's :data:`MARGIN_COLUMNS` into ``margin_cache`` under ``key`` (default
    the height): max|theta|/alpha at both widths, each in a run of its own."""
    key = H if key is None else key
    body = designed.body
    wv = float(designed.width)
    curves = []
    ratio = None
    if wv > 0 and (draw or up is None):
        block_v, res_v = simulate(H, wv, record, opts, draw, body=body)
        curves.append((f"design width, {wv:.3g} m", block_v, res_v))
        ratio = float(res_v.max_rotation_ratio)
    if opts.limit is None:
        return curves if draw else []
    if key not in margin_cache:
        margin_cache[key] = margin_fields(H, designed, record, up, opts, ratio)
    verge = designed.overturning_width
    if draw and verge is not None and verge > 0:
        curves.append((f"verge, {verge:.3g} m",) + simulate(H, float(verge), record, opts, True, body=body))
    return curves if draw else []
