"""The vertical component in ``pipeline run``: ``--vertical auto|none`` and ``--triplet H1 H2 V``.

A task has a vertical when its record is a PEER record whose search report lists one
(:mod:`pipeline.batch.peer_inputs`), a ``--triplet``, or a pair found by ``--pairs auto`` with exactly one
vertical of the same station.  With ``--vertical auto`` (the default) the three components are read
on one time axis (:func:`pulses.check_triplet`: cut to the shortest, the vertical made upward by
its stated polarity), and for every column as it stands the response with the vertical is computed
beside the horizontal-only one (:data:`VERTICAL_COLUMNS`), by the compiled engine
(``rocking.simulate(..., vertical=)``, model ``fast-vertical``); the design width is the wider of
the horizontal motion's and the one with the vertical (:func:`design`; ``design_governed_by``),
the design rules (Eq. 31, envelope) stay those of the horizontal motion alone.  A
vertical whose polarity is not stated is not used, and the row's ``warnings`` says why.
"""
from __future__ import annotations

import dataclasses

from ..reports.columns import Columns, FLAG, TEXT

VERTICAL_COLUMNS = Columns(
    ("vertical_file", "-", "The vertical component used with this record (`--vertical auto`: a PEER "
                           "record's vertical, a `--triplet`, or the vertical `--pairs auto` found "
                           "for the pair); blank when none was used (then every vertical_* is blank).", TEXT),
    ("vertical_polarity", "-", "`UP` or `DWN`, as the vertical's file name and header state it (a "
                               "`DWN` record is multiplied by -1 to give the upward acceleration).", TEXT),
    ("vertical_pga_g", "g", "Peak absolute vertical acceleration (scaled as the record, `scale`)."),
    ("vertical_min_effective_gravity", "-", "Smallest 1 + av/g over the record (av upward): below 0 "
                                            "the ground falls away faster than gravity (free flight)."),
    ("vertical_overturns", "-", "The column as it stands overturns under the horizontal motion of this "
                                "row together with the vertical (docs/theory.md section 10); compare "
                                "`overturns` (horizontal alone). Blank for `--height`.", FLAG),
    ("vertical_max_theta_ratio", "-", "max|theta|/alpha of the column as it stands with the vertical; "
                                      "compare `max_theta_ratio`."),
    ("vertical_lifts_off", "-", "g + av < 0 before the response ended: the block leaves the ground, "
                                "which the rocking model does not describe; the response with the "
                                "vertical stops there and its verdict is not a verdict.", FLAG),
    ("vertical_t_lift_off_s", "s", "First time of g + av < 0 (blank when it never happens)."),
    ("vertical_design_width_m", "m", "Design width with the vertical (`rocking.required_width`, "
                                       "rule exact, `vertical=`): the smallest width surviving the "
                                       "horizontal motion of this row together with the vertical, at "
                                       "that width and every larger one the search and the check "
                                       "examined; compare "
                                       "`design_width_m` (the wider of this and the horizontal motion's alone, `design_governed_by`). Blank where the vertical "
                                       "reaches -g (the block would leave the ground)."),
    ("vertical_model", "-", "Model that answered with the vertical: `fast-vertical` (the compiled "
                            "engine, `rocking.simulate(..., vertical=)`; `rest` if the column never "
                            "uplifts).", TEXT),
)


def attach(tasks, verticals: dict) -> list:
    """``tasks`` with ``vertical`` set for those whose ``(path, path2)`` is in ``verticals``."""
    out = []
    for t in tasks:
        v = verticals.get((t.path, t.path2)) if t.path2 is not None else None
        out.append(dataclasses.replace(t, vertical=v) if v else t)
    return out


def auto_verticals(paths, read, say) -> dict:
    """``{(first, second): vertical}`` for ``--pairs auto``: a pair with exactly one vertical of the
    same station (as :func:`pulses.pair_files` groups them)."""
    import pulses
    from pulses.pairs import _group_key

    meta = {}
    for p in paths:
        try:
            meta[p] = pulses.read_record(p, **read.kwargs()).metadata
        except Exception:
            pass
    found = pulses.pair_files(paths, metadata=meta)
    by_key = {}
    for v in found.verticals:
        by_key.setdefault(_group_key(v, meta.get(v)), []).append(v)
    out = {}
    for a, b in found.pairs:
        vs = by_key.get(_group_key(a, meta.get(a)), [])
        if len(vs) == 1:
            out[(str(a), str(b))] = str(vs[0])
        elif len(vs) > 1:
            say(f"pipeline run: note: {len(vs)} verticals for {a} and {b}: none used (name one with --triplet)")
    return out


# -- in the worker -----------------------------------------------------------------------------------
def design(record, up, height, horizontal, cap_mass_ratio=0.0, limit=None, overturning=None,
           body="rectangular", restitution=None):
    """The design width of a column ``height`` (m) tall: ``horizontal`` (the horizontal motion's
    answer) where there is no vertical or it reaches -g, else the wider of it and the answer with
    the vertical (``rocking.required_width(..., vertical=)``, ``governed_by`` set); with a level,
    ``overturning``: True (each motion's overturning design where it can change the level's: the
    level with each motion is at least the overturning design with it), as ``horizontal`` was
    designed, or the overturning design this function gave; ``restitution`` as ``horizontal``'s."""
    import numpy as np

    import rocking
    from pulses import G

    if up is None or float(np.min(1.0 + up.acc / G)) <= 0.0:
        return horizontal
    return rocking.required_width(height, record, rule="exact", vertical=up, horizontal=horizontal,
                                  cap_mass_ratio=cap_mass_ratio, limit=limit, overturning=overturning,
                                  body=body, eta=restitution)


def fields(block, record, up, shown_file, designed=None, options=None) -> dict:
    """The :data:`VERTICAL_COLUMNS` of one row (blank without a vertical); ``designed``: the
    answer of :func:`design` (its ``vertical_width`` is the design width with the vertical);
    ``options``: the run's (its restitution; a band: the most demanding of its values)."""
    import numpy as np

    import rocking
    from pulses import G

    if up is None:
        return VERTICAL_COLUMNS.blank()
    polarity = up.metadata.get("polarity")
    values = {"vertical_file": shown_file, "vertical_polarity": polarity,
              "vertical_pga_g": float(np.max(np.abs(up.acc))) / G,
              "vertical_min_effective_gravity": float(np.min(1.0 + up.acc / G)),
              "vertical_overturns": None, "vertical_max_theta_ratio": None, "vertical_lifts_off": None,
              "vertical_t_lift_off_s": None, "vertical_model": None, "vertical_design_width_m": None}
    if designed is not None and designed.vertical_width is not None:
        values["vertical_design_width_m"] = float(designed.vertical_width)
    if block is not None:
        if options is None:
            res = rocking.simulate(block, record, vertical=up, history=False)
        else:
            from . import margin

            res = margin.simulate(block.height, block.width, record, options, vertical=up)[1]
        values.update(vertical_overturns=bool(res.overturned), vertical_max_theta_ratio=float(res.max_rotation_ratio),
                      vertical_lifts_off=bool(res.lifts_off),
                      vertical_t_lift_off_s=None if not res.lifts_off else float(res.t_lift_off),
                      vertical_model=str(res.model))
    return VERTICAL_COLUMNS.row(values)
