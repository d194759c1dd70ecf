"""Closed-form design rules (docs/theory.md section 5): Eq. 31, Eq. 20 and the envelope rule.

Each gives the minimum ``tan(alpha)`` of a block of frequency parameter ``p`` under a pulse of
amplitude ``ap`` (m/s^2) and period ``Tp`` (s), with no time-history analysis.
"""
from __future__ import annotations

import math

import numpy as np

from pulses import G
from pulses.shapes import AntisymmetricRicker

from .errors import RockingInputError


def _inputs(ap, tp, p):
    """``ap``, ``tp``, ``p`` as float arrays, checked: finite, ``tp`` and ``p`` positive."""
    ap, tp, p = (np.asarray(v, dtype=float) for v in (ap, tp, p))
    shown = lambda v, bad: repr(float(v)) if v.ndim == 0 else repr(float(v[bad].ravel()[0]))
    for name, v in (("ap", ap), ("tp", tp), ("p", p)):
        if not np.all(np.isfinite(v)):
            raise RockingInputError(f"{name} must be finite, got {shown(v, ~np.isfinite(v))}")
    for name, v in (("tp", tp), ("p", p)):
        if np.any(v <= 0):
            raise RockingInputError(f"{name} must be positive, got {shown(v, v <= 0)}")
    return ap, tp, p


def _out(value):
    value = np.asarray(value, dtype=float)
    return float(value) if value.ndim == 0 else value


def eq31(ap, tp, p):
    """Eq. 31, the paper's design rule: ``tan(alpha_min) = (ap/g) p Tp / (1 + p Tp)``.

    Parameters
    ----------
    ap : float or array
        Pulse acceleration amplitude, m/s^2 (its sign is irrelevant).
    tp : float or array
        Pulse period, s.
    p : float or array
        Frequency parameter of the block, rad/s.

    Returns the minimum ``tan(alpha)`` (float, or array when any input is an array).
    Rinaldi (0.71 g, 0.8 s, p = 1.381 rad/s) gives 0.373.

    Examples
    --------
    >>> import rocking
    >>> from pulses import G
    >>> round(float(rocking.eq31(0.71 * G, 0.8, 1.381)), 4)    # tan(alpha) Rinaldi 228's pulse needs
    0.3727
    """
    ap, tp, p = _inputs(ap, tp, p)
    x = p * tp
    return _out(np.abs(ap) / G * x / (1.0 + x))


def eq20(ap, tp, p, lam=1.0):
    """Eq. 20: ``tan(alpha_min) = (ap/g) (1 - exp(-lam p Tp))`` (``ap`` in m/s^2).

    Examples
    --------
    >>> import rocking
    >>> from pulses import G
    >>> round(float(rocking.eq20(0.71 * G, 0.8, 1.381)), 4)
    0.4748
    """
    ap, tp, p = _inputs(ap, tp, p)
    if not (math.isfinite(lam) and lam > 0):
        raise RockingInputError(f"lam must be positive and finite, got {lam!r}")
    x = p * tp
    return _out(np.abs(ap) / G * -np.expm1(-float(lam) * x))


#: The envelope rule, per shape: ``("hill", n, c)`` for ``phi = x^n / (c + x^n)`` (Eq. 31 is
#: ``n = c = 1``) or ``("exp", lam)`` for Eq. 20's ``phi = 1 - exp(-lam x)``, with ``x = pTp``
#: and ``tan(alpha_min) = (ap/g) phi``.  ``None``: every realisable shape (one-sine, symmetric
#: and antisymmetric Ricker) at once.  Derived by ``python -m rocking.envelope`` from 3240 exact
#: minimum slenderness values (pTp 0.1-20 log-spaced, ap/g 0.1-1.5): for each exponent n the
#: largest conservative c, divided by 1.01 and rounded down; the n with the smallest median
#: over-design kept.  Checked on an offset grid (README "Design").
ENVELOPE = {
    None: ("hill", 2.5, 1.86),
    "sine": ("hill", 2.5, 1.86),
    "ricker-sym": ("hill", 1.75, 4.0),
    AntisymmetricRicker.shape: ("hill", 3.0, 5.13),
    "rect": ("exp", 2.0),
}
#: range over which the envelope was derived and checked conservative
ENVELOPE_RANGE = {"pTp": (0.1, 20.0), "ap/g": (0.1, 1.5)}


def envelope_rule(ap, tp, p, shape=None):
    """Conservative closed form derived from the exact answers (``rule="envelope"``).

    ``tan(alpha_min) = (ap/g) (pTp)^n / (c + (pTp)^n)``, a generalised Eq. 31 (which is
    ``n = c = 1``), with ``n = 2.5, c = 1.86`` for every realisable pulse (``shape=None``, the
    default: one-sine, symmetric and antisymmetric Ricker).  A shape name gives that shape's own
    coefficients (:data:`ENVELOPE`); the rectangular pulse, which is not realisable, takes Eq. 20's
    form with ``lambda = 2``.  Never above ``ap/g`` (no uplift).

    Valid over :data:`ENVELOPE_RANGE` (``0.1 <= pTp <= 20``, ``0.1 <= ap/g <= 1.5``) with ``eta``
    from Eq. 5: there it is never below the exact minimum slenderness (smallest margin 1 %), while
    its over-design is at most about 3x for ``pTp >= 1`` (Eq. 31 is up to 9 % short for the
    one-sine pulse and up to 33 % for the rectangular pulse).  For ``pTp < 1`` it is far above the
    exact answer of the Rickers, which barely rock such large blocks.

    Examples
    --------
    >>> import rocking
    >>> from pulses import G
    >>> round(float(rocking.envelope_rule(0.71 * G, 0.8, 1.381)), 4)
    0.2898
    """
    if shape not in ENVELOPE:
        raise ValueError(f"envelope_rule: unknown shape {shape!r}; choose one of "
                         f"{', '.join(str(s) for s in ENVELOPE)}")
    ap, tp, p = _inputs(ap, tp, p)
    x = p * tp
    form = ENVELOPE[shape]
    if form[0] == "hill":
        _, n, c = form
        xn = x**n
        phi = xn / (c + xn)
    else:
        phi = -np.expm1(-form[1] * x)
    return _out(np.abs(ap) / G * phi)
