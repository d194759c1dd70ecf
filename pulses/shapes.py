"""Acceleration pulse shapes of Makris & Vassiliou (2012), Eqs. 7-9 (docs/theory.md section 3).

Every shape is ``Shape(ap, tp, t0=0.0)``: amplitude ``ap`` in m/s^2 (a negative ``ap``
flips the polarity), period ``tp`` in s and time shift ``t0`` in s.  For the rectangular and
one-sine pulses ``t0`` is the arrival time (the pulse lives on ``t0 < t < t0 + tp``); for the
two Ricker wavelets it is the centre.  Calling a shape on an array of times returns the
ground acceleration in m/s^2.

A shape owns what is known about it, as class attributes and methods on the unit shape
(amplitude 1, period 1, dimensionless time ``tau = (t - t0) / tp``): its formula and slope,
support, extrema, Fourier transform, energy, velocity-to-acceleration factor, display name and
the windows the fitter uses.  Code elsewhere asks the shape (through the registry
:data:`SHAPES`) and never branches on its name: within ``pulses`` a new shape is one new class
here, added to :data:`SHAPES`.  What it still needs outside ``pulses`` is listed, step by step,
in :class:`Pulse`.
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

#: ``x = _ANTI_X * tau`` in Eq. 8
_ANTI_X = 2.0 * math.pi / math.sqrt(3.0)


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

    Notes
    -----
    Adding a shape.  In ``pulses`` a shape is one class: the fitter's shapes, the wavelet
    matching, the command line's ``--shapes`` and ``--pulse`` choices and the reports' shape
    columns all iterate :data:`SHAPES`.  The solvers in ``rocking`` still need code of their own:

    1. Subclass :class:`Pulse` in this module and define, on the unit shape
       (``tau = (t - t0) / tp``): ``shape`` (the short name), ``label`` (display name),
       ``equation`` (where the paper defines it, or None), ``kind`` (its code in the compiled
       solver: the next unused integer); :meth:`unit` and :meth:`slope` (the formula and its
       derivative in ``tau``), :meth:`spectrum` (Fourier transform), ``energy``
       (``integral unit^2 d tau``), ``vp_to_ap``; ``support_tau`` (outside it the acceleration is
       zero), ``extrema_tau``, ``centre_tau`` (middle of the pulse: its arrival is half a period
       earlier), ``antisymmetric``, ``realisable`` (ends at rest), ``boxcar``; ``window_tau``
       (where the fitter's correlation is measured), ``fit_tau`` (the samples its least squares
       uses, before a margin is added); ``pywt`` (PyWavelets' wavelet of the same curve and Tp per
       unit scale) where there is one.  Override :meth:`sampled` (and
       :meth:`sampled_with_derivatives`) where point samples do not place the shape finer than
       ``dt``, as :class:`Rectangular` does.
    2. Add the class to :data:`SHAPES`: everything in ``pulses`` and the command line takes it
       from there.
    3. The compiled solver, ``rocking/_core.pyx``: the code in its enum of forcing kinds and in
       ``KIND_CODES``, the acceleration in ``forcing`` and its Taylor coefficients in
       ``forcing_series``; ``rocking/engine.py`` names the codes and checks them against the
       shapes' at import.  Until then give a solver the shape only as samples
       (``pulses.Record(pulse(t), dt)``): the engine's kinds are read from :data:`SHAPES`, and the
       core computes no forcing for a code it was not compiled for.
    4. The reference solver, ``rocking/reference.py``: its piecewise forcing (a boxcar is
       constant on its support, every other shape is evaluated by :meth:`unit`).
    5. The envelope rule, ``ENVELOPE`` in ``rocking/closed_forms.py``: the shape's coefficients,
       derived by ``python -m rocking.envelope`` (which also lists the realisable shapes it fits
       together).
    6. Tests: the spectrum against the FFT of the sampled pulse, the slope and the extrema
       (``tests/test_fit.py``, which iterates :data:`SHAPES`), the fit of a noise-free pulse, and
       the solvers against the reference solver (``tests/test_design.py``).

    Examples
    --------
    >>> import numpy as np, pulses
    >>> pulse = pulses.make_pulse("ricker-sym", 3.0, 1.0, 5.0)
    >>> acc = pulse(np.arange(0.0, 10.0, 0.01))     # m/s^2 at any times (here a record's axis)
    >>> round(float(acc.max()), 6), acc.size
    (3.0, 1000)
    """

    ap: float
    tp: float
    t0: float = 0.0

    #: short name used across the package: "rect", "sine", "ricker-sym", "ricker-anti"
    shape = "pulse"
    #: display name
    label = "pulse"
    #: where Makris & Vassiliou (2012) define it ("Eq. 9"), or None
    equation = None
    #: integer code used by the compiled solver
    kind = 0
    #: ``(start, end)`` of the unit shape's support, in tau
    support_tau = (0.0, 1.0)
    #: tau of the unit shape's extrema inside its support
    extrema_tau = ()
    #: tau of the middle of the pulse (its arrival is at ``centre_tau - 1/2``)
    centre_tau = 0.5
    #: odd about its centre: it matches a record nearly as well with the opposite polarity
    #: half a lobe away
    antisymmetric = False
    #: the ground ends at rest (no residual velocity): a motion the ground can make
    realisable = True
    #: ``(start, end)`` in tau of the window over which a fitted pulse's correlation is measured
    window_tau = (0.0, 1.0)
    #: ``(start, end)`` in tau of the samples a least-squares fit uses (before its margin)
    fit_tau = (0.0, 1.0)
    #: ``integral unit(tau)^2 d tau`` over the support
    energy = 1.0
    #: ``ap = vp_to_ap * vp / Tp`` for a pulse of peak ground velocity ``vp`` (from rest)
    vp_to_ap = 1.0
    #: ``(PyWavelets name, Tp per unit scale)`` of the same curve, or None
    pywt = None
    #: 1 between two edges and 0 elsewhere: sampled as cell averages, piecewise linear in its
    #: edges, so least squares searches the edges instead of following a gradient
    boxcar = False

    def __post_init__(self):
        for name in ("ap", "tp", "t0"):
            value = float(getattr(self, name))
            if not math.isfinite(value):
                raise ValueError(f"{type(self).__name__}: {name} must be finite, got {value!r}")
            object.__setattr__(self, name, value)
        if self.tp <= 0.0:
            raise ValueError(f"{type(self).__name__}: tp must be positive, got {self.tp!r} s")

    # -- the unit shape (amplitude 1, period 1) ----------------------------------------------
    @staticmethod
    def unit(tau):
        """Unit-amplitude shape at dimensionless time ``tau = (t - t0) / tp`` (inside the support)."""
        raise NotImplementedError

    @staticmethod
    def slope(tau):
        """``d unit / d tau`` (inside the support)."""
        raise NotImplementedError

    def _unit(self, tau):
        """:meth:`unit` (the name that ``rocking.reference`` and ``benchmarks/baseline.py`` call)."""
        return self.unit(tau)

    @staticmethod
    def spectrum(nu):
        """Fourier transform of the unit shape at frequency ``nu`` (cycles per Tp).

        Convention ``W(nu) = integral w(tau) exp(-2 pi i nu tau) d tau`` with the shape's time
        origin; a shape of period ``Tp`` has transform ``Tp W(f Tp)``.
        """
        raise NotImplementedError

    @classmethod
    def sampled(cls, tp: float, t0: float, t, dt: float) -> np.ndarray:
        """Unit-amplitude pulse at sample times ``t`` (s), zero outside the support (the fitter's
        shape; a pulse in m/s^2 on a record's axis is ``pulse(record.time)``, see :meth:`sample`).

        Point samples; a shape whose point samples do not locate it finer than ``dt`` (the
        rectangle) overrides this with cell averages over ``[t - dt/2, t + dt/2]``.
        """
        tau = (t - t0) / tp
        lo, hi = cls.support_tau
        return np.where((tau >= lo) & (tau <= hi), cls.unit(tau), 0.0)

    @classmethod
    def unit_and_slope(cls, tau):
        """:meth:`unit` and :meth:`slope` at once (a shape whose two share work computes it once)."""
        return cls.unit(tau), cls.slope(tau)

    @classmethod
    def sampled_with_derivatives(cls, tp: float, t0: float, t, dt: float):
        """:meth:`sampled` and its derivatives with respect to ``tp`` and ``t0`` (for a Jacobian)."""
        tau = (t - t0) / tp
        lo, hi = cls.support_tau
        inside = (tau >= lo) & (tau <= hi)
        w, dw = cls.unit_and_slope(tau)
        m = np.where(inside, w, 0.0)
        dw = np.where(inside, dw, 0.0)
        return m, -dw * tau / tp, -dw / tp

    @classmethod
    def support_slice(cls, tp: float, t0: float, t_first: float, dt: float, n: int) -> slice:
        """The samples ``t_first + i dt`` (``0 <= i < n``, s) outside which :meth:`sampled` of the
        pulse ``(tp, t0)`` is zero: its support and a sample more each side (the cell averages
        reach half a sample beyond it, and the bounds are rounded outwards)."""
        lo, hi = cls.support_tau
        a = max(0, int(math.floor((t0 + lo * tp - t_first) / dt)) - 1)
        b = min(n, int(math.ceil((t0 + hi * tp - t_first) / dt)) + 2)
        return slice(a, max(a, b))

    @classmethod
    def support_columns(cls, tp: float, t0: float, t, dt: float):
        """:meth:`sampled_with_derivatives` on uniform increasing sample times ``t`` (step ``dt``,
        s), where it may be non-zero: ``(k, C)``, ``C`` of shape ``(3, len(t[k]))`` the values on
        ``t[k]``, zero on the other samples (for products of the columns computed on the support only).

        Point samples are non-zero where ``tau = (t - t0) / tp`` lies in the support, found by
        bisection (``tau`` increases with ``t``); the same values as :meth:`sampled_with_derivatives`.
        """
        k = cls.support_slice(tp, t0, float(t[0]), dt, t.size)
        tau = (t[k] - t0) / tp
        lo, hi = cls.support_tau
        i0, i1 = int(tau.searchsorted(lo)), int(tau.searchsorted(hi, "right"))
        tau = tau[i0:i1]
        out = np.empty((3, tau.size))
        out[0], dw = cls.unit_and_slope(tau)
        dw = -dw  # the operations of sampled_with_derivatives, written in place
        np.multiply(dw, tau, out=out[1])
        out[1] /= tp
        np.divide(dw, tp, out=out[2])
        return slice(k.start + i0, k.start + max(i0, i1)), out

    @classmethod
    def sampled_on_grid(cls, tp: float, t0: float, t, dt: float) -> np.ndarray:
        """:meth:`sampled` on uniform sample times ``t`` (step ``dt``, s), computed on the pulse's
        support only (:meth:`support_slice`): the same values, zero elsewhere."""
        out = np.zeros(t.size)
        k = cls.support_slice(tp, t0, float(t[0]), dt, t.size) if t.size else slice(0, 0)
        out[k] = cls.sampled(tp, t0, t[k], dt)
        return out

    @classmethod
    def cornered(cls) -> bool:
        """Whether the unit shape or its slope jumps at an edge of its support (a one-sine's
        corners, a rectangle's edges; a Ricker's truncation is below round-off).  Sampled, such
        a shape moves with a kink each time an edge crosses a sample time, so a least-squares
        objective has a kink there too, in which a gradient method can stop."""
        edges = np.array(cls.support_tau, dtype=float)
        jump = np.max(np.abs(cls.unit(edges))) + np.max(np.abs(cls.slope(edges))) / (2.0 * math.pi)
        return bool(jump > 1e-9)

    # -- common API -------------------------------------------------------------------
    def __call__(self, t):
        """Ground acceleration (m/s^2) at time(s) ``t`` (s)."""
        t = np.asarray(t, dtype=float)
        start, end = self.support
        tau = (t - self.t0) / self.tp
        inside = (t >= start) & (t <= end)
        return np.where(inside, self.ap * self.unit(tau), 0.0)

    @property
    def support(self) -> tuple[float, float]:
        """``(start, end)`` in s outside which the acceleration is zero."""
        lo, hi = self.support_tau
        return (self.t0 + lo * self.tp, self.t0 + hi * self.tp)

    @property
    def breakpoints(self) -> tuple[float, ...]:
        """Times (s) where the acceleration or its derivatives jump: solvers split there."""
        return self.support

    @property
    def extrema(self) -> list[float]:
        """Times (s) of the extrema of the acceleration inside its support."""
        return [self.t0 + tau * self.tp for tau in self.extrema_tau]

    @property
    def arrival(self) -> float:
        """Time the pulse starts, s: half a period before its centre."""
        return self.t0 + (self.centre_tau - 0.5) * self.tp

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
        """The pulse alone as a new :class:`pulses.Record`, sampled at step ``dt`` (s) over its own
        support: it starts at ``t_start = support[0]`` and lasts as long as the pulse.

        Not the pulse on a record's time axis: for that, evaluate it at the record's sample times,
        ``pulse(record.time)`` (m/s^2, one value per sample).  Nor :meth:`sampled`, the fitter's
        unit-amplitude shape.

        Examples
        --------
        >>> import numpy as np, pulses
        >>> pulse = pulses.OneSine(3.0, 1.0, t0=2.0)
        >>> alone = pulse.sample(0.01)
        >>> alone.t_start, alone.npts
        (2.0, 101)
        >>> on_axis = pulse(np.arange(0.0, 5.0, 0.01))   # a 5 s record's axis: 500 values
        >>> on_axis.size, round(float(on_axis[225]), 6)   # 2.25 s: the crest, ap
        (500, 3.0)
        """
        from .record import Record

        start, end = self.support
        n = int(math.floor((end - start) / dt + 1e-9)) + 1
        t = start + dt * np.arange(n)
        return Record(self(t), dt, name=name or repr(self), t_start=start)

    def __repr__(self):
        return f"{type(self).__name__}(ap={self.ap:.6g}, tp={self.tp:.6g}, t0={self.t0:.6g})"


