"""Near-fault scenario pulses: magnitude -> period (Eq. 6) and velocity amplitude -> acceleration.

Within about 10 km of the fault the pulse period grows with magnitude, Eq. 6:
``ln Tp = -2.9 + 0.5 Mw``, and the velocity pulse has an amplitude ``vp`` of 60-120 cm/s (about
90 cm/s typical).  The acceleration amplitude then follows from the shape, by integrating it
once (ground velocity from rest, ``v(t) = int ug''``):

=============  ===========================================================  ====================
shape          ground velocity                                             ``ap = c vp / Tp``
=============  ===========================================================  ====================
rect           ``ap t`` on the pulse, peak ``ap Tp`` at its end              ``c = 1``
sine           ``ap Tp/(2 pi) (1 - cos(2 pi t/Tp))``, peak ``ap Tp/pi``        ``c = pi``
ricker-sym     ``ap t exp(-pi^2 t^2/Tp^2)``, peak at ``t = Tp/(pi sqrt 2)``  ``c = pi sqrt(2 e)``
ricker-anti    ``ap/beta sqrt(3) Tp/(2 pi) (1 - x^2) exp(-x^2/2)``, peak x=0  ``c = 2 pi beta/sqrt 3``
=============  ===========================================================  ====================

(For the antisymmetric Ricker, ``x = 2 pi t/(sqrt(3) Tp)`` and ``d/dx[(1 - x^2) e^{-x^2/2}] =
(x^3 - 3x) e^{-x^2/2}``; the side lobes at ``x^2 = 3`` reach only ``2 e^{-3/2} = 0.45`` of the
central peak.)  The rectangular pulse leaves a residual velocity ``ap Tp``; it is not realisable.
"""
from __future__ import annotations

import math

from .shapes import BETA, SHAPES, Pulse, make_pulse

#: ``ap = VP_TO_AP[shape] * vp / Tp``: the factor between peak ground velocity and acceleration
VP_TO_AP = {
    "rect": 1.0,
    "sine": math.pi,
    "ricker-sym": math.pi * math.sqrt(2.0 * math.e),
    "ricker-anti": 2.0 * math.pi * BETA / math.sqrt(3.0),
}

#: typical range of near-fault velocity-pulse amplitudes, m/s
VP_RANGE = (0.6, 1.2)


def pulse_period(magnitude: float) -> float:
    """Eq. 6: near-fault pulse period (s) for moment magnitude ``Mw``: ``exp(-2.9 + 0.5 Mw)``."""
    magnitude = float(magnitude)
    if not math.isfinite(magnitude):
        raise ValueError(f"magnitude must be finite, got {magnitude!r}")
    return math.exp(-2.9 + 0.5 * magnitude)


def peak_velocity(pulse: Pulse) -> float:
    """Peak ground velocity (m/s) of a pulse starting from rest, from the closed forms above."""
    return abs(pulse.ap) * pulse.tp / VP_TO_AP[pulse.shape]


def design_pulse(magnitude: float, shape: str = "sine", vp: float = 0.9, t0: float = 0.0) -> Pulse:
    """A near-fault scenario pulse: ``Tp`` from Eq. 6 and ``ap`` from the velocity amplitude.

    Parameters
    ----------
    magnitude : float
        Moment magnitude ``Mw`` (Eq. 6 was fitted for about 5.5-7.6, sites within ~10 km).
    shape : str
        ``"sine"`` (default), ``"ricker-sym"``, ``"ricker-anti"`` or ``"rect"``.
    vp : float
        Peak ground velocity of the pulse, m/s (0.6-1.2 near the fault, 0.9 typical).
    t0 : float
        Arrival time or centre of the pulse, s.

    Returns
    -------
    pulses.Pulse
        With ``ap = c vp / Tp`` (m/s^2, ``c`` from :data:`VP_TO_AP`).  Mw 7.0, one-sine,
        0.9 m/s: Tp = 1.822 s, ap = 1.552 m/s^2 = 0.158 g.
    """
    if shape not in SHAPES:
        raise ValueError(f"unknown pulse shape {shape!r}; choose one of {', '.join(SHAPES)}")
    vp = float(vp)
    if not (math.isfinite(vp) and vp > 0.0):
        raise ValueError(f"vp must be a positive velocity in m/s, got {vp!r}")
    tp = pulse_period(magnitude)
    return make_pulse(shape, VP_TO_AP[shape] * vp / tp, tp, t0)
