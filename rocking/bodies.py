"""The shape of the rocking body (docs/theory.md, "Bodies"): what ``p`` and Housner's impact rule are
for a body other than the rectangular block.

Any symmetric rigid body that rocks in a plane on two edges, with its centre of mass at ``R`` from
the pivots at the angle ``alpha`` from the vertical and its moment of inertia ``I_o`` about a pivot,
obeys the rectangular block's equation of motion with

    p^2 = m g R / I_o,        eta = 1 - 2 m R^2 sin^2(alpha) / I_o     (Housner's impact rule)

so a body is one number: its inertia ratio ``k = I_o / (m R^2)``.  The rectangular block has
``k = 4/3`` (``p = sqrt(3 g / 4 R)``, Eq. 5); a solid circular cylinder of diameter ``D`` and
height ``H`` rocking in the plane of a diameter has ``I_o = m (5 D^2 / 16 + H^2 / 3)``, that is
``k = 4/3 - sin^2(alpha) / 12`` with ``tan(alpha) = D / H``.  In the formulas the rectangle's
values are multiplied by the ratio ``c = (4/3) / k`` (:meth:`Body.ratio`), which is 1 exactly for
the rectangle: its numbers are computed by the same floating operations as before.

A cylinder rocking in a plane leaves out what a real one may do besides: wobbling (rolling on its
rim, the rocking plane turning) and rolling or sliding on its base.  A body given by ``I_o``, ``R``
and ``alpha`` (:meth:`rocking.Block.from_body`) is that body only: it has no width to vary, so it
is checked, not designed.

Examples
--------
>>> from rocking.bodies import Body
>>> Body.parse("cyl"), Body.parse("rect").is_rectangular
(Body('cylinder'), True)
>>> import math
>>> round(Body.parse("cylinder").inertia_ratio(math.atan(1.8 / 7.5)), 4)
1.3288
"""
from __future__ import annotations

import math
from dataclasses import dataclass

#: the kinds of body and what a user may type for each (``--block cyl:7.5x1.8``)
KINDS = {"rectangular": ("rect", "rectangular", "block"), "cylinder": ("cyl", "cylinder"),
         "custom": ()}

#: inertia ratios within this relative distance of the rectangle's 4/3 are the rectangle's (a body
#: given the rectangle's own ``I_o`` differs from it only by the rounding of the user's product)
RECTANGLE_TOL = 1e-12


