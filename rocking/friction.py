"""The friction a rocking response needs (docs/theory.md, "Friction"): Housner's model lets the
block rock on its base but never slide, which holds only while the base's friction can carry the
horizontal force the rocking asks of it.

With the centre of mass at ``(x, z)`` from the pivot (``x = -s R sin(phi)``, ``z = R cos(phi)``,
``phi = alpha - |theta|``, ``s = sgn(theta)``) the base carries ``F_x = m (ug'' + x'')`` and
``F_z = m (g + uv'' + z'')``; with ``d = s alpha - theta``

    x'' = R (theta'' cos d + theta'^2 sin d),     z'' = R (theta'' sin d - theta'^2 cos d),

and ``theta''`` from the equation of motion at each instant (exactly, no finite difference).  At
rest ``theta'' = 0`` and the demand is ``|ug''| / (g + uv'')``.  Rocking without sliding needs
``mu >= |F_x| / F_z`` at every instant and ``F_z > 0``.  At an impact the ratio of the horizontal to
the vertical impulse is ``(1 - eta) / ((1 + eta) tan(alpha))`` (kinematics of the two pivots: any
body, any ``eta``, and a rocking frame with the frame's ``eta``).  For a rocking frame the beam
moves with the column tops (twice the centre of mass's motion), so each column's base carries
``(1 + gamma) m ug'' + (1 + 2 gamma) m x''`` and likewise vertically; the beam's seat on the
columns needs friction too, which is not checked here.

The demand is evaluated at every instant of the response's history, at both sides of each impact
(the state just before it integrated from the history's last instant before it), and between
the history's instants by quintic Hermite interpolation of the rotation, so that a peak between
two samples is not missed.

Examples
--------
>>> import pulses, rocking
>>> column = rocking.Block.from_dimensions(7.5, 1.8)
>>> pulse = pulses.Rectangular(0.5 * pulses.G, 1.0)
>>> need = rocking.friction_demand(rocking.simulate(column, pulse), pulse)
>>> round(need.uplift_demand, 4), round(need.impulse_ratio, 4)      # Shenton 1996: 0.3022
(0.3022, 0.1774)
>>> need.judge(0.25).slides, need.judge(0.6).slides
(True, False)
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pulses import G, Pulse, Record

#: points between two instants of the history at which the demand is also evaluated (quintic
#: Hermite interpolation of theta: its error ~ (p h)^6 / 1e4 of alpha, far below 1e-9)
SUBPOINTS = 4
#: RK4 steps from the history's last instant before an impact to the impact, at least, and the
#: largest ``p h`` of a step (error ~ (p h)^5 of the motion: 1e-10 at 0.01)
IMPACT_STEPS, IMPACT_PH = 2, 0.01


def impulse_ratio(eta: float, alpha: float) -> float:
    """Horizontal over vertical impulse at an impact, ``(1 - eta) / ((1 + eta) tan(alpha))``.

    Examples
    --------
    >>> import rocking
    >>> column = rocking.Block.from_dimensions(7.5, 1.8)
    >>> round(rocking.friction.impulse_ratio(column.eta, column.alpha), 4)
    0.1774
    """
    return (1.0 - eta) / ((1.0 + eta) * math.tan(alpha))


def uplift_demand(block, a: float, gravity: float = 1.0) -> float:
    """The friction needed at the instant the block at rest uplifts under a ground acceleration of
    ``a`` g (``|a| > gravity tan(alpha)``; ``gravity``: ``1 + uv''/g``), as
    :func:`friction_demand` evaluates it: Shenton's (1996) ``(a - q cos alpha) / (1 + q sin
    alpha)``, ``q = R theta''/g``, for the rectangular block.  Below uplift: ``|a| / gravity``.

    Examples
    --------
    >>> import math, rocking
    >>> block = rocking.Block.from_tan_alpha(1.0, 0.25)
    >>> round(rocking.friction.uplift_demand(block, 0.4), 4)
    0.2865
    """
    a = abs(float(a))
    if a <= gravity * block.tan_alpha:
        return a / gravity
    fx, fz = _forces(_Body.of(block), np.array([0.0]), np.array([0.0]), np.array([-a]),
                     np.array([float(gravity)]), np.array([1.0]))
    return float(abs(fx[0]) / fz[0])


@dataclass(frozen=True)
class _Body:
    """What the base forces need of a block: ``p``, ``alpha``, ``R/g`` of one column (s^2) and
    the frame's factors ``(1 + gamma, 1 + 2 gamma)``."""

    p: float
    alpha: float
    rg: float
    f1: float
    f2: float

    @classmethod
    def of(cls, block) -> "_Body":
        gamma = float(block.cap_mass_ratio)
        size = block.R * ((1.0 + 2.0 * gamma) / (1.0 + 3.0 * gamma) if gamma else 1.0)
        return cls(block.p, block.alpha, size / G, 1.0 + gamma, 1.0 + 2.0 * gamma)


