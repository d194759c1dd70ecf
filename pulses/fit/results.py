"""What the fitter returns: one :class:`Candidate` per shape, and the :class:`PulseFit` of a record."""
from __future__ import annotations

from dataclasses import dataclass, field

from ..shapes import Pulse
from ..units import G


@dataclass
class Candidate:
    """One fitted pulse shape.

    Attributes
    ----------
    shape : str
        A name of :data:`pulses.SHAPES` (the shapes of docs/theory.md section 2).
    ap : float
        Amplitude, m/s^2, signed by polarity.
    tp : float
        Period, s.
    t0 : float
        Arrival (rect, sine) or centre (Rickers), s, on the record's time axis.
    score : float
        Share of the record's energy the pulse explains (0-1).
    correlation : float
        Correlation of record and pulse within the pulse window (-1 to 1).
    pulse : pulses.Pulse
        The pulse object (``make_pulse(shape, ap, tp, t0)``).
    rank : int
        1 for the best candidate of the record, 2 for the runner-up, ...
    fit_window : (float, float) or None
        First and last sample times (s) used by the least-squares refinement (``None`` if the
        refinement did not improve on the coarse match).

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> best = pulses.fit_pulse(rec, shapes=["sine"]).best
    >>> best.rank, round(best.t0, 3), type(best.pulse).__name__
    (1, 2.0, 'OneSine')
    """

    shape: str
    ap: float
    tp: float
    t0: float
    score: float
    correlation: float
    pulse: Pulse = field(repr=False)
    rank: int = 0
    fit_window: tuple | None = field(default=None, repr=False)

    @property
    def ap_g(self) -> float:
        """Amplitude in g (signed)."""
        return self.ap / G

    @property
    def polarity(self) -> int:
        """+1 or -1: the sign of ``ap``."""
        return 1 if self.ap >= 0 else -1

    @property
    def lp(self) -> float:
        """Length scale ``Lp = |ap| Tp^2``, m."""
        return abs(self.ap) * self.tp**2

    @property
    def arrival(self) -> float:
        """Time the pulse starts, s: ``t0`` for rect and sine, ``t0 - Tp/2`` for the Rickers."""
        return self.pulse.arrival

    def as_dict(self) -> dict:
        return {"shape": self.shape, "rank": self.rank, "ap_m_s2": self.ap, "ap_g": self.ap_g,
                "tp_s": self.tp, "t0_s": self.t0, "arrival_s": self.arrival, "polarity": self.polarity,
                "lp_m": self.lp, "score": self.score, "correlation": self.correlation}


@dataclass
class PulseFit:
    """Pulse fits of one record, best first.

    Attributes
    ----------
    name : str
        Record name.
    candidates : list of Candidate
        One per shape, ranked by ``score`` (best first; ``rank`` 1 is the best).
    pga : float
        Peak ground acceleration of the record, m/s^2.
    pgv : float
        Peak ground velocity, m/s, after the baseline correction of :mod:`pulses.fit.baseline`.
    duration : float
        Length of the record, s.
    significant_duration : float
        D5-95 (time between 5 % and 95 % of the Arias intensity), s.
    weighting : str
        The least squares that gave the candidates: ``"background"`` (weighted by the
        background's spectrum) or ``"plain"`` (asked for, or where the record did not support
        the weighting: see :func:`fit_pulse`).

    Examples
    --------
    >>> import numpy as np, pulses
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> fit = pulses.fit_pulse(rec, shapes=["sine", "ricker-sym"])
    >>> [c.shape for c in fit.candidates], fit["sine"] is fit.best
    (['sine', 'ricker-sym'], True)
    """

    name: str
    candidates: list
    pga: float
    pgv: float
    duration: float
    significant_duration: float
    weighting: str = "plain"

    @property
    def best(self) -> Candidate:
        """The candidate that explains the most of the record's energy."""
        return self.candidates[0]

    def __getitem__(self, shape: str) -> Candidate:
        """The candidate of one shape: ``fit["sine"]``."""
        for c in self.candidates:
            if c.shape == shape:
                return c
        raise KeyError(f"no {shape!r} candidate; fitted shapes: {', '.join(c.shape for c in self.candidates)}")

    def to_frame(self):
        """One row per candidate (pandas DataFrame), best first, with the record's peaks."""
        import pandas as pd

        rows = []
        for c in self.candidates:
            row = {"record": self.name, **c.as_dict(), "best": c.rank == 1,
                   "pga_g": self.pga / G, "pgv_m_s": self.pgv, "duration_s": self.duration,
                   "d5_95_s": self.significant_duration, "weighting": self.weighting}
            rows.append(row)
        return pd.DataFrame(rows)

    def as_dict(self) -> dict:
        return {"record": self.name, "pga_g": self.pga / G, "pgv_m_s": self.pgv,
                "duration_s": self.duration, "d5_95_s": self.significant_duration,
                "weighting": self.weighting, "best": self.best.shape,
                "candidates": [c.as_dict() for c in self.candidates]}
