"""What both solvers share (the compiled one, :mod:`rocking.solver`, and the reference,
:mod:`rocking.reference`): the result objects, where a pulse's extrema lie, how long free
rocking can last.  Both import it; neither imports the other at module level."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pulses import Pulse

from .block import Block

#: post-impact angular velocity, over ``p * alpha``, below which a Zeno sequence is summed
ZENO_TOL = 1e-7

@dataclass
class RockingResult:
    """The response of one block to one excitation.

    Attributes
    ----------
    overturned : bool
        ``|theta|`` reached ``pi/2`` (during the excitation, or as the energy rule decides after).
    exceeded_alpha : bool
        ``|theta|`` exceeded ``alpha`` at some time.
    max_rotation : float
        ``max |theta|`` (rad), including the free rocking after the excitation (energy rule).
    max_rotation_ratio : float
        ``max |theta| / alpha``.
    impacts : ndarray
        Impact times (s) during the integrated part.
    n_impacts : int
        Number of impacts (the integrated part; a Zeno tail summed in closed form counts once).
    t, theta, omega : ndarray
        History at the grid nodes: time (s), rotation (rad), angular velocity (rad/s).
    model : str
        Which model answered: ``"rest"``, ``"linear"``, ``"fast"`` or ``"reference"``.
    verdict_by : str
        ``"no uplift"``, ``"integration"`` (overturned while integrating, or at rest at the end)
        or ``"energy rule"`` (decided from the state when the excitation ended).
    uplifted : bool
        The block left its rest position at least once.
    t_overturn : float
        Time (s) at which ``|theta|`` reached ``pi/2`` during the integration, else nan.

    Examples
    --------
    >>> import pulses, rocking
    >>> column = rocking.Block.from_dimensions(7.5, 1.8)
    >>> res = rocking.simulate(column, pulses.OneSine(ap=0.5 * pulses.G, tp=1.0))
    >>> res.t.shape == res.theta.shape, bool(res.exceeded_alpha)
    (True, False)
    """

    overturned: bool
    exceeded_alpha: bool
    max_rotation: float
    max_rotation_ratio: float
    impacts: np.ndarray
    n_impacts: int
    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    model: str
    verdict_by: str
    uplifted: bool
    t_overturn: float = math.nan
    block: Block | None = field(default=None, repr=False)

    def summary(self) -> dict:
        """Scalar results as a plain dict (for JSON and CSV)."""
        return {
            "overturned": bool(self.overturned),
            "exceeded_alpha": bool(self.exceeded_alpha),
            "max_rotation_rad": float(self.max_rotation),
            "max_rotation_ratio": float(self.max_rotation_ratio),
            "n_impacts": int(self.n_impacts),
            "uplifted": bool(self.uplifted),
            "t_overturn_s": None if math.isnan(self.t_overturn) else float(self.t_overturn),
            "model": self.model,
            "verdict_by": self.verdict_by,
        }


@dataclass
class BatchResult:
    """Scalar results of :func:`simulate_many`, one array entry per run.

    Examples
    --------
    >>> import pulses, rocking
    >>> column = rocking.Block.from_dimensions(7.5, 1.8)
    >>> pulse = pulses.OneSine(ap=0.3 * pulses.G, tp=1.0)
    >>> batch = rocking.simulate_many(column, pulse, scales=[1.0, 2.0, 4.0])
    >>> batch.overturned.tolist()
    [False, True, True]
    >>> batch.max_rotation_ratio.round(2).tolist()
    [0.1, 6.67, 6.67]
    """

    overturned: np.ndarray
    exceeded_alpha: np.ndarray
    max_rotation: np.ndarray
    max_rotation_ratio: np.ndarray
    n_impacts: np.ndarray
    uplifted: np.ndarray
    model: str
    #: with a vertical record (docs/theory.md section 10): whether each run left the ground
    #: (``g + av < 0``; its verdict is then not a verdict) and when (nan where not); else None
    lifts_off: np.ndarray | None = None
    t_lift_off: np.ndarray | None = None


def _pulse_extrema(pulse: Pulse) -> list[float]:
    """Times (s) of the extrema of the pulse's acceleration inside its support (the shape knows
    them: :attr:`pulses.Pulse.extrema`)."""
    return list(pulse.extrema)


def _free_rocking_horizon(block: Block) -> float:
    """An upper bound (s) on how long free rocking lasts before it comes to rest.

    Each half-cycle lasts less than ``~ (2/p) * acosh(...)``; with the energy falling by ``r`` at
    every impact, ``log(zeno)/log(r)`` impacts reach the Zeno threshold.  Generous by design:
    ``stop_at_rest`` ends the integration as soon as the block settles.
    """
    n_impacts = math.log(ZENO_TOL) / math.log(max(block.eta, 1e-3)) + 10 if block.eta > 0 else 10
    return min(50.0 / block.p * n_impacts, 1e7 / block.p)


def _result(block, over, max_abs, impacts, n_imp, t, th, om, model, verdict_by, uplifted, t_over):
    max_abs = float(max_abs)
    return RockingResult(bool(over), bool(max_abs > block.alpha), max_abs, max_abs / block.alpha,
                         np.asarray(impacts, dtype=float), int(n_imp), t, th, om, model,
                         verdict_by, bool(uplifted), float(t_over), block=block)