def _forces(body: _Body, theta, omega, u, ge, s):
    """``(F_x, F_z)`` over ``m g`` (a frame's per column, over its own weight times ``1 + gamma``
    in ``F_z``'s first term) where the block rocks on side ``s`` (+-1) or rests (``s = 0``)."""
    d = body.alpha * s - theta
    sd, cd = np.sin(d), np.cos(d)
    thdd = np.where(s == 0.0, 0.0, -body.p**2 * (ge * sd + u * cd))
    w2 = np.where(s == 0.0, 0.0, omega * omega)
    fx = body.f1 * u + body.f2 * body.rg * (thdd * cd + w2 * sd)
    fz = body.f1 * ge + body.f2 * body.rg * (thdd * sd - w2 * cd)
    return fx, fz


def _side(theta, omega, u, ge, tan_alpha):
    """The side each state rocks on: ``sgn(theta)``; at ``theta = 0`` the way it moves, or where at
    rest, the side it uplifts to (``-sgn(u)``) if ``|u| > ge tan(alpha)``, else 0 (rest)."""
    s = np.sign(theta)
    moving = (s == 0.0) & (omega != 0.0)
    s[moving] = np.sign(omega[moving])
    still = (s == 0.0) & (np.abs(u) > ge * tan_alpha)
    s[still] = -np.sign(u[still])
    return s


class _Forcing:
    """``u = ug''/g`` and ``ge = 1 + uv''/g`` at any time, as the solver saw them: a record linear
    between samples (zero outside), a pulse by its shape over its closed support."""

    def __init__(self, excitation, vertical=None):
        self.excitation, self.vertical = excitation, vertical
        self._time = excitation.time if isinstance(excitation, Record) else None
        self._vtime = None if vertical is None else vertical.time
        # a record's samples over g, as Python floats: one value at a time is then cheap
        self._lists = None
        same_axis = vertical is None or (
            isinstance(excitation, Record) and vertical.npts == excitation.npts
            and (vertical.t_start, vertical.dt) == (excitation.t_start, excitation.dt))
        if isinstance(excitation, Record) and same_axis:
            v = None if vertical is None else (vertical.acc / G).tolist()
            self._lists = (float(excitation.t_start), float(excitation.dt),
                           (excitation.acc / G).tolist(), v)

    def at(self, x: float) -> tuple[float, float]:
        """``(u, ge)`` at one time ``x`` (s), as :meth:`u` and :meth:`ge` give them."""
        if self._lists is None:
            return float(self.u(x)), float(self.ge(x))
        t0, dt, acc, vert = self._lists
        f = (x - t0) / dt
        k = int(math.floor(f))
        if k < 0 or k > len(acc) - 1 or (k == len(acc) - 1 and f > k):
            return 0.0, 1.0
        if k == len(acc) - 1:
            return acc[k], 1.0 + (vert[k] if vert is not None else 0.0)
        w = f - k
        u = acc[k] + w * (acc[k + 1] - acc[k])
        ge = 1.0 if vert is None else 1.0 + vert[k] + w * (vert[k + 1] - vert[k])
        return u, ge

    def u(self, t):
        t = np.asarray(t, dtype=float)
        ex = self.excitation
        if ex is None:
            return np.zeros_like(t)
        if isinstance(ex, Record):
            return np.interp(t, self._time, ex.acc, left=0.0, right=0.0) / G
        start, end = ex.support
        inside = (t >= start) & (t <= end)
        return np.where(inside, ex.ap * ex.unit((t - ex.t0) / ex.tp), 0.0) / G

    def ge(self, t):
        t = np.asarray(t, dtype=float)
        v = self.vertical
        if v is None:
            return np.ones_like(t)
        return 1.0 + np.interp(t, self._vtime, v.acc, left=0.0, right=0.0) / G

    def instants(self) -> np.ndarray:
        """The forcing's own instants: a record's samples, a pulse's extrema and ends."""
        ex = self.excitation
        if ex is None:
            return np.zeros(0)
        if isinstance(ex, Record):
            return ex.time
        return np.array(sorted({*ex.support, *ex.extrema}), dtype=float)

    def jumps(self) -> list[float]:
        """Times where the forcing jumps (a rectangular pulse's end): its right-hand value there
        is an instant of its own."""
        ex = self.excitation
        if isinstance(ex, Pulse) and getattr(ex, "boxcar", False):
            return [ex.support[1]]
        return []


