"""The narrowest width of a column whose annual rate of failure at a site meets a target.

The rate need not fall monotonically with the width (each width has its own critical scales,
and a record's can rise and fall), so: a scan of widths a factor :data:`RATIO` apart, from a
start down while the target is met or up until it is, then on above the first width that meets
it until :data:`CONFIRM` widths in a row do; the crossing is the narrowest scanned width above
which every scanned width meets the target, and it is bisected (geometrically) between it and the
scanned width just below, which does not, to ``rtol``.  The answer meets the target (its rate is
computed there) and the width just narrower that was computed does not.

Where fewer than two records fail up to the curve's last level, the curve sees no failure of the
column: its rate is 0 as far as the curve goes (stated in the table's ``note``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

#: ratio between scanned widths
RATIO = 1.25
#: widths in a row above the crossing that must meet the target
CONFIRM = 2
#: at most this many widths scanned each way
MAX_SCAN = 16
#: default relative width to which the crossing is bisected
RTOL = 0.005


@dataclass
class WidthRate:
    """The rate of failure of one width: ``rate`` (per year), the fit (None: fewer than two
    failures up to the curve's last level), the critical values."""

    width: float
    rate: float
    fragility: object = field(repr=False)
    critical: object = field(repr=False)
    stage: str = "scan"

    @property
    def note(self) -> str:
        if self.fragility is None:
            return (f"{self.critical.n_failed} record(s) fail up to the curve's last level: no "
                    "failure the curve sees")
        return ""


@dataclass
class TargetWidth:
    """The width for a target rate (:func:`target_width`).

    Attributes
    ----------
    target_rate : float
        The target, per year.
    width : float or None
        The narrowest width meeting it (None: none up to the widest scanned).
    rate : float or None
        The rate at :attr:`width`.
    narrower_width, narrower_rate : float or None
        The width just narrower that was computed, and its rate (above the target).
    widths : list of WidthRate
        Every width computed, in the order they were (``stage`` scan or refine).
    note : str
        Where the answer is bounded by the scan.
    """

    target_rate: float
    width: float | None
    rate: float | None
    narrower_width: float | None
    narrower_rate: float | None
    widths: list = field(repr=False)
    note: str = ""
    runs: int = 0
    seconds: float = 0.0

    def sorted(self) -> list:
        return sorted(self.widths, key=lambda w: w.width)


def target_width(runner, height, curve, target_rate, *, restitution=None, seed=0, limit=None,
                 cap_mass_ratio=0.0, start=None, rtol=RTOL, max_width=None) -> TargetWidth:
    """The narrowest width of a column ``height`` m tall whose rate of failure (overturning, or
    with ``limit`` R exceeding it) under ``curve`` is at most ``target_rate``, with the suite of
    ``runner`` (:class:`rocking.risk.suite.Runner`).  ``start``: the first width tried (default
    ``height / 8``); ``max_width``: the widest tried (default ``2 height``)."""
    import time

    from . import suite as suites
    from .rate import failure_rate

    t0, runs0 = time.perf_counter(), runner.runs
    seen = {}

    def evaluate(w, stage):
        key = round(w, 12)
        if key not in seen:
            cs = suites.critical_set(runner, height, w, curve, restitution=restitution, seed=seed,
                                     limit=limit, cap_mass_ratio=cap_mass_ratio)
            f = suites.fit(cs, curve, limit)
            rate = 0.0 if f is None else failure_rate(curve, f.median, f.beta).rate
            seen[key] = WidthRate(w, rate, f, cs, stage)
        return seen[key]

    def meets(w, stage="scan"):
        return evaluate(w, stage).rate <= target_rate

    top = float(max_width or 2.0 * height)
    lo, hi, note = _scan(meets, float(start or height / 8.0), top)
    if hi is not None and lo is not None:
        while hi / lo - 1.0 > rtol:
            mid = math.sqrt(lo * hi)
            if meets(mid, "refine"):
                hi = mid
            else:
                lo = mid
    widths = list(seen.values())
    res = TargetWidth(float(target_rate), hi, None if hi is None else evaluate(hi, "").rate,
                      lo, None if lo is None else evaluate(lo, "").rate, widths, note,
                      runner.runs - runs0, time.perf_counter() - t0)
    return res


def _scan(meets, w, top):
    """``(lo, hi, note)``: the scanned width just below the crossing (fails) and the crossing
    (meets, and so does every scanned width above it up to :data:`CONFIRM` more)."""
    note = ""
    if meets(w):
        hi = w
        for _ in range(MAX_SCAN):
            w /= RATIO
            if not meets(w):
                break
            hi = w
        else:
            return None, hi, f"meets the target at every width scanned, down to {hi:.4g} m"
        lo = w
    else:
        lo = w
        for _ in range(MAX_SCAN):
            w *= RATIO
            if w > top:
                return lo, None, f"no width up to {top:.4g} m meets the target"
            if meets(w):
                break
            lo = w
        else:
            return lo, None, f"no width up to {w:.4g} m meets the target"
        hi = w
    # above the crossing: every scanned width must meet it
    above, run = hi, 0
    while run < CONFIRM:
        above *= RATIO
        if above > top:
            break
        if meets(above):
            run += 1
        else:
            lo, hi, run = above, None, 0
            while hi is None:
                above *= RATIO
                if above > top:
                    return lo, None, f"no width up to {top:.4g} m meets the target throughout"
                if meets(above):
                    hi = above
                else:
                    lo = above
    return lo, hi, note
