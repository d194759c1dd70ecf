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
    >>> import rocking, pulses
    >>> res = rocking.simulate(rocking.Block.from_dimensions(7.5, 1.8), pulses.make_pulse("sine", 0.5 * pulses.G, 1.0))
    >>> res.verdict_by in ("no uplift", "integration", "energy rule"), res.t.shape == res.theta.shape
    (True, True)
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

    def as_dict(self) -> dict:
        """The scalar results (:meth:`summary`; a vertical run's lift-off too) and the block's
        ``p`` (rad/s) and ``alpha`` (rad): plain, JSON-safe numbers.

        Examples
        --------
        >>> import rocking, pulses
        >>> res = rocking.simulate(rocking.Block.from_dimensions(7.5, 1.8), pulses.make_pulse("sine", 3.0, 1.0))
        >>> res.as_dict()["overturned"], res.as_dict()["model"]
        (False, 'fast')
        """
        from pulses.export import plain

        out = self.summary()
        for name in ("lifts_off", "t_lift_off", "min_effective_gravity"):  # VerticalRockingResult's
            if hasattr(self, name):
                out[name] = getattr(self, name)
        if self.block is not None:
            out.update(p_rad_s=self.block.p, alpha_rad=self.block.alpha)
        return plain(out)

    def to_frame(self):
        """The history as a :class:`pandas.DataFrame`: ``t_s``, ``theta_rad``, ``omega_rad_s``, one
        row per grid node (empty where no history was kept)."""
        import pandas as pd

        return pd.DataFrame({"t_s": np.asarray(self.t, dtype=float), "theta_rad": np.asarray(self.theta, dtype=float),
                             "omega_rad_s": np.asarray(self.omega, dtype=float)})


@dataclass
class BatchResult:
    """Scalar results of :func:`simulate_many`, one array entry per run.

    Examples
    --------
    >>> import rocking, pulses
    >>> columns = [rocking.Block.from_dimensions(7.5, w) for w in (1.0, 1.8)]
    >>> many = rocking.simulate_many(columns, pulses.make_pulse("sine", 0.5 * pulses.G, 1.0))
    >>> many.max_rotation_ratio.shape, many.model
    ((2,), 'fast')
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

    def to_frame(self):
        """One row per run (:class:`pandas.DataFrame`), the arrays as columns and ``model``."""
        import pandas as pd

        cols = {name: np.ravel(getattr(self, name)) for name in
                ("overturned", "exceeded_alpha", "max_rotation", "max_rotation_ratio", "n_impacts",
                 "uplifted", "lifts_off", "t_lift_off") if getattr(self, name) is not None}
        df = pd.DataFrame(cols)
        df["model"] = self.model
        return df

    def as_dict(self) -> dict:
        """Every run's results as lists (plain, JSON-safe)."""
        from pulses.export import plain

        return plain({"model": self.model, **self.to_frame().drop(columns="model").to_dict("list")})


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
