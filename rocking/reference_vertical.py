"""Reference rocking response under horizontal and vertical ground motion (docs/theory.md section 10).

With an upward ground acceleration ``av(t)`` gravity is replaced by the effective gravity
``g + av(t)``::

    theta'' = -p^2 [ (1 + av/g) sin(alpha s - theta) + (ag/g) cos(alpha s - theta) ],  s = sgn(theta)

uplift from rest when ``|ag| > (g + av) tan(alpha)``, towards ``s = -sgn(ag)``; the impact rule
(Eq. 5) is unchanged.  Where ``g + av < 0`` the ground pulls away faster than gravity and the block
leaves it (free flight), which this model does not describe: the integration stops there and the
result says so (``lifts_off``, ``t_lift_off``), whether the block was rocking or at rest.

This is a second, independent implementation (plain Python and :func:`scipy.integrate.solve_ivp`,
DOP853 at ``rtol`` :data:`RTOL`), written for the yardstick role :mod:`rocking.reference` plays for
horizontal motion: slow by design.  Both records are piecewise linear between their common samples,
so on each sample interval the uplift and lift-off thresholds are linear in time and their
crossings are solved exactly; impacts, peaks and overturning are events located on the dense
output.  After the excitation the block rocks freely (``av = 0``): the integration goes on to the
first peak that follows (or overturning), since every later peak is lower (energy is constant in
flight and lost at impacts).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pulses import G, Record

from ._common import ZENO_TOL, RockingResult, _result
from .block import Block

#: relative and absolute tolerances of DOP853: those of rocking.reference (its yardstick role)
RTOL = 1e-12
ATOL = 1e-15
HALF_PI = 0.5 * math.pi
#: two records share a time axis when their steps and starts agree to this share of a step
#: (AT2 headers print dt to 4 or 5 digits)
SAME_AXIS_RTOL = 1e-6
#: free rocking after the excitation is integrated for at most this many 1/p (the first peak
#: comes within a few 1/p unless the block is at the verge of overturning)
FREE_HORIZON_P = 1e4


@dataclass
class VerticalRockingResult(RockingResult):
    """:class:`rocking.RockingResult` with the free-flight verdict.

    Attributes
    ----------
    lifts_off : bool
        ``g + av < 0`` at some time before the end of the response: the block leaves the ground
        there, which the model does not describe; the response stops at ``t_lift_off`` (then
        ``verdict_by`` is ``"lifts off"`` and ``overturned`` says only that it had not overturned
        before).
    t_lift_off : float
        First time (s) of ``g + av < 0``, else nan.
    min_effective_gravity : float
        Smallest ``1 + av/g`` of the vertical record (1 without one).

    Examples
    --------
    >>> import numpy as np, pulses, rocking
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.3 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> up = pulses.Record(-1.2 * pulses.G * np.sin(5.0 * t), 0.01)      # beyond g: the block lifts off
    >>> res = rocking.simulate_vertical_reference(rocking.Block.from_dimensions(7.5, 1.8), rec, up)
    >>> res.lifts_off, res.verdict_by, round(res.min_effective_gravity, 2)
    (True, 'lifts off', -0.2)
    """

    lifts_off: bool = False
    t_lift_off: float = math.nan
    min_effective_gravity: float = 1.0


def _linear_root(fa: float, fb: float, ta: float, tb: float) -> float:
    """Where the linear function with values ``fa`` at ``ta`` and ``fb`` at ``tb`` is zero."""
    if fa == fb:
        return ta
    t = ta + (tb - ta) * fa / (fa - fb)
    return min(max(t, ta), tb)


def check_axes(record: Record, vertical: Record) -> Record:
    """``vertical`` on the time axis of ``record`` (same step and start; a longer vertical is cut,
    a shorter one refused): the two are combined sample by sample."""
    if abs(record.dt - vertical.dt) > SAME_AXIS_RTOL * record.dt:
        raise ValueError(f"the vertical record's time step {vertical.dt:g} s differs from the "
                         f"horizontal's {record.dt:g} s: not on the same time axis")
    if abs(record.t_start - vertical.t_start) > SAME_AXIS_RTOL * record.dt:
        raise ValueError(f"the vertical record starts at {vertical.t_start:g} s, the horizontal at "
                         f"{record.t_start:g} s: not on the same time axis")
    if vertical.npts < record.npts:
        raise ValueError(f"the vertical record has {vertical.npts} samples, fewer than the "
                         f"horizontal's {record.npts}: cut the horizontal first (pulses.check_pair)")
    if vertical.npts > record.npts:
        vertical = Record(vertical.acc[:record.npts], vertical.dt, vertical.name, vertical.t_start,
                          vertical.metadata)
    return vertical


class _Run:
    def __init__(self, block: Block, zeno_tol: float):
        self.block = block
        self.p2 = block.p ** 2
        self.theta = self.omega = 0.0
        self.s = 0.0
        self.max_abs = 0.0
        self.impacts: list[float] = []
        self.rest_until = -math.inf
        self.overturned = False
        self.t_overturn = math.nan
        self.uplifted = False
        self.lifts_off = False
        self.t_lift_off = math.nan
        self.omega_zeno = zeno_tol * block.p * block.alpha
        self.hist = []

    # -- one interval with linear u = ag/g and v = av/g --------------------------------------------
    def interval(self, ta, tb, ua, ub, va, vb, stop_at_peak=False) -> bool:
        """Carry the state over ``[ta, tb]``; False once overturned, lifted off or (``stop_at_peak``)
        past the first peak."""
        blk = self.block
        tan_a = blk.tan_alpha
        su, sv = (ub - ua) / (tb - ta), (vb - va) / (tb - ta)

        def u(t):
            return ua + su * (t - ta)

        def v(t):
            return va + sv * (t - ta)

        # free flight: 1 + v < 0 somewhere in the interval ends the model there
        end = tb
        if 1.0 + va < 0.0:
            self._lift(ta)
            return False
        if 1.0 + vb < 0.0:
            end = _linear_root(1.0 + va, 1.0 + vb, ta, tb)
        t = ta
        while t < end:
            if self.s == 0.0:
                t = max(t, self.rest_until)
                if t >= end:
                    break
                # uplift when |u| > (1 + v) tan(alpha): two linear thresholds, solved exactly
                t_up, side = math.inf, 0.0
                for sign in (1.0, -1.0):  # sign of u at uplift
                    fa = sign * u(t) - (1.0 + v(t)) * tan_a
                    fb = sign * u(end) - (1.0 + v(end)) * tan_a
                    if fa > 0.0:
                        cand = t
                    elif fb > 0.0:
                        cand = _linear_root(fa, fb, t, end)
                        cand = min(end, cand + abs(cand) * 1e-16)
                    else:
                        continue
                    if cand < t_up:
                        t_up, side = cand, -sign
                if side == 0.0:
                    break
                self.s, self.theta, self.omega, self.uplifted = side, 0.0, 0.0, True
                t = t_up
                continue
            t = self._fly(t, end, u, v, stop_at_peak)
            if t is None:
                return False
        if end < tb:
            self._lift(end)
            return False
        return True

    def _lift(self, t):
        self.lifts_off, self.t_lift_off = True, float(t)

    def _fly(self, t, end, u, v, stop_at_peak):
        """Integrate one flight (no impact inside) from ``t``; the time reached, or None when the
        run ends (overturned, or past the first peak with ``stop_at_peak``)."""
        blk, p2, s = self.block, self.p2, self.s
        alpha, eta = blk.alpha, blk.eta

        def rhs(x, y):
            d = alpha * s - y[0]
            return [y[1], -p2 * ((1.0 + v(x)) * math.sin(d) + u(x) * math.cos(d))]

        def impact(x, y):
            return y[0]

        impact.terminal, impact.direction = True, -s

        def overturn(x, y):
            return s * y[0] - HALF_PI

        overturn.terminal, overturn.direction = True, 1.0

        def peak(x, y):
            return y[1]

        peak.terminal = stop_at_peak
        peak.direction = -s  # a peak away from the base: omega passes 0 from s to -s
        first_step = None
        if self.theta == 0.0 and self.omega != 0.0:  # a hop must not end inside its first step
            a = abs(rhs(t, [0.0, 0.0])[1])
            if a > 0:
                first_step = min(end - t, 0.05 * abs(self.omega) / a)
        # imported here: rocking.solver imports this module, and scipy.integrate costs every
        # process that solves (a batch's every worker) 0.16 s or more to import
        from scipy.integrate import solve_ivp

        sol = solve_ivp(rhs, (t, end), [self.theta, self.omega], method="DOP853", rtol=RTOL, atol=ATOL,
                        events=(impact, overturn, peak), first_step=first_step)
        if sol.status == -1:
            raise RuntimeError(f"reference integration failed: {sol.message}")
        self.max_abs = max(self.max_abs, float(np.max(np.abs(sol.y[0]))))
        for y in sol.y_events[2]:
            self.max_abs = max(self.max_abs, abs(float(y[0])))
        if sol.t_events[1].size:
            self.overturned, self.t_overturn = True, float(sol.t_events[1][0])
            self.max_abs = HALF_PI
            return None
        if sol.t_events[0].size:
            x = float(sol.t_events[0][0])
            om = eta * float(sol.y_events[0][0][1])
            self.impacts.append(x)
            self.s, self.theta, self.omega = -s, 0.0, om
            if abs(om) <= self.omega_zeno:  # a Zeno sequence: summed, the block is at rest
                uu, gv = u(x), 1.0 + v(x)
                a_new = p2 * (gv * math.sin(alpha) + self.s * uu * math.cos(alpha))
                a_old = p2 * (gv * math.sin(alpha) - self.s * uu * math.cos(alpha))
                tz = 0.0
                if a_new > 0 and a_old > 0:
                    tz = 2 * abs(om) / (1 - eta ** 2) * (1 / a_new + eta / a_old)
                self.rest_until = x + tz
                self.s, self.omega = 0.0, 0.0
            return x
        if stop_at_peak and sol.t_events[2].size:
            return None
        self.theta, self.omega = float(sol.y[0, -1]), float(sol.y[1, -1])
        return end


def simulate_vertical_reference(block: Block, record: Record, vertical: Record | None = None, *,
                                duration: float | None = None,
                                zeno_tol: float = ZENO_TOL) -> VerticalRockingResult:
    """Rocking response to horizontal ``record`` and upward vertical ``vertical`` (both m/s^2).

    Parameters
    ----------
    block : Block
        The block (its ``p``, ``alpha``, ``eta``).
    record : pulses.Record
        Horizontal ground acceleration ``ag``.
    vertical : pulses.Record, optional
        Upward ground acceleration ``av`` on the same time axis (a PEER ``DWN`` file multiplied by
        -1 first: :func:`pulses.triplets.upward`); None: horizontal motion only.
    duration : float, optional
        Only the first ``duration`` seconds of the records.
    zeno_tol : float, optional
        Post-impact angular velocity (over ``p alpha``) below which the block is taken to rest.

    Returns
    -------
    VerticalRockingResult
        ``model`` is ``"reference-vertical"``; ``lifts_off`` says whether the model ended in free
        flight (``g + av < 0``) and when.

    Examples
    --------
    >>> import numpy as np, pulses, rocking
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> rec = pulses.Record(pulses.make_pulse("sine", 0.3 * pulses.G, 1.0, 2.0)(t), 0.01)
    >>> up = pulses.Record(0.2 * pulses.G * np.sin(5.0 * t), 0.01)       # upward, m/s^2
    >>> res = rocking.simulate_vertical_reference(rocking.Block.from_dimensions(7.5, 1.8), rec, up)
    >>> res.overturned, res.lifts_off
    (False, False)
    """
    uval = record.acc / G
    vval = np.zeros_like(uval) if vertical is None else check_axes(record, vertical).acc / G
    n = record.npts - 1
    if duration is not None:
        n = min(n, max(1, math.ceil(duration / record.dt - 1e-9)))
    t = record.time
    run = _Run(block, zeno_tol)
    hist = [(t[0], 0.0, 0.0)]
    alive = True
    for k in range(n):
        alive = run.interval(t[k], t[k + 1], uval[k], uval[k + 1], vval[k], vval[k + 1])
        hist.append((run.t_overturn if run.overturned else
                     (run.t_lift_off if run.lifts_off else t[k + 1]), run.theta, run.omega))
        if not alive:
            break
    verdict_by = "integration"
    if alive and run.s != 0.0:  # free rocking after the excitation, to its first peak
        end = t[n] + FREE_HORIZON_P / block.p
        run.interval(t[n], end, 0.0, 0.0, 0.0, 0.0, stop_at_peak=True)
        verdict_by = "free rocking to the first peak"
    if run.lifts_off:
        verdict_by = "lifts off"
    th, om = run.theta, run.omega
    hist.append((hist[-1][0], th, om))
    ts, ths, oms = (np.array(c) for c in zip(*hist))
    res = _result(block, run.overturned, run.max_abs, run.impacts, len(run.impacts), ts, ths, oms,
                  "reference-vertical", verdict_by, run.uplifted, run.t_overturn)
    return VerticalRockingResult(**{f: getattr(res, f) for f in res.__dataclass_fields__},
                                 lifts_off=run.lifts_off, t_lift_off=run.t_lift_off,
                                 min_effective_gravity=float(np.min(1.0 + vval[:n + 1])))
