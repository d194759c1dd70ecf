"""The free-standing rigid rectangular block of Housner's model (docs/theory.md section 1)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

from pulses import G

from .bodies import RECTANGULAR, Body, check_frame
from .frame import check_cap_mass_ratio, eta_frame, frame_p
from .restitution import Restitution

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


def _p_alpha(height: float, width: float, gamma: float,
             body: Body = RECTANGULAR) -> tuple[float, float]:
    """``(p, alpha)`` (rad/s, rad) of a column ``height`` x ``width`` (m), a frame's with ``gamma``;
    of the ``body``'s shape (:mod:`rocking.bodies`; a cylinder's width is its diameter)."""
    radius = math.hypot(height / 2.0, width / 2.0)
    if body.is_rectangular:
        return frame_p(math.sqrt(3.0 * G / (4.0 * radius)), gamma), math.atan2(width, height)
    alpha = math.atan2(width, height)
    return body.p(radius, alpha), alpha


def _body(body, gamma: float) -> Body:
    """``body`` as a :class:`rocking.bodies.Body` (a name is parsed), checked against ``gamma``."""
    body = Body.parse(body)
    check_frame(body, gamma)
    return body


def _restitution(eta, alpha: float, gamma: float, who: str, body: Body = RECTANGULAR) -> float:
    """``eta`` checked to lie in [0, 1], or where None Eq. 5 at ``alpha`` (the frame's with
    ``gamma``, :func:`rocking.frame.eta_frame`; Housner's at ``gamma = 0``; the ``body``'s own
    impact rule for another body); a single :class:`rocking.restitution.Restitution` gives its
    ``eta`` at ``alpha`` (a factor: of the body's rule)."""
    if eta is None:
        value = eta_frame(alpha, gamma) if body.is_rectangular else body.eta_housner(alpha)
    elif isinstance(eta, Restitution):
        if body.is_rectangular or eta.kind != "factor" or eta.is_band:
            value = eta.eta_at(alpha, gamma)
        else:
            value = min(1.0, eta.low * body.eta_housner(alpha))
    else:
        value = float(eta)
    if not (math.isfinite(value) and 0.0 <= value <= 1.0):
        raise ValueError(f"{who}: eta must lie in [0, 1], got {eta!r}")
    return value


@dataclass(frozen=True)
class Block:
    """A rocking block described by its frequency parameter and slenderness.

    Parameters
    ----------
    p : float
        Frequency parameter ``sqrt(3 g / (4 R))``, rad/s.
    alpha : float
        Slenderness angle ``atan(b/h)``, rad, in (0, pi/2).
    eta : float or Restitution, optional
        Coefficient of restitution of the angular velocity at impact; default Eq. 5 (for a frame,
        :func:`rocking.frame.eta_frame`).  A single :class:`rocking.restitution.Restitution`
        (a factor of Eq. 5, an ``eta`` or an ``r``) is turned into its ``eta`` at ``alpha``.
    height, width : float, optional
        Full dimensions in m, when known (set by :meth:`from_dimensions`).
    cap_mass_ratio : float, optional
        A rocking frame (docs/theory.md section 8): columns capped by a free beam of ``cap_mass_ratio``
        times their total mass.  ``p`` is then the frame's (see :meth:`from_dimensions`); 0 (the
        default) is the lone column.  Not part of equality: blocks with the same ``p``,
        ``alpha`` and ``eta`` rock alike.
    body : rocking.bodies.Body or str, optional
        The body's shape (:mod:`rocking.bodies`): rectangular (the default), ``"cylinder"`` or a
        custom inertia ratio; it sets the default ``eta`` and what ``R`` is for a given ``p``, and
        the base forces of :func:`rocking.friction_demand`.  Not part of equality either.

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
    body: Body = field(default=RECTANGULAR, compare=False)

    def __post_init__(self):
        p, alpha = float(self.p), float(self.alpha)
        if not (math.isfinite(p) and p > 0.0):
            raise ValueError(f"Block: p must be positive and finite, got {self.p!r} rad/s")
        if not (math.isfinite(alpha) and 0.0 < alpha < math.pi / 2):
            raise ValueError(f"Block: alpha must lie in (0, pi/2) rad, got {self.alpha!r}")
        gamma = check_cap_mass_ratio(self.cap_mass_ratio)
        body = _body(self.body, gamma)
        eta = _restitution(self.eta, alpha, gamma, "Block", body)
        object.__setattr__(self, "p", p)
        object.__setattr__(self, "alpha", alpha)
        object.__setattr__(self, "eta", eta)
        object.__setattr__(self, "cap_mass_ratio", gamma)
        object.__setattr__(self, "body", body)

    @classmethod
    def from_dimensions(cls, height: float, width: float, eta: float | None = None, *,
                        cap_mass_ratio: float = 0.0, body: Body | str | None = None) -> "Block":
        """Block of full ``height`` and ``width`` (m): ``R = sqrt(h^2 + b^2)``, ``p = sqrt(3g/4R)``.

        With ``cap_mass_ratio = gamma > 0``: a rocking frame of such columns capped by a free beam
        of ``gamma`` times their total mass (docs/theory.md section 8), ``p`` multiplied by
        ``sqrt((1 + 2 gamma)/(1 + 3 gamma))`` and ``eta`` defaulting to the frame's.  With
        ``body="cylinder"``: a solid circular column of diameter ``width`` rocking in a plane,
        ``p^2 = m g R / I_o`` with ``I_o = m (5 D^2/16 + H^2/3)`` and its own impact rule
        (:mod:`rocking.bodies`).

        Examples
        --------
        >>> import rocking
        >>> drum = rocking.Block.from_dimensions(7.5, 1.8, body="cylinder")
        >>> round(drum.p, 4), round(drum.eta, 4)
        (1.3836, 0.918)
        """
        gamma = check_cap_mass_ratio(cap_mass_ratio)
        body = _body(body, gamma)
        if not body.has_dimensions:
            raise ValueError("Block: a custom body has no height and width; build it with "
                             "Block.from_body(I_o, R, alpha)")
        height, width = float(height), float(width)
        if not (math.isfinite(height) and height > 0.0 and math.isfinite(width) and width > 0.0):
            raise ValueError(f"Block: height and width must be positive and finite, got "
                             f"{height!r} x {width!r} m")
        return cls(*_p_alpha(height, width, gamma, body), eta, height=height, width=width,
                   cap_mass_ratio=gamma, body=body)

    @classmethod
    def from_tan_alpha(cls, p: float, tan_alpha: float, eta: float | None = None, *,
                       cap_mass_ratio: float = 0.0, body: Body | str | None = None) -> "Block":
        """Block of frequency parameter ``p`` (rad/s) and slenderness ``tan(alpha) = B/H``; with
        ``cap_mass_ratio``, a rocking frame whose (frame's) ``p`` is given; ``body`` as
        :meth:`from_dimensions` (it sets the default ``eta``)."""
        return cls(p, math.atan(tan_alpha), eta, cap_mass_ratio=cap_mass_ratio,
                   body=Body.parse(body))

    @classmethod
    def from_body(cls, I_o: float, R: float, alpha: float, eta: float | None = None, *,
                  mass: float = 1.0) -> "Block":
        """Any symmetric rigid body rocking in a plane on two edges: moment of inertia ``I_o``
        about a pivot (kg m^2, of a body of ``mass`` kg; per unit mass with the default 1),
        centre of mass at ``R`` (m) from the pivots at ``alpha`` (rad) from the vertical.

        ``p^2 = m g R / I_o`` and, by default, Housner's impact rule
        ``eta = 1 - 2 m R^2 sin^2(alpha) / I_o`` (docs/theory.md, "Bodies").  A body whose
        ``I_o`` is the rectangle's ``(4/3) m R^2`` to rounding (relative 1e-12) is the
        rectangular block: its numbers are the block's, bit for bit.

        Examples
        --------
        >>> import math, rocking
        >>> R, alpha = math.hypot(3.75, 0.9), math.atan2(1.8, 7.5)
        >>> rocking.Block.from_body(4 / 3 * R**2, R, alpha) == rocking.Block.from_dimensions(7.5, 1.8)
        True
        """
        I_o, R, alpha, mass = float(I_o), float(R), float(alpha), float(mass)
        for name, v in (("I_o", I_o), ("R", R), ("mass", mass)):
            if not (math.isfinite(v) and v > 0.0):
                raise ValueError(f"Block.from_body: {name} must be positive and finite, got {v!r}")
        if not (math.isfinite(alpha) and 0.0 < alpha < math.pi / 2):
            raise ValueError(f"Block.from_body: alpha must lie in (0, pi/2) rad, got {alpha!r}")
        try:
            body = Body.from_inertia(I_o / (mass * R * R))
        except ValueError:
            raise ValueError(f"Block.from_body: I_o = {I_o!r} is below m R^2 = {mass * R * R!r}: "
                             "no rigid body has its centre of mass at R with less") from None
        return cls(body.p(R, alpha), alpha, eta, body=body)

    @property
    def R(self) -> float:
        """Half-diagonal ``sqrt(h^2 + b^2)``, m, from ``p`` (a frame's: the size of the lone
        column that rocks like it, ``R (1 + 3 gamma)/(1 + 2 gamma)``); another body's distance
        from pivot to centre of mass, ``g / (k p^2)``."""
        if self.body.is_rectangular:
            return 3.0 * G / (4.0 * self.p**2)
        return self.body.radius(self.p, self.alpha)

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
        if not self.body.is_rectangular:
            dims += f", {self.body.describe()}"
        return (f"Block(p={self.p:.6g} rad/s, alpha={self.alpha:.6g} rad "
                f"(tan {self.tan_alpha:.4g}), eta={self.eta:.4g}{dims})")


class Blocks:
    """Many blocks as arrays: what a search runs by the thousand, without a :class:`Block` each
    (the same numbers as :class:`Block`, element by element).

    Parameters
    ----------
    p, alpha : array_like
        Frequency parameters (rad/s) and slenderness angles (rad), as :class:`Block`'s (not
        checked again: they come from checked dimensions or a search's own values).
    eta : float or Restitution, optional
        Coefficient of restitution of all; default Eq. 5 (the frame's with ``cap_mass_ratio``)
        at each ``alpha``; a single :class:`rocking.restitution.Restitution` at each ``alpha``.
    cap_mass_ratio : float, optional
        As :class:`Block`'s.
    body : rocking.bodies.Body or str, optional
        As :class:`Block`'s (the same for all).

    Iterating gives the :class:`Block` of each (for solvers that run one at a time).

    Examples
    --------
    >>> import rocking
    >>> many = rocking.Blocks.from_dimensions(7.5, [1.2, 1.8])
    >>> list(many)[1] == rocking.Block.from_dimensions(7.5, 1.8)
    True
    """

    def __init__(self, p, alpha, eta: float | None = None, *, cap_mass_ratio: float = 0.0,
                 height: float | None = None, widths=None, body: Body | str | None = None):
        import numpy as np

        gamma = check_cap_mass_ratio(cap_mass_ratio)
        body = _body(body, gamma)
        self.p = np.ascontiguousarray(p, dtype=float).ravel()
        self.alpha = np.ascontiguousarray(alpha, dtype=float).ravel()
        if eta is None or isinstance(eta, Restitution):
            self.eta = np.array([_restitution(eta, a, gamma, "Blocks", body)
                                 for a in self.alpha.tolist()], dtype=float)
        else:
            self.eta = np.full(self.p.size, _restitution(eta, 0.0, gamma, "Blocks"))
        self.cap_mass_ratio, self.height, self.body = gamma, height, body
        self.widths = [None] * self.p.size if widths is None else widths

    @classmethod
    def from_dimensions(cls, height: float, widths, eta: float | None = None, *,
                        cap_mass_ratio: float = 0.0, body: Body | str | None = None) -> "Blocks":
        """Columns ``height`` tall (m), one per width of ``widths`` (m); ``eta``,
        ``cap_mass_ratio`` and ``body`` as :meth:`Block.from_dimensions`."""
        import numpy as np

        gamma = check_cap_mass_ratio(cap_mass_ratio)
        body = _body(body, gamma)
        if not body.has_dimensions:
            raise ValueError("Blocks: a custom body has no height and width")
        height = float(height)
        widths = np.asarray(widths, dtype=float).ravel().tolist()
        if not (math.isfinite(height) and height > 0.0
                and all(math.isfinite(w) and w > 0.0 for w in widths)):
            raise ValueError(f"Blocks: height and widths must be positive and finite, got "
                             f"{height!r} x {widths!r} m")
        pa = [_p_alpha(height, w, gamma, body) for w in widths]
        return cls([x[0] for x in pa], [x[1] for x in pa], eta, cap_mass_ratio=gamma,
                   height=height, widths=widths, body=body)

    @classmethod
    def from_tan_alpha(cls, p, tan_alpha, eta: float | None = None, *,
                       cap_mass_ratio: float = 0.0, body: Body | str | None = None) -> "Blocks":
        """Blocks of frequency parameters ``p`` (rad/s) and slenderness ``tan(alpha)``, as
        :meth:`Block.from_tan_alpha` makes each."""
        import numpy as np

        alpha = [math.atan(t) for t in np.asarray(tan_alpha, dtype=float).ravel().tolist()]
        return cls(p, alpha, eta, cap_mass_ratio=cap_mass_ratio, body=body)

    def __len__(self) -> int:
        return int(self.p.size)

    def __iter__(self):
        for p, a, e, w in zip(self.p.tolist(), self.alpha.tolist(), self.eta.tolist(), self.widths):
            yield Block(p, a, e, height=self.height, width=w, cap_mass_ratio=self.cap_mass_ratio,
                        body=self.body)
