"""The free-standing rigid rectangular block of Housner's model (docs/theory.md section 1)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from pulses import G

from .frame import check_cap_mass_ratio, eta_frame, frame_p

#: slenderness at which Eq. 5 gives a perfectly plastic impact (eta = 0): asin(sqrt(2/3))
ALPHA_PLASTIC = math.asin(math.sqrt(2.0 / 3.0))


def eta_housner(alpha: float) -> float:
    """Largest coefficient of restitution for rocking, Eq. 5: ``1 - 1.5 sin^2(alpha)``.

    Clipped at 0 beyond ``alpha = 54.7 deg`` (no rocking, the impact is perfectly plastic).

    Examples
    --------
    >>> import rocking
    >>> round(rocking.eta_housner(0.2), 4)
    0.9408
    """
    return eta_frame(alpha, 0.0)  # the frame's formula at gamma = 0: one place for Eq. 5


@dataclass(frozen=True)
class Block:
    """A rocking block described by its frequency parameter and slenderness.

    Parameters
    ----------
    p : float
        Frequency parameter ``sqrt(3 g / (4 R))``, rad/s.
    alpha : float
        Slenderness angle ``atan(b/h)``, rad, in (0, pi/2).
    eta : float, optional
        Coefficient of restitution of the angular velocity at impact; default Eq. 5 (for a frame,
        :func:`rocking.frame.eta_frame`).
    height, width : float, optional
        Full dimensions in m, when known (set by :meth:`from_dimensions`).
    cap_mass_ratio : float, optional
        A rocking frame (docs/theory.md section 8): columns capped by a free beam of ``cap_mass_ratio``
        times their total mass.  ``p`` is then the frame's (see :meth:`from_dimensions`); 0 (the
        default) is the lone column.  Not part of equality: blocks with the same ``p``,
        ``alpha`` and ``eta`` rock alike.

    Examples
    --------
    >>> import rocking
    >>> column = rocking.Block.from_dimensions(7.5, 1.8)      # full height x full width, m
    >>> round(column.p, 3), round(column.alpha, 4), round(column.eta, 4)
    (1.381, 0.2355, 0.9183)
    """

    p: float
    alpha: float
    eta: float | None = None
    height: float | None = field(default=None, compare=False)
    width: float | None = field(default=None, compare=False)
    cap_mass_ratio: float = field(default=0.0, compare=False)

    def __post_init__(self):
        p, alpha = float(self.p), float(self.alpha)
        if not (math.isfinite(p) and p > 0.0):
            raise ValueError(f"Block: p must be positive and finite, got {self.p!r} rad/s")
        if not (math.isfinite(alpha) and 0.0 < alpha < math.pi / 2):
            raise ValueError(f"Block: alpha must lie in (0, pi/2) rad, got {self.alpha!r}")
        gamma = check_cap_mass_ratio(self.cap_mass_ratio)
        if self.eta is not None:
            eta = float(self.eta)
        else:
            eta = eta_housner(alpha) if gamma == 0.0 else eta_frame(alpha, gamma)
        if not (math.isfinite(eta) and 0.0 <= eta <= 1.0):
            raise ValueError(f"Block: eta must lie in [0, 1], got {self.eta!r}")
        object.__setattr__(self, "p", p)
        object.__setattr__(self, "alpha", alpha)
        object.__setattr__(self, "eta", eta)
        object.__setattr__(self, "cap_mass_ratio", gamma)

    @classmethod
    def from_dimensions(cls, height: float, width: float, eta: float | None = None, *,
                        cap_mass_ratio: float = 0.0) -> "Block":
        """Block of full ``height`` and ``width`` (m): ``R = sqrt(h^2 + b^2)``, ``p = sqrt(3g/4R)``.

        With ``cap_mass_ratio = gamma > 0``: a rocking frame of such columns capped by a free beam
        of ``gamma`` times their total mass (docs/theory.md section 8), ``p`` multiplied by
        ``sqrt((1 + 2 gamma)/(1 + 3 gamma))`` and ``eta`` defaulting to the frame's.
        """
        gamma = check_cap_mass_ratio(cap_mass_ratio)
        height, width = float(height), float(width)
        if not (math.isfinite(height) and height > 0.0 and math.isfinite(width) and width > 0.0):
            raise ValueError(f"Block: height and width must be positive and finite, got "
                             f"{height!r} x {width!r} m")
        radius = math.hypot(height / 2.0, width / 2.0)
        p = frame_p(math.sqrt(3.0 * G / (4.0 * radius)), gamma)
        return cls(p, math.atan2(width, height), eta, height=height, width=width,
                   cap_mass_ratio=gamma)

    @classmethod
    def from_tan_alpha(cls, p: float, tan_alpha: float, eta: float | None = None, *,
                       cap_mass_ratio: float = 0.0) -> "Block":
        """Block of frequency parameter ``p`` (rad/s) and slenderness ``tan(alpha) = B/H``; with
        ``cap_mass_ratio``, a rocking frame whose (frame's) ``p`` is given."""
        return cls(p, math.atan(tan_alpha), eta, cap_mass_ratio=cap_mass_ratio)

    @property
    def R(self) -> float:
        """Half-diagonal ``sqrt(h^2 + b^2)``, m, from ``p`` (a frame's: the size of the lone
        column that rocks like it, ``R (1 + 3 gamma)/(1 + 2 gamma)``)."""
        return 3.0 * G / (4.0 * self.p**2)

    @property
    def tan_alpha(self) -> float:
        """``tan(alpha) = b/h = B/H``."""
        return math.tan(self.alpha)

    @property
    def r(self) -> float:
        """Kinetic-energy ratio at impact, ``eta^2``."""
        return self.eta**2

    @property
    def uplift_acceleration(self) -> float:
        """Ground acceleration (m/s^2) that a block at rest needs to uplift: ``g tan(alpha)``."""
        return G * self.tan_alpha

    @property
    def verge_velocity(self) -> float:
        """Eq. 23: the angular velocity (rad/s) at rest that just brings the block to ``alpha``."""
        return self.p * math.sqrt(2.0 * (1.0 - math.cos(self.alpha)))

    def __repr__(self):
        dims = ""
        if self.height is not None:
            dims = f", {self.height:g} x {self.width:g} m"
        if self.cap_mass_ratio:
            dims += f", cap_mass_ratio={self.cap_mass_ratio:g}"
        return (f"Block(p={self.p:.6g} rad/s, alpha={self.alpha:.6g} rad "
                f"(tan {self.tan_alpha:.4g}), eta={self.eta:.4g}{dims})")
