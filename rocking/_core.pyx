# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True
# cython: initializedcheck=False, nonecheck=False, infer_types=False
"""The compiled core of the rocking solver: the event-driven engine (docs/theory.md section 2)
and the batch engine's lanes, compiled with the package (Cython, built by ``pip install``).

:mod:`rocking.engine` describes the engine and is its Python entry (:func:`rocking.engine.run`);
:mod:`rocking.lanes` describes the batch engine and spreads batches over threads.  Everything
here runs without the GIL on C doubles and pointers (no Python object, no allocation: the
scratch space is on the C stack), so that Python threads run batches in parallel.

The unrolled Taylor steps are generated: ``_taylor_fixed.pxi`` by ``rocking/_make_taylor.py``,
``_taylor_lanes.h`` (C) by ``rocking/_make_lanes.py`` (included below).
"""
from libc.stdint cimport int64_t
from libc.string cimport memset
from libc.math cimport (acos, copysign, cos, exp, fabs, fmax, isnan, sin, sinh, sqrt, tan,
                        INFINITY, NAN)

import numpy as np

from . import _dop853

cdef extern from *:
    """
    #define ROCKING_PI 3.141592653589793
    """
    double PI "ROCKING_PI"

cdef double HALF_PI = 0.5 * PI
cdef double TWO_PI = 2.0 * PI
cdef double SQRT3 = sqrt(3.0)
# the antisymmetric Ricker's peak factor, defined once with the shape (pulses.shapes.BETA)
from pulses.shapes import BETA as _SHAPE_BETA
cdef double BETA = _SHAPE_BETA

# forcing kinds (rocking.engine.KINDS), stepping methods (rocking.engine.METHODS), statuses
cdef enum:
    FREE = -1
    NODAL = 0
    RECT = 1
    SINE = 2
    RICKER_SYM = 3
    RICKER_ANTI = 4
#: the pulse codes the steps are compiled for, in the order rect, sine, ricker-sym, ricker-anti
#: (rocking.engine checks them against the shapes' own codes, pulses.shapes, at import)
KIND_CODES = (RECT, SINE, RICKER_SYM, RICKER_ANTI)

cdef enum:
    TAYLOR = 0
    RK8 = 1
    RK4 = 2
cdef enum:
    REST = 0
    ROCKING = 1
    OVERTURNED = 2
    LIFTOFF = 3  # g + av < 0: the block leaves the ground (the model stops there)
    FINAL = 4    # a lane of a batch stopped once its verdict and peak are final (_finals)

cdef enum:
    #: highest order of a Taylor step (rocking.engine.NMAX)
    NMAX = 40
    #: length of the series arrays
    M = NMAX + 3
    N_STAGES = 12
    #: steps in a row for which a lower order would have done before an unrolled step of forcing
    #: linear over the step (records) takes the next order down
    LOW_RUN_FIXED = 8
    #: intervals in a row in which a lower order sufficed for every rocking lane before it is
    #: lowered (rocking.lanes.LOW_RUN)
    LOW_RUN = 2
    #: intervals between the checks of which lanes of a batch run until final are final
    FINAL_EVERY = 16

cdef long MAX_EVENTS_PER_STEP = 1000000
#: a Taylor series is cut once two consecutive terms of theta and of ``h * omega`` fall below
#: ``TAYLOR_EPS`` times the size of the step's leading terms (rocking.engine.TAYLOR_EPS)
cdef double TAYLOR_EPS = 1e-15

cdef double RK8_A[N_STAGES][N_STAGES]
cdef double RK8_B[N_STAGES]
cdef double RK8_C[N_STAGES]
cdef double INV[M]       # 1/k (0 for k = 0)
cdef double INV2[M]      # 1/((k+1)(k+2))


def _tables():
    cdef int i, k
    for i in range(N_STAGES):
        RK8_B[i] = _dop853.B[i]
        RK8_C[i] = _dop853.C[i]
        for k in range(N_STAGES):
            RK8_A[i][k] = _dop853.A[i, k]
    INV[0] = 0.0
    for k in range(1, M):
        INV[k] = 1.0 / k
    for k in range(M):
        INV2[k] = 1.0 / ((k + 1) * (k + 2))


_tables()

ctypedef struct Forcing:
    # the ground motion: kind, amp (ap/g of a pulse, or the factor on the node values of ug''/g),
    # tp, t0 (a pulse's period and time shift, s), and the node values (records)
    int kind
    double amp, tp, t0
    const double* uval
    # vertical ground motion (docs/theory.md section 10, records only): 1 + av/g is
    # 1 + vamp * vval[j] at the nodes, linear between them; vval NULL: none (gravity 1)
    const double* vval
    double vamp

ctypedef struct Dyn:
    # the equation as the steppers take it: p (rad/s), sin and cos of alpha (alpha and 1 in the
    # linearised model), linear, method
    double p, sa, ca
    bint linear
    int method

ctypedef struct Outcome:
    # what run_core returns
    int status
    double theta, omega, t, max_abs
    long n_imp, n_hist
    bint uplifted
    double rest_until

include "_taylor_fixed.pxi"


# --------------------------------------------------------------------------- forcing
cdef double forcing(const Forcing* F, long j, double ta, double tb, double t) noexcept nogil:
    """Ground acceleration over g at time ``t`` inside interval ``j`` = ``[ta, tb]``."""
    cdef double tau, x2, x
    cdef int kind = F.kind
    if kind == NODAL:
        return F.amp * (F.uval[j] + (F.uval[j + 1] - F.uval[j]) * ((t - ta) / (tb - ta)))
    if kind == FREE:
        return 0.0
    if kind == RECT:
        return F.amp
    tau = (t - F.t0) / F.tp
    if kind == SINE:
        return F.amp * sin(TWO_PI * tau)
    if kind == RICKER_SYM:
        x2 = (PI * tau) * (PI * tau)
        return F.amp * (1.0 - 2.0 * x2) * exp(-x2)
    if kind == RICKER_ANTI:
        x = TWO_PI * tau / SQRT3
        return F.amp * (x * x - 3.0) * x * exp(-0.5 * x * x) / BETA
    return NAN  # no other kind reaches here (rocking.engine.check_kind), and none is guessed


# --------------------------------------------------------------------------- steppers
cdef inline (double, double) corner_sincos(double theta, double s, double sa,
                                           double ca) noexcept nogil:
    """``sin`` and ``cos`` of ``s alpha - theta`` (by angle addition; none needed at
    ``theta = 0``, just after an uplift or an impact)."""
    cdef double sn, cs
    if theta == 0.0:
        return s * sa, ca
    sn = sin(theta)
    cs = cos(theta)
    return s * sa * cs - ca * sn, ca * cs + s * sa * sn


cdef inline double _rhs(double theta, double s, double u, double p2, double sa, double ca,
                        bint linear) noexcept nogil:
    cdef double sin_d, cos_d
    if linear:
        return p2 * (theta - s * sa - u)  # sa carries alpha itself in the linear model
    sin_d, cos_d = corner_sincos(theta, s, sa, ca)
    return -p2 * (sin_d + u * cos_d)


cdef (double, double) step(const Forcing* F, long j, double ta, double tb, double t, double h,
                           double theta, double omega, double s, const Dyn* D, double* kt,
                           double* kw) noexcept nogil:
    """Advance ``(theta, omega)`` on side ``s`` from ``t`` by ``h`` (inside interval ``j``).

    Nonlinear: the 8th-order Dormand-Prince formula (fixed step; the 12 stages of DOP853) for
    ``method == RK8``, classical RK4 otherwise (the Taylor stepper is :func:`taylor_series`).
    Linear: the exact solution.
    """
    cdef double p = D.p, sa = D.sa, ca = D.ca, p2 = D.p * D.p
    cdef double u0, u1, y0, dy0, sh, chm1, hh, u_a, u_m, u_b
    cdef double k1t, k1w, k2t, k2w, k3t, k3w, k4t, k4w
    if D.linear:
        # forcing is linear on the interval: u(t + x) = u0 + u1 x, exact cosh/sinh solution
        u0 = forcing(F, j, ta, tb, t)
        u1 = (forcing(F, j, ta, tb, t + h) - u0) / h if h > 0 else 0.0
        # y = theta - s alpha - u obeys y'' = p^2 y; written as increments with
        # cosh(x) - 1 = 2 sinh(x/2)^2 so that short steps (Zeno hops) lose no digits
        y0 = theta - s * sa - u0
        dy0 = omega - u1
        sh = sinh(p * h)
        chm1 = 2.0 * sinh(0.5 * p * h) * sinh(0.5 * p * h)
        return (theta + y0 * chm1 + dy0 / p * sh + u1 * h,
                omega + y0 * p * sh + dy0 * chm1)
    if D.method == RK8:
        return _step_rk8(F, j, ta, tb, t, h, theta, omega, s, p2, sa, ca, kt, kw)
    hh = 0.5 * h
    u_a = forcing(F, j, ta, tb, t)
    u_m = forcing(F, j, ta, tb, t + hh)
    u_b = forcing(F, j, ta, tb, t + h)
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


cdef inline (double, double) _step_rk8(const Forcing* F, long j, double ta, double tb, double t,
                                       double h, double theta, double omega, double s, double p2,
                                       double sa, double ca, double* kt,
                                       double* kw) noexcept nogil:
    """One fixed step of the 8th-order Dormand-Prince formula (DOP853's 12 stages).

    ``kt``, ``kw``: scratch arrays of length ``N_STAGES``.
    """
    cdef int i, m
    cdef double th_i, om_i, u_i, th_new, om_new
    for i in range(N_STAGES):
        th_i = theta
        om_i = omega
        for m in range(i):
            th_i += h * RK8_A[i][m] * kt[m]
            om_i += h * RK8_A[i][m] * kw[m]
        u_i = forcing(F, j, ta, tb, t + RK8_C[i] * h)
        kt[i] = om_i
        kw[i] = _rhs(th_i, s, u_i, p2, sa, ca, False)
    th_new = theta
    om_new = omega
    for i in range(N_STAGES):
        th_new += h * RK8_B[i] * kt[i]
        om_new += h * RK8_B[i] * kw[i]
    return th_new, om_new


# --------------------------------------------------------------------------- Taylor series
cdef inline (double, double) linear_forcing(const Forcing* F, long j, double ta, double tb,
                                            double t, double h) noexcept nogil:
    """``(u0, u1)`` with ``u(t + x h) = u0 + u1 x`` for forcing linear over the step (records,
    rectangular pulse, free motion)."""
    cdef double slope
    if F.kind == NODAL:
        slope = F.amp * (F.uval[j + 1] - F.uval[j]) / (tb - ta)
        return F.amp * F.uval[j] + slope * (t - ta), slope * h
    if F.kind == RECT:
        return F.amp, 0.0
    return 0.0, 0.0


cdef inline (double, double) linear_gravity(const Forcing* F, long j, double ta, double tb,
                                            double t, double h) noexcept nogil:
    """``(g0, g1)`` with the effective gravity over g ``1 + av/g = g0 + g1 x`` over the step
    (``x = (t' - t) / h``; records are linear between samples)."""
    cdef double slope = F.vamp * (F.vval[j + 1] - F.vval[j]) / (tb - ta)
    return 1.0 + (F.vamp * F.vval[j] + slope * (t - ta)), slope * h


cdef inline double gravity(const Forcing* F, long j, double ta, double tb, double t) noexcept nogil:
    """Effective gravity over g, ``1 + av/g``, at ``t`` inside interval ``j`` (1 without a
    vertical)."""
    if F.vval == NULL:
        return 1.0
    return 1.0 + F.vamp * (F.vval[j] + (F.vval[j + 1] - F.vval[j]) * ((t - ta) / (tb - ta)))


