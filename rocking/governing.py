"""The governing pulse: which of a record's fitted pulses Eq. 31 is applied to (the rule of
``pipeline run``, here so that a loop in Python gives its numbers)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

#: a shape "fits" a record when its score is at least this fraction of the best shape's score
FIT_TOLERANCE = 0.7


def fitting_candidates(fit, tolerance: float = FIT_TOLERANCE) -> list:
    """The candidates of ``fit`` (a :class:`pulses.PulseFit`) that fit the record almost as well as
    the best: score at least ``tolerance`` times the best's, best first.

    Parameters
    ----------
    fit : pulses.PulseFit
        The record's pulse fits.
    tolerance : float
        Share of the best score a candidate needs (default :data:`FIT_TOLERANCE`).

    Returns
    -------
    list of pulses.Candidate
        Never empty: the best candidate fits (alone where its score is not a positive number).

    Examples
    --------
    >>> import pulses, rocking
    >>> import numpy as np
    >>> t = np.arange(0.0, 6.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 1.0)(t), 0.01)
    >>> fit = pulses.fit_pulse(rec, shapes=["sine", "ricker-sym"])
    >>> rocking.fitting_candidates(fit)[0].shape
    'sine'
    """
    best = fit.best
    b = float(best.score)
    if not math.isfinite(b) or b <= 0.0:
        return [best]
    return [c for c in fit.candidates if c is best or float(c.score) >= tolerance * b]


@dataclass
class GoverningPulse:
    """Outcome of :func:`governing_pulse`.

    Attributes
    ----------
    candidate : pulses.Candidate
        The governing pulse: the fitting candidate whose Eq. 31 width is largest.
    width : float
        Its Eq. 31 width (m) at :attr:`height` (the fixed point of :func:`rocking.required_width`,
        ``rule="eq31"``).
    height : float
        Full height of the column, m.
    widths : list of (float, pulses.Candidate)
        Every fitting candidate's Eq. 31 width (m), best fit first.

    Examples
    --------
    >>> import numpy as np, pulses, rocking
    >>> t = np.arange(0.0, 6.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 1.0)(t), 0.01)
    >>> gov = rocking.governing_pulse(pulses.fit_pulse(rec, shapes=["sine"]), 7.5)
    >>> gov.candidate.shape, gov.height
    ('sine', 7.5)
    """

    candidate: object
    width: float
    height: float
    widths: list = field(default_factory=list, repr=False)

    def as_dict(self) -> dict:
        """Plain numbers: the governing shape, its ap (m/s^2 and g), Tp (s), the Eq. 31 width (m),
        the height (m) and every fitting shape's width.

        Examples
        --------
        >>> import numpy as np, pulses, rocking
        >>> t = np.arange(0.0, 6.0, 0.01)
        >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 1.0)(t), 0.01)
        >>> gov = rocking.governing_pulse(pulses.fit_pulse(rec, shapes=["sine"]), 7.5)
        >>> sorted(gov.as_dict())[:3]
        ['ap_g', 'ap_m_s2', 'eq31_width_m']
        """
        c = self.candidate
        return {"shape": c.shape, "ap_m_s2": float(c.ap), "ap_g": float(c.ap_g), "tp_s": float(c.tp),
                "eq31_width_m": float(self.width), "height_m": float(self.height),
                "widths_m": {w_c[1].shape: float(w_c[0]) for w_c in self.widths}}


def governing_pulse(fit, height: float, *, cap_mass_ratio: float = 0.0,
                    tolerance: float = FIT_TOLERANCE, body=None) -> GoverningPulse:
    """The pulse Eq. 31 is applied to, as ``pipeline run`` chooses it.

    Among the shapes that fit the record (:func:`fitting_candidates`), the one whose Eq. 31
    fixed-point width at ``height`` is largest (the most demanding design; ties go to the better
    fit).  ``fit.best`` alone can give a narrower Eq. 31 width.

    Parameters
    ----------
    fit : pulses.PulseFit
        The record's pulse fits (:func:`pulses.fit_pulse`).
    height : float
        Full height of the column, m.
    cap_mass_ratio : float
        A rocking frame's cap beam mass over the columns' (0: a lone column).
    tolerance : float
        Share of the best score a shape needs to fit.
    body : rocking.bodies.Body or str, optional
        The column's shape (default rectangular; ``"cylinder"``: its ``p`` in Eq. 31).

    Returns
    -------
    GoverningPulse

    Examples
    --------
    >>> import pulses, rocking
    >>> import numpy as np
    >>> t = np.arange(0.0, 6.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.5 * pulses.G, 1.0, 1.0)(t), 0.01)
    >>> gov = rocking.governing_pulse(pulses.fit_pulse(rec), 7.5)
    >>> gov.width == max(w for w, _ in gov.widths)
    True
    """
    from .widths import required_width

    widths = [(float(required_width(height, c.pulse, rule="eq31", cap_mass_ratio=cap_mass_ratio,
                                    body=body).width), c)
              for c in fitting_candidates(fit, tolerance)]
    width, gov = max(widths, key=lambda wc: wc[0])  # max keeps the first of equal widths: the better fit
    return GoverningPulse(gov, width, float(height), widths)
