"""Near-fault scenario pulses: magnitude -> period (Eq. 6) and velocity amplitude -> acceleration.

Within about 10 km of the fault the pulse period grows with magnitude, Eq. 6:
``ln Tp = -2.9 + 0.5 Mw``, and the velocity pulse has an amplitude ``vp`` of 60-120 cm/s (about
90 cm/s typical).  The acceleration amplitude then follows from the shape, by integrating it
once (ground velocity from rest, ``v(t) = int ug''``): ``ap = c vp / Tp`` with ``c`` the shape's
:attr:`pulses.Pulse.vp_to_ap` (1 for the rectangle, pi for the one-sine, ``pi sqrt(2 e)`` for the
symmetric and ``2 pi beta / sqrt 3`` for the antisymmetric Ricker; each class shows its velocity
history).  The rectangular pulse leaves a residual velocity ``ap Tp``; it is not realisable.
"""
from __future__ import annotations

import math

from .shapes import SHAPES, Pulse, shape_class

#: ``ap = VP_TO_AP[shape] * vp / Tp``: the factor between peak ground velocity and acceleration
VP_TO_AP = {name: cls.vp_to_ap for name, cls in SHAPES.items()}

#: typical range of near-fault velocity-pulse amplitudes, m/s
VP_RANGE = (0.6, 1.2)


def pulse_period(magnitude: float) -> float:
    """Eq. 6: near-fault pulse period (s) for moment magnitude ``Mw``: ``exp(-2.9 + 0.5 Mw)``.

    Examples
    --------
    >>> import pulses
    >>> round(pulses.pulse_period(7.0), 3)     # s, for a magnitude 7 event
    1.822
    """
    magnitude = float(magnitude)
    if not math.isfinite(magnitude):
        raise ValueError(f"magnitude must be finite, got {magnitude!r}")
    return math.exp(-2.9 + 0.5 * magnitude)


def peak_velocity(pulse: Pulse) -> float:
    """Peak ground velocity (m/s) of a pulse starting from rest, from the closed forms above."""
    return abs(pulse.ap) * pulse.tp / type(pulse).vp_to_ap


def design_pulse(magnitude: float, shape: str = "sine", vp: float = 0.9, t0: float = 0.0) -> Pulse:
    """A near-fault scenario pulse: ``Tp`` from Eq. 6 and ``ap`` from the velocity amplitude.

    Parameters
    ----------
    magnitude : float
        Moment magnitude ``Mw`` (Eq. 6 was fitted for about 5.5-7.6, sites within ~10 km).
    shape : str
        ``"sine"`` (default) or another name of :data:`pulses.SHAPES`.
    vp : float
        Peak ground velocity of the pulse, m/s (0.6-1.2 near the fault, 0.9 typical).
    t0 : float
        Arrival time or centre of the pulse, s.

    Returns
    -------
    pulses.Pulse
        With ``ap = c vp / Tp`` (m/s^2, ``c`` from :data:`VP_TO_AP`).  Mw 7.0, one-sine,
        0.9 m/s: Tp = 1.822 s, ap = 1.552 m/s^2 = 0.158 g.

    Examples
    --------
    >>> import pulses
    >>> pulses.design_pulse(7.0)               # the one-sine of a magnitude 7 event (vp = 0.9 m/s)
    OneSine(ap=1.55173, tp=1.82212, t0=0)
    """
    cls = shape_class(shape)
    vp = float(vp)
    if not (math.isfinite(vp) and vp > 0.0):
        raise ValueError(f"vp must be a positive velocity in m/s, got {vp!r}")
    tp = pulse_period(magnitude)
    return cls(cls.vp_to_ap * vp / tp, tp, t0)
