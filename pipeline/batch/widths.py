"""The design width in a row of ``pipeline run``: the smallest width that survives the full record
(:func:`rocking.required_width`, rule ``exact``: its search, and the check above it for failing
slivers, docs/slivers.md), with the vertical where there is one (:func:`pipeline.batch.vertical.design`),
under a performance level with the overturning design beside it; and the check's columns.
"""
from __future__ import annotations

from . import vertical
from .stages import stage
from ..reports.answer import check_bin_words, check_reach_words
from ..reports.columns import Columns, FLAG, TEXT, WHOLE


DESIGN_WIDTH_COLUMNS = Columns(
    ("design_width_m", "m", "Design width: the smallest width for which a column of this height "
                              "survives the full record (max|theta|/alpha <= `design_limit` with "
                              "`--limit`), at that width and at every larger one the search and the "
                              "check above it examined: at least every width they found to fail, "
                              "refined just above the widest to a number of 6 significant digits "
                              "that was run and survived, so the value printed is the width tested "
                              "(`rocking.required_width`, rule exact, `.width`); with a vertical component, the wider of the horizontal "
                              "motion's and the one with the vertical (`design_governed_by`). "
                              "Independent of the pulse fit."),
    ("design_tan_alpha", "-", "tan(alpha) of the design width, design_width_m / height_m."),
    ("design_adequate", "-", "The column as it stands is at least as wide as the design width "
                               "(blank for `--height`). A column that survives (`overturns` False) "
                               "but is not design-adequate stands on a safe island: some slightly "
                               "wider column of the same height overturns under the same record.", FLAG),
    ("search_width_m", "m", "Diagnostic: the search's first transition (the smallest width above "
                            "which every width the search examined survives; `search_width`), "
                            "before the check above it; the design width is at least this."),
    ("design_governed_by", "-", "Which motion sets the design width: `horizontal` (the horizontal "
                                "motion alone) or `with vertical` (the horizontal motion with the "
                                "record's vertical); blank without a vertical.", TEXT),
    ("design_limit", "-", "The performance level of the design (`--limit` R: max|theta|/alpha <= R); "
                          "blank: overturning, the paper's question."),
    ("overturning_width_m", "m", "With `--limit` R: the overturning design of the same column and "
                                 "record, computed where it can change the level's (the same search, "
                                 "its check only above the level's own design width; with a vertical, "
                                 "the wider of the two motions'). Where it is wider than the level's "
                                 "own width it is the overturning design width in full and "
                                 "`design_width_m` is raised to at least it (a width that overturns "
                                 "fails every level); where not, the level governs and this is what "
                                 "was established: the overturning design width lies between it and "
                                 "`design_width_m` (docs/design.md, \"Performance levels\"). Blank "
                                 "without `--limit`."),
)


def design_width_fields(col, ver) -> dict:
    """The :data:`DESIGN_WIDTH_COLUMNS` of a column and its design (``ver``, :func:`design_width`)."""
    return DESIGN_WIDTH_COLUMNS.row({
        "design_width_m": float(ver.width), "design_tan_alpha": float(ver.width) / col.height,
        "design_adequate": None if col.width is None else col.width >= float(ver.width),
        "search_width_m": None if ver.search_width is None else float(ver.search_width),
        "design_governed_by": ver.governed_by, "design_limit": ver.limit,
        "overturning_width_m": ver.overturning_width,
    })


CHECK_COLUMNS = Columns(
    ("failing_share", "-", "What the check above the search width found (docs/slivers.md): near the "
                           "search's first transition (`search_width_m`) the response is chaotic and "
                           "failing slivers thinner than the search's 0.05 % grid may lie above it. "
                           "After the search, a check runs `check_runs` jittered widths (seeded from "
                           "the record, off the search's grid) from the search width up to "
                           f"{check_reach_words()} or the no-uplift width (height x PGA / g), whichever "
                           f"is smaller, in bins of {check_bin_words()} of it, more where the response varies from one "
                           "width to the next (in a direction of a pair, only above a lower bound of the "
                           "pair's design width, docs/site.md): this is the share of them that fail (0: none did; "
                           "blank: no check, as in a direction of a pair whose check could not reach "
                           "the pair's design width). The design width `design_width_m` lies just above the "
                           "widest failing width found."),
    ("widest_failing_width_m", "m", "The widest width the search or the check found to fail above "
                                    "the search width (a failing sliver; blank where none was found, "
                                    "which does not prove there is none); the design width lies just "
                                    "above it."),
    ("check_runs", "-", "Number of widths (solver runs) of the check above the search width: 300 "
                        "and more where the response varies (0: not checked; in a direction of a pair, "
                        "those above a lower bound of the pair's design width, docs/site.md).", WHOLE),
)


def check_fields(ver) -> dict:
    """The :data:`CHECK_COLUMNS` of a design (``ver``, :func:`design_width`)."""
    return CHECK_COLUMNS.row({
        "failing_share": ver.failing_share, "widest_failing_width_m": ver.widest_failing_width,
        "check_runs": ver.check_runs,
    })


def height_key(col):
    """What a height's designs are kept under: the height (a rectangular column's, as before), or
    with the body's kind (``(7.5, "cylinder")``)."""
    return col.height if col.body == "rectangular" else (col.height, col.body)


def design_width(record, up, height, cap_mass_ratio, limit, settings, body="rectangular", restitution=None):
    """The design width of a column ``height`` (m) tall under ``record`` (with its vertical ``up``
    where there is one, :func:`pipeline.batch.vertical.design`).  With a level ``limit``: the
    level's design first, then the overturning design where it can change it (a width that
    overturns fails every level; ``rocking.required_width(..., overturning=True)``: its search, its
    check above the level's width), the level with each motion at least that motion's
    overturning width; ``.overturning_width`` is that design's width.  ``restitution``: a
    :class:`rocking.restitution.Restitution` (a band: the design covering it, each value designed
    so) or None (Eq. 5)."""
    import rocking

    kw = dict(rule="exact", cap_mass_ratio=cap_mass_ratio, settings=settings, body=body, eta=restitution)
    over = None if limit is None else True
    alone = stage("verify", rocking.required_width, height, record, limit=limit, overturning=over, **kw)
    return stage("verify", vertical.design, record, up, height, alone, cap_mass_ratio, limit, over,
                  body, restitution)


def check_settings(task) -> dict:
    """The search's settings for each column: the check above the design width where
    pipeline.batch.passes asks for it (docs/slivers.md)."""
    from rocking.search import DEFAULT_SETTINGS

    base = DEFAULT_SETTINGS if task.check else DEFAULT_SETTINGS.replace(check_runs=0)
    above = dict(zip(task.columns, task.check_above))
    return {col: base.replace(check_above=above.get(col, 0.0)) for col in task.columns}