@dataclass
class FrictionDemand:
    """The friction a response needs: ``|F_x| / F_z`` at every instant evaluated.

    Attributes
    ----------
    t, demand, normal, rocking : ndarray
        Times (s, ascending; an impact's instant twice, before and after), the demand
        ``|F_x| / F_z``, the normal force ``F_z`` over the weight ``m g`` and whether the block
        rocks there (False: at rest).
    max_demand, t_max : float
        The largest demand (rocking, resting and impacts' impulses together) and when (s).
    rocking_max : float
        The largest ``|F_x| / F_z`` of the continuous motion (rocking and rest), without the
        impulses.
    min_normal, t_min_normal : float
        The smallest normal force over the weight, and when (at or below 0 the base lets go: the
        block leaves the ground, which the model does not describe).
    uplift_demand, t_uplift : float
        The demand at the first uplift from rest (Shenton's closed form for the rectangular
        block) and when; nan where the block never uplifts from rest.
    impulse_ratio : float
        Horizontal over vertical impulse of every impact, ``(1 - eta)/((1 + eta) tan(alpha))``.
    impacts : ndarray
        Impact times (s): where :attr:`impulse_ratio` is asked of the base.
    body, restitution : str
        Which model answered: the body's shape and ``eta``.

    Examples
    --------
    >>> import pulses, rocking
    >>> column = rocking.Block.from_dimensions(7.5, 1.8)
    >>> pulse = pulses.OneSine(0.5 * pulses.G, 1.0)
    >>> need = rocking.friction_demand(rocking.simulate(column, pulse), pulse)
    >>> round(need.max_demand, 3), need.body, need.t.shape == need.demand.shape
    (0.3, 'rectangular', True)
    """

    t: np.ndarray = field(repr=False)
    demand: np.ndarray = field(repr=False)
    normal: np.ndarray = field(repr=False)
    rocking: np.ndarray = field(repr=False)
    max_demand: float
    t_max: float
    rocking_max: float
    min_normal: float
    t_min_normal: float
    uplift_demand: float
    t_uplift: float
    impulse_ratio: float
    impacts: np.ndarray = field(repr=False)
    body: str = "rectangular"
    restitution: str = ""

    def judge(self, mu: float) -> "FrictionCheck":
        """The verdict with a friction coefficient ``mu``: where the demand exceeds it the column
        slides, outside the model (:class:`FrictionCheck`)."""
        return FrictionCheck.of(self, mu)

    def to_frame(self):
        """``t_s``, ``demand``, ``normal_over_weight``: one row per instant evaluated."""
        import pandas as pd

        return pd.DataFrame({"t_s": self.t, "demand": self.demand, "normal_over_weight": self.normal})

    def as_dict(self) -> dict:
        """The scalar results (plain, JSON-safe)."""
        from pulses.export import plain

        keys = ("max_demand", "t_max", "rocking_max", "min_normal", "t_min_normal",
                "uplift_demand", "t_uplift", "impulse_ratio", "body", "restitution")
        return plain({k: getattr(self, k) for k in keys} | {"n_impacts": int(self.impacts.size)})


