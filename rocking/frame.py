"""Rocking frames: identical free-standing columns capped by a free rigid beam (docs/theory.md section 8).

``N`` columns (each ``R``, ``alpha``, ``p``) carry a rigid beam of mass ``m_b`` that rests on them
without connection (Makris & Vassiliou 2013).  With ``gamma = m_b / (N m)`` (the beam's mass over
the columns' total mass) the frame obeys the single-column equation of motion with

* ``p_frame = p sqrt((1 + 2 gamma) / (1 + 3 gamma))`` (:func:`frame_p`), i.e. it rocks like one
  column of the same ``alpha`` and the larger size ``R (1 + 3 gamma) / (1 + 2 gamma)``
  (:func:`equivalent_size`);
* the velocity ratio at impact ``eta_frame`` (:func:`eta_frame`);
* uplift at ``|ug''| > g tan(alpha)`` whatever ``gamma``.

A frame is a :class:`rocking.Block` built with ``cap_mass_ratio=gamma``
(``Block.from_dimensions(height, width, cap_mass_ratio=gamma)``); everything that takes a block
takes a frame.  ``tests/test_frame.py`` checks both forms against a direct two-body computation
(Lagrange's equation and the impulse-momentum balance written from the bodies' coordinates).
"""
from __future__ import annotations

import math


def check_cap_mass_ratio(gamma) -> float:
    """``gamma`` as a float, or a one-line ``ValueError`` when it is not finite and >= 0."""
    try:
        value = float(gamma)
    except (TypeError, ValueError):
        raise ValueError(f"cap_mass_ratio must be a number >= 0, got {gamma!r}") from None
    if not (math.isfinite(value) and value >= 0.0):
        raise ValueError(f"cap_mass_ratio must be finite and >= 0 (beam mass over the columns' "
                         f"total mass), got {gamma!r}")
    return value


def frame_p(p: float, gamma: float) -> float:
    """Frequency parameter of the frame, rad/s: ``p sqrt((1 + 2 gamma) / (1 + 3 gamma))``.

    Parameters
    ----------
    p : float
        Frequency parameter of one column, ``sqrt(3 g / (4 R))``, rad/s.
    gamma : float
        Cap mass ratio ``m_b / (N m)``.  ``gamma = 0`` returns ``p`` itself.

    Examples
    --------
    >>> import rocking
    >>> round(rocking.frame_p(1.381, 0.5), 4)
    1.2352
    """
    if gamma == 0.0:
        return p
    return p * math.sqrt((1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma))


def equivalent_size(radius: float, gamma: float) -> float:
    """Half-diagonal (m) of the lone column of the same ``alpha`` that rocks like the frame:
    ``R (1 + 3 gamma) / (1 + 2 gamma)``.

    Examples
    --------
    >>> import rocking
    >>> round(rocking.equivalent_size(4.0, 0.5), 4)
    5.0
    """
    return radius * (1.0 + 3.0 * gamma) / (1.0 + 2.0 * gamma)


def eta_frame(alpha: float, gamma: float) -> float:
    """Largest velocity ratio at impact of the frame (Housner's Eq. 5 at ``gamma = 0``):

    ``(1 - 1.5 sin^2(alpha) + 3 gamma cos(2 alpha)) / (1 + 3 gamma)``, clipped at 0 (a perfectly
    plastic impact).  It tends to ``cos(2 alpha)`` as ``gamma -> infinity``; it is below Housner's
    by ``1.5 gamma sin^2(alpha) / (1 + 3 gamma)``: a heavy beam makes every impact more dissipative.

    Parameters
    ----------
    alpha : float
        Slenderness ``atan(b/h)`` of the columns, rad.
    gamma : float
        Cap mass ratio ``m_b / (N m)``.

    Examples
    --------
    >>> import rocking
    >>> round(rocking.eta_frame(0.2, 0.5), 4)
    0.929
    """
    s2 = math.sin(alpha) ** 2
    if gamma == 0.0:
        return max(0.0, 1.0 - 1.5 * s2)
    return max(0.0, (1.0 - 1.5 * s2 + 3.0 * gamma * math.cos(2.0 * alpha)) / (1.0 + 3.0 * gamma))
