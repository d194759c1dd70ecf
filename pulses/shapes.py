"""Acceleration pulse shapes of Makris & Vassiliou (2012), Eqs. 7-9 (SPEC section 3).

Every shape is ``Shape(ap, tp, t0=0.0)``: amplitude ``ap`` in m/s^2 (a negative ``ap``
flips the polarity), period ``tp`` in s and time shift ``t0`` in s.  For the rectangular and
one-sine pulses ``t0`` is the arrival time (the pulse lives on ``t0 < t < t0 + tp``); for the
two Ricker wavelets it is the centre.  Calling a shape on an array of times returns the
ground acceleration in m/s^2.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: Normalising constant of the antisymmetric Ricker wavelet (Eq. 8): the peak of
#: ``(x^2 - 3) x exp(-x^2/2)``, reached at ``x^2 = 3 - sqrt(6)``.  The paper rounds it to 1.38.
BETA = float(
    abs((3.0 - math.sqrt(6.0) - 3.0) * math.sqrt(3.0 - math.sqrt(6.0))
        * math.exp(-(3.0 - math.sqrt(6.0)) / 2.0))
)

#: Half-width of the support kept for the Ricker wavelets, in periods: beyond it the symmetric
#: wavelet stays below 2e-19 ap (2.2 Tp) and the antisymmetric one below 3e-20 ap (2.8 Tp), far
#: below any digit a double-precision solver resolves, so the truncation changes nothing.
RICKER_HALF_SUPPORT = {"ricker-sym": 2.2, "ricker-anti": 2.8}


@dataclass(frozen=True)
class Pulse:
    """Base class of the pulse shapes.

    Parameters
    ----------
    ap : float
        Peak acceleration, m/s^2.  Negative values flip the polarity.
    tp : float
        Pulse period, s (for the Rickers: the period at the peak of the Fourier amplitude).
    t0 : float, optional
        Arrival time (rectangular, one-sine) or centre (Rickers), s.
    """

    ap: float
    tp: float
    t0: float = 0.0

    #: short name used across the package: "rect", "sine", "ricker-sym", "ricker-anti"
    shape = "pulse"
    #: integer code used by the compiled solver
    kind = 0

    def __post_init__(self):
        for name in ("ap", "tp", "t0"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise ValueError(f"{type(self).__name__}: {name} must be finite, got {value!r}")
            object.__setattr__(self, name, value)
        if self.tp <= 0.0:
            raise ValueError(f"{type(self).__name__}: tp must be positive, got {self.tp!r} s")

    # -- shape-specific pieces -------------------------------------------------------
    def _unit(self, tau):
        """Unit-amplitude shape at dimensionless time ``tau = (t - t0) / tp``."""
        raise NotImplementedError

    @property
    def support(self) -> tuple[float, float]:
        """``(start, end)`` in s outside which the acceleration is zero."""
        raise NotImplementedError

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times (s) where the acceleration or its derivatives jump: solvers split there."""
        return self.support

    # -- common API -------------------------------------------------------------------
    def __call__(self, t):
        """Ground acceleration (m/s^2) at time(s) ``t`` (s)."""
        t = np.asarray(t, dtype=float)
        start, end = self.support
        tau = (t - self.t0) / self.tp
        inside = (t >= start) & (t <= end)
        return np.where(inside, self.ap * self._unit(tau), 0.0)

    @property
    def omega_p(self) -> float:
        """Circular frequency ``2 pi / tp`` of the pulse, rad/s."""
        return 2.0 * math.pi / self.tp

    @property
    def lp(self) -> float:
        """Persistence length scale ``Lp = |ap| tp^2`` (m)."""
        return abs(self.ap) * self.tp**2

    @property
    def duration(self) -> float:
        start, end = self.support
        return end - start

    def scaled(self, factor: float) -> "Pulse":
        """The same pulse with its amplitude multiplied by ``factor``."""
        return type(self)(self.ap * factor, self.tp, self.t0)

    def sample(self, dt: float, name: str | None = None):
        """Sample the pulse at step ``dt`` (s) over its support, as a :class:`pulses.Record`."""
        from .record import Record

        start, end = self.support
        n = int(math.floor((end - start) / dt + 1e-9)) + 1
        t = start + dt * np.arange(n)
        return Record(self(t), dt, name=name or repr(self), t_start=start)

    def __repr__(self):
        return f"{type(self).__name__}(ap={self.ap:.6g}, tp={self.tp:.6g}, t0={self.t0:.6g})"


class Rectangular(Pulse):
    """Housner's rectangular pulse: ``ap`` for ``t0 < t < t0 + tp`` (design pulse of Eq. 31)."""

    shape = "rect"
    kind = 1

    def _unit(self, tau):
        return np.ones_like(tau)

    @property
    def support(self):
        return (self.t0, self.t0 + self.tp)

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        start, end = self.support
        return np.where((t > start) & (t < end), self.ap, 0.0)


class OneSine(Pulse):
    """One-sine pulse, Eq. 9: ``ap sin(2 pi (t - t0) / tp)`` for ``t0 < t < t0 + tp``."""

    shape = "sine"
    kind = 2

    def _unit(self, tau):
        return np.sin(2.0 * np.pi * tau)

    @property
    def support(self):
        return (self.t0, self.t0 + self.tp)


class _Ricker(Pulse):
    """The Ricker wavelets' common part: a support of :data:`RICKER_HALF_SUPPORT` periods each side."""

    @property
    def support(self):
        half = RICKER_HALF_SUPPORT[self.shape] * self.tp
        return (self.t0 - half, self.t0 + half)


class SymmetricRicker(_Ricker):
    """Symmetric Ricker wavelet, Eq. 7: ``ap (1 - 2 pi^2 tau^2) exp(-pi^2 tau^2)``, ``tau = (t-t0)/tp``.

    The second derivative of a Gaussian (PyWavelets' ``mexh``); its Fourier amplitude peaks at
    period ``tp``.
    """

    shape = "ricker-sym"
    kind = 3

    def _unit(self, tau):
        x2 = (np.pi * tau) ** 2
        return (1.0 - 2.0 * x2) * np.exp(-x2)


class AntisymmetricRicker(_Ricker):
    """Antisymmetric Ricker wavelet, Eq. 8: ``(ap/beta) (x^2 - 3) x exp(-x^2/2)``.

    ``x = 2 pi (t - t0) / (sqrt(3) tp)``; ``beta`` (:data:`BETA`) makes the peak equal ``ap``.
    The third derivative of a Gaussian (PyWavelets' ``gaus3``); its Fourier amplitude peaks at
    period ``tp``.  With ``ap > 0`` the lobe before the centre is positive, the one after negative.
    """

    shape = "ricker-anti"
    kind = 4

    def _unit(self, tau):
        x = 2.0 * np.pi * tau / np.sqrt(3.0)
        return (x * x - 3.0) * x * np.exp(-0.5 * x * x) / BETA


#: shape name -> class
SHAPES = {cls.shape: cls for cls in (Rectangular, OneSine, SymmetricRicker, AntisymmetricRicker)}


def make_pulse(shape: str, ap: float, tp: float, t0: float = 0.0) -> Pulse:
    """Build a pulse from its short name (``"rect"``, ``"sine"``, ``"ricker-sym"``, ``"ricker-anti"``)."""
    try:
        cls = SHAPES[shape]
    except KeyError:
        raise ValueError(f"unknown pulse shape {shape!r}; choose one of {', '.join(SHAPES)}") from None
    return cls(ap, tp, t0)
