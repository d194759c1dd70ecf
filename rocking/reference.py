"""The reference model: adaptive DOP853 (scipy) at ``rtol = 1e-12`` with located events.

Slow by design; it is the yardstick for the fast and linearised models.  The integration is split
wherever the forcing is not smooth (every record sample, the pulse's support ends and, so that
the uplift search sees a monotonic forcing, its extrema).  Impacts (``theta = 0``), peaks
(``omega = 0``) and overturning (``|theta| = pi/2``) are events located by scipy's root finder on
the DOP853 dense output; uplift times are roots of the forcing itself.  The rules of the model
(uplift, impact, Zeno accumulation, energy verdict after the excitation) are those of
docs/theory.md section 2, written here a second time in plain Python, independently of the compiled engine.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from pulses import G, Record

from . import engine
from ._common import _free_rocking_horizon, _pulse_extrema, _result
from .block import Block

RTOL = 1e-12
ATOL = 1e-15
HALF_PI = 0.5 * math.pi


def _segments(excitation, duration):
    """List of ``(ta, tb, u)``: intervals with a smooth forcing ``u(t) = ug''(t)/g`` on each."""
    if isinstance(excitation, Record):
        uval = excitation.acc / G
        t = excitation.time
        n = excitation.npts - 1
        if duration is not None:
            n = min(n, max(1, math.ceil(duration / excitation.dt - 1e-9)))
        segs = []
        for k in range(n):
            ta, tb, ua, ub = t[k], t[k + 1], uval[k], uval[k + 1]
            slope = (ub - ua) / (tb - ta)
            segs.append((ta, tb, (lambda x, ua=ua, ta=ta, slope=slope: ua + slope * (x - ta))))
        return segs

    start, end = excitation.support
    if duration is not None:
        end = min(end, start + duration)
    marks = sorted({start, end, *[x for x in _pulse_extrema(excitation) if start < x < end]})
    ap_g, tp, t0 = excitation.ap / G, excitation.tp, excitation.t0
    if excitation.shape == "rect":
        def u(x):
            return ap_g
    else:
        unit = excitation._unit

        def u(x):
            return ap_g * float(unit((x - t0) / tp))
    return [(a, b, u) for a, b in zip(marks[:-1], marks[1:])]


def _rhs_factory(p, alpha, u):
    p2 = p * p

    def rhs(t, y, s):
        d = alpha * s - y[0]
        return [y[1], -p2 * (math.sin(d) + u(t) * math.cos(d))]

    return rhs


class _State:
    """Mutable state of the reference integration."""

    def __init__(self, block, theta0, omega0, zeno_tol):
        self.block = block
        self.theta, self.omega = float(theta0), float(omega0)
        self.s = (1.0 if theta0 > 0 else -1.0) if theta0 != 0 else (
            (1.0 if omega0 > 0 else -1.0) if omega0 != 0 else 0.0)
        self.max_abs = abs(theta0)
        self.impacts = []
        self.rest_until = -math.inf
        self.overturned = False
        self.t_overturn = math.nan
        self.uplifted = self.s != 0.0
        self.omega_zeno = zeno_tol * block.p * block.alpha
        self.hist = []


def _advance(state: _State, ta: float, tb: float, u, stop_at_rest: bool = False) -> bool:
    """Carry ``state`` from ``ta`` to ``tb`` (forcing ``u``); False once overturned or settled."""
    blk = state.block
    p, alpha, eta, tan_a = blk.p, blk.alpha, blk.eta, blk.tan_alpha
    t = ta
    rhs = _rhs_factory(p, alpha, u)
    while t < tb:
        if state.s == 0.0:
            if stop_at_rest:
                return False
            t = max(t, state.rest_until)
            if t >= tb:
                break
            ua, ub = u(t), u(tb)
            if abs(ua) > tan_a:
                t_up, u_up = t, ua
            elif abs(ub) > tan_a:
                level = math.copysign(tan_a, ub)
                t_up = brentq(lambda x: u(x) - level, t, tb, xtol=1e-15, rtol=1e-15)
                t_up = min(tb, t_up + abs(t_up) * 1e-16)
                u_up = ub
            else:
                break
            state.s = -1.0 if u_up > 0 else 1.0
            state.theta = state.omega = 0.0
            state.uplifted = True
            t = t_up
            continue
        s = state.s

        def impact(x, y, s):
            return y[0]

        impact.terminal, impact.direction = True, -s

        def overturn(x, y, s):
            return s * y[0] - HALF_PI

        overturn.terminal, overturn.direction = True, 1.0

        def peak(x, y, s):
            return y[1]

        first_step = None
        if state.theta == 0.0 and state.omega != 0.0:
            # a flight that starts at theta = 0 must not end inside the first step
            a = abs(rhs(t, [0.0, 0.0], s)[1])
            if a > 0:
                first_step = min(tb - t, 0.05 * abs(state.omega) / a)
        sol = solve_ivp(rhs, (t, tb), [state.theta, state.omega], method="DOP853", rtol=RTOL,
                        atol=ATOL, events=(impact, overturn, peak), args=(s,),
                        first_step=first_step)
        if sol.status == -1:
            raise RuntimeError(f"reference integration failed: {sol.message}")
        for y in sol.y_events[2]:
            state.max_abs = max(state.max_abs, abs(y[0]))
        state.max_abs = max(state.max_abs, float(np.max(np.abs(sol.y[0]))))
        if sol.status == 1 and sol.t_events[1].size:
            state.overturned = True
            state.t_overturn = float(sol.t_events[1][0])
            state.theta, state.omega = float(sol.y_events[1][0][0]), float(sol.y_events[1][0][1])
            state.max_abs = HALF_PI
            return False
        if sol.status == 1 and sol.t_events[0].size:
            t = float(sol.t_events[0][0])
            om = float(sol.y_events[0][0][1])
            state.impacts.append(t)
            state.s = -s
            state.theta, state.omega = 0.0, eta * om
            if abs(state.omega) <= state.omega_zeno:
                uu = u(t)
                a_new = p * p * (math.sin(alpha) + state.s * uu * math.cos(alpha))
                a_old = p * p * (math.sin(alpha) - state.s * uu * math.cos(alpha))
                # at rest (after the hops' accumulation time when both sides hold the block;
                # now when the forcing is at or past the uplift threshold on one side)
                tz = 0.0
                if a_new > 0 and a_old > 0:
                    tz = 2 * abs(state.omega) / (1 - eta**2) * (1 / a_new + eta / a_old)
                state.rest_until = t + tz
                state.s, state.omega = 0.0, 0.0
            continue
        state.theta, state.omega = float(sol.y[0, -1]), float(sol.y[1, -1])
        t = tb
    return True


def simulate_reference(block: Block, excitation=None, *, theta0=0.0, omega0=0.0, duration=None,
                       zeno_tol=1e-7):
    """Rocking response by the reference model (see module docstring); same result type as
    :func:`rocking.simulate`."""

    state = _State(block, theta0, omega0, zeno_tol)
    hist = [(0.0 if excitation is None else excitation.support[0], state.theta, state.omega)]
    if excitation is None:
        length = duration if duration is not None else _free_rocking_horizon(block)
        over_e, peak_e = engine.energy_verdict(theta0, omega0, block.p, block.alpha, block.eta,
                                               False)
        _advance(state, 0.0, length, lambda x: 0.0, stop_at_rest=duration is None)
        hist.append((length, state.theta, state.omega))
        over = over_e or state.overturned
        verdict_by = "integration" if state.overturned or state.s == 0 else "energy rule"
        max_abs = HALF_PI if over else max(state.max_abs, peak_e if state.s != 0 else 0.0)
        t, th, om = (np.array(c) for c in zip(*hist))
        return _result(block, over, max_abs, state.impacts, len(state.impacts), t, th, om,
                       "reference", verdict_by, True, state.t_overturn)
    for ta, tb, u in _segments(excitation, duration):
        alive = _advance(state, ta, tb, u)
        hist.append((state.t_overturn if state.overturned else tb, state.theta, state.omega))
        if not alive:
            break
    if state.overturned:
        over, verdict_by = True, "integration"
        max_abs = HALF_PI
    elif state.s == 0.0:
        over, verdict_by, max_abs = False, "integration", state.max_abs
    else:
        over, peak = engine.energy_verdict(state.theta, state.omega, block.p, block.alpha,
                                           block.eta, False)
        verdict_by = "energy rule"
        max_abs = HALF_PI if over else max(state.max_abs, peak)
    start, end = excitation.support
    if duration is not None and start + duration > end and not state.overturned:
        state2 = state
        _advance(state2, end, start + duration, lambda x: 0.0)
        hist.append((state2.t_overturn if state2.overturned else start + duration,
                     state2.theta, state2.omega))
        if not over:
            max_abs = max(max_abs, state2.max_abs)
    t, th, om = (np.array(c) for c in zip(*hist))
    return _result(block, over, max_abs, state.impacts, len(state.impacts), t, th, om,
                   "reference", verdict_by, state.uplifted, state.t_overturn)
