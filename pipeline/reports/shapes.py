"""The pulse shapes in the reports of ``pipeline run``: which get their own group of columns, in
which order and under which name, how they are listed in the columns' meanings, and the rule of
the governing pulse that ``columns.md`` states.
"""
from __future__ import annotations

from pulses.shapes import SHAPES
from rocking.governing import FIT_TOLERANCE  # noqa: F401 (a shape "fits" a record: rocking.governing_pulse's rule, in the reports)

#: shapes that get their own group of columns, in this order: every shape of ``pulses.SHAPES``, the
#: realisable ones first (the registry's order kept within each group)
SHAPE_NAMES = tuple(sorted(SHAPES, key=lambda shape: not SHAPES[shape].realisable))


def shape_list() -> str:
    """The shapes of :data:`SHAPE_NAMES` in words, for the columns' descriptions:
    ``"`sine` (one-sine, Eq. 9), ... or `rect` (rectangular)"``."""
    words = []
    for name in SHAPE_NAMES:
        cls = SHAPES[name]
        words.append(f"`{name}` ({cls.label}{', ' + cls.equation if cls.equation else ''})")
    return ", ".join(words[:-1]) + " or " + words[-1] if len(words) > 1 else words[0]


GOVERNING_RULE = (
    "Among the shapes that fit the record (score at least "
    f"{FIT_TOLERANCE:g} x the best shape's score, listed in `shapes_fitting`), the governing pulse is "
    "the one whose Eq. 31 fixed-point width at the column's height is largest (the most demanding "
    "design; ties go to the better fit). `eq31_width_m` and `governing_eq31_tan_alpha` use it. "
    "Eq. 31 designs depend on the shape, so this rule is conservative among plausible shapes; the "
    "verification under the full record (`overturns`, `eq31_width_overturns`, `design_width_m`) "
    "does not depend on any shape and is the arbiter."
)


def _shape_key(shape: str) -> str:
    return shape.replace("-", "_")
