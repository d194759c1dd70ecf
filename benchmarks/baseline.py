"""The usual approach: scipy ``solve_ivp`` with an impact event, restarted at every impact.

This is how rocking blocks are commonly solved in Python scripts and the yardstick of issue 2's
speed target ("at least 1000x faster and 1000x more accurate than the usual approach"):

- the full nonlinear Eq. 3 of docs/theory.md section 2 in ``solve_ivp`` (RK45 by default, default tolerances
  ``rtol=1e-3, atol=1e-6``), ``max_step`` equal to the record's time step so that no sample is
  stepped over (for an analytic pulse: ``Tp / 200``);
- the ground acceleration read linearly between samples (the same forcing every model sees);
- a terminal event at ``theta = 0`` (impact): the integration stops, ``omega`` is multiplied by
  ``eta``, the side flips and ``solve_ivp`` is restarted from there;
- a terminal event at ``|theta| = pi/2`` (overturned), and a non-terminal one at ``omega = 0``
  so that peaks between output points are located (max|theta| is taken over both);
- rest: a block at rest uplifts when ``|ug''| > g tan(alpha)``; after an impact whose outgoing
  velocity is below an arbitrary threshold (``rest_tol * p * alpha``) the block is put at rest (the
  usual way to stop the chatter of a Zeno sequence; the answer depends on this threshold);
- after the excitation, free rocking is integrated for ``tail`` seconds (zero ground motion, no
  ``max_step``: nothing to resolve), since the last peak may come after the ground stops.

Written for the benchmarks only: plain Python, no compilation, deliberately what a careful user
would write in an afternoon.  It is not part of the package.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from pulses import G, Record

HALF_PI = 0.5 * math.pi


@dataclass
class UsualResult:
    overturned: bool
    max_rotation: float
    max_rotation_ratio: float
    n_impacts: int
    n_restarts: int
    capped: bool  # hit the restart cap (chatter)


def _forcing(excitation):
    """Scalar ``u(t) = ug''(t)/g`` and the end time of the excitation."""
    if isinstance(excitation, Record):
        uval = excitation.acc / G
        dt, t0, n = excitation.dt, excitation.t_start, excitation.npts

        def u(t):
            x = (t - t0) / dt
            k = int(x)
            if k < 0 or k >= n - 1:
                return float(uval[-1]) if k == n - 1 else 0.0
            f = x - k
            return float(uval[k] * (1.0 - f) + uval[k + 1] * f)

        return u, excitation.support, dt
    start, end = excitation.support
    ap_g, tp, tc = excitation.ap / G, excitation.tp, excitation.t0
    unit = excitation._unit

    def u(t):
        if t < start or t > end:
            return 0.0
        return ap_g * float(unit((t - tc) / tp))

    return u, (start, end), tp / 200.0


def _uplift_time(u, t, t_end, tan_a, h):
    """First time in ``[t, t_end]`` where ``|u| > tan(alpha)`` (scan at ``h``, then bisect)."""
    if abs(u(t)) > tan_a:
        return t
    a = t
    while a < t_end:
        b = min(a + h, t_end)
        if abs(u(b)) > tan_a:
            lo, hi = a, b
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                if abs(u(mid)) > tan_a:
                    hi = mid
                else:
                    lo = mid
            return hi
        a = b
    return None


def simulate_usual(block, excitation, *, method="RK45", rtol=1e-3, atol=1e-6, max_step=None,
                   rest_tol=1e-3, tail=10.0, max_restarts=20000) -> UsualResult:
    """Rocking response by the usual approach (see module docstring)."""
    u, (t_start, t_exc_end), h_default = _forcing(excitation)
    if max_step is None:
        max_step = h_default
    p2, alpha, eta, tan_a = block.p ** 2, block.alpha, block.eta, block.tan_alpha
    omega_rest = rest_tol * block.p * alpha
    t_end = t_exc_end + tail

    def rhs(t, y, s):
        d = alpha * s - y[0]
        return [y[1], -p2 * (math.sin(d) + u(t) * math.cos(d))]

    def impact(t, y, s):
        return y[0]

    impact.terminal = True

    def overturn(t, y, s):
        return abs(y[0]) - HALF_PI

    overturn.terminal = True
    overturn.direction = 1.0

    def peak(t, y, s):  # not terminal: locates the peaks between output points
        return y[1]

    t, theta, omega, s = t_start, 0.0, 0.0, 0.0
    max_abs, n_imp, restarts = 0.0, 0, 0
    while t < t_end and restarts < max_restarts:
        if s == 0.0:  # at rest: wait for uplift
            if t >= t_exc_end:
                break
            t_up = _uplift_time(u, t, t_exc_end, tan_a, h_default)
            if t_up is None:
                break
            t, theta, omega = t_up, 0.0, 0.0
            s = -1.0 if u(t_up) > 0 else 1.0
        impact.direction = -s
        # forced part: no sample stepped over; free part after the excitation: no limit
        stop = t_exc_end if t < t_exc_end else t_end
        step = max_step if t < t_exc_end else np.inf
        sol = solve_ivp(rhs, (t, stop), [theta, omega], method=method, rtol=rtol, atol=atol,
                        max_step=step, events=(impact, overturn, peak), args=(s,))
        restarts += 1
        max_abs = max(max_abs, float(np.max(np.abs(sol.y[0]))))
        if sol.y_events[2].size:
            max_abs = max(max_abs, float(np.max(np.abs(sol.y_events[2][:, 0]))))
        if sol.status == 1 and sol.t_events[1].size:
            return UsualResult(True, HALF_PI, HALF_PI / alpha, n_imp, restarts, False)
        if sol.status == 1 and sol.t_events[0].size:
            t_new = float(sol.t_events[0][0])
            om = float(sol.y_events[0][0][1])
            n_imp += 1
            if abs(eta * om) < omega_rest or t_new <= t:
                t, theta, omega, s = t_new, 0.0, 0.0, 0.0
            else:
                t, theta, omega, s = t_new, 0.0, eta * om, -s
            continue
        t, theta, omega = float(sol.t[-1]), float(sol.y[0, -1]), float(sol.y[1, -1])
    return UsualResult(False, max_abs, max_abs / alpha, n_imp, restarts, restarts >= max_restarts)