@dataclass(frozen=True)
class Body:
    """The shape of a rocking body: ``"rectangular"``, ``"cylinder"`` (solid, circular, rocking in a
    plane) or ``"custom"`` (a constant inertia ratio ``inertia = I_o / (m R^2)``).

    Examples
    --------
    >>> import math
    >>> from rocking.bodies import CYLINDER
    >>> alpha = math.atan(1.8 / 7.5)
    >>> round(CYLINDER.eta_housner(alpha), 4)                  # the cylinder's impact rule
    0.918
    """

    kind: str = "rectangular"
    inertia: float | None = None

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"body: kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        if self.kind == "custom":
            k = float(self.inertia) if self.inertia is not None else math.nan
            # a point mass at R has k = 1; no rigid body has less about a point at distance R
            if not (math.isfinite(k) and k >= 1.0):
                raise ValueError("body: a custom body's inertia ratio I_o / (m R^2) must be "
                                 f"finite and at least 1, got {self.inertia!r}")
            object.__setattr__(self, "inertia", k)
        elif self.inertia is not None:
            raise ValueError(f"body: a {self.kind} body's inertia follows from its shape; "
                             "inertia= goes with kind='custom'")

    @classmethod
    def parse(cls, text) -> "Body":
        """A body from its name (``rect``, ``rectangular``, ``cyl``, ``cylinder``); a
        :class:`Body` as it is; None is the rectangle."""
        if text is None:
            return RECTANGULAR
        if isinstance(text, cls):
            return text
        name = str(text).strip().lower()
        for kind, names in KINDS.items():
            if name in names:
                return cls(kind)
        known = ", ".join(n for names in KINDS.values() for n in names)
        raise ValueError(f"body: unknown shape {text!r}; choose one of {known}")

    @classmethod
    def from_inertia(cls, inertia_ratio: float) -> "Body":
        """The body of inertia ratio ``I_o / (m R^2)``: the rectangle where it is 4/3 to
        :data:`RECTANGLE_TOL`, else a custom body."""
        k = float(inertia_ratio)
        if math.isfinite(k) and abs(0.75 * k - 1.0) <= RECTANGLE_TOL:
            return RECTANGULAR
        return cls("custom", k)

    @property
    def is_rectangular(self) -> bool:
        return self.kind == "rectangular"

    @property
    def has_dimensions(self) -> bool:
        """Whether the body follows from a height and a width (and so can be designed)."""
        return self.kind != "custom"

    def inertia_ratio(self, alpha: float) -> float:
        """``k = I_o / (m R^2)`` at slenderness ``alpha`` (rad)."""
        if self.kind == "rectangular":
            return 4.0 / 3.0
        if self.kind == "cylinder":
            return 4.0 / 3.0 - math.sin(alpha) ** 2 / 12.0
        return self.inertia

    def ratio(self, alpha: float) -> float:
        """``c = (4/3) / k``: the body's ``p^2`` and ``1 - eta`` over the rectangle's of the same
        ``R`` and ``alpha`` (1.0 exactly for the rectangle)."""
        if self.kind == "rectangular":
            return 1.0
        if self.kind == "cylinder":
            s2 = math.sin(alpha) ** 2
            return 16.0 / (16.0 - s2)
        return (4.0 / 3.0) / self.inertia

    def p(self, radius: float, alpha: float) -> float:
        """Frequency parameter (rad/s) of the body of size ``R = radius`` (m): ``sqrt(g R m / I_o)``."""
        from pulses import G

        if self.kind == "rectangular":
            return math.sqrt(3.0 * G / (4.0 * radius))
        return math.sqrt(3.0 * G / (4.0 * radius) * self.ratio(alpha))

    def radius(self, p: float, alpha: float) -> float:
        """Size ``R`` (m) of the body of frequency parameter ``p`` (rad/s): ``g / (k p^2)``."""
        from pulses import G

        if self.kind == "rectangular":
            return 3.0 * G / (4.0 * p**2)
        return 3.0 * G / (4.0 * p**2) * self.ratio(alpha)

    def eta_housner(self, alpha: float) -> float:
        """Housner's impact rule for this body, ``1 - 2 sin^2(alpha) / k`` (Eq. 5 for the
        rectangle, ``1 - 1.5 sin^2(alpha)``), clipped at 0 (a perfectly plastic impact)."""
        s2 = math.sin(alpha) ** 2
        if self.kind == "rectangular":
            return max(0.0, 1.0 - 1.5 * s2)
        return max(0.0, 1.0 - 1.5 * self.ratio(alpha) * s2)

    def prefix(self) -> str:
        """What a column label starts with (``cyl:``); empty for the rectangle."""
        return "" if self.kind == "rectangular" else ("cyl:" if self.kind == "cylinder" else "body:")

    def describe(self) -> str:
        """Plain words for reports: ``rectangular``, ``cylinder (planar rocking)``,
        ``body I_o/(m R^2) = 1.2``."""
        if self.kind == "cylinder":
            return "cylinder (planar rocking)"
        if self.kind == "custom":
            return f"body I_o/(m R^2) = {self.inertia:.6g}"
        return "rectangular"

    def __repr__(self) -> str:
        return f"Body({self.kind!r})" if self.kind != "custom" else f"Body('custom', {self.inertia!r})"


RECTANGULAR = Body("rectangular")
CYLINDER = Body("cylinder")


def check_frame(body: Body, gamma: float) -> None:
    """A rocking frame (``cap_mass_ratio > 0``) is modelled for rectangular columns only:
    ValueError otherwise (docs/theory.md section 8 derives its ``p`` and ``eta`` for them)."""
    if gamma and not body.is_rectangular:
        raise ValueError(f"cap_mass_ratio: rocking frames are modelled for rectangular columns "
                         f"only (docs/theory.md section 8), not a {body.kind} body; design the "
                         "columns alone (cap_mass_ratio=0) or as rectangular")
