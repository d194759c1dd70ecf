"""The records of a site's suite in a hazard curve's measure, and their critical values at a width.

A :class:`Member` is one record of the suite: a single component, or a pair of horizontals
designed for in several directions (its critical scale is the smallest over them, its measure
the pair's RotD50, the measure of current ground-motion models).  :func:`critical_set` finds each
member's critical scale (:func:`rocking.critical_scale`) for a column of a given width, with the
restitution sampled per member (reproducibly: the member's own stream of ``seed``, the same at
every width, so that the rate against the width is not noise) and up to the hazard curve's last
level (a record that does not fail there is censored at it: the curve says nothing above).
:class:`Runner` spreads the critical scales over processes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: directions (deg) a pair of components is designed for in :func:`members` (the two recorded
#: components and the diagonals between them)
DIRECTIONS = (0.0, 45.0, 90.0, 135.0)


@dataclass(frozen=True)
class Member:
    """A record of the suite: its name, the ground motions it is checked under (one per direction)
    and its intensity measure (unscaled; g, or cm/s for PGV)."""

    name: str
    components: tuple = field(repr=False)
    intensity: float = math.nan


def members(records, measure, names=None) -> list[Member]:
    """:class:`Member` s of ``records``: each a :class:`pulses.Record` (one component) or a pair
    ``(first, second)`` of horizontals at right angles (checked in :data:`DIRECTIONS`, measured by
    its RotD50)."""
    import pulses
    from pulses.intensity import intensity, rotd

    out = []
    for i, rec in enumerate(records):
        name = names[i] if names else None
        if isinstance(rec, (tuple, list)):
            if len(rec) != 2:
                raise ValueError("risk: a pair of records is (first, second)")
            first, second = rec
            comps = tuple(pulses.component(first, second, d) for d in DIRECTIONS)
            out.append(Member(name or f"{first.name}+{second.name}", comps,
                              rotd(first, second, measure)))
        else:
            out.append(Member(name or rec.name or f"record {i + 1}", (rec,), intensity(rec, measure)))
    bad = [m.name for m in out if not (math.isfinite(m.intensity) and m.intensity > 0)]
    if bad:
        raise ValueError(f"risk: no {measure} in record(s) {', '.join(bad)} (all zero?)")
    return out


def restitution_of(restitution, seed: int, index: int):
    """The single restitution member ``index`` is computed with: a draw from the band on the
    member's own stream of ``seed`` (None: Eq. 5)."""
    if restitution is None or not restitution.is_band:
        return restitution
    return restitution.sample(np.random.default_rng((int(seed), int(index))), 1)[0]


# -- the work, in this process or spread over a pool ------------------------------------------------
_COMPONENTS: list = []


def _init(components):
    global _COMPONENTS
    _COMPONENTS = components


def _critical(args):
    """The critical scale of one component (by its index in the runner's list) for one column."""
    import rocking

    k, height, width, eta, gamma, up_to, limit, body = args
    block = rocking.Block.from_dimensions(height, width, eta, cap_mass_ratio=gamma, body=body)
    return rocking.critical_scale(block, _COMPONENTS[k], up_to=up_to, limit=limit)


class Runner:
    """Critical scales of the suite's components, here (``jobs`` 1) or in ``jobs`` processes that
    receive the records once, for columns of ``body``'s shape (rocking.bodies).  A context manager
    (the pool is stopped on leaving it)."""

    def __init__(self, suite, jobs: int = 1, body="rectangular"):
        self.suite, self.body = suite, body
        self.index = [(i, j) for i, m in enumerate(suite) for j in range(len(m.components))]
        self.components = [suite[i].components[j] for i, j in self.index]
        self.jobs = max(1, int(jobs or 1))
        self.pool = None
        #: critical scales computed (one per component and width)
        self.runs = 0

    def __enter__(self):
        if self.jobs > 1 and len(self.components) > 1:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            methods = multiprocessing.get_all_start_methods()
            ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
            self.pool = ProcessPoolExecutor(max_workers=self.jobs, mp_context=ctx,
                                            initializer=_init, initargs=(self.components,))
        else:
            _init(self.components)
        return self

    def __exit__(self, *exc):
        if self.pool is not None:
            self.pool.shutdown(wait=True, cancel_futures=True)
            self.pool = None

    def map(self, tasks):
        self.runs += len(tasks)
        if self.pool is None:
            return [_critical(t) for t in tasks]
        return list(self.pool.map(_critical, tasks, chunksize=max(1, len(tasks) // (4 * self.jobs))))


@dataclass
class CriticalSet:
    """Every member's critical scale for one column: ``entries`` (the weakest direction's
    :class:`rocking.CriticalScale`), ``restitutions`` (what each was computed with; None: Eq. 5)."""

    width: float
    entries: list
    restitutions: list
    intensities: np.ndarray

    @property
    def n_failed(self) -> int:
        return sum(e.scale is not None for e in self.entries)

    def critical_values(self) -> np.ndarray:
        """Each member's critical measure (inf: none up to the curve's last level)."""
        return np.array([math.inf if e.scale is None else e.scale * im
                         for e, im in zip(self.entries, self.intensities)])


def critical_set(runner, height, width, curve, *, restitution=None, seed=0, limit=None,
                 cap_mass_ratio=0.0, sample=True) -> CriticalSet:
    """Each member's critical scale for the column ``height`` x ``width`` (m), up to the curve's
    last level; the restitution drawn per member where ``sample`` (else Eq. 5)."""
    suite = runner.suite
    top = float(curve.imls[curve.rates > 0][-1])
    rests = [restitution_of(restitution, seed, i) if sample else None for i in range(len(suite))]
    tasks = []
    for k, (i, _) in enumerate(runner.index):
        up_to = max(top / suite[i].intensity, 1e-9)
        tasks.append((k, float(height), float(width), rests[i], float(cap_mass_ratio), up_to, limit,
                      runner.body))
    results = runner.map(tasks)
    entries = []
    for i in range(len(suite)):
        mine = [r for (m, _), r in zip(runner.index, results) if m == i]
        entries.append(min(mine, key=lambda c: math.inf if c.scale is None else c.scale))
    return CriticalSet(float(width), entries, rests, np.array([m.intensity for m in suite]))


def fit(cset, curve, limit=None):
    """The lognormal fragility of a :class:`CriticalSet` in the curve's measure, or None where
    fewer than two members fail up to the curve's last level (the curve then sees no failure)."""
    import rocking

    if cset.n_failed < 2:
        return None
    try:
        return rocking.fragility(cset.entries, measure=curve.measure, limit=limit,
                                 intensities=cset.intensities)
    except ValueError:
        return None