def _one_minus_exp(omega):
    """``1 - exp(-i omega)``."""
    return (1.0 - np.cos(omega)) + 1j * np.sin(omega)


class Rectangular(Pulse):
    """Housner's rectangular pulse: ``ap`` for ``t0 < t < t0 + tp`` (design pulse of Eq. 31).

    It leaves a residual velocity ``ap Tp``: it is not realisable, only a design idealisation.

    Examples
    --------
    >>> import pulses
    >>> pulse = pulses.Rectangular(3.0, 1.0)
    >>> pulse.support, float(pulse(0.5))
    ((0.0, 1.0), 3.0)
    """

    shape = "rect"
    label = "rectangular"
    kind = 1
    realisable = False
    boxcar = True
    energy = 1.0
    #: peak velocity ``ap Tp`` at its end
    vp_to_ap = 1.0

    @staticmethod
    def unit(tau):
        return np.ones_like(tau)

    @staticmethod
    def slope(tau):
        return np.zeros_like(tau)

    @staticmethod
    def spectrum(nu):
        omega = 2.0 * math.pi * np.asarray(nu, dtype=float)
        small = np.abs(omega) < 1e-8
        safe = np.where(small, 1.0, omega)
        return np.where(small, 1.0 + 0j, _one_minus_exp(omega) / (1j * safe))

    @classmethod
    def sampled(cls, tp, t0, t, dt):
        # point samples cannot place the edges closer than dt: the cell averages can
        lo = np.maximum(t - 0.5 * dt, t0)
        hi = np.minimum(t + 0.5 * dt, t0 + tp)
        return np.clip(hi - lo, 0.0, None) / dt

    @classmethod
    def sampled_with_derivatives(cls, tp, t0, t, dt):
        # cell averages: the edges move through the cells they sit in
        m = cls.sampled(tp, t0, t, dt)
        lo = np.maximum(t - 0.5 * dt, t0)
        hi = np.minimum(t + 0.5 * dt, t0 + tp)
        inside = hi > lo
        end_moves = inside & (t0 + tp < t + 0.5 * dt)
        start_moves = inside & (t0 > t - 0.5 * dt)
        d_tp = end_moves / dt
        d_t0 = (end_moves.astype(float) - start_moves) / dt
        return m, d_tp, d_t0

    @classmethod
    def support_columns(cls, tp, t0, t, dt):
        k = cls.support_slice(tp, t0, float(t[0]), dt, t.size)
        return k, np.stack(cls.sampled_with_derivatives(tp, t0, t[k], dt))

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        start, end = self.support
        return np.where((t > start) & (t < end), self.ap, 0.0)