@dataclass(frozen=True)
class FrictionCheck:
    """Whether a response stays inside the model with friction coefficient ``mu``.

    ``slides``: the demand exceeds ``mu`` at some instant (``t_slide``, the first; ``how``:
    ``"rocking"``, ``"at rest"`` or ``"at an impact"``); ``lifts_off``: the normal force reaches 0.

    Examples
    --------
    >>> import pulses, rocking
    >>> column = rocking.Block.from_dimensions(7.5, 1.8)
    >>> pulse = pulses.Rectangular(0.5 * pulses.G, 1.0)
    >>> check = rocking.friction_demand(rocking.simulate(column, pulse), pulse).judge(0.3)
    >>> check.slides, check.how, check.describe()
    (True, 'rocking', 'slides at 0 s, rocking (mu 0.3)')
    """

    mu: float
    slides: bool
    t_slide: float
    how: str
    lifts_off: bool
    max_demand: float

    @classmethod
    def of(cls, need: FrictionDemand, mu: float) -> "FrictionCheck":
        mu = check_mu(mu)
        over = np.flatnonzero((need.demand > mu) | (need.normal <= 0.0))
        t_slide, how = math.inf, ""
        if over.size:
            t_slide = float(need.t[over[0]])
            how = "rocking" if need.rocking[over[0]] else "at rest"
        if need.impacts.size and need.impulse_ratio > mu and need.impacts[0] < t_slide:
            t_slide, how = float(need.impacts[0]), "at an impact"
        slides = math.isfinite(t_slide)
        return cls(mu, slides, t_slide if slides else math.nan, how, bool(need.min_normal <= 0.0),
                   need.max_demand)

    def describe(self) -> str:
        """Plain words for a row: ``no sliding (mu 0.6)`` or ``slides at 1.23 s, rocking (mu 0.3)``."""
        if not self.slides:
            return f"no sliding (mu {self.mu:g})"
        return f"slides at {self.t_slide:.4g} s, {self.how} (mu {self.mu:g})"


def check_mu(mu) -> float:
    """A friction coefficient as a float, or a one-line ValueError (finite, > 0)."""
    try:
        value = float(mu)
    except (TypeError, ValueError):
        raise ValueError(f"friction: mu must be a number, got {mu!r}") from None
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"friction: mu must be positive and finite, got {mu!r}")
    return value


# --------------------------------------------------------------------------- the demand
_EMPTY = tuple(np.zeros(0) for _ in range(7))