cdef (int, bint) forcing_series(const Forcing* F, long j, double ta, double tb, double t,
                                double h, double* U, long n_terms) noexcept nogil:
    """Taylor coefficients of ``u(t + x h)`` in powers of ``x`` (``u = ug''/g``), into ``U``.

    Returns ``(nu, complete)``: the number of coefficients written, and whether the rest are
    zero.  Records (linear on the interval), the rectangular pulse and free motion: 2, complete.
    Smooth pulses (their series from the recurrence ``E' = g' E`` for ``E = exp(g)``): the first
    ``min(n_terms, NMAX + 1)``, complete only when that is ``NMAX + 1``.
    """
    cdef int kind = F.kind, k, r
    cdef long n
    cdef double amp = F.amp, tp = F.tp, t0 = F.t0
    cdef double w, sn, cs, c, y0, dy, g1, g2, e, p0, p1, p2, p3, scale, e1, e2, e3
    if kind == NODAL or kind == FREE or kind == RECT:
        U[0], U[1] = linear_forcing(F, j, ta, tb, t, h)
        return 2, True
    n = min(n_terms, NMAX + 1)
    if kind == SINE:
        w = TWO_PI * h / tp
        sn = sin(TWO_PI * (t - t0) / tp)
        cs = cos(TWO_PI * (t - t0) / tp)
        c = amp
        for k in range(n):
            r = k % 4
            U[k] = c * (sn if r == 0 else (cs if r == 1 else (-sn if r == 2 else -cs)))
            c *= w * INV[k + 1]
        return <int>n, n == NMAX + 1
    # Ricker pulses: P(y) exp(g(y)) with y = y0 + dy x linear in x
    if kind == RICKER_SYM:
        y0 = PI * (t - t0) / tp
        dy = PI * h / tp
        g1 = -2.0 * y0 * dy
        g2 = -dy * dy
        e = exp(-y0 * y0)
        p0 = 1.0 - 2.0 * y0 * y0
        p1 = -4.0 * y0 * dy
        p2 = -2.0 * dy * dy
        p3 = 0.0
        scale = amp
    else:
        y0 = TWO_PI * (t - t0) / (tp * SQRT3)
        dy = TWO_PI * h / (tp * SQRT3)
        g1 = -y0 * dy
        g2 = -0.5 * dy * dy
        e = exp(-0.5 * y0 * y0)
        p0 = y0 * (y0 * y0 - 3.0)
        p1 = 3.0 * (y0 * y0 - 1.0) * dy
        p2 = 3.0 * y0 * dy * dy
        p3 = dy * dy * dy
        scale = amp / BETA
    # E_k = (g1 E_{k-1} + 2 g2 E_{k-2}) / k;  U_k = sum_i P_i E_{k-i}
    e1 = 0.0
    e2 = 0.0
    e3 = 0.0  # E_{k-1}, E_{k-2}, E_{k-3}
    for k in range(n):
        if k > 0:
            e = (g1 * e1 + 2.0 * g2 * e2) * INV[k]
        U[k] = scale * (p0 * e + p1 * e1 + p2 * e2 + p3 * e3)
        e3 = e2
        e2 = e1
        e1 = e
    return <int>n, n == NMAX + 1


cdef (int, double, double) taylor_series(const double* U, int nu, bint complete, double h,
                                         double theta, double omega, double s, double p2,
                                         double sa, double ca, double* cf, double* S, double* C,
                                         bint sc_known, double s0, double c0, bint vert,
                                         double g0, double g1) noexcept nogil:
    """Taylor coefficients of ``theta(t + x h)`` in powers of ``x``, into ``cf``.

    Returns ``(n, s1, c1)``: the order ``n`` of the polynomial, and ``sin(phi)``, ``cos(phi)`` at
    the end of the step (their series summed), which the next step takes as its ``s0``, ``c0``
    when ``sc_known`` (so a step needs no function evaluation at all).  ``n = -1`` if the series
    needs more than the ``nu`` forcing terms given and they are not ``complete``.

    With ``phi = s alpha - theta``, Eq. 3 reads ``phi'' = p^2 (sin(phi) + u cos(phi))``; the
    series of ``S = sin(phi)`` and ``C = cos(phi)`` follow from ``S' = C phi'``, ``C' = -S phi'``
    (``S_k = (1/k) sum_j j phi_j C_{k-j}``), so each order costs one short convolution and no
    function evaluation.  The series is cut when two consecutive terms of ``theta`` and of
    ``h omega`` fall below :data:`TAYLOR_EPS` times the leading terms.  ``U`` holds ``2 M``
    floats: the forcing's series, then the series of ``h theta'`` (scratch).  ``vert``: vertical
    ground motion, the sine series multiplied by the effective gravity ``g0 + g1 x``
    (docs/theory.md section 10).
    """
    cdef double q, tol, sk, ck, f, s1, c1
    cdef int n, k, i
    cdef double* D = <double*>U + M  # D[i] = i cf[i] = -i phi_i: the series of h theta'
    if sc_known:
        S[0] = s0
        C[0] = c0
    else:
        S[0], C[0] = corner_sincos(theta, s, sa, ca)
    q = p2 * h * h
    cf[0] = theta
    cf[1] = omega * h
    if vert:
        cf[2] = -0.5 * q * (g0 * S[0] + U[0] * C[0])
    else:
        cf[2] = -0.5 * q * (S[0] + U[0] * C[0])
    tol = TAYLOR_EPS * (fabs(theta) + fabs(cf[1]) + fabs(cf[2]))
    n = 2
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
        sk *= INV[k]
        ck *= INV[k]
        S[k] = sk
        C[k] = ck
        f = sk
        if vert:
            f = g0 * sk + g1 * S[k - 1]
        for i in range(min(nu, k + 1)):
            f += U[i] * C[k - i]
        cf[k + 2] = -q * f * INV2[k]
        n = k + 2
        D[n] = n * cf[n]
        if fabs(D[n]) <= tol and fabs(D[n - 1]) <= tol:
            break
    s1 = 0.0
    c1 = 0.0
    for k in range(n - 2, -1, -1):  # S_{n-1}, C_{n-1} are as small as cf[n - 1]
        s1 += S[k]
        c1 += C[k]
    return n, s1, c1


cdef inline (double, double) taylor_eval(const double* cf, int n, double x,
                                         double h) noexcept nogil:
    """``(theta, omega)`` at ``t + x h`` from the coefficients of :func:`taylor_series`."""
    cdef double th = cf[n], om = n * cf[n]
    cdef int k
    for k in range(n - 1, 0, -1):
        th = th * x + cf[k]
        om = om * x + k * cf[k]
    return th * x + cf[0], om / h


cdef inline double taylor_acc(const double* cf, int n, double x, double h) noexcept nogil:
    """``theta''`` at ``t + x h`` from the coefficients of :func:`taylor_series`."""
    cdef double acc = n * (n - 1) * cf[n]
    cdef int k
    for k in range(n - 1, 1, -1):
        acc = acc * x + k * (k - 1) * cf[k]
    return acc / (h * h)


# --------------------------------------------------------------------------- Hermite helpers
cdef inline (double, double, double, double) _hermite(double th_a, double om_a, double th_b,
                                                      double om_b, double h) noexcept nogil:
    return (th_a, h * om_a, 3.0 * (th_b - th_a) - h * (2.0 * om_a + om_b),
            2.0 * (th_a - th_b) + h * (om_a + om_b))


cdef inline double _cubic(double c0, double c1, double c2, double c3, double x) noexcept nogil:
    return c0 + x * (c1 + x * (c2 + x * c3))


cdef inline (double, double) _stationary(double c1, double c2, double c3) noexcept nogil:
    """Roots of the derivative ``c1 + 2 c2 x + 3 c3 x^2`` inside (0, 1), sorted (nan if none)."""
    cdef double r1 = NAN, r2 = NAN, a = 3.0 * c3, b = 2.0 * c2, c = c1
    cdef double disc, sq, q, x1, x2
    if fabs(a) < 1e-300 or fabs(a) * 1e12 < fabs(b):
        if b != 0.0:
            r1 = -c / b
    else:
        disc = b * b - 4.0 * a * c
        if disc >= 0.0:
            sq = sqrt(disc)
            q = -0.5 * (b + copysign(sq, b))
            x1 = q / a
            x2 = c / q if q != 0.0 else NAN
            # min and max as Python's (the first argument when either is nan)
            r1 = x2 if x2 < x1 else x1
            r2 = x2 if x2 > x1 else x1
    if not (r1 > 0.0 and r1 < 1.0):
        r1 = NAN
    if not (r2 > 0.0 and r2 < 1.0):
        r2 = NAN
    if isnan(r1):
        r1 = r2
        r2 = NAN
    return r1, r2


cdef (double, double, bint) _first_crossing(double c0, double c1, double c2, double c3, double s,
                                            double level) noexcept nogil:
    """First x in (0, 1] where ``s*H(x) - level`` turns non-positive, given it starts >= 0.

    Returns ``(lo, hi, interior)`` bracketing it (``interior``: found at an extremum of the
    interpolant inside the step, which the caller must confirm, because the interpolation error
    can fake a shallow dip), or ``(-1, -1, False)`` if there is none.
    """
    cdef double e1, e2, lo = 0.0, hi, value
    cdef int k
    e1, e2 = _stationary(c1, c2, c3)
    for k in range(3):
        hi = e1 if k == 0 else (e2 if k == 1 else 1.0)
        if isnan(hi) or hi <= lo:
            continue
        value = s * _cubic(c0, c1, c2, c3, hi) - level
        if k < 2:
            if value < 0.0:
                return lo, hi, True
        elif value < 0.0 or (value == 0.0 and s * c0 - level > 0.0):
            return lo, hi, False
        lo = hi
    return -1.0, -1.0, False


cdef double _cubic_root(double c0, double c1, double c2, double c3, double s, double lo,
                        double hi) noexcept nogil:
    """The root of the cubic ``c0 + c1 x + c2 x^2 + c3 x^3`` in ``[lo, hi]``, where it is monotonic
    with ``s H(lo) > 0 >= s H(hi)`` (a bracket from :func:`_first_crossing`), to rounding.

    Newton from ``hi``, kept inside the bracket, which each evaluation narrows (a bisection when a
    step would leave it).  A step that starts at ``theta = 0`` (just after an impact: ``c0 = 0``)
    starts from the root of ``c1 + c2 x + c3 x^2`` in the bracket (small hops, whose root is close
    to the top of the hop, took Newton from ``hi`` ~11 iterations)."""
    cdef double x = hi, disc, qq, r, f, d, xn
    cdef int it
    if c0 == 0.0:
        disc = c2 * c2 - 4.0 * c3 * c1
        if disc >= 0.0 and (c2 != 0.0 or c3 != 0.0):
            qq = -0.5 * (c2 + copysign(sqrt(disc), c2))
            r = qq / c3 if c3 != 0.0 else NAN
            if lo <= r <= hi:
                x = r
            else:
                r = c1 / qq if qq != 0.0 else NAN
                if lo <= r <= hi:
                    x = r
    for it in range(200):
        f = _cubic(c0, c1, c2, c3, x)
        if s * f > 0.0:
            lo = x
        else:
            hi = x
        d = c1 + x * (2.0 * c2 + 3.0 * c3 * x)
        xn = x - f / d if d != 0.0 else 0.5 * (lo + hi)
        if not (lo <= xn <= hi):
            xn = 0.5 * (lo + hi)
        if fabs(xn - x) < 4e-16 or hi - lo < 4e-16:
            return xn
        x = xn
    return x


cdef inline (double, double) _sub(const Forcing* F, long j, double ta, double tb, double t,
                                  double h, double x, double theta, double omega, double s,
                                  const Dyn* D, double* kt, double* kw, const double* cf,
                                  int n) noexcept nogil:
    """State at ``t + x h`` inside the current step of length ``h`` that starts at
    ``(t, theta, omega)``: the step's Taylor polynomial when it has one (``n > 0``), else the
    solution re-integrated from the start of the step."""
    if n > 0:
        return taylor_eval(cf, n, x, h)
    return step(F, j, ta, tb, t, x * h, theta, omega, s, D, kt, kw)


cdef (double, double, int, double, double) _advance(
        const Forcing* F, long j, double ta, double tb, double t, double h, double theta,
        double omega, double s, const Dyn* D, double* kt, double* kw, double* U, double* S,
        double* C, double* cf, bint sc_known, double s0, double c0, long n_hint) noexcept nogil:
    """One step of length ``h``: ``(theta, omega, n, s1, c1)`` at ``t + h``, with ``n`` the order
    of the Taylor polynomial left in ``cf`` (0 when another stepper was used) and ``s1``, ``c1``
    as returned by :func:`taylor_series`.  ``n_hint``: the order of the previous step (the
    forcing series of smooth pulses is computed a few terms beyond it, and in full if needed)."""
    cdef int nu, n
    cdef bint complete
    cdef double s1, c1, th, om, g0 = 1.0, g1 = 0.0
    cdef bint vert = F.vval != NULL
    if D.method == TAYLOR and not D.linear:
        if vert:
            g0, g1 = linear_gravity(F, j, ta, tb, t, h)
        nu, complete = forcing_series(F, j, ta, tb, t, h, U, n_hint + 4)
        n, s1, c1 = taylor_series(U, nu, complete, h, theta, omega, s, D.p * D.p, D.sa, D.ca, cf,
                                  S, C, sc_known, s0, c0, vert, g0, g1)
        if n < 0:
            nu, complete = forcing_series(F, j, ta, tb, t, h, U, NMAX + 1)
            n, s1, c1 = taylor_series(U, nu, complete, h, theta, omega, s, D.p * D.p, D.sa, D.ca,
                                      cf, S, C, sc_known, s0, c0, vert, g0, g1)
        th, om = taylor_eval(cf, n, 1.0, h)
        return th, om, n, s1, c1
    th, om = step(F, j, ta, tb, t, h, theta, omega, s, D, kt, kw)
    return th, om, 0, 0.0, 0.0


