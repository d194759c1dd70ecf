"""Which directions of a pair get the check above the search width and the figures.

A pair designed in many directions is governed by its widest direction: the pair's design width
``D`` is the widest of its directions' design widths ``W_d``, each above every failing width its
check found (docs/slivers.md).  The check (:mod:`rocking.binned`, the default layout) is
*separable in a threshold*: run only above ``T`` (``SearchSettings.check_above``), a direction's
check runs exactly the widths its whole check runs above ``T``, with the same verdicts (and the
bins below ``T`` down to the first holding a width run at or below ``T``), so its design width
``W_d(T)`` is ``W_d`` wherever ``W_d > T``, and at most ``W_d`` otherwise.  A direction left
unchecked has the design width ``W_d(T)`` for any ``T`` at or above its *reach* ``step min(check_span
w, H PGA / g)`` (``w`` its search width, ``H PGA / g`` the no-uplift width under its component,
``step`` the search's scan step, :func:`_bracket_step`: a failing width the check could find is
at most its top, and the bracket above it ends at the next width run).

The argument: let every direction ``d`` be checked above some ``T_d < D'``, ``D'`` the widest of
the ``W_d(T_d)`` (the pair's design width the run reports).  Then ``D' <= D``, since every
``W_d(T_d) <= W_d``; and for a direction ``g`` with ``W_g = D``, ``T_g < D' <= D = W_g``, so
``W_g(T_g) = W_g = D`` and ``D' >= D``.  So ``D'`` is the design width ``--thorough`` (every
direction checked whole, as a lone record) finds, whatever the bounds, as long as each lies below
the final ``D'``.  Any width a direction reports (its search width at least) is such a bound.
``pipeline run`` computes a pair in passes:

1. a few *scout* directions (the recorded components, the pulse's and its normal, every
   :data:`SCOUT_EVERY` th direction in angle order): the search only (no check), no figure
   (unless ``--plots all``);
2. the other directions, each checked above the widest width the scouts found (a lower bound of
   the pair's design width), in the same task as its search;
3. the governing direction (the widest design width so far, the first such in angle order, as in
   ``pairs.csv``) with its whole check, and its figures, where not done;
4. then, while any is left, every unchecked direction whose reach lies above the pair's design
   width found so far, checked above that width: the whole direction again (the check uses the
   search's widths, and may raise the direction's design width, which other columns use).

A pair goes on to its next pass as soon as all its results are in (:meth:`Plan.next_pass`),
whatever the batch's other pairs are doing: a direction computed again in a later pass then finds
its search, fit and exact minimum slenderness still kept by the worker (:mod:`pipeline.batch.memo`),
however long the batch.  The directions checked above a bound say how many widths they ran
(``check_runs``); those left unchecked say so (``check_runs`` 0, ``failing_share`` blank).  Each pass is the same
:func:`pipeline.batch.record.process_record` on tasks whose ``check``, ``check_above`` and
``plot`` switches are set here; a lone record is one pass, checked whole and drawn.  With the
former layout (``check_layout="rounds"``, not separable) ``check_above`` switches a direction's
check off where its rounds could not reach above it, and runs it whole otherwise; the bounds are
then divided by ``step``, for the bracket above the rounds' top.
"""
from __future__ import annotations

import collections
import dataclasses


#: a check whose top lies within this share of the design width is run all the same (the rows'
#: numbers are read back from text, with their rounding)
MARGIN = 1e-6


def _bracket_step() -> float:
    """How far above a check's top the design width it sets may lie: a failing width is raised to
    the end of its bracket, the next width run above it, at worst the search's next scanned width
    (geometric, ``record_scan`` widths from ``record_low`` of the no-uplift width up to it)."""
    from rocking.search import DEFAULT_SETTINGS as s

    return (1.0 / s.record_low) ** (1.0 / (s.record_scan - 1))


def staged(task, options) -> bool:
    """Whether ``task`` is computed in passes: a direction of a pair, without ``--thorough``."""
    return task.direction is not None and not options.thorough


#: every this many directions of a pair (in angle order) one is a scout of the first pass
SCOUT_EVERY = 4
#: the directions chosen for what they are are scouts too
SCOUT_KINDS = ("component-1", "component-2", "pulse", "pulse-normal")


def first_pass(tasks, options) -> tuple[list, set]:
    """The tasks in their first-pass form: a pair's directions without check and figure (with
    ``--plots all``, with their figures), every other task checked and drawn; and the indices of
    the directions held back for the second pass (not scouts)."""
    out, held, seen = [], set(), {}
    for t in tasks:
        if staged(t, options):
            t = dataclasses.replace(t, check=False, plot=bool(options.plots_all))
            k = seen[t.pair] = seen.get(t.pair, -1) + 1
            if k % SCOUT_EVERY and t.direction_kind not in SCOUT_KINDS:
                held.add(t.index)
        out.append(t)
    return out, held


@dataclasses.dataclass
class _Direction:
    index: int
    checked: bool
    plotted: bool
    #: per column label: (design width, check top, widest failing width or None)
    columns: dict
    #: checked in full, not only above a bound (None: as ``checked``)
    full: bool | None = None

    def __post_init__(self):
        if self.full is None:
            self.full = self.checked