def friction_demand(result, excitation=None, *, vertical: Record | None = None) -> FrictionDemand:
    """The friction coefficient the response ``result`` needs, over time (module docstring).

    Parameters
    ----------
    result : RockingResult
        A response of :func:`rocking.simulate` kept with its history (``history=True``, the
        default); its ``block`` says the body, ``p``, ``alpha``, ``eta`` and frame.
    excitation : pulses.Pulse or pulses.Record, optional
        The ground acceleration that ``result`` answered (None: free rocking).
    vertical : pulses.Record, optional
        The upward vertical acceleration, where the response had one (``g`` becomes ``g + uv''``).

    Returns
    -------
    FrictionDemand

    Examples
    --------
    >>> import pulses, rocking
    >>> drum = rocking.Block.from_dimensions(7.5, 1.8, body="cylinder")
    >>> pulse = pulses.Rectangular(0.6 * pulses.G, 1.0)
    >>> need = rocking.friction_demand(rocking.simulate(drum, pulse), pulse)
    >>> round(need.uplift_demand, 4), round(need.min_normal, 3)
    (0.3239, 0.867)
    """
    block = getattr(result, "block", None)
    t = np.asarray(getattr(result, "t", ()), dtype=float)
    if block is None or t.size < 2:
        raise ValueError("friction_demand: a response with its history and block "
                         "(rocking.simulate(..., history=True))")
    body, forcing = _Body.of(block), _Forcing(excitation, vertical)
    theta, omega = np.asarray(result.theta, dtype=float), np.asarray(result.omega, dtype=float)
    impacts = np.sort(np.asarray(result.impacts, dtype=float))
    if result.overturned:   # falling: up to its last instant within alpha (then it topples)
        within = np.flatnonzero(np.abs(theta) <= block.alpha)
        n = max(2, int(within[-1]) + 1 if within.size else 2)
        t, theta, omega = t[:n], theta[:n], omega[:n]
        impacts = impacts[impacts <= t[-1]]
    nodes = _Nodes(t, theta, omega, forcing, block.tan_alpha)
    parts = [nodes.instants(), *nodes.between(body, impacts), nodes.jump_instants(forcing)]
    events, uplifts = _events(body, block, nodes, forcing, impacts)
    parts += events
    tt, th, om, uu, gg, ss, order = (np.concatenate([p[i] for p in parts]) for i in range(7))
    fx, fz = _forces(body, th, om, uu, gg, ss)
    idx = np.lexsort((order, tt))
    tt, fx, fz, ss = tt[idx], fx[idx], fz[idx], ss[idx]
    with np.errstate(divide="ignore", invalid="ignore"):
        demand = np.where(fz > 0.0, np.abs(fx) / fz, np.inf)
    normal = fz / body.f1
    ratio = impulse_ratio(block.eta, block.alpha)
    k, j = int(np.argmax(demand)), int(np.argmin(normal))
    top, t_top = float(demand[k]), float(tt[k])
    if impacts.size and ratio > top:
        top, t_top = ratio, float(impacts[0])
    up_t, up_d = (math.nan, math.nan)
    if uplifts:
        first = min(uplifts)
        up_t, up_d = first
    return FrictionDemand(tt, demand, normal, ss != 0.0, top, t_top, float(demand[k]),
                          float(normal[j]), float(tt[j]), float(up_d), float(up_t), ratio, impacts,
                          block.body.describe(), f"eta {block.eta:.6g}")