cdef inline bint _below(const double* cf, int n, double level) noexcept nogil:
    """Whether ``|theta| < level`` all over the step, by the bound ``sum |cf_k|`` of its
    polynomial on ``[0, 1]`` (with a 1 % margin, so that a peak computed by :func:`_step_peak`
    cannot reach ``level`` either)."""
    cdef double b = 0.0
    cdef int k
    for k in range(n + 1):
        b += fabs(cf[k])
    return 1.01 * b < level


cdef double _step_peak(const Forcing* F, long j, double ta, double tb, double t, double h,
                       double th_a, double om_a, double th_b, double om_b, double s, const Dyn* D,
                       double* kt, double* kw, double h_step, const double* cf, int n,
                       double max_abs) noexcept nogil:
    """``max_abs`` raised to the largest ``|theta|`` at a turning point strictly inside
    ``[t, t + h]``, if larger.

    ``[t, t + h]`` is the start of the current step of length ``h_step`` (see :func:`_sub`).
    The turning point is located on the cubic Hermite interpolant, the solution is evaluated
    there (Taylor polynomial, or re-integration), and the small residual velocity is removed by
    one quadratic (Newton) correction, so the peak is as accurate as the stepper rather than the
    interpolant.
    """
    cdef double c0, c1, c2, c3, e1, e2, peak = max_abs, x, th_e, om_e, acc, u_e, value
    cdef int k
    c0, c1, c2, c3 = _hermite(th_a, om_a, th_b, om_b, h)
    e1, e2 = _stationary(c1, c2, c3)
    for k in range(2):
        x = e1 if k == 0 else e2
        if isnan(x):
            continue
        th_e, om_e = _sub(F, j, ta, tb, t, h_step, x * h / h_step, th_a, om_a, s, D, kt, kw,
                          cf, n)
        if n > 0:
            acc = taylor_acc(cf, n, x * h / h_step, h_step)
        else:
            u_e = forcing(F, j, ta, tb, t + x * h)
            acc = _rhs(th_e, s, u_e, D.p * D.p, D.sa, D.ca, D.linear)
        value = th_e
        if acc != 0.0:
            value = th_e - 0.5 * om_e * om_e / acc
        if fabs(value) > peak:
            peak = fabs(value)
    return peak


# --------------------------------------------------------------------------- energy rule
cdef inline double _potential(double x, double alpha, bint linear) noexcept nogil:
    """Potential energy over m g R at ``|theta| = x`` (zero at rest)."""
    if linear:
        return 0.5 * alpha * alpha - 0.5 * (alpha - x) * (alpha - x)
    return cos(alpha - x) - cos(alpha)


cdef inline double _peak_from_energy(double e, double alpha, bint linear) noexcept nogil:
    """Peak ``|theta|`` of a block with energy ``e`` (over m g R) below the critical one."""
    if linear:
        return alpha - sqrt(max(alpha * alpha - 2.0 * e, 0.0))
    return alpha - acos(min(cos(alpha) + e, 1.0))


cdef (bint, double) energy_verdict(double theta, double omega, double p, double alpha,
                                   double eta, bint linear) noexcept nogil:
    """Decide overturning after the excitation ends (docs/theory.md section 2), exactly.

    Returns ``(overturns, next_peak)``; ``next_peak`` is the largest ``|theta|`` of the free
    motion that follows (``pi/2`` if it overturns).
    """
    cdef double x = fabs(theta), e, e_crit, r
    cdef bint away
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
cdef double _uplift_time(const Forcing* F, long j, double ta, double tb, double t, double t2,
                         double tan_a) noexcept nogil:
    """First time in ``[t, t2]`` where ``|u| > tan(alpha)`` (monotonic u), or nan."""
    cdef double ua, ub, level, x, lo, hi, mid
    cdef int it
    ua = forcing(F, j, ta, tb, t)
    if fabs(ua) > tan_a:
        return t
    ub = forcing(F, j, ta, tb, t2)
    if fabs(ub) <= tan_a:
        return NAN
    level = copysign(tan_a, ub)
    if F.kind == NODAL:
        x = t + (t2 - t) * (level - ua) / (ub - ua)
        return min(max(x, t), t2)
    lo = t
    hi = t2  # bisection to the last representable time
    for it in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if fabs(forcing(F, j, ta, tb, mid)) > tan_a:
            hi = mid
        else:
            lo = mid
    return hi


ctypedef struct Cruise:
    # the state _cruise carries: interval, time, theta, omega, max|theta|, history length; sin and
    # cos of the angle to the corner (when known); the unrolled steps' order and run of steps a
    # lower one would have done; and the step it stopped at (pending: theta, omega, sin, cos at
    # its end and its order, its polynomial in cf)
    long j
    double t, theta, omega, max_abs
    long n_hist
    bint sc_known
    double s_phi, c_phi
    long order, n_low
    bint pending
    double th2, om2, s_next, c_next
    long n_used


cdef void _cruise(const Forcing* F, double t_start, double h_uniform, const double* nodes,
                  bint uniform, long n_int, double s, double sa, double ca, double p2, double* cf,
                  bint record, double* hist_t, double* hist_theta, double* hist_omega,
                  Cruise* c) noexcept nogil:
    """Whole intervals from ``c.j`` on, each one unrolled Taylor step, while nothing happens.

    Stops (with the state at the start of interval ``c.j``, for :func:`run_core` to take that
    interval the general way) at the first interval where ``theta`` or ``omega`` would change
    sign or reach ``pi/2``, or where the series needs more terms than the unrolled orders have.
    The block must be rocking at the start of interval ``c.j`` (``c.t`` is its start).  When it
    stopped at an event, the step it took there is ``c.pending`` (its polynomial in ``cf``), so
    that it is not taken twice.
    """
    cdef long j = c.j, order = c.order, n_low = c.n_low, n_used = 0
    cdef double t = c.t, theta = c.theta, omega = c.omega, max_abs = c.max_abs
    cdef bint sc_known = c.sc_known, pending = False
    cdef double s_phi = c.s_phi, c_phi = c.c_phi
    cdef double th2 = 0.0, om2 = 0.0, s_next = 0.0, c_next = 1.0, wh2
    cdef long n_hist = c.n_hist
    cdef double h = h_uniform, q = p2 * h_uniform * h_uniform
    cdef double inv_h = 1.0 / h_uniform if uniform else 0.0
    cdef double wh, ta, tb, h_new, u0, u1, g0, g1
    cdef int stop, flag
    cdef FixedRun res
    # the loop carries omega h (one step's length to the next on a uniform grid: no rounding
    # from omega to omega h and back at every step, and two multiplications less on the chain
    # of dependent operations from one step to the next)
    wh = omega * h
    if (uniform and F.kind == NODAL and F.vval == NULL and not record and j < n_int
            and t == t_start + j * h_uniform):
        # records without history (the common case): the same loop, stripped to what changes
        # from one interval to the next
        if not sc_known:
            s_phi, c_phi = corner_sincos(theta, s, sa, ca)
            sc_known = True
        while j < n_int:
            # one loop per order (fixed_run_N, each holding one unrolled step)
            stop = fixed_run(order, F.uval, F.amp, j, n_int, q, s, theta, wh, s_phi, c_phi,
                             max_abs, n_low, LOW_RUN_FIXED, TAYLOR_EPS, cf, &res)
            j, theta, wh, s_phi, c_phi = res.j, res.theta, res.wh, res.s_phi, res.c_phi
            max_abs, n_low = res.max_abs, res.n_low
            th2, s_next, c_next = res.th2, res.s_next, res.c_next
            if stop == 1:
                break  # the series needs more terms: run_core() raises the order (rare)
            n_used = order
            if res.lower:
                order -= 2  # a lower order has been enough for a while
            if stop == 3:
                om2 = res.wh2 * inv_h
                pending = True
                break  # a turning point, an impact or overturning: the general way
            if stop == 0:
                break
        t = t_start + j * h_uniform
        omega = wh * inv_h
    else:
        while j < n_int:
            if uniform:
                ta = t_start + j * h_uniform
                tb = t_start + (j + 1) * h_uniform
            else:
                ta = nodes[j]
                tb = nodes[j + 1]
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
            if F.kind == NODAL:
                u0 = F.amp * F.uval[j]
                u1 = F.amp * (F.uval[j + 1] - F.uval[j])
            else:
                u0, u1 = linear_forcing(F, j, ta, tb, t, h)
            if F.vval != NULL:
                # vertical ground motion: the effective gravity g0 + g1 x over the interval; an
                # interval where it turns negative (lift-off) is left to run_core
                g0 = 1.0 + F.vamp * F.vval[j]
                g1 = F.vamp * (F.vval[j + 1] - F.vval[j])
                if g0 < 0.0 or g0 + g1 < 0.0:
                    break
                th2, wh2, s_next, c_next, flag = taylor_fixed_v(order, u0, u1, g0, g1, q, theta,
                                                                wh, s_phi, c_phi, TAYLOR_EPS, cf)
            else:
                th2, wh2, s_next, c_next, flag = taylor_fixed(order, u0, u1, q, theta, wh, s_phi,
                                                              c_phi, TAYLOR_EPS, cf)
            if flag == 0:
                break  # the series needs more terms: run_core() raises the order (rare)
            n_used = order
            n_low = n_low + 1 if flag == 2 else 0
            if n_low >= LOW_RUN_FIXED and order > ORDERS_FIRST:
                order -= 2  # a lower order has been enough for a while
                n_low = 0
            if not (wh * wh2 > 0.0 and s * th2 > 0.0 and fabs(th2) < HALF_PI):
                om2 = wh2 * inv_h
                pending = True
                break  # a turning point, an impact or overturning: the general way
            if fabs(th2) > max_abs:
                max_abs = fabs(th2)
            theta = th2
            wh = wh2
            t = tb
            omega = wh * inv_h
            s_phi = s_next
            c_phi = c_next
            if record:
                hist_t[n_hist] = t
                hist_theta[n_hist] = theta
                hist_omega[n_hist] = omega
                n_hist += 1
            j += 1
    c.j, c.t, c.theta, c.omega, c.max_abs, c.n_hist = j, t, theta, omega, max_abs, n_hist
    c.sc_known, c.s_phi, c.c_phi, c.order, c.n_low = sc_known, s_phi, c_phi, order, n_low
    c.pending, c.th2, c.om2, c.s_next, c.c_next, c.n_used = (pending, th2, om2, s_next, c_next,
                                                             n_used)


cdef (double, double) _uplift_vertical(const Forcing* F, long j, double ta, double tb, double t,
                                       double t2, double tan_a) noexcept nogil:
    """:func:`_uplift` under vertical ground motion too (a record): the block uplifts when
    ``|u| > (1 + av/g) tan(alpha)`` (docs/theory.md section 10), towards ``-sgn(u)``.  Both
    ``u`` and ``1 + av/g`` are linear over the interval, so each side's threshold
    ``+-u - (1 + av/g) tan(alpha)`` is linear: its first positive value is found in closed form."""
    cdef double ua = forcing(F, j, ta, tb, t), ub = forcing(F, j, ta, tb, t2)
    cdef double ga = gravity(F, j, ta, tb, t), gb = gravity(F, j, ta, tb, t2)
    cdef double best = INFINITY, side = 0.0, sign, fa, fb, cand
    cdef int k
    for k in range(2):
        sign = 1.0 if k == 0 else -1.0  # the sign of u at uplift
        fa = sign * ua - ga * tan_a
        fb = sign * ub - gb * tan_a
        if fa > 0.0:
            cand = t
        elif fb > 0.0:
            cand = min(max(t + (t2 - t) * (fa / (fa - fb)), t), t2)
        else:
            continue
        if cand < best:
            best = cand
            side = -sign
    if side == 0.0:
        return t2, 0.0
    return best, side