class OneSine(Pulse):
    """One-sine pulse, Eq. 9: ``ap sin(2 pi (t - t0) / tp)`` for ``t0 < t < t0 + tp``.

    Examples
    --------
    >>> import pulses
    >>> pulse = pulses.OneSine(3.0, 1.0)       # ap = 3 m/s^2, Tp = 1 s, t0 = 0
    >>> round(float(pulse(0.25)), 6), pulse.support      # the crest at Tp/4
    (3.0, (0.0, 1.0))
    """

    shape = "sine"
    label = "one-sine"
    equation = "Eq. 9"
    kind = 2
    extrema_tau = (0.25, 0.75)
    antisymmetric = True
    energy = 0.5
    #: velocity ``ap Tp/(2 pi) (1 - cos(2 pi t/Tp))``, peak ``ap Tp / pi``
    vp_to_ap = math.pi

    @staticmethod
    def unit(tau):
        return np.sin(2.0 * np.pi * tau)

    @staticmethod
    def slope(tau):
        return 2.0 * np.pi * np.cos(2.0 * np.pi * tau)

    @classmethod
    def unit_and_slope(cls, tau):
        x = 2.0 * np.pi * tau  # the same operations as unit and slope, the angle once
        return np.sin(x), 2.0 * np.pi * np.cos(x)

    @staticmethod
    def spectrum(nu):
        nu = np.asarray(nu, dtype=float)
        omega = 2.0 * math.pi * nu
        denom = 4.0 * math.pi**2 - omega**2
        near = np.abs(np.abs(nu) - 1.0) < 1e-9
        safe = np.where(near, 1.0, denom)
        return np.where(near, -0.5j * np.sign(nu), _one_minus_exp(omega) * (2.0 * math.pi / safe))


