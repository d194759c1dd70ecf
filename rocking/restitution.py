"""The coefficient of restitution as a design input (docs/theory.md, "Restitution").

Housner's rule (Eq. 5) gives the largest velocity ratio at impact for which a block rocks rather
than bounces, ``eta = 1 - 1.5 sin^2(alpha)``.  Tests find less on soft interfaces and, on hard
ones, a little less or a little more: a restitution is an input with a band, not a constant.
:class:`Restitution` is that input, one value or a band ``low:high``, stated in one of three ways:

``factor``
    a multiple of Eq. 5 at the column's own slenderness (and of the frame's rule for a rocking
    frame), so it follows the width a design tries: ``eta = min(1, factor * eta_Eq5(alpha))``
    (``eta`` above 1 would create energy at impact, so the factor saturates at a perfectly
    elastic impact);
``eta``
    the velocity ratio itself, the same at every width;
``r``
    the kinetic-energy ratio ``r = eta^2``, as tests often report it.

Examples
--------
>>> from rocking.restitution import Restitution
>>> band = Restitution.parse("0.95:1.05")
>>> band, band.is_band
(Restitution('0.95:1.05'), True)
>>> round(Restitution.parse("1.025").eta_at(0.2355), 4)
0.9413
>>> [round(v.eta_at(0.2355), 4) for v in band.values(3)]
[0.8724, 0.9183, 0.9643]
>>> Restitution.parse("r=0.81").eta_at(0.2355)
0.9
"""
from __future__ import annotations

import math
from dataclasses import dataclass

#: the ways a restitution is stated (see the module's docstring)
KINDS = ("factor", "eta", "r")

_SYNTAX = ("FACTOR or LOW:HIGH (factors of Eq. 5), eta=VALUE[:HIGH] (velocity ratio) or "
           "r=VALUE[:HIGH] (energy ratio)")


@dataclass(frozen=True)
class Restitution:
    """A restitution at impact: one value or a band, as a factor of Eq. 5, an ``eta`` or an ``r``.

    Parameters
    ----------
    low : float
        The value (or the band's lower end).
    high : float, optional
        The band's upper end; None (or ``low``): a single value.
    kind : {"factor", "eta", "r"}
        How ``low`` and ``high`` are stated (module docstring).

    Examples
    --------
    >>> import rocking
    >>> concrete = rocking.Restitution.parse("0.95:0.97")       # a band of factors of Eq. 5
    >>> column = rocking.Block.from_dimensions(7.5, 1.8, rocking.Restitution(0.97))
    >>> round(column.eta, 4), round(column.r, 4)                 # velocity and energy ratios
    (0.8908, 0.7934)
    >>> concrete.is_band, [str(v) for v in concrete.values(3)]
    (True, ['0.95', '0.96', '0.97'])
    """

    low: float
    high: float | None = None
    kind: str = "factor"

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ValueError(f"restitution: kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        low = float(self.low)
        high = low if self.high is None else float(self.high)
        top = math.inf if self.kind == "factor" else 1.0
        for v in (low, high):
            if not (math.isfinite(v) and 0.0 <= v <= top):
                where = "a factor of Eq. 5 must be 0 or more" if self.kind == "factor" else \
                    f"{self.kind} must lie in [0, 1]"
                raise ValueError(f"restitution: {where}, got {v!r}")
        if high < low:
            raise ValueError(f"restitution: a band LOW:HIGH needs LOW <= HIGH, got {low!r}:{high!r}")
        object.__setattr__(self, "low", low)
        object.__setattr__(self, "high", high)

    @classmethod
    def parse(cls, text) -> "Restitution":
        """From the text a user types: ``1.025``, ``0.95:1.05``, ``eta=0.9``, ``r=0.7:0.85``.

        A :class:`Restitution` is returned as it is; a number is a factor of Eq. 5.  Errors are
        one-line :class:`ValueError` that say the syntax.
        """
        if isinstance(text, cls):
            return text
        if isinstance(text, (int, float)) and not isinstance(text, bool):
            return cls(float(text))
        if not isinstance(text, str):
            raise ValueError(f"restitution: expected {_SYNTAX}, got {text!r}")
        kind, sep, body = text.strip().partition("=")
        if not sep:
            kind, body = "factor", text.strip()
        kind = kind.strip().lower()
        if kind not in KINDS:
            raise ValueError(f"restitution: {kind!r} is not a kind; expected {_SYNTAX}")
        ends = body.split(":")
        try:
            values = [float(v) for v in ends]
        except ValueError:
            raise ValueError(f"restitution: expected {_SYNTAX}, got {text!r}") from None
        if len(values) not in (1, 2):
            raise ValueError(f"restitution: expected {_SYNTAX}, got {text!r}")
        return cls(values[0], values[-1], kind)

    @property
    def is_band(self) -> bool:
        """Whether this is a band (``low < high``) rather than one value."""
        return self.high > self.low

    @property
    def is_housner(self) -> bool:
        """Whether this is Eq. 5 itself (the factor 1), the package's default."""
        return self.kind == "factor" and self.low == self.high == 1.0

    def eta_at(self, alpha: float, gamma: float = 0.0) -> float:
        """The velocity ratio ``eta`` of a single value at slenderness ``alpha`` (rad) for a frame
        with cap mass ratio ``gamma`` (0: the lone column)."""
        if self.is_band:
            raise ValueError(f"restitution: the band {self} has no single eta; take one of "
                             "its values() or a sample()")
        if self.kind == "eta":
            return self.low
        if self.kind == "r":
            return math.sqrt(self.low)
        from .frame import eta_frame

        return min(1.0, self.low * eta_frame(alpha, gamma))

    def values(self, n: int) -> list["Restitution"]:
        """``n`` single values evenly spaced over the band, its ends included (the value itself
        for a single value)."""
        if not self.is_band:
            return [self]
        n = int(n)
        if n < 2:
            raise ValueError(f"restitution: a band needs at least 2 values, got {n}")
        step = (self.high - self.low) / (n - 1)
        return [Restitution(self.low + i * step if i < n - 1 else self.high, kind=self.kind)
                for i in range(n)]

    def sample(self, rng, size: int) -> list["Restitution"]:
        """``size`` single values drawn uniformly over the band with the numpy Generator ``rng``
        (the value itself, ``size`` times, for a single value)."""
        if not self.is_band:
            return [self] * int(size)
        return [Restitution(float(v), kind=self.kind)
                for v in rng.uniform(self.low, self.high, int(size))]

    def __str__(self) -> str:
        """As :meth:`parse` reads it back."""
        prefix = "" if self.kind == "factor" else f"{self.kind}="
        body = f"{self.low:g}" if not self.is_band else f"{self.low:g}:{self.high:g}"
        return prefix + body

    def __repr__(self) -> str:
        return f"Restitution({str(self)!r})"

    def describe(self) -> str:
        """Plain words for reports: ``Eq. 5``, ``1.025 x Eq. 5``, ``eta 0.9``, ``r 0.7-0.85``."""
        if self.is_housner:
            return "Eq. 5"
        if self.kind == "factor":
            body = f"{self.low:g}" if not self.is_band else f"{self.low:g}-{self.high:g}"
            return f"{body} x Eq. 5"
        body = f"{self.low:g}" if not self.is_band else f"{self.low:g}-{self.high:g}"
        return f"{self.kind} {body}"