cdef (double, double) _uplift(const Forcing* F, long j, double ta, double tb, double t, double t2,
                              double tan_a, double rest_until) noexcept nogil:
    """A block at rest from ``t``: ``(t_up, s)``, when and to which side it uplifts inside
    ``[t, t2]`` (``|ug''|`` first exceeds ``g tan(alpha)``, not before ``rest_until``), or
    ``(t2, 0)`` if it stays at rest."""
    cdef double t_up, u_up
    if rest_until >= t2:
        return t2, 0.0
    if rest_until > t:
        t = rest_until
    if F.vval != NULL:
        return _uplift_vertical(F, j, ta, tb, t, t2, tan_a)
    t_up = _uplift_time(F, j, ta, tb, t, t2, tan_a)
    if isnan(t_up):
        return t2, 0.0
    u_up = forcing(F, j, ta, tb, t_up)
    if fabs(u_up) <= tan_a:  # touching the threshold from below at t2
        u_up = forcing(F, j, ta, tb, t2)
    return t_up, (-1.0 if u_up > 0.0 else 1.0)


cdef bint _unrolled(bint fixed, long* order_io, long* n_low_io, long lowest, long highest,
                    long low_run, const Forcing* F, long j, double ta, double tb, double t,
                    double h, double* U, double q, double theta, double omega, double s_phi,
                    double c_phi, double* cf, double* out) noexcept nogil:
    """One step of the unrolled Taylor steps (forcing linear over the step, ``fixed``, or given by
    its series, written into ``U``), at the order that ``order_io``, ``n_low_io`` adapt: raised
    until the series is summed (False if even ``highest`` is not enough: the general loop takes
    the step), lowered after ``low_run`` steps in a row where a lower one would have done.
    ``out``: theta, omega, sin, cos at the end of the step and the order it took (its
    polynomial is in ``cf``)."""
    cdef long order = order_io[0], n_low = n_low_io[0], n_used
    cdef double wh = omega * h, u0, u1, th2, wh2, s_next, c_next, g0, g1
    cdef int flag
    while True:
        if fixed and F.vval != NULL:
            u0, u1 = linear_forcing(F, j, ta, tb, t, h)
            g0, g1 = linear_gravity(F, j, ta, tb, t, h)
            th2, wh2, s_next, c_next, flag = taylor_fixed_v(order, u0, u1, g0, g1, q, theta, wh,
                                                            s_phi, c_phi, TAYLOR_EPS, cf)
        elif fixed:
            u0, u1 = linear_forcing(F, j, ta, tb, t, h)
            th2, wh2, s_next, c_next, flag = taylor_fixed(order, u0, u1, q, theta, wh, s_phi,
                                                          c_phi, TAYLOR_EPS, cf)
        else:
            forcing_series(F, j, ta, tb, t, h, U, order - 1)
            th2, wh2, s_next, c_next, flag = taylor_smooth(order, U, q, theta, wh, s_phi, c_phi,
                                                           TAYLOR_EPS, cf)
        if flag != 0 or order >= highest:
            break
        order += 2  # the series needs more terms: the next order up
    if flag == 0:
        order_io[0] = order + 2  # beyond the unrolled orders
        out[4] = order
        return False
    n_used = order
    n_low = n_low + 1 if flag == 2 else 0
    if n_low >= low_run and order > lowest:
        order -= 2  # a lower order has been enough for a while
        n_low = 0
    order_io[0] = order
    n_low_io[0] = n_low
    out[0] = th2
    out[1] = wh2 / h
    out[2] = s_next
    out[3] = c_next
    out[4] = n_used
    return True


cdef double _zeno_rest(const Forcing* F, long j, double ta, double tb, double t, double omega,
                       double s, const Dyn* D, double eta) noexcept nogil:
    """After an impact with ``|omega|`` below the Zeno threshold (block on side ``s`` now): the
    remaining geometric series of hops summed in closed form.  Returns the time until which the
    block is at rest."""
    cdef double u_now = forcing(F, j, ta, tb, t), a_new, a_old, p = D.p, g
    if D.linear:  # (sa is alpha itself in the linearised model)
        a_new = p * p * (D.sa + s * u_now)
        a_old = p * p * (D.sa - s * u_now)
    elif F.vval != NULL:  # the effective gravity (docs/theory.md section 10)
        g = gravity(F, j, ta, tb, t)
        a_new = p * p * (g * D.sa + s * u_now * D.ca)
        a_old = p * p * (g * D.sa - s * u_now * D.ca)
    else:
        a_new = p * p * (D.sa + s * u_now * D.ca)
        a_old = p * p * (D.sa - s * u_now * D.ca)
    if a_new > 0.0 and a_old > 0.0:
        return t + 2.0 * fabs(omega) / (1.0 - eta * eta) * (1.0 / a_new + eta / a_old)
    # the forcing is at or past the uplift threshold on one side: at rest now, to uplift as the
    # rest rule says (what is left out is again hops of height ~(zeno_tol alpha)^2; hopping on
    # would take ever shorter hops, millions of them, down to rounding)
    return t


cdef (double, double, double) _overturn(double c0, double c1, double c2, double c3, double s,
                                        double th2, double t, double h) noexcept nogil:
    """``|theta|`` reaches ``pi/2`` inside the step (``th2`` at its end beyond it): ``(t, theta,
    omega)`` there, by bisection on the step's cubic Hermite interpolant."""
    cdef double lo, hi, x, mid
    cdef int it
    cdef bint interior
    lo, hi, interior = _first_crossing(c0, c1, c2, c3, -s, -HALF_PI)
    x = 1.0 if lo < 0.0 else hi
    for it in range(60):
        if lo < 0.0:
            break
        mid = 0.5 * (lo + hi)
        if s * _cubic(c0, c1, c2, c3, mid) < HALF_PI:
            lo = mid
        else:
            hi = mid
        x = hi
    return t + x * h, copysign(HALF_PI, th2), c1 / h + x * (2.0 * c2 + 3.0 * c3 * x) / h


cdef enum:
    ORDERS_FIRST = 4      # ORDERS[0]
    ORDERS_LAST = 16      # ORDERS[-1]
    ORDERS_START = 8      # ORDERS[2]: the first unrolled order tried
    SMOOTH_FIRST = 8      # SMOOTH_ORDERS[0]
    SMOOTH_LAST = 24      # SMOOTH_ORDERS[-1]
    SMOOTH_START = 12     # SMOOTH_ORDERS[2]
    SMOOTH_LOW_RUN = 16   # steps in a row a lower order must have sufficed (smooth pulses)