class _Ricker(Pulse):
    """The Ricker wavelets' common part: centred on ``t0``, with a truncated support."""

    centre_tau = 0.0
    #: both Rickers are below 1e-8 of their peak beyond 2 Tp from the centre
    fit_tau = (-2.0, 2.0)


class SymmetricRicker(_Ricker):
    """Symmetric Ricker wavelet, Eq. 7: ``ap (1 - 2 pi^2 tau^2) exp(-pi^2 tau^2)``, ``tau = (t-t0)/tp``.

    The second derivative of a Gaussian (PyWavelets' ``mexh``); its Fourier amplitude peaks at
    period ``tp``.

    Examples
    --------
    >>> import pulses
    >>> pulses.SymmetricRicker(3.0, 1.0).support      # centred on t0 = 0
    (-2.2, 2.2)
    """

    shape = "ricker-sym"
    label = "symmetric Ricker"
    equation = "Eq. 7"
    kind = 3
    #: beyond 2.2 Tp the wavelet stays below 2e-19 ap, far below any digit a double-precision
    #: solver resolves, so the truncation changes nothing
    support_tau = (-2.2, 2.2)
    extrema_tau = (-math.sqrt(1.5) / math.pi, 0.0, math.sqrt(1.5) / math.pi)
    #: holds all but 1e-3 of the amplitude
    window_tau = (-1.0, 1.0)
    #: ``integral (1 - 2 u^2)^2 exp(-2 u^2) du / pi`` with ``u = pi tau``
    energy = 3.0 / (4.0 * math.sqrt(2.0 * math.pi))
    #: velocity ``ap t exp(-pi^2 t^2 / Tp^2)``, peak at ``t = Tp / (pi sqrt 2)``
    vp_to_ap = math.pi * math.sqrt(2.0 * math.e)
    #: ``mexh`` at scale ``s`` is Eq. 7 with ``x = sqrt(2) pi t / Tp``: ``Tp = sqrt(2) pi s``
    pywt = ("mexh", math.sqrt(2.0) * math.pi)

    @staticmethod
    def unit(tau):
        x2 = (np.pi * tau) ** 2
        return (1.0 - 2.0 * x2) * np.exp(-x2)

    @staticmethod
    def slope(tau):
        x2 = (np.pi * tau) ** 2
        return -2.0 * np.pi**2 * tau * (3.0 - 2.0 * x2) * np.exp(-x2)

    @classmethod
    def unit_and_slope(cls, tau):
        x2 = (np.pi * tau) ** 2
        e = np.exp(-x2)  # the same operations as unit and slope, the exponential once
        return (1.0 - 2.0 * x2) * e, -2.0 * np.pi**2 * tau * (3.0 - 2.0 * x2) * e

    @staticmethod
    def spectrum(nu):
        # w = -(1/(2 pi^2)) g'' with g = exp(-pi^2 tau^2), G(nu) = exp(-nu^2)/sqrt(pi)
        nu = np.asarray(nu, dtype=float)
        return (2.0 / math.sqrt(math.pi)) * nu**2 * np.exp(-nu**2) + 0j


