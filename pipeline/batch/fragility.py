"""``--fragility`` in ``pipeline run``, record by record: the critical scale of each column as it
stands under the row's record (:func:`rocking.critical_scale`: the smallest factor on the record
that overturns it, or with ``--limit R`` given makes max|theta|/alpha exceed R; a scan respecting
the safe islands above it).  The suite's lognormal fragility is fitted to these after the run
(:func:`pipeline.reports.suite.fragility_tables`).
"""
from __future__ import annotations

import math

from . import margin
from ..reports.columns import Columns, TEXT

FRAGILITY_COLUMNS = Columns(
    ("critical_scale", "-", "`--fragility`: smallest factor k (on this row's record, already scaled "
                            "by `scale`) for which k times the record overturns the column as it "
                            "stands (with `--limit` R: makes max|theta|/alpha exceed R; `rocking.critical_scale`: "
                            "a scan that respects safe islands, refined to 1e-6); blank when no factor up to `fragility_up_to` does, or "
                            "without `--fragility`."),
    ("critical_pga_g", "g", "PGA of the record at its critical scale."),
    ("critical_islands", "-", "Factor ranges above `critical_scale` where the column survives again "
                              "(`a-b`, `;`-separated; the last may end at `fragility_up_to`).", TEXT),
    ("uplift_scale", "-", "Below this factor the column never uplifts (g tan(alpha) / PGA)."),
    ("fragility_up_to", "-", "Largest factor examined."),
)


def fields(height, block, record, options) -> dict:
    """The :data:`FRAGILITY_COLUMNS` of one row: blank without ``--fragility`` or for a column given
    by its height only (``block`` None); with a restitution band, the weakest of its values (the
    smallest critical scale)."""
    import rocking
    from pulses import G

    if not options.fragility or block is None:
        return FRAGILITY_COLUMNS.blank()
    scales = [rocking.critical_scale(b, record, up_to=options.up_to, limit=options.fragility_limit)
              for b in margin.blocks(height, block.width, options)]
    cs = min(scales, key=lambda s: math.inf if s.scale is None else s.scale)
    return FRAGILITY_COLUMNS.row({
        "critical_scale": cs.scale,
        "critical_pga_g": None if cs.critical_pga is None else cs.critical_pga / G,
        "critical_islands": "; ".join(f"{a:.6g}-{b:.6g}" for a, b in cs.islands),
        "uplift_scale": float(cs.uplift_scale), "fragility_up_to": float(cs.up_to),
    })