cdef Outcome run_core(const Forcing* F, double t_start, double h_uniform, long n_sub,
                      const double* nodes, bint uniform, double p, double alpha, double eta,
                      bint linear, int method, double zeno_tol, bint stop_at_rest, bint record,
                      long j0, double theta0, double omega0, double rest_until0, long n_end,
                      double* hist_t, double* hist_theta, double* hist_omega, double* impacts,
                      long n_impacts_max, long order0) noexcept nogil:
    """The engine (:func:`rocking.engine.run`) from interval ``j0`` to the end of interval
    ``n_end - 1``; it allocates nothing (the batch engine calls it for single intervals where
    something happens, with ``order0`` the order its lanes step at: the unrolled steps start
    there; 0: the engine's own first order)."""
    cdef double work[2 * N_STAGES + 5 * M]
    cdef double* kt = work
    cdef double* kw = work + N_STAGES
    cdef double* U = work + 2 * N_STAGES
    cdef double* S = work + 2 * N_STAGES + 2 * M
    cdef double* C = work + 2 * N_STAGES + 3 * M
    cdef double* cf = work + 2 * N_STAGES + 4 * M
    cdef double tan_a = tan(alpha), p2 = p * p, sa, ca
    cdef bint sc_known = False, pending = False, fixed, unrolled, uplifted, converged, interior
    cdef double s_phi = 0.0, c_phi = 1.0, th2 = 0.0, om2 = 0.0, s_next = 0.0, c_next = 1.0
    cdef long nt = 0, n_pending = 0, order, n_low = 0, lowest, highest, low_run, n_general
    cdef double theta, omega, s, max_abs, rest_until, omega_zeno, t, ta, tb, hsub, t2, h
    cdef long n_imp = 0, j, n_int, n_hist = 0, events, k, it
    cdef int status
    cdef Dyn D
    cdef Cruise cr
    cdef double stepped[5]
    cdef double c0, c1, c2, c3, lo, hi, th_e, x, th_x, om_x, xn, t_imp, t_lift, g_a, g_b
    cdef Outcome out
    cdef int n_adv
    # forcing linear over each step: unrolled Taylor steps of a fixed order, adapted as we go
    # (raised as soon as a step's last terms are too large, lowered after a run of steps where
    # a lower one would have done); any other step takes the general loop
    fixed = method == TAYLOR and not linear and (F.kind == NODAL or F.kind == RECT
                                                 or F.kind == FREE)
    # smooth pulses: the same with the forcing's own series (unrolled up to SMOOTH_LAST)
    unrolled = method == TAYLOR and not linear
    if fixed:
        lowest, highest, low_run = ORDERS_FIRST, ORDERS_LAST, LOW_RUN_FIXED
        order = min(max(order0, ORDERS_FIRST), ORDERS_LAST) if order0 > 0 else ORDERS_START
    else:
        # steps in a row a lower order must have sufficed: more than for records, whose steps
        # are all alike
        lowest, highest, low_run = SMOOTH_FIRST, SMOOTH_LAST, SMOOTH_LOW_RUN
        order = SMOOTH_START
    n_general = ORDERS_LAST  # order of the last step of the general Taylor loop
    if linear:
        sa = alpha
        ca = 1.0
    else:
        sa = sin(alpha)
        ca = cos(alpha)
    D.p, D.sa, D.ca, D.linear, D.method = p, sa, ca, linear, method
    theta = theta0
    omega = omega0
    if theta != 0.0:
        s = 1.0 if theta > 0.0 else -1.0
    elif omega != 0.0:
        s = 1.0 if omega > 0.0 else -1.0
    else:
        s = 0.0
    uplifted = s != 0.0
    max_abs = fabs(theta)
    rest_until = rest_until0
    omega_zeno = zeno_tol * p * alpha
    status = ROCKING if s != 0.0 else REST
    j = j0
    t = nodes[j] if not uniform else t_start + j * h_uniform
    n_int = n_end
    if record:
        hist_t[0] = t
        hist_theta[0] = theta
        hist_omega[0] = omega
        n_hist = 1
    while j < n_int:
        if s == 0.0 and F.kind == NODAL and uniform and not stop_at_rest and rest_until <= t:
            # at rest under a record: on to the first interval whose ends exceed the uplift
            # threshold (the forcing is linear between them), the history meanwhile zero
            while (j < n_int and F.vval == NULL and fabs(F.amp * F.uval[j]) <= tan_a
                   and fabs(F.amp * F.uval[j + 1]) <= tan_a):
                j += 1
                if record:
                    hist_t[n_hist] = t_start + j * h_uniform
                    hist_theta[n_hist] = 0.0
                    hist_omega[n_hist] = 0.0
                    n_hist += 1
            # under vertical motion too: |u| <= (1 + av/g) tan(alpha) at both ends (both linear
            # in between; a negative effective gravity, lift-off, fails it)
            while (j < n_int and F.vval != NULL
                   and fabs(F.amp * F.uval[j]) <= (1.0 + F.vamp * F.vval[j]) * tan_a
                   and fabs(F.amp * F.uval[j + 1]) <= (1.0 + F.vamp * F.vval[j + 1]) * tan_a):
                j += 1
                if record:
                    hist_t[n_hist] = t_start + j * h_uniform
                    hist_theta[n_hist] = 0.0
                    hist_omega[n_hist] = 0.0
                    n_hist += 1
            t = max(t, t_start + j * h_uniform)
            if j >= n_int:
                break
        if fixed and n_sub == 1 and s != 0.0 and order <= ORDERS_LAST:
            # the common case, whole intervals with no event, in a tight loop
            cr.j, cr.t, cr.theta, cr.omega, cr.max_abs, cr.n_hist = j, t, theta, omega, max_abs, n_hist
            cr.sc_known, cr.s_phi, cr.c_phi, cr.order, cr.n_low = sc_known, s_phi, c_phi, order, n_low
            _cruise(F, t_start, h_uniform, nodes, uniform, n_int, s, sa, ca, p2, cf, record,
                    hist_t, hist_theta, hist_omega, &cr)
            j, t, theta, omega, max_abs, n_hist = cr.j, cr.t, cr.theta, cr.omega, cr.max_abs, cr.n_hist
            sc_known, s_phi, c_phi, order, n_low = cr.sc_known, cr.s_phi, cr.c_phi, cr.order, cr.n_low
            pending, th2, om2, s_next, c_next, n_pending = (cr.pending, cr.th2, cr.om2, cr.s_next,
                                                            cr.c_next, cr.n_used)
            if j >= n_int:
                break
        if uniform:
            ta = t_start + j * h_uniform
            tb = t_start + (j + 1) * h_uniform
        else:
            ta = nodes[j]
            tb = nodes[j + 1]
        hsub = (tb - ta) / n_sub
        t_lift = INFINITY
        if F.vval != NULL:
            # lift-off: the effective gravity 1 + av/g (linear over the interval) turns negative
            # inside it; the run stops there (docs/theory.md section 10)
            g_a = 1.0 + F.vamp * F.vval[j]
            g_b = 1.0 + F.vamp * F.vval[j + 1]
            if g_a < 0.0:
                t_lift = ta
            elif g_b < 0.0:
                t_lift = min(max(ta + (tb - ta) * (g_a / (g_a - g_b)), ta), tb)
        for k in range(n_sub):
            t2 = tb if k == n_sub - 1 else ta + (k + 1) * hsub
            if t2 > t_lift:
                t2 = t_lift
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
                    t, s = _uplift(F, j, ta, tb, t, t2, tan_a, rest_until)
                    if s == 0.0:
                        break
                    theta = 0.0
                    omega = 0.0
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
                elif unrolled and order <= highest:
                    if not sc_known:
                        s_phi, c_phi = corner_sincos(theta, s, sa, ca)
                        sc_known = True
                    if _unrolled(fixed, &order, &n_low, lowest, highest, low_run, F, j, ta, tb,
                                 t, h, U, p2 * h * h, theta, omega, s_phi, c_phi, cf, stepped):
                        th2, om2, s_next, c_next = stepped[0], stepped[1], stepped[2], stepped[3]
                        nt = <long>stepped[4]
                if nt == 0:
                    th2, om2, n_adv, s_next, c_next = _advance(
                        F, j, ta, tb, t, h, theta, omega, s, &D, kt, kw, U, S, C, cf, sc_known,
                        s_phi, c_phi, n_general)
                    nt = n_adv
                    if nt > 0:
                        n_general = nt
                        if unrolled:  # back to the unrolled steps when they suffice
                            order = max(lowest, nt + (nt & 1))
                # sin and cos of the angle to the corner carry over only to an accepted step
                sc_known = False
                if omega * om2 > 0.0 and s * th2 > 0.0 and fabs(th2) < HALF_PI:
                    # fast path: no turning point, so theta is monotonic over the step and can
                    # neither reach 0 nor peak inside it (the common case)
                    if fabs(th2) > max_abs:
                        max_abs = fabs(th2)
                    theta = th2
                    omega = om2
                    t = t2
                    sc_known = nt > 0
                    s_phi = s_next
                    c_phi = c_next
                    continue
                c0, c1, c2, c3 = _hermite(theta, omega, th2, om2, h)
                # ---- impact: theta reaches 0 (first crossing of the step, grazes included)
                lo, hi, interior = _first_crossing(c0, c1, c2, c3, s, 0.0)
                if interior:
                    # a dip of the interpolant inside the step: real only if the solution dips
                    th_e, om_x = _sub(F, j, ta, tb, t, h, hi, theta, omega, s, &D, kt, kw, cf, nt)
                    if s * th_e > 0.0:
                        lo = -1.0
                if lo >= 0.0 and events < MAX_EVENTS_PER_STEP:
                    # the root of the cubic (cheap; one root in [lo, hi], where it is monotonic),
                    # then Newton on the step's polynomial or the re-integrated solution: its
                    # first iteration corrects the interpolation error, the second confirms
                    # convergence to rounding
                    x = _cubic_root(c0, c1, c2, c3, s, lo, hi)
                    converged = False
                    for it in range(8):
                        th_x, om_x = _sub(F, j, ta, tb, t, h, x, theta, omega, s, &D, kt, kw, cf,
                                          nt)
                        if om_x == 0.0:
                            break
                        xn = x - th_x / (om_x * h)
                        if xn <= 0.0 or xn > 1.0:
                            break
                        converged = fabs(xn - x) < 4e-16
                        x = xn
                        if converged:
                            break  # (th_x, om_x) is the state 4e-16 h before x: kept as is
                    if not converged:
                        th_x, om_x = _sub(F, j, ta, tb, t, h, x, theta, omega, s, &D, kt, kw, cf,
                                          nt)
                    t_imp = t + x * h
                    if t_imp <= t:
                        t_imp = t + 4.5e-16 * max(fabs(t), 1.0)  # at least one ulp of t
                    # the peak between t and the impact (none above max_abs if the polynomial's
                    # bound says so: the small hops of a block coming to rest)
                    if nt == 0 or not _below(cf, nt, max_abs):
                        max_abs = _step_peak(F, j, ta, tb, t, t_imp - t, theta, omega, th_x,
                                             om_x, s, &D, kt, kw, h, cf, nt, max_abs)
                    t = t_imp
                    if n_imp < n_impacts_max:
                        impacts[n_imp] = t
                    n_imp += 1
                    omega = eta * om_x
                    s = -s
                    theta = 0.0
                    if fabs(omega) <= omega_zeno:
                        # ---- Zeno: the remaining hops summed in closed form
                        rest_until = _zeno_rest(F, j, ta, tb, t, omega, s, &D, eta)
                        s = 0.0
                        omega = 0.0
                        status = REST
                    continue
                if lo >= 0.0:  # too many events in one step: settle (never loops forever)
                    s = 0.0
                    theta = 0.0
                    omega = 0.0
                    status = REST
                    rest_until = t2
                    continue
                if fabs(th2) >= HALF_PI:
                    # ---- overturning: |theta| reaches pi/2
                    t, theta, omega = _overturn(c0, c1, c2, c3, s, th2, t, h)
                    max_abs = HALF_PI
                    status = OVERTURNED
                    break
                # ---- a turning point inside the step
                if nt == 0 or not _below(cf, nt, max_abs):
                    max_abs = _step_peak(F, j, ta, tb, t, h, theta, omega, th2, om2, s, &D, kt,
                                         kw, h, cf, nt, max_abs)
                if fabs(th2) > max_abs:
                    max_abs = fabs(th2)
                theta = th2
                omega = om2
                t = t2
                sc_known = nt > 0
                s_phi = s_next
                c_phi = c_next
            if status == OVERTURNED or (stop_at_rest and status == REST):
                break
        if t_lift < INFINITY and status != OVERTURNED:
            status = LIFTOFF
            t = t_lift
        if record:
            hist_t[n_hist] = t
            hist_theta[n_hist] = theta
            hist_omega[n_hist] = omega
            n_hist += 1
        if status == OVERTURNED or status == LIFTOFF or (stop_at_rest and status == REST):
            break
        j += 1
    if status == REST:
        theta = 0.0
        omega = 0.0
    out.status, out.theta, out.omega, out.t, out.max_abs = status, theta, omega, t, max_abs
    out.n_imp, out.n_hist, out.uplifted, out.rest_until = n_imp, n_hist, uplifted, rest_until
    return out


cdef inline const double* _ptr(const double[::1] a) noexcept:
    return &a[0] if a.shape[0] > 0 else NULL


cdef inline double* _wptr(double[::1] a) noexcept:
    return &a[0] if a.shape[0] > 0 else NULL


def run(int kind, double amp, double tp, double t0, const double[::1] uval, double t_start,
        double h, long n_sub, const double[::1] nodes, double p, double alpha, double eta,
        bint linear, int method, double zeno_tol, bint stop_at_rest, bint record, long j0,
        double theta0, double omega0, double rest_until, long n_end, double[::1] hist_t,
        double[::1] hist_theta, double[::1] hist_omega, double[::1] impacts,
        const double[::1] vval=None, double vamp=0.0):
    """The engine called from Python (:func:`rocking.engine.run` checks the arguments), without
    the GIL.  Returns ``(status, theta, omega, t_end, max_abs_theta, n_impacts, n_hist,
    uplifted, rest_until)``.  ``vval``: the vertical ground motion's node values (``1 + av/g =
    1 + vamp * vval``), a record's on a uniform grid stepped by Taylor steps only."""
    cdef Forcing F
    cdef Outcome o
    cdef const double* nodes_p = _ptr(nodes)
    cdef double* ht = _wptr(hist_t)
    cdef double* hth = _wptr(hist_theta)
    cdef double* hom = _wptr(hist_omega)
    cdef double* imp = _wptr(impacts)
    cdef bint uniform = nodes.shape[0] == 0
    cdef long n_imp_max = impacts.shape[0]
    F.kind, F.amp, F.tp, F.t0, F.uval = kind, amp, tp, t0, _ptr(uval)
    F.vval, F.vamp = NULL, 0.0
    if vval is not None:
        if not (kind == NODAL and nodes.shape[0] == 0 and method == TAYLOR and not linear):
            raise ValueError("vertical ground motion: records on a uniform grid, Taylor steps of "
                             "the nonlinear equation only")
        if vval.shape[0] < n_end + 1 or vval.shape[0] < 1:
            raise ValueError("the vertical node values are fewer than the intervals run")
        F.vval, F.vamp = &vval[0], vamp
    if record and not (hist_t.shape[0] >= n_end - j0 + 1 and hist_theta.shape[0] >= n_end - j0 + 1
                       and hist_omega.shape[0] >= n_end - j0 + 1):
        raise ValueError("the history arrays are shorter than the intervals run")
    if nodes.shape[0] == 0 and kind == NODAL and uval.shape[0] < n_end + 1:
        raise ValueError("the node values are fewer than the intervals run")
    if nodes.shape[0] != 0 and nodes.shape[0] < n_end + 1:
        raise ValueError("the node times are fewer than the intervals run")
    with nogil:
        o = run_core(&F, t_start, h, n_sub, nodes_p, uniform, p, alpha, eta, linear, method,
                     zeno_tol, stop_at_rest, record, j0, theta0, omega0, rest_until, n_end, ht,
                     hth, hom, imp, n_imp_max, 0)
    return (o.status, o.theta, o.omega, o.t, o.max_abs, o.n_imp, o.n_hist, bool(o.uplifted),
            o.rest_until)


# --------------------------------------------------------------------------- batch engine
# the lanes' steps (generated C, rocking/_make_lanes.py), and the rows of a chunk's float state
# (one column per lane) and of its integer state
cdef extern from "_taylor_lanes.h":
    enum:
        R_A, R_Q, R_SA, R_CA, R_TAN, R_P, R_ALPHA, R_ETA, R_TH, R_OM, R_SIDE, R_SPHI, R_CPHI
        R_REST, R_MX, NF
        I_STATUS, I_NIMP, I_UP, I_RUN, I_WAKE, NI
        LANES  # runs stepped together at most (rocking.lanes.LANES)
        CF_TH2, CF_OM2, CF_S1, CF_C1, CF_OWN, NCF
        E_TH2, E_OM2, E_S1, E_C1, E_OM, E_SIDE, E_H, E_T, E_U0, E_U1, E_Q, E_SA, E_CA
        E_TAN, E_P2, E_ETA, E_MX, E_OMZ, E_NIMP, E_REM, E_OK, E_NTH, E_NOM, E_NSIDE, E_NS, E_NC, E_WHY
        E_NREST, E_NEED, E_XE, E_TE, E_OE, E_LOW, NE
    int64_t rocking_lanes_step(int64_t order, int64_t n, double uj, double duj, double* f,
                               int64_t* bad, double h, double eps, int64_t* n_low,
                               double* cf) noexcept nogil
    void rocking_events(int64_t order, int64_t m, double* e, double* nx, double eps) noexcept nogil
    void rocking_peaks(int64_t order, int64_t m, double* e, double* nx, double eps) noexcept nogil