class AntisymmetricRicker(_Ricker):
    """Antisymmetric Ricker wavelet, Eq. 8: ``(ap/beta) (x^2 - 3) x exp(-x^2/2)``.

    ``x = 2 pi (t - t0) / (sqrt(3) tp)``; ``beta`` (:data:`BETA`) makes the peak equal ``ap``.
    The third derivative of a Gaussian (PyWavelets' ``gaus3``); its Fourier amplitude peaks at
    period ``tp``.  With ``ap > 0`` the lobe before the centre is positive, the one after negative.

    Examples
    --------
    >>> import pulses
    >>> pulses.AntisymmetricRicker(3.0, 1.0).support
    (-2.8, 2.8)
    """

    shape = "ricker-anti"
    label = "antisymmetric Ricker"
    equation = "Eq. 8"
    kind = 4
    #: beyond 2.8 Tp the wavelet stays below 3e-20 ap
    support_tau = (-2.8, 2.8)
    #: where ``x^2 = 3 -+ sqrt(6)``
    extrema_tau = tuple(sgn * math.sqrt(3.0 + d * math.sqrt(6.0)) * (math.sqrt(3.0) / (2.0 * math.pi))
                        for sgn in (-1, 1) for d in (-1, 1))
    antisymmetric = True
    #: holds all but 1e-3 of the amplitude
    window_tau = (-1.25, 1.25)
    #: ``integral (x^2 - 3)^2 x^2 exp(-x^2) dx / (a beta^2)`` with ``x = a tau``
    energy = 15.0 * math.sqrt(math.pi) / (8.0 * _ANTI_X * BETA**2)
    #: velocity ``ap/beta sqrt(3) Tp/(2 pi) (1 - x^2) exp(-x^2/2)``, peak at ``x = 0`` (the side
    #: lobes at ``x^2 = 3`` reach only ``2 exp(-3/2) = 0.45`` of it)
    vp_to_ap = 2.0 * math.pi * BETA / math.sqrt(3.0)
    #: ``gaus3`` at scale ``s`` is Eq. 8 with ``u = x / sqrt(2)``: ``Tp = 2 pi s / sqrt(6)``
    pywt = ("gaus3", 2.0 * math.pi / math.sqrt(6.0))

    @staticmethod
    def unit(tau):
        x = 2.0 * np.pi * tau / np.sqrt(3.0)
        return (x * x - 3.0) * x * np.exp(-0.5 * x * x) / BETA

    @staticmethod
    def slope(tau):
        x = 2.0 * np.pi * tau / np.sqrt(3.0)
        x2 = x * x
        return _ANTI_X * (-x2 * x2 + 6.0 * x2 - 3.0) * np.exp(-0.5 * x2) / BETA

    @classmethod
    def unit_and_slope(cls, tau):
        x = 2.0 * np.pi * tau / np.sqrt(3.0)
        x2 = x * x
        e = np.exp(-0.5 * x2)  # the same operations as unit and slope, the exponential once
        return (x2 - 3.0) * x * e / BETA, _ANTI_X * (-x2 * x2 + 6.0 * x2 - 3.0) * e / BETA

    @staticmethod
    def spectrum(nu):
        # w = -(1/(beta a^3)) d^3/dtau^3 exp(-a^2 tau^2/2), a = 2 pi / sqrt(3)
        nu = np.asarray(nu, dtype=float)
        a = _ANTI_X
        return (1j * 8.0 * math.pi**3 * math.sqrt(2.0 * math.pi) / (BETA * a**4)) * nu**3 \
            * np.exp(-2.0 * math.pi**2 * nu**2 / a**2)


#: shape name -> class: the registry every other module iterates
SHAPES = {cls.shape: cls for cls in (Rectangular, OneSine, SymmetricRicker, AntisymmetricRicker)}


def shape_class(shape: str) -> type[Pulse]:
    """The class of a shape from its short name; ValueError for an unknown name.

    Examples
    --------
    >>> import pulses
    >>> pulses.shape_class("ricker-sym").__name__
    'SymmetricRicker'
    """
    try:
        return SHAPES[shape]
    except (KeyError, TypeError):
        raise ValueError(f"unknown pulse shape {shape!r}; choose one of {', '.join(SHAPES)}") from None


def make_pulse(shape: str, ap: float, tp: float, t0: float = 0.0) -> Pulse:
    """Build a pulse from its short name (``"rect"``, ``"sine"``, ``"ricker-sym"``, ``"ricker-anti"``).

    Examples
    --------
    >>> import pulses
    >>> p = pulses.make_pulse("sine", 3.0, 1.0, 0.5)      # ap 3 m/s^2, Tp 1 s, from t0 = 0.5 s
    >>> type(p).__name__, p.support
    ('OneSine', (0.5, 1.5))
    """
    return shape_class(shape)(ap, tp, t0)