class Plan:
    """What each pair's directions have given so far, and which to compute next."""

    def __init__(self, options, held=()):
        from rocking.search import DEFAULT_SETTINGS

        self.options = options
        #: the check's layout is separable in a threshold: a check above a bound runs only there
        self.separable = DEFAULT_SETTINGS.check_layout == "bins"
        self.span = DEFAULT_SETTINGS.check_reach
        self.step = _bracket_step()
        #: what a lower bound of the pair's design width is divided by to give check_above: the
        #: binned check refines its own bracket across the bound; the rounds' is allowed for here
        self.below = 1.0 if self.separable else self.step
        self.pairs: dict[str, dict[int, _Direction]] = {}
        #: the directions held back from the first pass (indices)
        self.held = set(held)
        #: per pair, its tasks handed out (:meth:`sent`) whose results are not noted yet: a pair
        #: goes on to its next pass as soon as it has none, whatever the other pairs are doing,
        #: so that a batch finishes a pair while its searches are still kept by the workers
        self.pending: collections.Counter = collections.Counter()
        self._out = 0  # the sum of pending
        #: the pairs noted since the last :meth:`next_pass`, the only ones it need look at
        self._dirty: set = set()
        #: the held directions by pair, not handed out yet (made at the first :meth:`next_pass`)
        self._held: dict | None = None
        #: the pairs whose passes :meth:`next_pass` found done, not yet taken by the caller (the
        #: runner notes them in the resume journal: a later run keeps such a pair whole)
        self.done: list = []

    def note(self, task, rows) -> None:
        """Record what ``task`` (as computed, with its switches) gave: its rows as its report holds
        them (:func:`pipeline.batch.row.rows_of`; empty: failed)."""
        if not staged(task, self.options):
            return
        from .site import pair_of

        pair = pair_of(task)
        if self.pending[pair] > 0:
            self.pending[pair] -= 1
            self._out -= 1
        self._dirty.add(pair)
        group = self.pairs.setdefault(pair, {})
        if not rows:
            group.pop(task.index, None)
            return
        cols = {}
        for r in rows:  # as the report holds them (6 digits): a resumed run decides as the first did
            w, H, pga, widest = (r.get(k) for k in ("design_width_m", "height_m", "pga_g", "widest_failing_width_m"))
            # the widest design width its check could set (above the reach of its rounds)
            cols[r["column"]] = (w, self.step * min(self.span * w, H * pga), widest)
        full = bool(task.check) and not (self.separable and any(task.check_above))
        group[task.index] = _Direction(task.index, bool(task.check), bool(task.plot), cols, full)

    def sent(self, tasks) -> None:
        """Note that ``tasks`` were handed out to be computed (their results come to :meth:`note`)."""
        from .site import pair_of

        for t in tasks:
            if staged(t, self.options):
                self.pending[pair_of(t)] += 1
                self._out += 1

    def next_pass(self, tasks) -> list:
        """The tasks to compute next (their switches set), from ``tasks`` (the run's tasks, by
        index, as last computed): the next pass of every pair with no task out; empty when those
        are settled.  A pair's held directions come first, then its governing direction and
        those whose check could reach above its design width, pass after pass."""
        from .site import pair_of

        ready = {p for p in self._dirty if not self.pending[p]}
        self._dirty -= ready
        if self._held is None:  # the held directions by pair, once
            self._held = {}
            for i in sorted(self.held):
                self._held.setdefault(pair_of(tasks[i]), []).append(i)
        held = self._held
        if not self._out:  # nothing out: every pair still holding some is ready
            ready |= set(held)
        out = []
        for pair in sorted(ready, key=lambda p: min(held.get(p) or self.pairs.get(p) or [0])):
            if pair in held:
                out += self._held_pass(tasks, pair, held.pop(pair))
                continue
            want, design, whole = _wanted(self.pairs.get(pair, {}), bool(self.options.plots))
            if not want:
                self.done.append(pair)
            for i, plot in sorted(want.items()):
                # the governing direction's check whole; the others' rounds where they could reach
                # above the pair's design width so far
                above = () if plot or i in whole else tuple(design.get(c.label, 0.0) * (1.0 - MARGIN) / self.below
                                              for c in tasks[i].columns)
                out.append(dataclasses.replace(tasks[i], check=True, check_above=above, plot=plot or tasks[i].plot))
        return out

    def _held_pass(self, tasks, pair, indices) -> list:
        """The held directions of ``pair`` (``indices``), each checked where its check could reach
        above the widest width its scouts found."""
        lower = {}  # the scouts' widest design width (not their checks': the same on a resumed run)
        for d in self.pairs.get(pair, {}).values():
            for label, (w, _, _) in d.columns.items():
                lower[label] = max(lower.get(label, 0.0), w)
        self.held -= set(indices)
        out = []
        for i in indices:
            t = tasks[i]
            above = tuple(lower.get(c.label, 0.0) * (1.0 - MARGIN) / self.below for c in t.columns)
            out.append(dataclasses.replace(t, check=True, check_above=above))
        return out


def _wanted(group, plots: bool) -> tuple[dict, dict, set]:
    """``{index: draw}`` of the directions of one pair to compute (checked) next, the pair's
    design width so far by column label (where its governing direction is checked whole), and the
    indices of the governing directions to check whole."""
    want, designs, whole = {}, {}, set()
    labels = {c for d in group.values() for c in d.columns}
    for label in labels:
        dirs = [d for d in sorted(group.values(), key=lambda d: d.index) if label in d.columns]
        gov = max(dirs, key=lambda d: d.columns[label][0])  # the first of equal widths
        if not gov.full or (plots and not gov.plotted):
            want[gov.index] = plots
            whole.add(gov.index)
            continue
        design = designs[label] = max(max(w, f or 0.0) for d in dirs if d.checked for w, _, f in [d.columns[label]])
        for d in dirs:
            if not d.checked and d.columns[label][1] > design * (1.0 - MARGIN):
                want.setdefault(d.index, False)
    return want, designs, whole