#: counts a batch in lanes keeps (rocking.lanes.STATS): steps kept in lanes, turning points and
#: impacts taken in lanes, intervals handed to the engine (rocking lanes, lanes at rest, rocking
#: lanes for a too low order), and the events left to the engine by why (rocking_events_N)
cdef enum:
    ST_KEPT = 0
    ST_TURNS = 1
    ST_ENGINE = 2
    ST_REST = 3
    ST_IMPACTS = 4
    ST_LOW = 5
    ST_WHY = 6   # 6 .. 10: overturning, uplift after a Zeno sequence, the root, the rest's
                 # order, more events in one interval than EVENT_ROUNDS
    N_STATS = 11
    #: rounds of the events' pass in one interval (each takes one event per lane: a turning point,
    #: or an impact and the step over the rest of the interval, where the next round looks; the
    #: hops of a block coming to rest take a round each)
    EVENT_ROUNDS = 4096

ctypedef struct Chunk:
    # the state of up to LANES runs stepped together: NF rows of floats, NI rows of integers,
    # why each lane was left by the last step (lanes_N), each lane's polynomial of that step and
    # its end state (NCF rows), and the events' scratches (NE rows, one column per lane
    # gathered: the round's and the next round's, in turn)
    double f[NF][LANES]
    long i[NI][LANES]
    int64_t bad[LANES]
    double cf[NCF][LANES]
    double e[2][NE][LANES]