class _Nodes:
    """The history's instants with their forcing, side and rest flags."""

    def __init__(self, t, theta, omega, forcing, tan_alpha):
        self.t, self.theta, self.omega, self.tan_alpha = t, theta, omega, tan_alpha
        self._forcing = forcing
        self.u, self.ge = forcing.u(t), forcing.ge(t)
        self.rest = (theta == 0.0) & (omega == 0.0)
        self.s = _side(theta, omega, self.u, self.ge, tan_alpha)

    def instants(self):
        n = self.t.size
        return self.t, self.theta, self.omega, self.u, self.ge, self.s, np.zeros(n)

    def jump_instants(self, forcing):
        """The right-hand side of every jump of the forcing at a node."""
        out = []
        for tj in forcing.jumps():
            for i in np.flatnonzero(self.t == tj).tolist():
                ge = float(forcing.ge(tj))
                s = _side(self.theta[i:i + 1], self.omega[i:i + 1], np.zeros(1), np.array([ge]),
                          self.tan_alpha)[0]
                out.append((tj, self.theta[i], self.omega[i], 0.0, ge, s, 3.0))
        return tuple(np.array(v, dtype=float) for v in zip(*out)) if out else _EMPTY

    def between(self, body: _Body, impacts):
        """Sub-points of the intervals without an event: quintic Hermite interpolation of theta
        where the block rocks at both ends on one side, the forcing alone where it rests."""
        t, th, om, s = self.t, self.theta, self.omega, self.s
        hit = np.zeros(t.size - 1, dtype=bool)
        if impacts.size:
            k = np.searchsorted(t, impacts, side="left") - 1
            hit[k[(k >= 0) & (k < hit.size)]] = True
        moving = ~self.rest
        smooth = (~hit & moving[:-1] & moving[1:] & (np.sign(th[:-1]) * np.sign(th[1:]) >= 0)
                  & (s[:-1] == s[1:]) & (s[:-1] != 0.0))
        still = ~hit & self.rest[:-1] & self.rest[1:]
        return [self._hermite(body, np.flatnonzero(smooth)), self._still(np.flatnonzero(still))]

    def _taus(self, k):
        tau = np.arange(1, SUBPOINTS + 1) / (SUBPOINTS + 1.0)
        h = (self.t[k + 1] - self.t[k])[:, None]
        return tau[None, :], h, (self.t[k][:, None] + h * tau[None, :])

    def _hermite(self, body, k):
        tau, h, tt = self._taus(k)
        acc = -body.p**2 * (self.ge * np.sin(body.alpha * self.s - self.theta)
                            + self.u * np.cos(body.alpha * self.s - self.theta))
        y0, y1 = self.theta[k][:, None], self.theta[k + 1][:, None]
        v0, v1 = h * self.omega[k][:, None], h * self.omega[k + 1][:, None]
        a0, a1 = h * h * acc[k][:, None], h * h * acc[k + 1][:, None]
        t2, t3, t4, t5 = tau**2, tau**3, tau**4, tau**5
        th = ((1 - 10 * t3 + 15 * t4 - 6 * t5) * y0 + (tau - 6 * t3 + 8 * t4 - 3 * t5) * v0
              + 0.5 * (t2 - 3 * t3 + 3 * t4 - t5) * a0 + (10 * t3 - 15 * t4 + 6 * t5) * y1
              + (-4 * t3 + 7 * t4 - 3 * t5) * v1 + 0.5 * (t3 - 2 * t4 + t5) * a1)
        dth = ((-30 * t2 + 60 * t3 - 30 * t4) * y0 + (1 - 18 * t2 + 32 * t3 - 15 * t4) * v0
               + 0.5 * (2 * tau - 9 * t2 + 12 * t3 - 5 * t4) * a0
               + (30 * t2 - 60 * t3 + 30 * t4) * y1 + (-12 * t2 + 28 * t3 - 15 * t4) * v1
               + 0.5 * (3 * t2 - 8 * t3 + 5 * t4) * a1) / h
        s = np.broadcast_to(self.s[k][:, None], th.shape)
        return self._pack(tt, th, dth, s, 1.0)

    def _still(self, k):
        """Sub-points of intervals at rest: the forcing's own instants inside them (a record's
        samples, a pulse's extrema) besides the evenly spaced ones."""
        _, _, tt = self._taus(k)
        own = self._forcing.instants()
        j = np.searchsorted(self.t, own, side="right") - 1
        inside = (j >= 0) & (j < self.t.size - 1) & (own > self.t[np.clip(j, 0, None)])
        mask = np.zeros(self.t.size - 1, dtype=bool)
        mask[k] = True
        tt = np.concatenate([tt.ravel(), own[inside][mask[j[inside]]]])
        zero = np.zeros_like(tt)
        return self._pack(tt, zero, zero, zero, 1.0)

    def _pack(self, tt, th, om, s, order):
        forcing = self._forcing
        u, ge = forcing.u(tt.ravel()), forcing.ge(tt.ravel())
        s = np.array(s, dtype=float).ravel()
        return (tt.ravel(), np.asarray(th).ravel(), np.asarray(om).ravel(), u, ge, s,
                np.full(u.size, order))


