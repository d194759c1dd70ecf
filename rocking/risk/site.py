"""Risk at a site: :func:`risk` and its :class:`RiskResult` (docs/risk.md).

From a suite of records and a hazard curve: each record's critical scale for the column as it
stands (:mod:`rocking.risk.suite`) turned into the curve's measure, the lognormal fragility of the
suite (with the restitution sampled per record, and with Eq. 5 alone for comparison), its fit and
bootstrap band, the annual rate of failure and what follows (return period, probability in
``years``, survival over an ``age``, the share per band of the measure), and, for a target, the
narrowest width that meets it (:mod:`rocking.risk.target`).  The rows of the reports are made
here, in one place (:meth:`RiskResult.rows` and the others).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

#: resamplings of the records for the band of the rate, and samples of the fit's p-value
N_BOOT = 200
#: the band of the rate: these percentiles of the bootstrap
BAND = (5.0, 95.0)


@dataclass
class ModeRisk:
    """One failure mode (overturning, or ``max|theta|/alpha > R``) of the column as it stands."""

    limit: float | None
    critical: object = field(repr=False)
    fragility: object = field(repr=False)
    fragility_eq5: object = field(repr=False)
    rate: object = field(repr=False)
    band: tuple = (None, None)
    fit: object = None

    @property
    def mode(self) -> str:
        return "overturning" if self.limit is None else f"max theta/alpha > {self.limit:g}"


@dataclass
class RiskResult:
    """What :func:`risk` returns.

    Attributes
    ----------
    curve : HazardCurve
    height, width : float
        The column (``width`` None: only the width for the target was asked).
    modes : list of ModeRisk
        Overturning, and the level ``limit`` where one was given, of the column as it stands.
    target : TargetWidth or None
    years, age : float
        The probability of failure is given in ``years``; the survival over ``age`` (None: not asked).
    restitution : str
        The restitution as given (``Eq. 5`` by default), sampled per record where a band.
    """

    curve: object
    height: float
    width: float | None
    modes: list
    target: object
    years: float
    age: float | None
    restitution: str
    seed: int
    names: list = field(repr=False, default_factory=list)
    #: the level R the target is for (None: overturning)
    limit: float | None = None
    #: the column's shape (rocking.bodies; a cylinder's width is its diameter)
    body: str = "rectangular"

    @property
    def rate(self) -> float | None:
        """The annual rate of overturning of the column as it stands."""
        return self.modes[0].rate.rate if self.modes and self.modes[0].rate else None

    def rows(self) -> list[dict]:
        """``risk.csv``: one row per failure mode of the column as it stands, and one for the width
        for the target (columns :data:`rocking.risk.rows.RISK_COLUMNS`)."""
        from . import rows

        return rows.risk_rows(self)

    def record_rows(self) -> list[dict]:
        from . import rows

        return rows.record_rows(self)

    def width_rows(self) -> list[dict]:
        from . import rows

        return rows.width_rows(self)

    def disaggregation_rows(self) -> list[dict]:
        from . import rows

        return rows.disaggregation_rows(self)

    def to_frame(self):
        """:meth:`rows` as a pandas DataFrame."""
        import pandas as pd

        from .rows import RISK_COLUMNS

        return pd.DataFrame(self.rows(), columns=list(RISK_COLUMNS.names))

    def as_dict(self) -> dict:
        """Every table, plain and JSON-safe."""
        from pulses.export import plain

        return plain({"curve": self.curve.as_dict(), "risk": self.rows(), "records": self.record_rows(),
                      "widths": self.width_rows(), "disaggregation": self.disaggregation_rows()})


def _mode(runner, curve, height, width, limit, restitution, seed, gamma, n_boot):
    from . import suite as suites
    from .rate import failure_rate

    cs = suites.critical_set(runner, height, width, curve, restitution=restitution, seed=seed,
                             limit=limit, cap_mass_ratio=gamma)
    f = suites.fit(cs, curve, limit)
    f5 = f
    if restitution is not None and not restitution.is_housner:
        f5 = suites.fit(suites.critical_set(runner, height, width, curve, limit=limit,
                                            cap_mass_ratio=gamma, sample=False), curve, limit)
    if f is None:
        return ModeRisk(limit, cs, None, f5, None)
    rate = failure_rate(curve, f.median, f.beta)
    meds, betas = f.bootstrap(n_boot, seed)
    rates = [failure_rate(curve, m, b).rate for m, b in zip(meds, betas)]
    band = tuple(float(v) for v in np.percentile(rates, BAND)) if rates else (None, None)
    return ModeRisk(limit, cs, f, f5, rate, band, f.goodness_of_fit(n_boot, seed))


def risk(records, hazard, *, height, width=None, target_rate=None, target_poe=None, years=50.0,
         age=None, limit=None, restitution=None, seed=0, cap_mass_ratio=0.0, names=None,
         n_boot=N_BOOT, jobs=1, body="rectangular", **read) -> RiskResult:
    """The annual rate of failure of a column at a site, and the width for a target.

    Parameters
    ----------
    records : sequence of pulses.Record or (Record, Record)
        The site's suite: single components, or pairs of horizontals (checked in
        :data:`rocking.risk.suite.DIRECTIONS`, measured by their RotD50).
    hazard : HazardCurve or path
        The site's hazard curve, or a file :func:`rocking.risk.read_hazard` reads (``**read``:
        its ``site``, ``site_row``, ``imt``, ``units``, ``format``).
    height, width : float
        The column, m (``width`` None: only the width for the target).
    target_rate : float, optional
        Annual rate of failure aimed at (e.g. ``1e-4``); or ``target_poe`` such as ``"2%/50"``.
    years, age : float
        The probability of failure is given in ``years`` (50); ``age``: also the probability of
        having stood that long.
    limit : float, optional
        A level R in (0, 1]: its rate too, and the target is for it.
    restitution : rocking.restitution.Restitution or str, optional
        Eq. 5 by default; a band is sampled per record (``seed``), and the fit with Eq. 5 alone
        is reported beside it.
    jobs : int
        Processes for the critical scales.
    body : str, optional
        The column's shape (:mod:`rocking.bodies`; ``"cylinder"``: ``width`` is its diameter).

    Examples
    --------
    >>> import numpy as np, pulses, rocking
    >>> from rocking.risk import HazardCurve
    >>> t = np.arange(0.0, 6.0, 0.01)
    >>> recs = [pulses.Record(pulses.make_pulse("sine", a * pulses.G, tp, 1.0)(t), 0.01, name=f"p{i}")
    ...         for i, (a, tp) in enumerate([(0.3, 1.0), (0.25, 1.5), (0.4, 0.8), (0.2, 2.0)])]
    >>> x = np.geomspace(0.01, 5.0, 60)
    >>> curve = HazardCurve("PGA", x, 1e-4 * x ** -2.2, units="g")
    >>> res = rocking.risk(recs, curve, height=7.5, width=1.8, n_boot=20)
    >>> f"{res.rate:.2e}", res.modes[0].fragility.n
    ('8.33e-04', 4)
    """
    from . import suite as suites
    from .curve import HazardCurve

    curve = hazard if isinstance(hazard, HazardCurve) else _read(hazard, read)
    suite = suites.members(records, curve.measure, names)
    return assess(suite, curve, height=height, width=width, target_rate=target_rate,
                  target_poe=target_poe, years=years, age=age, limit=limit, restitution=restitution,
                  seed=seed, cap_mass_ratio=cap_mass_ratio, n_boot=n_boot, jobs=jobs, body=body)


def assess(suite, curve, *, height, width=None, target_rate=None, target_poe=None, years=50.0,
           age=None, limit=None, restitution=None, seed=0, cap_mass_ratio=0.0, n_boot=N_BOOT,
           jobs=1, body="rectangular") -> RiskResult:
    """:func:`risk` for a suite already made (:class:`rocking.risk.suite.Member` s, as the
    pipeline makes them from its tasks: a pair in the directions the run designed for); ``body``:
    the column's shape (rocking.bodies; a cylinder's width is its diameter)."""
    from ..restitution import Restitution
    from . import suite as suites
    from .rate import parse_poe, rate_for
    from .target import target_width

    rest = None if restitution is None else Restitution.parse(restitution)
    if target_poe is not None:
        if target_rate is not None:
            raise ValueError("risk: give target_rate or target_poe, not both")
        target_rate = rate_for(*parse_poe(target_poe))
    _check(height, width, target_rate, years, age)
    gamma = float(cap_mass_ratio)
    with suites.Runner(suite, jobs, body) as runner:
        modes = []
        if width is not None:
            for lim in [None] + ([limit] if limit is not None else []):
                modes.append(_mode(runner, curve, height, width, lim, rest, seed, gamma, n_boot))
        target = None
        if target_rate is not None:
            target = target_width(runner, height, curve, target_rate, restitution=rest, seed=seed,
                                  limit=limit, cap_mass_ratio=gamma, start=width)
    return RiskResult(curve, float(height), None if width is None else float(width), modes, target,
                      float(years), None if age is None else float(age),
                      "Eq. 5" if rest is None else rest.describe(), int(seed), [m.name for m in suite],
                      limit, str(body))


def _read(path, read):
    from .formats import read_hazard

    return read_hazard(path, **read)


def _check(height, width, target_rate, years, age) -> None:
    for name, v, can_be_none in (("height", height, False), ("width", width, True),
                                 ("target_rate", target_rate, True), ("years", years, False),
                                 ("age", age, True)):
        if v is None and can_be_none:
            continue
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise ValueError(f"risk: {name} must be a positive number, got {v!r}")