cdef inline (long, long) lanes_step(long order, long n, double uj, double duj, Chunk* L, double h,
                                    double eps) noexcept nogil:
    """The lanes' step of order ``order`` (the highest for larger) on lanes ``0 .. n-1`` of
    ``L``: ``(n_bad, n_low)``, the lanes left and the kept lanes a lower order would have done.
    The step runs over whole vectors: the lanes after ``n`` it takes too are at rest or
    overturned (or unused), with omega 0, which no step keeps (their ``bad`` is not read)."""
    cdef int64_t n_low = 0
    cdef long top = min(LANES, (n + 3) // 4 * 4)
    cdef int64_t n_bad = rocking_lanes_step(order, top, uj, duj, &L.f[0][0], &L.bad[0], h, eps,
                                            &n_low, &L.cf[0][0])
    return n_bad - (top - n), n_low


cdef void _gather(double* e, long k, long i, long rows, double uj, double duj, Chunk* L,
                  double ta, double h, double zeno_tol) noexcept nogil:
    """Lane ``i``'s step into column ``k`` of the events' scratch ``e``."""
    cdef long r
    for r in range(rows):
        e[r * LANES + k] = L.cf[r][i]
    for r in range(rows, ORDERS_LAST + 1):  # (a round of a higher order reads them)
        e[r * LANES + k] = 0.0
    e[E_TH2 * LANES + k] = L.cf[CF_TH2][i]
    e[E_OM2 * LANES + k] = L.cf[CF_OM2][i]
    e[E_S1 * LANES + k] = L.cf[CF_S1][i]
    e[E_C1 * LANES + k] = L.cf[CF_C1][i]
    e[E_OM * LANES + k] = L.f[R_OM][i]
    e[E_SIDE * LANES + k] = L.f[R_SIDE][i]
    e[E_H * LANES + k] = h
    e[E_T * LANES + k] = ta
    e[E_U0 * LANES + k] = L.f[R_A][i] * uj
    e[E_U1 * LANES + k] = L.f[R_A][i] * duj
    e[E_Q * LANES + k] = L.f[R_Q][i]
    e[E_SA * LANES + k] = L.f[R_SA][i]
    e[E_CA * LANES + k] = L.f[R_CA][i]
    e[E_TAN * LANES + k] = L.f[R_TAN][i]
    e[E_P2 * LANES + k] = L.f[R_P][i] * L.f[R_P][i]
    e[E_ETA * LANES + k] = L.f[R_ETA][i]
    e[E_MX * LANES + k] = L.f[R_MX][i]
    e[E_OMZ * LANES + k] = zeno_tol * L.f[R_P][i] * L.f[R_ALPHA][i]
    e[E_NIMP * LANES + k] = 0.0
    e[E_REM * LANES + k] = 0.0


cdef inline long n_events(Chunk* L, long n) noexcept nogil:
    """How many of lanes ``0 .. n-1`` the step left with something happening in it (bad 1)."""
    cdef long i, m = 0
    for i in range(n):
        m += L.bad[i] == 1
    return m


ctypedef struct Restep:
    # the lanes whose step needs more terms than the chunk's order, gathered (rocking_lanes_N's
    # rows; the others unused)
    double f[NF][LANES]
    int64_t bad[LANES]
    double cf[NCF][LANES]


cdef void _restep(long order, long n, double uj, double duj, Chunk* L, double h) noexcept nogil:
    """The lanes whose step needs more terms than ``order`` (bad 2), stepped again at the next
    orders up (cut at their own: the same bits as in a chunk of that order), those still short at
    the highest left to the engine (bad 2)."""
    cdef Restep R
    cdef long idx[LANES]
    cdef long m = 0, k, i, r, top, o = order
    cdef int64_t n_low = 0
    cdef int rows[8]
    rows[:] = [R_A, R_Q, R_TH, R_OM, R_SIDE, R_SPHI, R_CPHI, R_MX]
    for i in range(n):
        if L.bad[i] == 2:
            idx[m] = i
            m += 1
    while m > 0 and o < ORDERS_LAST:
        o += 2
        top = min(LANES, (m + 3) // 4 * 4)
        for k in range(top):   # (padding lanes: omega 0, which no step keeps)
            for r in range(8):
                R.f[rows[r]][k] = L.f[rows[r]][idx[k]] if k < m else 0.0
        rocking_lanes_step(o, top, uj, duj, &R.f[0][0], &R.bad[0], h, TAYLOR_EPS, &n_low,
                           &R.cf[0][0])
        top = 0
        for k in range(m):
            i = idx[k]
            if R.bad[k] == 2:
                idx[top] = i
                top += 1
                continue
            L.bad[i] = R.bad[k]
            for r in range(8):
                L.f[rows[r]][i] = R.f[rows[r]][k]
            for r in range(o + 1):
                L.cf[r][i] = R.cf[r][k]
            for r in range(CF_TH2, CF_OWN + 1):
                L.cf[r][i] = R.cf[r][k]
        m = top


cdef inline void _column(double* dst, long m2, const double* src, long k) noexcept nogil:
    """The inputs of a lane (the polynomial and :data:`E_TH2` .. :data:`E_REM`) from column ``k``
    of ``src`` to column ``m2`` of ``dst``."""
    cdef long r
    for r in range(ORDERS_LAST + 1):
        dst[r * LANES + m2] = src[r * LANES + k]
    for r in range(E_TH2, E_REM + 1):
        dst[r * LANES + m2] = src[r * LANES + k]


cdef void _settle(const double* e, const double* nx, long k, long i, long j, double ok, Chunk* L,
                  int64_t* stats) noexcept nogil:
    """Lane ``i`` to the end of the interval as column ``k`` of the events' scratches found it
    (``e`` the round's, ``nx`` the next round's: the peak and the impacts so far)."""
    L.f[R_MX][i] = nx[E_MX * LANES + k]
    L.i[I_NIMP][i] += <long>nx[E_NIMP * LANES + k]
    L.bad[i] = 0
    stats[ST_IMPACTS] += <long>nx[E_NIMP * LANES + k]
    if ok == 4.0:  # at rest after a Zeno sequence
        L.i[I_STATUS][i] = REST
        L.i[I_WAKE][i] = j + 1
        L.f[R_REST][i] = e[E_NREST * LANES + k]
        L.f[R_TH][i] = 0.0
        L.f[R_OM][i] = 0.0
        L.f[R_SIDE][i] = 0.0
        L.f[R_SPHI][i] = 0.0
        L.f[R_CPHI][i] = 1.0
        return
    L.f[R_TH][i] = e[E_NTH * LANES + k]
    L.f[R_OM][i] = e[E_NOM * LANES + k]
    L.f[R_SIDE][i] = e[E_NSIDE * LANES + k]
    L.f[R_SPHI][i] = e[E_NS * LANES + k]
    L.f[R_CPHI][i] = e[E_NC * LANES + k]
    stats[ST_TURNS] += ok == 1.0


cdef long _events(long n, long j, double uj, double duj, Chunk* L, double ta, double h,
                  double zeno_tol, int64_t* stats) noexcept nogil:
    """The lanes the step left with something happening in it (bad 1), in rounds of one pass
    over them all (rocking_events_N, then rocking_peaks_N where a peak may be new; on their
    step's polynomial), each round one event per lane: a turning point, or an impact and the
    step after it (over a hop, or to the end of the interval), where the next round looks, or a
    Zeno sequence summed in closed form.  Each round reads its scratch and writes the next
    round's (the two in turn).  Those settled are written back (bad 0); the engine takes the
    others through the interval (overturning, a root the pass cannot settle, an uplift after a
    Zeno sequence).  Returns how many lanes came to rest."""
    cdef long idx[LANES]
    cdef long m = 0, m2, top, k, i, rounds, n_rest = 0, own, low
    cdef long order = ORDERS_FIRST  # the first round's: the highest own order of the lanes' steps
    cdef double ok
    cdef double* e = &L.e[0][0][0]
    cdef double* nx = &L.e[1][0][0]
    cdef double* swap
    cdef bint peaks
    for i in range(n):
        if L.bad[i] == 1:
            own = <long>L.cf[CF_OWN][i]
            _gather(e, m, i, own + 1, uj, duj, L, ta, h, zeno_tol)
            order = max(order, own)
            idx[m] = i
            m += 1
    for rounds in range(EVENT_ROUNDS):
        if m == 0:
            return n_rest
        top = min(LANES, (m + 3) // 4 * 4)  # whole vectors (the rest of the last one: stale)
        rocking_events(order, top, e, nx, TAYLOR_EPS)
        peaks = False
        for k in range(m):
            peaks = peaks or e[E_NEED * LANES + k] != 0.0
        if peaks:
            rocking_peaks(order, top, e, nx, TAYLOR_EPS)
        m2 = 0
        low = ORDERS_FIRST
        for k in range(m):
            ok = e[E_OK * LANES + k]
            i = idx[k]
            if ok == 0.0:
                stats[ST_WHY - 1 + <long>e[E_WHY * LANES + k]] += 1
            elif ok == 3.0:  # more in the interval: the next round, from the next step
                if m2 != k:
                    _column(nx, m2, nx, k)
                low = max(low, <long>e[E_LOW * LANES + k])
                idx[m2] = i
                m2 += 1
            elif ok == 5.0:  # the round again, at the next order up
                _column(nx, m2, e, k)
                low = max(low, order + 2)
                idx[m2] = i
                m2 += 1
            else:
                _settle(e, nx, k, i, j, ok, L, stats)
                n_rest += ok == 4.0
        m = m2
        order = low
        swap = e
        e = nx
        nx = swap
    stats[ST_WHY + 4] += m  # too many events in one interval: the engine takes them
    return n_rest


cdef inline void _swap(Chunk* L, long i, long k) noexcept nogil:
    cdef int r
    cdef double x
    cdef long y
    if i != k:
        for r in range(NF):
            x = L.f[r][i]
            L.f[r][i] = L.f[r][k]
            L.f[r][k] = x
        for r in range(NI):
            y = L.i[r][i]
            L.i[r][i] = L.i[r][k]
            L.i[r][k] = y


cdef (long, long) _partition(Chunk* L, long n_live) noexcept nogil:
    """Reorder lanes ``0 .. n_live-1``: rocking first, then at rest, then overturned; returns
    ``(n_rocking, n_live)``.  Two-pointer partitions: only lanes out of place move (a few per
    call: a lane changes state at an uplift, a return to rest or an overturning)."""
    cdef long i = 0, m = n_live, k
    while True:  # overturned (and final) lanes to the end
        while i < m and L.i[I_STATUS][i] != OVERTURNED and L.i[I_STATUS][i] != FINAL:
            i += 1
        while m > i and (L.i[I_STATUS][m - 1] == OVERTURNED or L.i[I_STATUS][m - 1] == FINAL):
            m -= 1
        if i >= m:
            break
        _swap(L, i, m - 1)
    i = 0
    k = m
    while True:  # rocking lanes to the front
        while i < k and L.i[I_STATUS][i] == ROCKING:
            i += 1
        while k > i and L.i[I_STATUS][k - 1] != ROCKING:
            k -= 1
        if i >= k:
            break
        _swap(L, i, k - 1)
    return k, m


cdef long _wake(const double* uval, long j, long n_int, double a, double tan_a) noexcept nogil:
    """First interval from ``j`` on where a block at rest may uplift (an end of the interval
    above the threshold; the forcing is linear in between), ``n_int`` if none."""
    while j < n_int and fabs(a * uval[j]) <= tan_a and fabs(a * uval[j + 1]) <= tan_a:
        j += 1
    return j


#: the energy bound of a lane's finality must lie below its peak's energy by this share (the
#: bound holds for the exact solution; the steps agree with it to rounding)
cdef double FINAL_MARGIN = 1e-9


cdef long _finals(Chunk* L, long n_live, double rest_u) noexcept nogil:
    """Mark FINAL the live lanes whose verdict and peak can no longer change: with
    ``E = omega^2/2 + p^2 (cos(alpha - |theta|) - cos alpha)`` (0 at rest), the ground can raise
    ``sqrt(E)`` by at most ``p^2 / sqrt(2)`` times ``rest_u``, the integral of ``|ug''/g|`` (the
    lane's amplitude aside) over the rest of the record (``|dE/dt| = p^2 |u cos(.) omega| <= p^2
    |u| sqrt(2 E)``; impacts only lower ``E``, and so does the free rocking after the record); a
    lane whose bound stays below the energy of its peak so far, ``p^2 (cos(alpha - max|theta|) -
    cos alpha)``, never again reaches its peak: it neither overturns nor rocks any higher.
    Returns how many were marked."""
    cdef long i, st, m = 0
    cdef double p2, e, b, top
    for i in range(n_live):
        st = L.i[I_STATUS][i]
        if (st != ROCKING and st != REST) or not L.f[R_MX][i] > 0.0:
            continue
        p2 = L.f[R_P][i] * L.f[R_P][i]
        e = 0.0
        if st == ROCKING:
            e = 0.5 * L.f[R_OM][i] * L.f[R_OM][i] + p2 * (L.f[R_CPHI][i] - L.f[R_CA][i])
            e = fmax(e, 0.0)
        b = sqrt(e) + p2 * 0.7071067811865476 * fabs(L.f[R_A][i]) * rest_u
        top = p2 * (cos(L.f[R_ALPHA][i] - L.f[R_MX][i]) - L.f[R_CA][i])
        if b * b < top * (1.0 - FINAL_MARGIN):
            L.i[I_STATUS][i] = FINAL
            m += 1
            # still, as a lane at rest (a lane past the rocking ones may be stepped with them:
            # omega 0 keeps it as it is)
            L.f[R_TH][i] = 0.0
            L.f[R_OM][i] = 0.0
            L.f[R_SIDE][i] = 0.0
            L.f[R_SPHI][i] = 0.0
            L.f[R_CPHI][i] = 1.0
    return m


cdef void _chunk(long i0, long i1, const double* amp, const double* uval, double t_start,
                 double h, long n_int, const double* p, const double* alpha, const double* eta,
                 double zeno_tol, unsigned char* overturned, double* max_abs,
                 int64_t* n_impacts, unsigned char* uplifted, int64_t* stats,
                 const double* rest_u) noexcept nogil:
    """Runs ``i0 .. i1-1`` (at most :data:`LANES`) from rest over the whole record; results
    (after the energy rule at the end of the record) written at their indices.  ``rest_u``
    (or NULL): the integral of ``|ug''/g|`` from each node to the end of the record; each lane is
    then stopped once its verdict and its peak are final (:func:`_finals`, every
    :data:`FINAL_EVERY` intervals; its impacts are counted up to there).

    ``stats`` (:data:`N_STATS` integers, the ``ST_*`` counts) is incremented by what was done
    in lanes and what was handed to the engine.
    """
    cdef Chunk L
    cdef long n = i1 - i0, i, k, j, n_bad, n_two, w, b, st, st2, n_rested
    cdef Forcing F
    cdef Outcome o
    cdef long order = ORDERS_START, n_low = 0, n_rocking = 0, n_live = n, next_wake = 0
    cdef double ta, tb, th, om, pk
    cdef bint all_low, wake_all, raise_order, changed, over, short
    memset(&L.f[0][0], 0, sizeof(L.f))  # (unused lanes at rest: omega 0, see lanes_step)
    for i in range(n):
        k = i0 + i
        L.f[R_A][i] = amp[k]
        L.f[R_Q][i] = (p[k] * h) * (p[k] * h)
        L.f[R_SA][i] = sin(alpha[k])
        L.f[R_CA][i] = cos(alpha[k])
        L.f[R_TAN][i] = tan(alpha[k])
        L.f[R_P][i] = p[k]
        L.f[R_ALPHA][i] = alpha[k]
        L.f[R_ETA][i] = eta[k]
        L.f[R_TH][i] = 0.0
        L.f[R_OM][i] = 0.0
        L.f[R_SIDE][i] = 0.0
        L.f[R_SPHI][i] = 0.0
        L.f[R_CPHI][i] = 1.0
        L.f[R_REST][i] = -INFINITY
        L.f[R_MX][i] = 0.0
        L.i[I_STATUS][i] = REST
        L.i[I_NIMP][i] = 0
        L.i[I_UP][i] = 0
        L.i[I_RUN][i] = k
        L.i[I_WAKE][i] = 0
        L.bad[i] = 0
    F.kind, F.tp, F.t0, F.uval = NODAL, 1.0, 0.0, uval
    F.vval, F.vamp = NULL, 0.0
    memset(&L.e[0][0][0], 0, sizeof(L.e))  # (the events' padding columns compute on what is there)
    for j in range(n_int):
        if n_live == 0:
            break
        if rest_u != NULL and j % FINAL_EVERY == 0 and j > 0:
            if _finals(&L, n_live, rest_u[j]) > 0:
                n_rocking, n_live = _partition(&L, n_live)
        if n_rocking == 0 and j < next_wake:
            continue
        ta = t_start + j * h
        tb = t_start + (j + 1) * h
        n_bad = 0
        n_rested = 0
        all_low = False
        short = False
        if n_rocking > 0:
            n_bad, n_two = lanes_step(order, n_rocking, uval[j], uval[j + 1] - uval[j], &L, h,
                                      TAYLOR_EPS)
            stats[ST_KEPT] += n_rocking - n_bad
            all_low = n_two == n_rocking
            short = False
            if n_bad > 0:
                short = n_bad > n_events(&L, n_rocking)
                if short:  # steps again, at higher orders (and the chunk's order raised below)
                    stats[ST_LOW] += n_bad - n_events(&L, n_rocking)
                    _restep(order, n_rocking, uval[j], uval[j + 1] - uval[j], &L, h)
                n_rested = _events(n_rocking, j, uval[j], uval[j + 1] - uval[j], &L, ta, h,
                                   zeno_tol, stats)
                if n_rested > 0:
                    next_wake = min(next_wake, j + 1)
        wake_all = j >= next_wake
        if n_bad > 0 or wake_all:  # lanes that need attention in this interval
            raise_order = short
            changed = n_rested > 0
            if wake_all:
                next_wake = n_int
            for i in range(n_rocking if not wake_all else n_live):
                st = L.i[I_STATUS][i]
                if st == ROCKING:
                    b = L.bad[i]
                    if b == 0:
                        continue
                else:  # at rest: the engine only where the block may uplift in this interval
                    if L.i[I_WAKE][i] > j:
                        next_wake = min(next_wake, L.i[I_WAKE][i])
                        continue
                    if L.f[R_REST][i] >= tb:  # at rest after a Zeno sequence until then
                        next_wake = min(next_wake, j + 1)
                        continue
                    w = _wake(uval, j, n_int, L.f[R_A][i], L.f[R_TAN][i])
                    if w > j:
                        L.i[I_WAKE][i] = w
                        next_wake = min(next_wake, w)
                        continue
                # something happens in this interval: the engine takes this lane through it
                stats[ST_ENGINE if st == ROCKING else ST_REST] += 1
                F.amp = L.f[R_A][i]
                o = run_core(&F, t_start, h, 1, NULL, True, L.f[R_P][i], L.f[R_ALPHA][i],
                             L.f[R_ETA][i], False, TAYLOR, zeno_tol, False, False, j,
                             L.f[R_TH][i], L.f[R_OM][i], L.f[R_REST][i], j + 1, NULL, NULL, NULL,
                             NULL, 0, 0)
                st2 = o.status
                th = o.theta
                om = o.omega
                if o.max_abs > L.f[R_MX][i]:
                    L.f[R_MX][i] = o.max_abs
                L.i[I_NIMP][i] += o.n_imp
                if o.uplifted:
                    L.i[I_UP][i] = 1
                L.f[R_REST][i] = o.rest_until
                L.i[I_STATUS][i] = st2
                changed = changed or st2 != st
                if st2 == ROCKING:
                    L.f[R_TH][i] = th
                    L.f[R_OM][i] = om
                    if th != 0.0:
                        L.f[R_SIDE][i] = 1.0 if th > 0.0 else -1.0
                    else:
                        L.f[R_SIDE][i] = 1.0 if om > 0.0 else -1.0
                    L.f[R_SPHI][i], L.f[R_CPHI][i] = corner_sincos(th, L.f[R_SIDE][i],
                                                                   L.f[R_SA][i], L.f[R_CA][i])
                else:
                    L.f[R_TH][i] = 0.0
                    L.f[R_OM][i] = 0.0
                    L.f[R_SIDE][i] = 0.0
                    L.f[R_SPHI][i] = 0.0
                    L.f[R_CPHI][i] = 1.0
                    if st2 == REST:
                        L.i[I_WAKE][i] = j + 1
                        next_wake = min(next_wake, j + 1)
            if changed:
                n_rocking, n_live = _partition(&L, n_live)
            if raise_order and order < ORDERS_LAST:
                order += 2
                n_low = 0
                continue
        if all_low:
            n_low += 1
            if n_low >= LOW_RUN and order > ORDERS_FIRST:
                order -= 2
                n_low = 0
        else:
            n_low = 0
    for i in range(n):
        k = L.i[I_RUN][i]
        st = L.i[I_STATUS][i]
        over = st == OVERTURNED
        pk = L.f[R_MX][i]
        if st == ROCKING:
            over, th = energy_verdict(L.f[R_TH][i], L.f[R_OM][i], L.f[R_P][i], L.f[R_ALPHA][i],
                                      L.f[R_ETA][i], False)
            if th > pk:
                pk = th
        overturned[k] = over
        max_abs[k] = HALF_PI if over else pk
        n_impacts[k] = L.i[I_NIMP][i]
        uplifted[k] = L.i[I_UP][i] != 0


cdef void _one_by_one(long i0, long i1, int kind, const double* amp, double tp, double t0,
                      const double* uval, const double* nodes, bint uniform, double t_start,
                      double h, long n_int, const int64_t* n_sub, const double* p,
                      const double* alpha, const double* eta, bint linear, double zeno_tol,
                      int method, unsigned char* overturned, double* max_abs,
                      int64_t* n_impacts, unsigned char* uplifted, const double* vval,
                      double* t_lift) noexcept nogil:
    """Runs ``i0 .. i1-1`` from rest one by one with :func:`run_core`, then the energy rule.
    ``vval`` (or NULL): the vertical ground motion's node values, scaled as the record
    (``1 + amp * vval``); ``t_lift`` (with it): the lift-off time of each run (nan if none)."""
    cdef Forcing F
    cdef Outcome o
    cdef long i
    cdef bint over
    cdef double mx, peak
    F.kind, F.tp, F.t0, F.uval = kind, tp, t0, uval
    F.vval, F.vamp = vval, 0.0
    for i in range(i0, i1):
        F.amp = amp[i]
        F.vamp = amp[i]
        o = run_core(&F, t_start, h, n_sub[i], nodes, uniform, p[i], alpha[i], eta[i], linear,
                     method, zeno_tol, False, False, 0, 0.0, 0.0, -INFINITY, n_int, NULL, NULL,
                     NULL, NULL, 0, 0)
        mx = o.max_abs
        if t_lift != NULL:
            t_lift[i] = o.t if o.status == LIFTOFF else NAN
        if o.status == OVERTURNED:
            over = True
        elif o.status == ROCKING:
            over, peak = energy_verdict(o.theta, o.omega, p[i], alpha[i], eta[i], linear)
            if peak > mx:
                mx = peak
        else:
            over = False
        overturned[i] = over
        max_abs[i] = HALF_PI if over else mx
        n_impacts[i] = o.n_imp
        uplifted[i] = o.uplifted


def kernel(bint lanes, long i0, long i1, int kind, const double[::1] amp, double tp, double t0,
           const double[::1] uval, const double[::1] nodes, double t_start, double h, long n_int,
           const int64_t[::1] n_sub, const double[::1] p, const double[::1] alpha,
           const double[::1] eta, bint linear, double zeno_tol, int method,
           unsigned char[::1] overturned, double[::1] max_abs, int64_t[::1] n_impacts,
           unsigned char[::1] uplifted, int64_t[::1] stats, const double[::1] vval=None,
           double[::1] t_lift=None, const double[::1] rest_u=None):
    """Runs ``i0 .. i1-1`` of a batch from rest, then the energy rule; results written at their
    indices (``overturned`` and ``uplifted`` as bytes 0 or 1).  ``lanes``: stepped together (at
    most :data:`LANES` runs; a record on a uniform grid, one Taylor step per sample), else one by
    one with :func:`run_core`.  Runs without the GIL: :func:`rocking.lanes.run_batch` spreads
    calls over threads.  ``vval``: the vertical ground motion's node values (one by one only,
    records on a uniform grid, Taylor steps; scaled as the record), with ``t_lift`` the lift-off
    time of each run (nan if none).  ``rest_u`` (lanes only): the integral of ``|ug''/g|`` from
    each node to the end of the record, to stop each run once its verdict and peak are final
    (``_finals``; ``n_impacts`` then counts the impacts up to there)."""
    cdef const double* rest_u_p = NULL
    cdef const double* vval_p = NULL
    cdef double* t_lift_p = NULL
    cdef const double* uval_p = _ptr(uval)
    cdef const double* nodes_p = _ptr(nodes)
    cdef bint uniform = nodes.shape[0] == 0
    cdef int64_t counts[N_STATS]
    cdef long k
    if not (0 <= i0 <= i1 <= p.shape[0] and p.shape[0] <= min(amp.shape[0], alpha.shape[0],
            eta.shape[0], n_sub.shape[0], overturned.shape[0], max_abs.shape[0],
            n_impacts.shape[0], uplifted.shape[0]) and stats.shape[0] >= 4):
        raise ValueError("batch arrays of unequal lengths")
    if lanes and i1 - i0 > LANES:
        raise ValueError(f"at most {LANES} runs are stepped together")
    if (lanes or (kind == NODAL and uniform)) and uval.shape[0] < n_int + 1:
        raise ValueError("the node values are fewer than the intervals run")
    if not uniform and nodes.shape[0] < n_int + 1:
        raise ValueError("the node times are fewer than the intervals run")
    if vval is not None:
        if lanes or kind != NODAL or not uniform or linear or method != TAYLOR:
            raise ValueError("vertical ground motion: records on a uniform grid, one by one, "
                             "Taylor steps of the nonlinear equation only")
        if vval.shape[0] < n_int + 1 or t_lift is None or t_lift.shape[0] < p.shape[0]:
            raise ValueError("the vertical node values are fewer than the intervals run, or no "
                             "room for the lift-off times")
        vval_p = &vval[0]
        t_lift_p = &t_lift[0]
    if rest_u is not None:
        if not lanes or rest_u.shape[0] < n_int + 1:
            raise ValueError("rest_u: lanes only, a value at every node")
        rest_u_p = &rest_u[0]
    if i1 <= i0:
        return
    with nogil:
        if lanes:
            for k in range(N_STATS):
                counts[k] = 0
            _chunk(i0, i1, &amp[0], uval_p, t_start, h, n_int, &p[0], &alpha[0], &eta[0],
                   zeno_tol, &overturned[0], &max_abs[0], &n_impacts[0], &uplifted[0], counts,
                   rest_u_p)
            for k in range(min(N_STATS, stats.shape[0])):
                stats[k] += counts[k]
        else:
            _one_by_one(i0, i1, kind, &amp[0], tp, t0, uval_p, nodes_p, uniform, t_start, h,
                        n_int, &n_sub[0], &p[0], &alpha[0], &eta[0], linear, zeno_tol, method,
                        &overturned[0], &max_abs[0], &n_impacts[0], &uplifted[0], vval_p,
                         t_lift_p)


# --------------------------------------------------------------------------- from Python
# the compiled pieces that tests and rocking.reference call one at a time
def py_energy_verdict(double theta, double omega, double p, double alpha, double eta,
                      bint linear):
    cdef bint over
    cdef double peak
    over, peak = energy_verdict(theta, omega, p, alpha, eta, linear)
    return bool(over), peak


def abs_max(const double[::1] a):
    """``max|a|`` of a float array (as ``np.max(np.abs(a))`` for finite values, 0 if empty), in
    one pass with four running maxima (independent chains of compare and select)."""
    cdef double m0 = 0.0, m1 = 0.0, m2 = 0.0, m3 = 0.0, x0, x1, x2, x3
    cdef Py_ssize_t n = a.shape[0], i = 0
    with nogil:
        while i + 4 <= n:
            x0 = fabs(a[i])
            x1 = fabs(a[i + 1])
            x2 = fabs(a[i + 2])
            x3 = fabs(a[i + 3])
            m0 = x0 if x0 > m0 else m0
            m1 = x1 if x1 > m1 else m1
            m2 = x2 if x2 > m2 else m2
            m3 = x3 if x3 > m3 else m3
            i += 4
        while i < n:
            x0 = fabs(a[i])
            m0 = x0 if x0 > m0 else m0
            i += 1
    return max(max(m0, m1), max(m2, m3))


def vertical_bounds(const double[::1] uval, const double[::1] vval, double amp, double vamp,
                    double tan_a, long n):
    """One pass over the first ``n`` nodes of a record and its vertical (docs/theory.md section
    10): ``(quiet, g_min, g_max, zero, u_max)``: whether ``|amp u| <= (1 + vamp v) tan_a`` at
    every node (then, both being linear between nodes, the block never uplifts and never lifts
    off), the smallest and largest effective gravity ``1 + vamp v``, whether the vertical is zero,
    and ``max |u|`` (the record's peak, unscaled)."""
    cdef double v_min = INFINITY, v_max = -INFINITY, excess = -INFINITY, u_max = 0.0, v, u, e
    cdef Py_ssize_t i
    if n > uval.shape[0] or n > vval.shape[0] or n < 1:
        raise ValueError("fewer node values than asked for")
    with nogil:
        for i in range(n):  # branch-free running extrema
            v = vval[i]
            u = fabs(uval[i])
            v_min = v if v < v_min else v_min
            v_max = v if v > v_max else v_max
            u_max = u if u > u_max else u_max
            e = fabs(amp) * u - (1.0 + vamp * v) * tan_a
            excess = e if e > excess else excess
    return (bool(excess <= 0.0), 1.0 + vamp * (v_min if vamp >= 0 else v_max),
            1.0 + vamp * (v_max if vamp >= 0 else v_min), v_min == 0.0 and v_max == 0.0, u_max)


def py_forcing_series(int kind, double amp, double tp, double t0, const double[::1] uval, long j,
                      double ta, double tb, double t, double h, double[::1] U, long n_terms):
    cdef Forcing F
    cdef int nu
    cdef bint complete
    if U.shape[0] < 2 * M:
        raise ValueError(f"U needs {2 * M} floats")
    F.kind, F.amp, F.tp, F.t0, F.uval = kind, amp, tp, t0, _ptr(uval)
    F.vval, F.vamp = NULL, 0.0
    nu, complete = forcing_series(&F, j, ta, tb, t, h, &U[0], n_terms)
    return nu, bool(complete)


def py_taylor_series(const double[::1] U, int nu, bint complete, double h, double theta,
                     double omega, double s, double p2, double sa, double ca, double[::1] cf,
                     double[::1] S, double[::1] C, bint sc_known, double s0, double c0,
                     bint vert=False, double g0=1.0, double g1=0.0):
    cdef double Uc[2 * M]
    cdef int n, k
    cdef double s1, c1
    if cf.shape[0] < M or S.shape[0] < M or C.shape[0] < M or U.shape[0] < min(nu, M):
        raise ValueError(f"cf, S and C need {M} floats")
    for k in range(2 * M):
        Uc[k] = U[k] if k < U.shape[0] and k < M else 0.0
    n, s1, c1 = taylor_series(Uc, nu, complete, h, theta, omega, s, p2, sa, ca, &cf[0], &S[0],
                              &C[0], sc_known, s0, c0, vert, g0, g1)
    return n, s1, c1


def py_taylor_eval(const double[::1] cf, int n, double x, double h):
    if not 0 <= n < cf.shape[0]:
        raise ValueError("order beyond the coefficients")
    return taylor_eval(&cf[0], n, x, h)


def py_taylor_fixed(long order, double u0, double u1, double q, double theta, double wh,
                    double s0, double c0, double eps, double[::1] cf):
    """:data:`ORDERS` step of order ``order`` (the highest for larger); its polynomial in ``cf``."""
    if cf.shape[0] < min(max(order, ORDERS_FIRST), ORDERS_LAST) + 1:
        raise ValueError("cf is shorter than the step's polynomial")
    return taylor_fixed(order, u0, u1, q, theta, wh, s0, c0, eps, &cf[0])


def py_taylor_fixed_v(long order, double u0, double u1, double g0, double g1, double q,
                      double theta, double wh, double s0, double c0, double eps, double[::1] cf):
    """The vertical step ``taylor_v_N`` of :data:`ORDERS` order ``order``; its polynomial in
    ``cf``."""
    if cf.shape[0] < min(max(order, ORDERS_FIRST), ORDERS_LAST) + 1:
        raise ValueError("cf is shorter than the step's polynomial")
    return taylor_fixed_v(order, u0, u1, g0, g1, q, theta, wh, s0, c0, eps, &cf[0])


def py_taylor_smooth(long order, const double[::1] U, double q, double theta, double wh,
                     double s0, double c0, double eps, double[::1] cf):
    """:data:`SMOOTH_ORDERS` step of order ``order`` (forcing series ``U``)."""
    cdef long n = min(max(order, SMOOTH_FIRST), SMOOTH_LAST)
    if cf.shape[0] < n + 1 or U.shape[0] < n - 1:
        raise ValueError("U or cf is shorter than the step needs")
    return taylor_smooth(order, &U[0], q, theta, wh, s0, c0, eps, &cf[0])


def py_lanes_step(long order, long n, double uj, double duj, double[:, ::1] state, double h,
                  double eps, int64_t[::1] bad):
    """The lanes' step of order ``order`` on ``n`` lanes of ``state`` (rows amp, q, theta, omega,
    side, s_phi, c_phi, peak; one column per lane), in place; returns ``(n_bad, n_low)``."""
    cdef Chunk L
    cdef long i, r
    cdef int rows[8]
    rows[:] = [R_A, R_Q, R_TH, R_OM, R_SIDE, R_SPHI, R_CPHI, R_MX]
    if not (0 <= n <= LANES and state.shape[0] >= 8 and state.shape[1] >= n and bad.shape[0] >= n):
        raise ValueError("state must hold 8 rows of n <= LANES lanes")
    memset(&L, 0, sizeof(L))
    for r in range(8):
        for i in range(n):
            L.f[rows[r]][i] = state[r, i]
    res = lanes_step(order, n, uj, duj, &L, h, eps)
    for r in range(8):
        for i in range(n):
            state[r, i] = L.f[rows[r]][i]
    for i in range(n):
        bad[i] = L.bad[i]
    return res


def py_events(long order, long m, double[:, ::1] e, double[:, ::1] nx, bint peaks):
    """A round of the lanes' events of order ``order`` on columns ``0 .. m-1`` of the round's
    scratch ``e``, writing the next round's ``nx`` (each ``NE`` rows of ``LANES`` columns,
    rocking._make_lanes.event_rows()), in place, then its peaks where ``peaks``."""
    cdef Chunk L
    cdef long r, k, b
    if not (0 <= m <= LANES and e.shape[0] == NE and e.shape[1] == LANES
            and nx.shape[0] == NE and nx.shape[1] == LANES):
        raise ValueError(f"e and nx must be {NE} x {LANES}")
    for r in range(NE):
        for k in range(LANES):
            L.e[0][r][k] = e[r, k]
            L.e[1][r][k] = nx[r, k]
    rocking_events(order, m, &L.e[0][0][0], &L.e[1][0][0], TAYLOR_EPS)
    if peaks:
        rocking_peaks(order, m, &L.e[0][0][0], &L.e[1][0][0], TAYLOR_EPS)
    for r in range(NE):
        for k in range(LANES):
            e[r, k] = L.e[0][r][k]
            nx[r, k] = L.e[1][r][k]