def _events(body: _Body, block, nodes: _Nodes, forcing: _Forcing, impacts):
    """The instants of the intervals with an event (an impact, an uplift from rest): integrated
    from the history's instant before it (RK4, :func:`_stretch`), both sides of
    each impact; and the uplifts ``[(t, demand)]``."""
    from ._common import ZENO_TOL

    t, rows, uplifts = nodes.t, [], []
    for i in np.flatnonzero(nodes.rest & (nodes.s != 0.0)).tolist():
        uplifts.append((float(t[i]), _demand(body, 0.0, 0.0, nodes.u[i], nodes.ge[i], nodes.s[i])))
    k_imp = np.searchsorted(t, impacts, side="left") - 1
    starts = nodes.rest[:-1] & ~nodes.rest[1:]
    todo = sorted(set(k_imp[(k_imp >= 0) & (k_imp < t.size - 1)].tolist())
                  | set(np.flatnonzero(starts).tolist()))
    zeno = ZENO_TOL * block.p * block.alpha
    for k in todo:
        here = impacts[k_imp == k]
        state = _start(body, nodes, forcing, k, here[0] if here.size else t[k + 1], uplifts)
        if state is None:
            continue
        for ti in here.tolist():
            state = _stretch(body, forcing, state, ti, rows, 1.0)
            om = block.eta * state[2]
            rows.append((ti, 0.0, om, *_uf(forcing, ti), -state[3], 2.0))
            if abs(om) <= zeno:
                state = None
                break
            state = (ti, 0.0, om, -state[3])
        if state is not None and state[0] < t[k + 1]:
            _stretch(body, forcing, state, t[k + 1], rows, 1.0, last=False)
    out = tuple(np.array(v, dtype=float) for v in zip(*rows)) if rows else _EMPTY
    return [out], uplifts


def _uf(forcing, x):
    return forcing.at(float(x))


def _demand(body, theta, omega, u, ge, s) -> float:
    fx, fz = _forces(body, *(np.array([float(v)]) for v in (theta, omega, u, ge, s)))
    return float(abs(fx[0]) / fz[0]) if fz[0] > 0.0 else math.inf


def _start(body, nodes, forcing, k, t_next, uplifts):
    """``(t, theta, omega, s)`` the block leaves instant ``k`` of the history with: its state, or
    where it rests there, the uplift inside the interval (appended to ``uplifts``); None where it
    does not uplift before ``t_next``."""
    t0 = float(nodes.t[k])
    if not nodes.rest[k]:
        return t0, float(nodes.theta[k]), float(nodes.omega[k]), float(nodes.s[k])
    if nodes.s[k] != 0.0:
        return t0, 0.0, 0.0, float(nodes.s[k])
    tan_a = nodes.tan_alpha
    f = lambda x: abs(float(forcing.u(x))) - float(forcing.ge(x)) * tan_a   # noqa: E731
    lo, hi = t0, float(t_next)
    if f(hi) <= 0.0:
        return None
    for _ in range(60):   # bisection to rounding: the uplift threshold's crossing
        mid = 0.5 * (lo + hi)
        if f(mid) > 0.0:
            hi = mid
        else:
            lo = mid
    u, ge = _uf(forcing, hi)
    s = -math.copysign(1.0, u)
    uplifts.append((hi, _demand(body, 0.0, 0.0, u, ge, s)))
    return hi, 0.0, 0.0, s


def _stretch(body, forcing, state, t_end, rows, order, last=True):
    """RK4 from ``state`` to ``t_end`` on its side (steps of ``p h`` up to :data:`IMPACT_PH`, at
    twice ``p`` for the forcing's share), each step's state appended to ``rows`` (the end's too
    where ``last``); the state at ``t_end``."""
    t, th, om, s = state
    steps = max(IMPACT_STEPS, math.ceil(2.0 * body.p * (t_end - t) / IMPACT_PH))
    h = (t_end - t) / steps
    p2, alpha = body.p**2, body.alpha

    def acc(x, y):
        u, ge = _uf(forcing, x)
        d = alpha * s - y
        return -p2 * (ge * math.sin(d) + u * math.cos(d))

    for i in range(steps):
        k1t, k1w = om, acc(t, th)
        k2t, k2w = om + 0.5 * h * k1w, acc(t + 0.5 * h, th + 0.5 * h * k1t)
        k3t, k3w = om + 0.5 * h * k2w, acc(t + 0.5 * h, th + 0.5 * h * k2t)
        k4t, k4w = om + h * k3w, acc(t + h, th + h * k3t)
        th += h / 6.0 * (k1t + 2 * k2t + 2 * k3t + k4t)
        om += h / 6.0 * (k1w + 2 * k2w + 2 * k3w + k4w)
        t = t_end if i == steps - 1 else t + h
        if last or i < steps - 1:
            rows.append((t, th, om, *_uf(forcing, t), s, order))
    return t, th, om, s
