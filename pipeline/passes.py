"""Which directions of a pair get the check above the verified width and the figures.

A pair designed in many directions is governed by its widest direction: the pair's design width is
the widest of its directions' verified widths and of the failing widths their checks find
(docs/slivers.md).  The check of a direction (1500 runs) changes that answer only where it can
find a failing width above the pair's design width, and it looks only up to ``check_top = min(
check_span w, H PGA / g)`` (``rocking.search.SearchSettings``; the no-uplift width under the
direction's component).  So ``pipeline run`` computes a pair in passes:

1. every direction: the search only (no check), no figure (unless ``--plots all``);
2. the governing direction (widest verified width, the first such in angle order, as in
   ``pairs.csv``): the search and the check, and its figures;
3. then, while any is left, every unchecked direction whose ``check_top`` lies above the pair's
   design width found so far (the widest verified or failing width of the checked directions).

A direction left unchecked cannot find a failing width above the pair's final design width, so
the pair's design width is the one ``--thorough`` (every direction checked, as a lone record)
finds; the unchecked directions' rows say so (``check_runs`` 0, ``failing_share`` blank).  Each
pass is the same :func:`pipeline.batch.process_record` on tasks whose ``check`` and ``plot``
switches are set here; a lone record is one pass, checked and drawn.
"""
from __future__ import annotations

import dataclasses

#: a check whose top lies within this share of the design width is run all the same (the rows'
#: numbers are read back from text, with their rounding)
MARGIN = 1e-6


def staged(task, options) -> bool:
    """Whether ``task`` is computed in passes: a direction of a pair, without ``--thorough``."""
    return task.direction is not None and not options.thorough


def first_pass(tasks, options) -> list:
    """The tasks of the first pass: a pair's directions without check and figure (with ``--plots
    all``, with their figures), every other task checked and drawn."""
    out = []
    for t in tasks:
        if staged(t, options):
            t = dataclasses.replace(t, check=False, plot=bool(options.plots_all))
        out.append(t)
    return out


@dataclasses.dataclass
class _Direction:
    index: int
    checked: bool
    plotted: bool
    #: per column label: (verified width, check top, widest failing width or None)
    columns: dict


class Plan:
    """What each pair's directions have given so far, and which to compute next."""

    def __init__(self, options):
        from rocking.search import DEFAULT_SETTINGS

        self.options = options
        self.span = float(DEFAULT_SETTINGS.check_span)
        self.pairs: dict[str, dict[int, _Direction]] = {}

    def note(self, task, rows) -> None:
        """Record what ``task`` (as computed, with its switches) gave: its rows (empty: failed)."""
        if not staged(task, self.options):
            return
        from .site import pair_of

        group = self.pairs.setdefault(pair_of(task), {})
        if not rows:
            group.pop(task.index, None)
            return
        cols = {}
        for r in rows:
            w = float(r["verified_width_m"])
            top = min(self.span * w, float(r["height_m"]) * float(r["pga_g"]))
            widest = r.get("widest_failing_width_m")
            cols[r["column"]] = (w, top, None if widest in (None, "") else float(widest))
        group[task.index] = _Direction(task.index, bool(task.check), bool(task.plot), cols)

    def next_pass(self, tasks) -> list:
        """The tasks to compute next (their switches set), from ``tasks`` (the run's tasks, by
        index, as last computed); empty when every pair is settled."""
        out = []
        for group in self.pairs.values():
            want = _wanted(group, bool(self.options.plots))
            out += [dataclasses.replace(tasks[i], check=True, plot=plot or tasks[i].plot)
                    for i, plot in sorted(want.items())]
        return out


def _wanted(group, plots: bool) -> dict:
    """``{index: draw}`` of the directions of one pair to compute (checked) next."""
    want = {}
    labels = {c for d in group.values() for c in d.columns}
    for label in labels:
        dirs = [d for d in sorted(group.values(), key=lambda d: d.index) if label in d.columns]
        gov = max(dirs, key=lambda d: d.columns[label][0])  # the first of equal widths
        if not gov.checked or (plots and not gov.plotted):
            want[gov.index] = plots
            continue
        design = max(max(w, f or 0.0) for d in dirs if d.checked for w, _, f in [d.columns[label]])
        for d in dirs:
            if not d.checked and d.columns[label][1] > design * (1.0 - MARGIN):
                want.setdefault(d.index, False)
    return want
