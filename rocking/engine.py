"""Compiled event-driven engine for the rocking block (SPEC section 2), in numba.

One routine, :func:`run`, integrates Eq. 3 over a grid of nodes (record samples, or pulse
breakpoints and extrema subdivided into equal steps) and handles everything between:

* **rest and uplift**: a block at rest is not integrated; within each interval the forcing is
  monotonic (records are linear between samples, pulse grids include every extremum), so the
  first time ``|ug''| = g tan(alpha)`` is found exactly and the block uplifts to
  ``sgn(theta) = -sgn(ug'')``;
* **stepping** of the full nonlinear equation (``linear=False``) by its Taylor series (default:
  the series of ``theta``, ``sin`` and ``cos`` of the angle to the corner and of the forcing
  follow from recurrences, summed to rounding level, so each step is exact to rounding and its
  polynomial is the solution everywhere inside the step), or by the fixed-step 8th-order
  Dormand-Prince formula or classical RK4 (for comparison); or the exact ``cosh``/``sinh``
  solution of the linearised equation for forcing linear on each interval (``linear=True``);
* **impacts**: detected on the cubic Hermite interpolant of the step, then located by Newton
  iterations on the step's Taylor polynomial (or, for the Runge-Kutta and linear steppers, on
  the solution re-integrated from the start of the step), so the impact time is as accurate as
  the stepper itself; the angular velocity is multiplied by ``eta``;
* **Zeno sequences**: once the post-impact velocity falls below ``zeno_tol * p * alpha`` while
  both sides are restoring, the remaining geometric series of hops is summed in closed form and
  the block is put at rest at the accumulation time (no threshold on the *result*: the hops
  left out are ``(zeno_tol * alpha)^2`` small); when the forcing is at or past the uplift
  threshold on one side the block is put at rest at once, and the rest rule uplifts it (hopping
  on would take ever shorter hops down to rounding, millions of them);
* **peaks**: ``max|theta|`` includes the extremum of the Hermite interpolant inside each step;
* **overturning**: ``|theta|`` reaching ``pi/2``;
* **end of the excitation**: the energy rule of SPEC section 2 decides overturning exactly and
  gives the next peak, without further integration (:func:`energy_verdict`).

All angles in rad, times in s, accelerations as ``ug''/g`` (dimensionless).
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np
from numba import njit

from ._taylor_fixed import ORDERS as FIXED_ORDERS
from . import _dop853
from ._compiling import compiling_notice, first_call_done
from ._taylor_fixed import SMOOTH_ORDERS, fixed_run, taylor_fixed, taylor_smooth

#: Butcher tableau of the 8th-order Dormand-Prince formula (the 12 stages of DOP853; source
#: named in :mod:`rocking._dop853`)
N_STAGES = _dop853.N_STAGES
RK8_A = np.ascontiguousarray(_dop853.A)
RK8_B = np.ascontiguousarray(_dop853.B)
RK8_C = np.ascontiguousarray(_dop853.C)

HALF_PI = 0.5 * math.pi
TWO_PI = 2.0 * math.pi
SQRT3 = math.sqrt(3.0)
BETA = abs((3.0 - math.sqrt(6.0) - 3.0) * math.sqrt(3.0 - math.sqrt(6.0))
           * math.exp(-(3.0 - math.sqrt(6.0)) / 2.0))

# forcing kinds (match pulses.*.kind); FREE = no ground motion
FREE = -1
NODAL = 0  # piecewise linear between node values (records; sampled pulses for the linear model)
RECT, SINE, RICKER_SYM, RICKER_ANTI = 1, 2, 3, 4
#: the forcing kinds the engine computes, with their names
KINDS = {FREE: "free", NODAL: "nodal", RECT: "rect", SINE: "sine", RICKER_SYM: "ricker-sym",
         RICKER_ANTI: "ricker-anti"}

# stepping methods of the nonlinear equation
TAYLOR, RK8, RK4 = 0, 1, 2
METHODS = {"taylor": TAYLOR, "rk8": RK8, "rk4": RK4}
#: highest order of a Taylor step (steps are kept short enough, ``p h <= PH_MAX``, that the series
#: reaches rounding level far below it)
NMAX = 40
#: floats of the scratch space of :func:`run_core` (stages, forcing and sin/cos series, coefficients)
WORK_SIZE = 2 * N_STAGES + 5 * (NMAX + 3)
#: a Taylor series is cut once two consecutive terms of theta and of ``h * omega`` fall below
#: ``TAYLOR_EPS`` times the size of the step's leading terms
TAYLOR_EPS = 1e-15
_INV = np.array([0.0] + [1.0 / k for k in range(1, NMAX + 3)])
_INV2 = np.array([1.0 / ((k + 1) * (k + 2)) for k in range(NMAX + 3)])

# status codes returned by run()
REST, ROCKING, OVERTURNED = 0, 1, 2

_MAX_EVENTS_PER_STEP = 1_000_000

#: steps in a row for which a lower order would have done before an unrolled step of forcing
#: linear over the step (records) takes the next order down
LOW_RUN_FIXED = 8

# The engine's scalar arguments, bundled.  Arrays travel as arguments of their own: numba counts
# a reference (an atomic operation) to every array taken out of a tuple, at every call, which
# cost 10-20 % of the batch engine's time when the bundles held them.
#: the ground motion: ``kind`` (:data:`KINDS`), ``amp`` (``ap/g`` of a pulse, or the factor on
#: the node values ``uval`` of ``ug''/g`` for ``NODAL``), ``tp``, ``t0`` (a pulse's period and
#: time shift, s)
Forcing = namedtuple("Forcing", "kind amp tp t0")
#: the grid: ``t_start``, ``h`` (s; the uniform grid ``t_start + j h`` unless node times are
#: given), ``n_sub`` (RK4 or exact sub-steps per interval)
Grid = namedtuple("Grid", "t_start h n_sub")
#: the block: ``p`` (rad/s), ``alpha`` (rad), ``eta`` (coefficient of restitution)
Rocker = namedtuple("Rocker", "p alpha eta")
#: how the equation is integrated: ``linear`` (the linearised equation), ``method``
#: (:data:`METHODS`), ``zeno_tol`` (Zeno sequences summed once ``|omega| < zeno_tol p alpha``),
#: ``stop_at_rest`` (free motion: stop once at rest), ``record`` (write the history)
Settings = namedtuple("Settings", "linear method zeno_tol stop_at_rest record")
#: where a run starts: interval ``j0`` (at its start time), ``theta`` (rad), ``omega`` (rad/s),
#: at rest until ``rest_until`` (s; after a Zeno sequence, ``-inf`` if not)
Start = namedtuple("Start", "j0 theta omega rest_until")
#: the equation as the steppers take it: ``p`` (rad/s), ``sa``, ``ca`` (sin and cos of alpha;
#: alpha and 1 in the linearised model), ``linear``, ``method``
Dynamics = namedtuple("Dynamics", "p sa ca linear method")


# --------------------------------------------------------------------------- forcing
@njit(cache=True)
def abs_max(a):
    """``max|a|`` of a float array (as ``np.max(np.abs(a))`` for finite values), in one pass with
    four running maxima (independent chains of compare and select)."""
    m0 = m1 = m2 = m3 = 0.0
    n = a.shape[0]
    i = 0
    while i + 4 <= n:
        x0, x1, x2, x3 = abs(a[i]), abs(a[i + 1]), abs(a[i + 2]), abs(a[i + 3])
        m0 = x0 if x0 > m0 else m0
        m1 = x1 if x1 > m1 else m1
        m2 = x2 if x2 > m2 else m2
        m3 = x3 if x3 > m3 else m3
        i += 4
    while i < n:
        x0 = abs(a[i])
        m0 = x0 if x0 > m0 else m0
        i += 1
    return max(max(m0, m1), max(m2, m3))


@njit(cache=True)
def forcing(F, uval, j, ta, tb, t):
    """Ground acceleration over g at time ``t`` inside interval ``j`` = ``[ta, tb]`` of the
    forcing ``F`` (:class:`Forcing`)."""
    kind, amp, tp, t0 = F
    if kind == NODAL:
        return amp * (uval[j] + (uval[j + 1] - uval[j]) * ((t - ta) / (tb - ta)))
    if kind == FREE:
        return 0.0
    if kind == RECT:
        return amp
    tau = (t - t0) / tp
    if kind == SINE:
        return amp * math.sin(TWO_PI * tau)
    if kind == RICKER_SYM:
        x2 = (math.pi * tau) ** 2
        return amp * (1.0 - 2.0 * x2) * math.exp(-x2)
    if kind == RICKER_ANTI:
        x = TWO_PI * tau / SQRT3
        return amp * (x * x - 3.0) * x * math.exp(-0.5 * x * x) / BETA
    return math.nan  # no other kind reaches here (check_kind), and none is guessed


# --------------------------------------------------------------------------- steppers
@njit(cache=True, inline="always")
def corner_sincos(theta, s, sa, ca):
    """``sin`` and ``cos`` of ``s alpha - theta`` (by angle addition; none needed at ``theta = 0``,
    just after an uplift or an impact)."""
    if theta == 0.0:
        return s * sa, ca
    sn, cs = math.sin(theta), math.cos(theta)
    return s * sa * cs - ca * sn, ca * cs + s * sa * sn


@njit(cache=True, inline="always")
def _rhs(theta, s, u, p2, sa, ca, linear):
    if linear:
        return p2 * (theta - s * sa - u)  # sa carries alpha itself in the linear model
    sin_d, cos_d = corner_sincos(theta, s, sa, ca)
    return -p2 * (sin_d + u * cos_d)


@njit(cache=True)
def step(F, uval, j, ta, tb, t, h, theta, omega, s, D, kt, kw):
    """Advance ``(theta, omega)`` on side ``s`` from ``t`` by ``h`` (inside interval ``j``).

    Nonlinear: the 8th-order Dormand-Prince formula (fixed step; the 12 stages of DOP853) for
    ``method == RK8``, classical RK4 otherwise (the Taylor stepper is :func:`taylor_series`,
    called by :func:`run` directly).  Linear: the exact solution.  ``D``: :class:`Dynamics`.
    """
    p, sa, ca, linear, method = D
    p2 = p * p
    if linear:
        # forcing is linear on the interval: u(t + x) = u0 + u1 x, exact cosh/sinh solution
        u0 = forcing(F, uval, j, ta, tb, t)
        u1 = (forcing(F, uval, j, ta, tb, t + h) - u0) / h if h > 0 else 0.0
        # y = theta - s alpha - u obeys y'' = p^2 y; written as increments with
        # cosh(x) - 1 = 2 sinh(x/2)^2 so that short steps (Zeno hops) lose no digits
        y0 = theta - s * sa - u0
        dy0 = omega - u1
        sh = math.sinh(p * h)
        chm1 = 2.0 * math.sinh(0.5 * p * h) ** 2
        return (theta + y0 * chm1 + dy0 / p * sh + u1 * h,
                omega + y0 * p * sh + dy0 * chm1)
    if method == RK8:
        return _step_rk8(F, uval, j, ta, tb, t, h, theta, omega, s, p2, sa, ca, kt, kw)
    hh = 0.5 * h
    u_a = forcing(F, uval, j, ta, tb, t)
    u_m = forcing(F, uval, j, ta, tb, t + hh)
    u_b = forcing(F, uval, j, ta, tb, t + h)
    k1t = omega
    k1w = _rhs(theta, s, u_a, p2, sa, ca, False)
    k2t = omega + hh * k1w
    k2w = _rhs(theta + hh * k1t, s, u_m, p2, sa, ca, False)
    k3t = omega + hh * k2w
    k3w = _rhs(theta + hh * k2t, s, u_m, p2, sa, ca, False)
    k4t = omega + h * k3w
    k4w = _rhs(theta + h * k3t, s, u_b, p2, sa, ca, False)
    return (theta + h / 6.0 * (k1t + 2.0 * k2t + 2.0 * k3t + k4t),
            omega + h / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w))


@njit(cache=True, inline="always")  # one call site
def _step_rk8(F, uval, j, ta, tb, t, h, theta, omega, s, p2, sa, ca, kt, kw):
    """One fixed step of the 8th-order Dormand-Prince formula (DOP853's 12 stages).

    ``kt``, ``kw``: scratch arrays of length ``N_STAGES``.
    """
    for i in range(N_STAGES):
        th_i, om_i = theta, omega
        for m in range(i):
            th_i += h * RK8_A[i, m] * kt[m]
            om_i += h * RK8_A[i, m] * kw[m]
        u_i = forcing(F, uval, j, ta, tb, t + RK8_C[i] * h)
        kt[i] = om_i
        kw[i] = _rhs(th_i, s, u_i, p2, sa, ca, False)
    th_new, om_new = theta, omega
    for i in range(N_STAGES):
        th_new += h * RK8_B[i] * kt[i]
        om_new += h * RK8_B[i] * kw[i]
    return th_new, om_new


# --------------------------------------------------------------------------- Taylor series
@njit(cache=True, inline="always")
def linear_forcing(F, uval, j, ta, tb, t, h):
    """``(u0, u1)`` with ``u(t + x h) = u0 + u1 x`` for forcing linear over the step (records,
    rectangular pulse, free motion)."""
    kind, amp, _, _ = F
    if kind == NODAL:
        slope = amp * (uval[j + 1] - uval[j]) / (tb - ta)
        return amp * uval[j] + slope * (t - ta), slope * h
    if kind == RECT:
        return amp, 0.0
    return 0.0, 0.0


@njit(cache=True)
def forcing_series(F, uval, j, ta, tb, t, h, U, n_terms):
    """Taylor coefficients of ``u(t + x h)`` in powers of ``x`` (``u = ug''/g``), into ``U``.

    Returns ``(nu, complete)``: the number of coefficients written, and whether the rest are
    zero.  Records (linear on the interval), the rectangular pulse and free motion: 2, complete.
    Smooth pulses (their series from the recurrence ``E' = g' E`` for ``E = exp(g)``): the first
    ``min(n_terms, NMAX + 1)``, complete only when that is ``NMAX + 1``.
    """
    kind, amp, tp, t0 = F
    if kind == NODAL or kind == FREE or kind == RECT:
        U[0], U[1] = linear_forcing(F, uval, j, ta, tb, t, h)
        return 2, True
    n = min(n_terms, NMAX + 1)
    if kind == SINE:
        w = TWO_PI * h / tp
        sn = math.sin(TWO_PI * (t - t0) / tp)
        cs = math.cos(TWO_PI * (t - t0) / tp)
        c = amp
        for k in range(n):
            r = k % 4
            U[k] = c * (sn if r == 0 else (cs if r == 1 else (-sn if r == 2 else -cs)))
            c *= w * _INV[k + 1]
        return n, n == NMAX + 1
    # Ricker pulses: P(y) exp(g(y)) with y = y0 + dy x linear in x
    if kind == RICKER_SYM:
        y0 = math.pi * (t - t0) / tp
        dy = math.pi * h / tp
        g1, g2 = -2.0 * y0 * dy, -dy * dy
        e = math.exp(-y0 * y0)
        p0, p1, p2, p3 = 1.0 - 2.0 * y0 * y0, -4.0 * y0 * dy, -2.0 * dy * dy, 0.0
        scale = amp
    else:
        y0 = TWO_PI * (t - t0) / (tp * SQRT3)
        dy = TWO_PI * h / (tp * SQRT3)
        g1, g2 = -y0 * dy, -0.5 * dy * dy
        e = math.exp(-0.5 * y0 * y0)
        p0, p1, p2, p3 = y0 * (y0 * y0 - 3.0), 3.0 * (y0 * y0 - 1.0) * dy, 3.0 * y0 * dy * dy, dy ** 3
        scale = amp / BETA
    # E_k = (g1 E_{k-1} + 2 g2 E_{k-2}) / k;  U_k = sum_i P_i E_{k-i}
    e1, e2, e3 = 0.0, 0.0, 0.0  # E_{k-1}, E_{k-2}, E_{k-3}
    for k in range(n):
        if k > 0:
            e = (g1 * e1 + 2.0 * g2 * e2) * _INV[k]
        U[k] = scale * (p0 * e + p1 * e1 + p2 * e2 + p3 * e3)
        e1, e2, e3 = e, e1, e2
    return n, n == NMAX + 1


@njit(cache=True)
def taylor_series(U, nu, complete, h, theta, omega, s, p2, sa, ca, cf, S, C, sc_known, s0, c0):
    """Taylor coefficients of ``theta(t + x h)`` in powers of ``x``, into ``cf``.

    Returns ``(n, s1, c1)``: the order ``n`` of the polynomial, and ``sin(phi)``, ``cos(phi)`` at
    the end of the step (their series summed), which the next step takes as its ``s0``, ``c0``
    when ``sc_known`` (so a step needs no function evaluation at all).  ``n = -1`` if the series
    needs more than the ``nu`` forcing terms given and they are not ``complete``.

    With ``phi = s alpha - theta``, Eq. 3 reads ``phi'' = p^2 (sin(phi) + u cos(phi))``; the
    series of ``S = sin(phi)`` and ``C = cos(phi)`` follow from ``S' = C phi'``, ``C' = -S phi'``
    (``S_k = (1/k) sum_j j phi_j C_{k-j}``), so each order costs one short convolution and no
    function evaluation.  The series is cut when two consecutive terms of ``theta`` and of
    ``h omega`` fall below :data:`TAYLOR_EPS` times the leading terms.
    """
    if sc_known:
        S[0], C[0] = s0, c0
    else:
        S[0], C[0] = corner_sincos(theta, s, sa, ca)
    q = p2 * h * h
    cf[0] = theta
    cf[1] = omega * h
    cf[2] = -0.5 * q * (S[0] + U[0] * C[0])
    tol = TAYLOR_EPS * (abs(theta) + abs(cf[1]) + abs(cf[2]))
    n = 2
    D = U[NMAX + 3:]  # D[i] = i cf[i] = -i phi_i: the series of h theta'
    D[1] = cf[1]
    D[2] = 2.0 * cf[2]
    for k in range(1, NMAX - 1):
        if k >= nu and not complete:
            return -1, 0.0, 0.0
        sk = 0.0
        ck = 0.0
        for i in range(1, k + 1):
            sk -= D[i] * C[k - i]
            ck += D[i] * S[k - i]
        sk *= _INV[k]
        ck *= _INV[k]
        S[k] = sk
        C[k] = ck
        f = sk
        for i in range(min(nu, k + 1)):
            f += U[i] * C[k - i]
        cf[k + 2] = -q * f * _INV2[k]
        n = k + 2
        D[n] = n * cf[n]
        if abs(D[n]) <= tol and abs(D[n - 1]) <= tol:
            break
    s1, c1 = 0.0, 0.0
    for k in range(n - 2, -1, -1):  # S_{n-1}, C_{n-1} are as small as cf[n - 1]
        s1 += S[k]
        c1 += C[k]
    return n, s1, c1


@njit(cache=True, inline="always")
def taylor_eval(cf, n, x, h):
    """``(theta, omega)`` at ``t + x h`` from the coefficients of :func:`taylor_series`."""
    th = cf[n]
    om = n * cf[n]
    for k in range(n - 1, 0, -1):
        th = th * x + cf[k]
        om = om * x + k * cf[k]
    return th * x + cf[0], om / h


@njit(cache=True, inline="always")
def taylor_acc(cf, n, x, h):
    """``theta''`` at ``t + x h`` from the coefficients of :func:`taylor_series`."""
    acc = n * (n - 1) * cf[n]
    for k in range(n - 1, 1, -1):
        acc = acc * x + k * (k - 1) * cf[k]
    return acc / (h * h)


# --------------------------------------------------------------------------- Hermite helpers
@njit(cache=True, inline="always")
def _hermite(th_a, om_a, th_b, om_b, h):
    c0 = th_a
    c1 = h * om_a
    c2 = 3.0 * (th_b - th_a) - h * (2.0 * om_a + om_b)
    c3 = 2.0 * (th_a - th_b) + h * (om_a + om_b)
    return c0, c1, c2, c3


@njit(cache=True, inline="always")
def _cubic(c0, c1, c2, c3, x):
    return c0 + x * (c1 + x * (c2 + x * c3))


@njit(cache=True, inline="always")
def _stationary(c1, c2, c3):
    """Roots of the derivative ``c1 + 2 c2 x + 3 c3 x^2`` inside (0, 1), sorted (nan if none)."""
    r1, r2 = np.nan, np.nan
    a, b, c = 3.0 * c3, 2.0 * c2, c1
    if abs(a) < 1e-300 or abs(a) * 1e12 < abs(b):
        if b != 0.0:
            r1 = -c / b
    else:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0:
            sq = math.sqrt(disc)
            q = -0.5 * (b + math.copysign(sq, b))
            x1 = q / a
            x2 = c / q if q != 0.0 else np.nan
            r1, r2 = min(x1, x2), max(x1, x2)
    if not (r1 > 0.0 and r1 < 1.0):
        r1 = np.nan
    if not (r2 > 0.0 and r2 < 1.0):
        r2 = np.nan
    if np.isnan(r1):
        r1, r2 = r2, np.nan
    return r1, r2


@njit(cache=True)
def _first_crossing(c0, c1, c2, c3, s, level):
    """First x in (0, 1] where ``s*H(x) - level`` turns non-positive, given it starts >= 0.

    Returns ``(lo, hi, interior)`` bracketing it (``interior``: found at an extremum of the
    interpolant inside the step, which the caller must confirm, because the interpolation error
    can fake a shallow dip), or ``(-1, -1, False)`` if there is none.
    """
    e1, e2 = _stationary(c1, c2, c3)
    lo = 0.0
    for k in range(3):
        hi = e1 if k == 0 else (e2 if k == 1 else 1.0)
        if np.isnan(hi) or hi <= lo:
            continue
        value = s * _cubic(c0, c1, c2, c3, hi) - level
        if k < 2:
            if value < 0.0:
                return lo, hi, True
        elif value < 0.0 or (value == 0.0 and s * c0 - level > 0.0):
            return lo, hi, False
        lo = hi
    return -1.0, -1.0, False


@njit(cache=True)
def _cubic_root(c0, c1, c2, c3, s, lo, hi):
    """The root of the cubic ``c0 + c1 x + c2 x^2 + c3 x^3`` in ``[lo, hi]``, where it is monotonic
    with ``s H(lo) > 0 >= s H(hi)`` (a bracket from :func:`_first_crossing`), to rounding.

    Newton from ``hi``, kept inside the bracket, which each evaluation narrows (a bisection when a
    step would leave it): a few iterations where bisection to 1e-4 then Newton took ~20.  A step
    that starts at ``theta = 0`` (just after an impact: ``c0 = 0``) starts from the root of
    ``c1 + c2 x + c3 x^2`` in the bracket (small hops, whose root is close to the top of the hop,
    took Newton from ``hi`` ~11 iterations)."""
    x = hi
    if c0 == 0.0:
        disc = c2 * c2 - 4.0 * c3 * c1
        if disc >= 0.0 and (c2 != 0.0 or c3 != 0.0):
            qq = -0.5 * (c2 + math.copysign(math.sqrt(disc), c2))
            for r in (qq / c3 if c3 != 0.0 else np.nan, c1 / qq if qq != 0.0 else np.nan):
                if lo <= r <= hi:
                    x = r
                    break
    for _ in range(200):
        f = _cubic(c0, c1, c2, c3, x)
        if s * f > 0.0:
            lo = x
        else:
            hi = x
        d = c1 + x * (2.0 * c2 + 3.0 * c3 * x)
        xn = x - f / d if d != 0.0 else 0.5 * (lo + hi)
        if not (lo <= xn <= hi):
            xn = 0.5 * (lo + hi)
        if abs(xn - x) < 4e-16 or hi - lo < 4e-16:
            return xn
        x = xn
    return x


@njit(cache=True)
def _sub(F, uval, j, ta, tb, t, h, x, theta, omega, s, D, kt, kw, cf, n):
    """State at ``t + x h`` inside the current step of length ``h`` that starts at
    ``(t, theta, omega)``: the step's Taylor polynomial when it has one (``n > 0``), else the
    solution re-integrated from the start of the step."""
    if n > 0:
        return taylor_eval(cf, n, x, h)
    return step(F, uval, j, ta, tb, t, x * h, theta, omega, s, D, kt, kw)


@njit(cache=True)
def _advance(F, uval, j, ta, tb, t, h, theta, omega, s, D, kt, kw, U, S, C, cf, sc_known, s0, c0,
             n_hint):
    """One step of length ``h``: ``(theta, omega, n, s1, c1)`` at ``t + h``, with ``n`` the order
    of the Taylor polynomial left in ``cf`` (0 when another stepper was used) and ``s1``, ``c1``
    as returned by :func:`taylor_series`.  ``n_hint``: the order of the previous step (the
    forcing series of smooth pulses is computed a few terms beyond it, and in full if needed)."""
    p, sa, ca, linear, method = D
    if method == TAYLOR and not linear:
        nu, complete = forcing_series(F, uval, j, ta, tb, t, h, U, n_hint + 4)
        n, s1, c1 = taylor_series(U, nu, complete, h, theta, omega, s, p * p, sa, ca, cf, S, C,
                                  sc_known, s0, c0)
        if n < 0:
            nu, complete = forcing_series(F, uval, j, ta, tb, t, h, U, NMAX + 1)
            n, s1, c1 = taylor_series(U, nu, complete, h, theta, omega, s, p * p, sa, ca, cf, S,
                                      C, sc_known, s0, c0)
        th, om = taylor_eval(cf, n, 1.0, h)
        return th, om, n, s1, c1
    th, om = step(F, uval, j, ta, tb, t, h, theta, omega, s, D, kt, kw)
    return th, om, 0, 0.0, 0.0


@njit(cache=True, inline="always")
def _below(cf, n, level):
    """Whether ``|theta| < level`` all over the step, by the bound ``sum |cf_k|`` of its
    polynomial on ``[0, 1]`` (with a 1 % margin, so that a peak computed by :func:`_step_peak`
    cannot reach ``level`` either)."""
    b = 0.0
    for k in range(n + 1):
        b += abs(cf[k])
    return 1.01 * b < level


@njit(cache=True)
def _step_peak(F, uval, j, ta, tb, t, h, th_a, om_a, th_b, om_b, s, D, kt, kw, h_step, cf, n,
               max_abs):
    """``max_abs`` raised to the largest ``|theta|`` at a turning point strictly inside
    ``[t, t + h]``, if larger.

    ``[t, t + h]`` is the start of the current step of length ``h_step`` (see :func:`_sub`).
    The turning point is located on the cubic Hermite interpolant, the solution is evaluated
    there (Taylor polynomial, or re-integration), and the small residual velocity is removed by
    one quadratic (Newton) correction, so the peak is as accurate as the stepper rather than the
    interpolant.
    """
    p, sa, ca, linear, _ = D
    c0, c1, c2, c3 = _hermite(th_a, om_a, th_b, om_b, h)
    e1, e2 = _stationary(c1, c2, c3)
    peak = max_abs
    for k in range(2):
        x = e1 if k == 0 else e2
        if np.isnan(x):
            continue
        th_e, om_e = _sub(F, uval, j, ta, tb, t, h_step, x * h / h_step, th_a, om_a, s, D, kt, kw,
                          cf, n)
        if n > 0:
            acc = taylor_acc(cf, n, x * h / h_step, h_step)
        else:
            u_e = forcing(F, uval, j, ta, tb, t + x * h)
            acc = _rhs(th_e, s, u_e, p * p, sa, ca, linear)
        value = th_e
        if acc != 0.0:
            value = th_e - 0.5 * om_e * om_e / acc
        if abs(value) > peak:
            peak = abs(value)
    return peak


# --------------------------------------------------------------------------- energy rule
@njit(cache=True)
def _potential(x, alpha, linear):
    """Potential energy over m g R at ``|theta| = x`` (zero at rest)."""
    if linear:
        return 0.5 * alpha * alpha - 0.5 * (alpha - x) ** 2
    return math.cos(alpha - x) - math.cos(alpha)


@njit(cache=True)
def _peak_from_energy(e, alpha, linear):
    """Peak ``|theta|`` of a block with energy ``e`` (over m g R) below the critical one."""
    if linear:
        return alpha - math.sqrt(max(alpha * alpha - 2.0 * e, 0.0))
    return alpha - math.acos(min(math.cos(alpha) + e, 1.0))


@njit(cache=True)
def energy_verdict(theta, omega, p, alpha, eta, linear):
    """Decide overturning after the excitation ends (SPEC section 2), exactly.

    Returns ``(overturns, next_peak)``; ``next_peak`` is the largest ``|theta|`` of the free
    motion that follows (``pi/2`` if it overturns).
    """
    x = abs(theta)
    if x == 0.0 and omega == 0.0:
        return False, 0.0
    e = 0.5 * omega * omega / (p * p) + _potential(x, alpha, linear)
    e_crit = _potential(alpha, alpha, linear)
    r = eta * eta
    if theta == 0.0:
        away = True  # just after an impact or uplift, moving into a side
    elif omega == 0.0:  # at a turning point
        if x > alpha:
            return True, HALF_PI  # beyond the top at rest: falls outward
        if x == alpha:
            return False, x  # the verge: infinite time to fall either way
        away = False
    else:
        away = theta * omega > 0.0
    if away:
        if x >= alpha or e > e_crit:
            return True, HALF_PI
        return False, max(x, _peak_from_energy(e, alpha, linear))
    # moving toward zero
    if x > alpha and e < e_crit:
        return True, HALF_PI  # cannot climb back over the top: falls outward
    if r * e > e_crit:
        return True, HALF_PI  # passes the impact with enough energy to overturn
    return False, _peak_from_energy(r * e, alpha, linear)


# --------------------------------------------------------------------------- main loop
@njit(cache=True)
def _uplift_time(F, uval, j, ta, tb, t, t2, tan_a):
    """First time in ``[t, t2]`` where ``|u| > tan(alpha)`` (monotonic u), or nan."""
    ua = forcing(F, uval, j, ta, tb, t)
    if abs(ua) > tan_a:
        return t
    ub = forcing(F, uval, j, ta, tb, t2)
    if abs(ub) <= tan_a:
        return np.nan
    level = math.copysign(tan_a, ub)
    if F[0] == NODAL:
        x = t + (t2 - t) * (level - ua) / (ub - ua)
        return min(max(x, t), t2)
    lo, hi = t, t2  # bisection to the last representable time
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if abs(forcing(F, uval, j, ta, tb, mid)) > tan_a:
            hi = mid
        else:
            lo = mid
    return hi


@njit(cache=True)
def _cruise(F, uval, grid, nodes, j, n_int, t, theta, omega, s, sa, ca, p2, max_abs, trig, orders,
            cf, record, hist_t, hist_theta, hist_omega, n_hist):
    """Whole intervals from ``j`` on, each one unrolled Taylor step, while nothing happens.

    Stops (returning the state at the start of interval ``j``, for :func:`run_core` to take that
    interval the general way) at the first interval where ``theta`` or ``omega`` would change
    sign or reach ``pi/2``, or where the series needs more terms than the unrolled orders have.
    The block must be rocking at the start of interval ``j`` (``t`` is its start).  ``trig``:
    ``(known, sin, cos)`` of the angle to the corner; ``orders``: ``(order, n_low)`` of the
    unrolled steps.

    Returns ``(motion, trig, orders, pending)``: ``motion = (j, t, theta, omega, max_abs,
    n_hist)``, ``trig`` and ``orders`` as given, updated, and, when it stopped at an event, the
    step it took there, ``pending = (True, theta, omega, sin, cos, order)`` at its end (its
    polynomial in ``cf``), so that it is not taken twice.
    """
    kind, amp, _, _ = F
    t_start, h_uniform, _ = grid
    sc_known, s_phi, c_phi = trig
    order, n_low = orders
    pending, th2, om2, s_next, c_next, n_used = False, 0.0, 0.0, 0.0, 1.0, 0
    uniform = nodes.shape[0] == 0
    h, q, inv_h = h_uniform, p2 * h_uniform * h_uniform, 1.0 / h_uniform if uniform else 0.0
    # the loop carries omega h (one step's length to the next on a uniform grid: no rounding
    # from omega to omega h and back at every step, and two multiplications less on the chain
    # of dependent operations from one step to the next)
    wh = omega * h
    if uniform and kind == NODAL and not record and j < n_int and t == t_start + j * h_uniform:
        # records without history (the common case): the same loop, stripped to what changes
        # from one interval to the next
        if not sc_known:
            s_phi, c_phi = corner_sincos(theta, s, sa, ca)
            sc_known = True
        while j < n_int:
            # one loop per order (rocking._taylor_fixed.fixed_run_N, each holding one unrolled
            # step: one loop holding all seven cost ~4 ns a step)
            res = fixed_run(order, uval, amp, j, n_int, q, s, theta, wh, s_phi, c_phi, max_abs,
                            n_low, LOW_RUN_FIXED, TAYLOR_EPS, cf)
            (stop, j, theta, wh, s_phi, c_phi, max_abs, n_low, th2, wh2, s_next, c_next,
             lower) = res
            if stop == 1:
                break  # the series needs more terms: run_core() raises the order (rare)
            n_used = order
            if lower:
                order -= 2  # a lower order has been enough for a while
            if stop == 3:
                om2 = wh2 * inv_h
                pending = True
                break  # a turning point, an impact or overturning: the general way
        t = t_start + j * h_uniform
        omega = wh * inv_h
        return ((j, t, theta, omega, max_abs, n_hist), (sc_known, s_phi, c_phi), (order, n_low),
                (pending, th2, om2, s_next, c_next, n_used))
    while j < n_int:
        if uniform:
            ta = t_start + j * h_uniform
            tb = t_start + (j + 1) * h_uniform
        else:
            ta, tb = nodes[j], nodes[j + 1]
            h_new = tb - ta
            wh = omega * h_new
            h = h_new
            q = p2 * h * h
            inv_h = 1.0 / h
        if t != ta:
            break
        if not sc_known:
            s_phi, c_phi = corner_sincos(theta, s, sa, ca)
            sc_known = True
        if kind == NODAL:
            u0, u1 = amp * uval[j], amp * (uval[j + 1] - uval[j])
        else:
            u0, u1 = linear_forcing(F, uval, j, ta, tb, t, h)
        th2, wh2, s_next, c_next, flag = taylor_fixed(order, u0, u1, q, theta, wh, s_phi, c_phi,
                                                      TAYLOR_EPS, cf)
        if flag == 0:
            break  # the series needs more terms: run_core() raises the order (rare)
        n_used = order
        n_low = n_low + 1 if flag == 2 else 0
        if n_low >= LOW_RUN_FIXED and order > FIXED_ORDERS[0]:
            order -= 2  # a lower order has been enough for a while
            n_low = 0
        if not (wh * wh2 > 0.0 and s * th2 > 0.0 and abs(th2) < HALF_PI):
            om2 = wh2 * inv_h
            pending = True
            break  # a turning point, an impact or overturning: the general way
        if abs(th2) > max_abs:
            max_abs = abs(th2)
        theta, wh, t = th2, wh2, tb
        omega = wh * inv_h
        s_phi, c_phi = s_next, c_next
        if record:
            hist_t[n_hist], hist_theta[n_hist], hist_omega[n_hist] = t, theta, omega
            n_hist += 1
        j += 1
    return ((j, t, theta, omega, max_abs, n_hist), (sc_known, s_phi, c_phi), (order, n_low),
            (pending, th2, om2, s_next, c_next, n_used))


@njit(cache=True)
def _skip_rest(amp, uval, grid, j, n_int, t, tan_a, record, hist_t, hist_theta, hist_omega,
               n_hist):
    """At rest under a record on a uniform grid: on to the first interval whose ends exceed the
    uplift threshold (the forcing is linear between them), the history meanwhile zero.  Returns
    ``(j, t, n_hist)``."""
    t_start, h_uniform, _ = grid
    while j < n_int and abs(amp * uval[j]) <= tan_a and abs(amp * uval[j + 1]) <= tan_a:
        j += 1
        if record:
            hist_t[n_hist] = t_start + j * h_uniform
            hist_theta[n_hist], hist_omega[n_hist] = 0.0, 0.0
            n_hist += 1
    return j, max(t, t_start + j * h_uniform), n_hist


@njit(cache=True)
def _uplift(F, uval, j, ta, tb, t, t2, tan_a, rest_until):
    """A block at rest from ``t``: ``(t_up, s)``, when and to which side it uplifts inside
    ``[t, t2]`` (``|ug''|`` first exceeds ``g tan(alpha)``, not before ``rest_until``), or
    ``(t2, 0)`` if it stays at rest."""
    if rest_until >= t2:
        return t2, 0.0
    if rest_until > t:
        t = rest_until
    t_up = _uplift_time(F, uval, j, ta, tb, t, t2, tan_a)
    if np.isnan(t_up):
        return t2, 0.0
    u_up = forcing(F, uval, j, ta, tb, t_up)
    if abs(u_up) <= tan_a:  # touching the threshold from below at t2
        u_up = forcing(F, uval, j, ta, tb, t2)
    return t_up, -1.0 if u_up > 0.0 else 1.0


@njit(cache=True)
def _unrolled(fixed, orders, bounds, F, uval, j, ta, tb, t, h, U, q, theta, omega, s_phi, c_phi,
              cf):
    """One step of the unrolled Taylor steps (:mod:`rocking._taylor_fixed`; forcing linear over
    the step, ``fixed``, or given by its series, written into ``U``), at the order that
    ``orders = (order, n_low)`` adapts: raised until the series is summed (``ok`` False if even
    the highest of ``bounds = (lowest, highest, low_run)`` is not enough: the general loop takes
    the step), lowered after ``low_run`` steps in a row where a lower one would have done.
    Returns ``(ok, theta, omega, sin, cos, n, orders)``: the state at the end of the step, the
    order ``n`` it took (its polynomial is in ``cf``), and the orders for the next step."""
    order, n_low = orders
    lowest, highest, low_run = bounds
    wh = omega * h
    while True:
        # (one call site of each: the unrolled orders are inlined once)
        if fixed:
            u0, u1 = linear_forcing(F, uval, j, ta, tb, t, h)
            th2, wh2, s_next, c_next, flag = taylor_fixed(order, u0, u1, q, theta, wh, s_phi,
                                                          c_phi, TAYLOR_EPS, cf)
        else:
            forcing_series(F, uval, j, ta, tb, t, h, U, order - 1)
            th2, wh2, s_next, c_next, flag = taylor_smooth(order, U, q, theta, wh, s_phi, c_phi,
                                                           TAYLOR_EPS, cf)
        if flag != 0 or order >= highest:
            break
        order += 2  # the series needs more terms: the next order up
    if flag == 0:
        return False, 0.0, 0.0, 0.0, 1.0, order, (order + 2, n_low)  # beyond the unrolled orders
    n_used = order
    n_low = n_low + 1 if flag == 2 else 0
    if n_low >= low_run and order > lowest:
        order -= 2  # a lower order has been enough for a while
        n_low = 0
    return True, th2, wh2 / h, s_next, c_next, n_used, (order, n_low)


@njit(cache=True)
def _zeno_rest(F, uval, j, ta, tb, t, omega, s, D, eta):
    """After an impact with ``|omega|`` below the Zeno threshold (block on side ``s`` now): the
    remaining geometric series of hops summed in closed form.  Returns the time until which the
    block is at rest."""
    p, sa, ca, linear, _ = D
    u_now = forcing(F, uval, j, ta, tb, t)
    if linear:  # (sa is alpha itself in the linearised model)
        a_new = p * p * (sa + s * u_now)
        a_old = p * p * (sa - s * u_now)
    else:
        a_new = p * p * (sa + s * u_now * ca)
        a_old = p * p * (sa - s * u_now * ca)
    if a_new > 0.0 and a_old > 0.0:
        return t + 2.0 * abs(omega) / (1.0 - eta * eta) * (1.0 / a_new + eta / a_old)
    # the forcing is at or past the uplift threshold on one side: at rest now, to uplift as the
    # rest rule says (what is left out is again hops of height ~(zeno_tol alpha)^2; hopping on
    # would take ever shorter hops, millions of them, down to rounding)
    return t


@njit(cache=True)
def _overturn(cubic, s, th2, t, h):
    """``|theta|`` reaches ``pi/2`` inside the step (``th2`` at its end beyond it): ``(t, theta,
    omega)`` there, by bisection on the step's cubic Hermite interpolant ``cubic``."""
    c0, c1, c2, c3 = cubic
    lo, hi, _ = _first_crossing(c0, c1, c2, c3, -s, -HALF_PI)
    x = 1.0 if lo < 0.0 else hi
    for _ in range(60):
        if lo < 0.0:
            break
        mid = 0.5 * (lo + hi)
        if s * _cubic(c0, c1, c2, c3, mid) < HALF_PI:
            lo = mid
        else:
            hi = mid
        x = hi
    return t + x * h, math.copysign(HALF_PI, th2), c1 / h + x * (2.0 * c2 + 3.0 * c3 * x) / h


@njit(cache=True, nogil=True)
def run_core(F, uval, grid, nodes, block, settings, start, n_end, hist_t, hist_theta, hist_omega,
             impacts, work):
    """:func:`run` from interval ``start.j0`` to the end of interval ``n_end - 1``, with scratch
    space ``work`` (:data:`WORK_SIZE` floats) so that it allocates nothing (the batch engine,
    :mod:`rocking.lanes`, calls it for single intervals where something happens).  Arguments as
    :func:`run` takes them.

    Returns :func:`run`'s values and, last, the time until which the block is at rest after a
    Zeno sequence (``-inf`` if none pending).
    """
    kind, amp, _, _ = F
    t_start, h_uniform, n_sub = grid
    p, alpha, eta = block
    linear, method, zeno_tol, stop_at_rest, record = settings
    tan_a = math.tan(alpha)
    m = NMAX + 3
    kt = work[:N_STAGES]
    kw = work[N_STAGES:2 * N_STAGES]
    U = work[2 * N_STAGES:2 * N_STAGES + 2 * m]
    S = work[2 * N_STAGES + 2 * m:2 * N_STAGES + 3 * m]
    C = work[2 * N_STAGES + 3 * m:2 * N_STAGES + 4 * m]
    cf = work[2 * N_STAGES + 4 * m:2 * N_STAGES + 5 * m]
    # sin, cos of s alpha - theta when known (initial values that are passed on to compiled
    # functions as np.bool_ / np.int64: a bare constant is typed as a literal, and numba would
    # compile the callee once more for it)
    sc_known, s_phi, c_phi = np.bool_(False), 0.0, 1.0
    pending, th2, om2, s_next, c_next, nt, n_pending = False, 0.0, 0.0, 0.0, 1.0, 0, 0
    # forcing linear over each step: unrolled Taylor steps of a fixed order, adapted as we go
    # (raised as soon as a step's last terms are too large, lowered after a run of steps where
    # a lower one would have done); any other step takes the general loop
    fixed = method == TAYLOR and not linear and (kind == NODAL or kind == RECT or kind == FREE)
    # smooth pulses: the same with the forcing's own series (unrolled up to SMOOTH_ORDERS[-1])
    unrolled = method == TAYLOR and not linear
    # (constants passed on to compiled functions as np.int64: a bare constant is typed as a
    # literal, and numba would compile the callee once more for it)
    if fixed:
        bounds = (FIXED_ORDERS[0], FIXED_ORDERS[-1], LOW_RUN_FIXED)
        order = np.int64(FIXED_ORDERS[2])
    else:
        # steps in a row a lower order must have sufficed: more than for records, whose steps
        # are all alike
        bounds = (SMOOTH_ORDERS[0], SMOOTH_ORDERS[-1], 16)
        order = np.int64(SMOOTH_ORDERS[2])
    orders = (order, np.int64(0))
    n_general = np.int64(FIXED_ORDERS[-1])  # order of the last step of the general Taylor loop
    p2 = p * p
    if linear:
        sa, ca = alpha, 1.0
    else:
        sa, ca = math.sin(alpha), math.cos(alpha)
    D = Dynamics(p, sa, ca, linear, method)
    uniform = nodes.shape[0] == 0
    theta, omega = start.theta, start.omega
    if theta != 0.0:
        s = 1.0 if theta > 0.0 else -1.0
    elif omega != 0.0:
        s = 1.0 if omega > 0.0 else -1.0
    else:
        s = 0.0
    uplifted = s != 0.0
    max_abs = abs(theta)
    n_imp = 0
    rest_until = start.rest_until
    omega_zeno = zeno_tol * p * alpha
    status = ROCKING if s != 0.0 else REST
    j = start.j0
    t = nodes[j] if not uniform else t_start + j * h_uniform
    n_int = n_end
    n_hist = 0
    if record:
        hist_t[0], hist_theta[0], hist_omega[0] = t, theta, omega
        n_hist = 1
    while j < n_int:
        if s == 0.0 and kind == NODAL and uniform and not stop_at_rest and rest_until <= t:
            j, t, n_hist = _skip_rest(amp, uval, grid, j, n_int, t, tan_a, record, hist_t,
                                      hist_theta, hist_omega, n_hist)
            if j >= n_int:
                break
        if fixed and n_sub == 1 and s != 0.0 and orders[0] <= FIXED_ORDERS[-1]:
            # the common case, whole intervals with no event, in a tight loop
            motion, trig, orders, pend = _cruise(
                F, uval, grid, nodes, j, n_int, t, theta, omega, s, sa, ca, p2, max_abs,
                (sc_known, s_phi, c_phi), orders, cf, record, hist_t, hist_theta, hist_omega,
                n_hist)
            j, t, theta, omega, max_abs, n_hist = motion
            sc_known, s_phi, c_phi = trig
            pending, th2, om2, s_next, c_next, n_pending = pend
            if j >= n_int:
                break
        if uniform:
            ta = t_start + j * h_uniform
            tb = t_start + (j + 1) * h_uniform
        else:
            ta, tb = nodes[j], nodes[j + 1]
        hsub = (tb - ta) / n_sub
        for k in range(n_sub):
            t2 = tb if k == n_sub - 1 else ta + (k + 1) * hsub
            events = 0
            while t < t2:
                events += 1
                if s == 0.0:
                    # ---- at rest: wait for |ug''| > g tan(alpha)
                    sc_known = False
                    if stop_at_rest:
                        status = REST
                        t = max(t, rest_until)
                        break
                    t, s = _uplift(F, uval, j, ta, tb, t, t2, tan_a, rest_until)
                    if s == 0.0:
                        break
                    theta, omega = 0.0, 0.0
                    uplifted = True
                    status = ROCKING
                    if t >= t2:
                        break
                # ---- a step: the one the tight loop took and stopped at, an unrolled Taylor
                # step, else the general loop (any order, other methods, the linear model)
                h = t2 - t
                nt = 0
                if pending:
                    nt = n_pending
                    pending = False
                elif unrolled and orders[0] <= bounds[1]:
                    if not sc_known:
                        s_phi, c_phi = corner_sincos(theta, s, sa, ca)
                        sc_known = True
                    ok, th2, om2, s_next, c_next, n_used, orders = _unrolled(
                        fixed, orders, bounds, F, uval, j, ta, tb, t, h, U, p2 * h * h, theta,
                        omega, s_phi, c_phi, cf)
                    if ok:
                        nt = n_used
                if nt == 0:
                    th2, om2, nt, s_next, c_next = _advance(
                        F, uval, j, ta, tb, t, h, theta, omega, s, D, kt, kw, U, S, C, cf, sc_known,
                        s_phi, c_phi, n_general)
                    if nt > 0:
                        n_general = nt
                        if unrolled:  # back to the unrolled steps when they suffice
                            orders = (max(bounds[0], nt + (nt & 1)), orders[1])
                # sin and cos of the angle to the corner carry over only to an accepted step
                sc_known = False
                if omega * om2 > 0.0 and s * th2 > 0.0 and abs(th2) < HALF_PI:
                    # fast path: no turning point, so theta is monotonic over the step and can
                    # neither reach 0 nor peak inside it (the common case)
                    if abs(th2) > max_abs:
                        max_abs = abs(th2)
                    theta, omega, t = th2, om2, t2
                    sc_known, s_phi, c_phi = nt > 0, s_next, c_next
                    continue
                cubic = _hermite(theta, omega, th2, om2, h)
                # ---- impact: theta reaches 0 (first crossing of the step, grazes included)
                lo, hi, interior = _first_crossing(cubic[0], cubic[1], cubic[2], cubic[3], s, 0.0)
                if interior:
                    # a dip of the interpolant inside the step: real only if the solution dips
                    th_e, _ = _sub(F, uval, j, ta, tb, t, h, hi, theta, omega, s, D, kt, kw, cf, nt)
                    if s * th_e > 0.0:
                        lo = -1.0
                if lo >= 0.0 and events < _MAX_EVENTS_PER_STEP:
                    # the root of the cubic (cheap; one root in [lo, hi], where it is monotonic),
                    # then Newton on the step's polynomial or the re-integrated solution: its
                    # first iteration corrects the interpolation error, the second confirms
                    # convergence to rounding (here, not in a function of its own: a call would
                    # count references to the four arrays it needs at every impact)
                    x = _cubic_root(cubic[0], cubic[1], cubic[2], cubic[3], s, lo, hi)
                    converged = False
                    for _ in range(8):
                        th_x, om_x = _sub(F, uval, j, ta, tb, t, h, x, theta, omega, s, D, kt, kw,
                                          cf, nt)
                        if om_x == 0.0:
                            break
                        xn = x - th_x / (om_x * h)
                        if xn <= 0.0 or xn > 1.0:
                            break
                        converged = abs(xn - x) < 4e-16
                        x = xn
                        if converged:
                            break  # (th_x, om_x) is the state 4e-16 h before x: kept as is
                    if not converged:
                        th_x, om_x = _sub(F, uval, j, ta, tb, t, h, x, theta, omega, s, D, kt, kw,
                                          cf, nt)
                    t_imp = t + x * h
                    if t_imp <= t:
                        t_imp = t + 4.5e-16 * max(abs(t), 1.0)  # at least one ulp of t
                    # the peak between t and the impact (none above max_abs if the polynomial's
                    # bound says so: the small hops of a block coming to rest; checked here, as
                    # a call would count references to four arrays)
                    if nt == 0 or not _below(cf, nt, max_abs):
                        max_abs = _step_peak(F, uval, j, ta, tb, t, t_imp - t, theta, omega, th_x,
                                             om_x, s, D, kt, kw, h, cf, nt, max_abs)
                    t = t_imp
                    if n_imp < impacts.shape[0]:
                        impacts[n_imp] = t
                    n_imp += 1
                    omega = eta * om_x
                    s = -s
                    theta = 0.0
                    if abs(omega) <= omega_zeno:
                        # ---- Zeno: the remaining hops summed in closed form
                        rest_until = _zeno_rest(F, uval, j, ta, tb, t, omega, s, D, eta)
                        s = 0.0
                        omega = 0.0
                        status = REST
                    continue
                if lo >= 0.0:  # too many events in one step: settle (never loops forever)
                    s = 0.0
                    theta, omega = 0.0, 0.0
                    status = REST
                    rest_until = t2
                    continue
                if abs(th2) >= HALF_PI:
                    # ---- overturning: |theta| reaches pi/2
                    t, theta, omega = _overturn(cubic, s, th2, t, h)
                    max_abs = HALF_PI
                    status = OVERTURNED
                    break
                # ---- a turning point inside the step
                if nt == 0 or not _below(cf, nt, max_abs):
                    max_abs = _step_peak(F, uval, j, ta, tb, t, h, theta, omega, th2, om2, s, D, kt,
                                         kw, h, cf, nt, max_abs)
                if abs(th2) > max_abs:
                    max_abs = abs(th2)
                theta, omega, t = th2, om2, t2
                sc_known, s_phi, c_phi = nt > 0, s_next, c_next
            if status == OVERTURNED or (stop_at_rest and status == REST):
                break
        if record:
            hist_t[n_hist], hist_theta[n_hist], hist_omega[n_hist] = t, theta, omega
            n_hist += 1
        if status == OVERTURNED or (stop_at_rest and status == REST):
            break
        j += 1
    if status == REST:
        theta, omega = 0.0, 0.0
    return status, theta, omega, t, max_abs, n_imp, n_hist, uplifted, rest_until


def run(forcing, uval, grid, nodes, n_int, block, settings, history, impacts, start=None):
    """Integrate the rocking block over intervals ``start.j0 .. n_int - 1`` of the grid.

    Parameters
    ----------
    forcing : Forcing
        ``(kind, amp, tp, t0)``: the ground motion (see :func:`forcing`).
    uval : float array
        Node values of ``ug''/g`` for ``kind == NODAL`` (else not read).
    grid : Grid
        ``(t_start, h, n_sub)``: the uniform grid ``t_start + j h`` (s) unless ``nodes`` are
        given, and RK4 (or exact) sub-steps per interval.
    nodes : float array
        Node times (s); empty for the uniform grid.
    n_int : int
        Intervals of the grid to run to.
    block : Rocker
        ``(p, alpha, eta)`` (rad/s, rad, -).
    settings : Settings
        ``(linear, method, zeno_tol, stop_at_rest, record)``: the linearised equation (exact
        stepping) instead of the nonlinear one; the nonlinear stepping ``TAYLOR``, ``RK8`` or
        ``RK4``; Zeno sequences summed once ``|omega| < zeno_tol * p * alpha``; stop as soon as
        the block is at rest (free motion only); write the history.
    history : (t, theta, omega) float arrays
        The history (s, rad, rad/s) when ``record``, one value per interval end from ``j0``
        (length ``n_int - j0 + 1``).
    impacts : float array
        Impact times (s); impacts beyond its length are counted only.
    start : Start, optional
        ``(j0, theta, omega, rest_until)``: first interval (its start time), the state there
        (rad, rad/s), at rest until ``rest_until`` (after a Zeno sequence; ``-inf`` if not).
        Default: interval 0, at rest.

    Returns
    -------
    status, theta, omega, t_end, max_abs_theta, n_impacts, n_hist, uplifted, rest_until
    """
    kind, amp, tp, t0 = forcing
    check_kind(kind)
    t_start, h, n_sub = grid
    linear, method, zeno_tol, stop_at_rest, record = settings
    j0, theta0, omega0, rest_until = start or (0, 0.0, 0.0, -math.inf)
    # every scalar as the one type compiled for it (an int theta0 would compile a second
    # version), and plain tuples: numba reads them from Python four times faster than named ones
    # (~0.7 against ~2.6 us each), and :func:`_entry` names them again in compiled code
    args = ((int(kind), float(amp), float(tp), float(t0)), as_input(uval),
            (float(t_start), float(h), int(n_sub)), as_input(nodes),
            (float(block[0]), float(block[1]), float(block[2])),
            (bool(linear), int(method), float(zeno_tol), bool(stop_at_rest), bool(record)),
            (int(j0), float(theta0), float(omega0), float(rest_until)),
            int(n_int), *history, impacts, np.zeros(WORK_SIZE))
    if first_call_done(_entry):  # the common case, without the notice's context (~10 us)
        return _entry(*args)
    with compiling_notice(_entry):
        return _entry(*args)


@njit(cache=True, nogil=True)
def _entry(forcing, uval, grid, nodes, block, settings, start, n_end, hist_t, hist_theta,
           hist_omega, impacts, work):
    """:func:`run_core` called from Python, with its bundles as plain tuples."""
    return run_core(Forcing(*forcing), uval, Grid(*grid), nodes, Rocker(*block),
                    Settings(*settings), Start(*start), n_end, hist_t, hist_theta, hist_omega,
                    impacts, work)


def as_input(a):
    """``a`` as the compiled code takes arrays: float64, C-contiguous, writeable (numba compiles
    one version per array type; a read-only record would otherwise get a second one)."""
    if a.dtype == np.float64 and a.flags.c_contiguous and a.flags.writeable:
        return a
    return np.require(a, dtype=np.float64, requirements=("C", "W"))


def check_kind(kind):
    """Raise :class:`rocking.errors.RockingInputError` unless ``kind`` is one of :data:`KINDS`
    (the engine computes only the forcing it knows: an unknown kind is never guessed)."""
    if kind not in KINDS:
        from .errors import RockingInputError

        raise RockingInputError(f"the engine has no forcing of kind {kind!r}; it knows "
                                f"{', '.join(f'{k} ({n})' for k, n in KINDS.items())}")
