"""Risk at a site: a column's fragility against a hazard curve (docs/risk.md).

:class:`HazardCurve`, :func:`read_hazard` (every format of :mod:`rocking.risk.formats`),
:func:`risk` (the rate of overturning of a column and the width for a target rate, a
:class:`RiskResult`), the rate integral (:mod:`rocking.risk.rate`), the width for a target
(:mod:`rocking.risk.target`) and OpenQuake's NRML fragility models (:mod:`rocking.risk.nrml`).
"""
from .curve import HazardCurve, HazardError

__all__ = ["HazardCurve", "HazardError", "RiskResult", "TargetWidth", "read_hazard", "risk",
           "target_width"]


def __getattr__(name):
    if name == "read_hazard":
        from .formats import read_hazard

        return read_hazard
    if name in ("risk", "RiskResult"):
        from . import site

        return getattr(site, name)
    if name in ("target_width", "TargetWidth"):
        from . import target

        return getattr(target, name)
    raise AttributeError(f"module 'rocking.risk' has no attribute {name!r}")
