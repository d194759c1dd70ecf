"""``simulate`` and ``simulate_many``: the rocking response of a block to a pulse or a record.

Model only what the case needs (SPEC section 2):

* ``"rest"``: the ground acceleration never reaches ``g tan(alpha)``; the block never uplifts and
  nothing is integrated;
* ``"linear"``: the exact solution of the linearised equation (error grows with ``alpha``;
  ``model="auto"`` uses it only where its measured error is inside ``tol``, see
  :data:`LINEAR_ERROR_COEFF`);
* ``"fast"``: the compiled nonlinear engine (:mod:`rocking.engine`);
* ``"reference"``: adaptive DOP853 at ``rtol = 1e-12`` (:mod:`rocking.reference`), the yardstick.

After the excitation ends the energy rule decides overturning exactly, with no further
integration (unless a longer ``duration`` is asked for, to draw the free rocking).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pulses import G, Pulse, Record

from . import engine
from .block import Block
from .lanes import run_lanes

#: Accuracy knob of the fast engine: the largest ``p_eff * h`` of a step, with
#: ``p_eff = p sqrt(1 + max|ug''|/g)`` (the fastest rate of the linearised dynamics).  The Taylor
#: stepper sums its series to rounding whatever the step, but longer steps need more terms and
#: make event detection on the cubic interpolant coarser; one step per sample of any usual record
#: is far inside it.  Measured in ``benchmarks``: max|theta|/alpha agrees with the reference to
#: ~1e-10 on pulses and 1e-12 or better on records, for the Taylor and the 8th-order formula alike.
PH_MAX = 0.2
#: the same knob for the RK4 option (``method="rk4"``), which needs far smaller steps: rocking
#: responses to broadband records amplify local errors, and RK4 at one step per 200 Hz sample can
#: be off by 1e-5 in max|theta|/alpha (see benchmarks)
PH_MAX_RK4 = 0.05
#: steps per pulse period, at least (resolves the forcing of the pulse itself).  max|theta|/alpha
#: agrees with the reference to 2e-10 at 16 steps and 4e-12 at 50 (24 pulses of all shapes near
#: overturning, benchmarks/RESULTS.md section 1a), far inside the 1e-6 asked for.
STEPS_PER_TP = 16
#: ``model="auto"`` picks the linearised model when ``LINEAR_ERROR_COEFF * alpha**2 <= tol``.
#: Its error in ``max|theta|/alpha`` against the nonlinear solution grows like alpha**2; the
#: worst measured ratio error/alpha**2 is 5 on pulses (four shapes, p*Tp 0.5-8,
#: ap/(g tan alpha) 1.3-3) and 42 on long broadband records with hundreds of small impacts
#: (benchmarks, "linearised model error"); about twice the worst is used.  With the default
#: ``tol = 1e-6`` that means alpha < 1e-4: the linearised model is there for comparison and for
#: users who accept a coarser ``tol``.
LINEAR_ERROR_COEFF = 100.0
#: post-impact angular velocity, over ``p * alpha``, below which a Zeno sequence is summed
ZENO_TOL = 1e-7
#: steps of the linearised model per pulse period (its forcing is the chord of each step)
LINEAR_STEPS_PER_TP = 4000

MODELS = ("auto", "fast", "linear", "reference")


@dataclass
class RockingResult:
    """The response of one block to one excitation.

    Attributes
    ----------
    overturned : bool
        ``|theta|`` reached ``pi/2`` (during the excitation, or as the energy rule decides after).
    exceeded_alpha : bool
        ``|theta|`` exceeded ``alpha`` at some time.
    max_rotation : float
        ``max |theta|`` (rad), including the free rocking after the excitation (energy rule).
    max_rotation_ratio : float
        ``max |theta| / alpha``.
    impacts : ndarray
        Impact times (s) during the integrated part.
    n_impacts : int
        Number of impacts (the integrated part; a Zeno tail summed in closed form counts once).
    t, theta, omega : ndarray
        History at the grid nodes: time (s), rotation (rad), angular velocity (rad/s).
    model : str
        Which model answered: ``"rest"``, ``"linear"``, ``"fast"`` or ``"reference"``.
    verdict_by : str
        ``"no uplift"``, ``"integration"`` (overturned while integrating, or at rest at the end)
        or ``"energy rule"`` (decided from the state when the excitation ended).
    uplifted : bool
        The block left its rest position at least once.
    t_overturn : float
        Time (s) at which ``|theta|`` reached ``pi/2`` during the integration, else nan.
    """

    overturned: bool
    exceeded_alpha: bool
    max_rotation: float
    max_rotation_ratio: float
    impacts: np.ndarray
    n_impacts: int
    t: np.ndarray
    theta: np.ndarray
    omega: np.ndarray
    model: str
    verdict_by: str
    uplifted: bool
    t_overturn: float = math.nan
    block: Block | None = field(default=None, repr=False)

    def summary(self) -> dict:
        """Scalar results as a plain dict (for JSON and CSV)."""
        return {
            "overturned": bool(self.overturned),
            "exceeded_alpha": bool(self.exceeded_alpha),
            "max_rotation_rad": float(self.max_rotation),
            "max_rotation_ratio": float(self.max_rotation_ratio),
            "n_impacts": int(self.n_impacts),
            "uplifted": bool(self.uplifted),
            "t_overturn_s": None if math.isnan(self.t_overturn) else float(self.t_overturn),
            "model": self.model,
            "verdict_by": self.verdict_by,
        }


@dataclass
class BatchResult:
    """Scalar results of :func:`simulate_many`, one array entry per run."""

    overturned: np.ndarray
    exceeded_alpha: np.ndarray
    max_rotation: np.ndarray
    max_rotation_ratio: np.ndarray
    n_impacts: np.ndarray
    uplifted: np.ndarray
    model: str


# --------------------------------------------------------------------------- grids
def _pulse_extrema(pulse: Pulse) -> list[float]:
    """Times (s) of the extrema of the pulse's acceleration inside its support."""
    if pulse.shape == "sine":
        taus = [0.25, 0.75]
    elif pulse.shape == "ricker-sym":
        x = math.sqrt(1.5) / math.pi
        taus = [-x, 0.0, x]
    elif pulse.shape == "ricker-anti":
        c = math.sqrt(3.0) / (2.0 * math.pi)
        taus = [sgn * math.sqrt(3.0 + d * math.sqrt(6.0)) * c for sgn in (-1, 1) for d in (-1, 1)]
    else:
        taus = []
    return [pulse.t0 + tau * pulse.tp for tau in taus]


def _pulse_grid(pulse: Pulse, h_max: float, t_end: float | None = None) -> np.ndarray:
    """Nodes over the pulse's support: breakpoints and extrema, subdivided into steps <= h_max."""
    start, end = pulse.support
    if t_end is not None:
        end = min(end, t_end)
    marks = np.array(sorted({start, end, *[x for x in _pulse_extrema(pulse) if start < x < end]}))
    a, b = marks[:-1], marks[1:]
    n = np.maximum(1, np.ceil((b - a) / h_max - 1e-9)).astype(np.int64)
    piece = np.repeat(np.arange(n.size), n)  # piece of each node but the last
    k = np.arange(piece.size) - np.repeat(np.cumsum(n) - n, n)  # its index inside the piece
    nodes = np.empty(piece.size + 1)
    nodes[:-1] = a[piece] + (b - a)[piece] * (k / n[piece])
    nodes[-1] = end
    return nodes


def _n_sub(h: float, p_eff: np.ndarray | float, ph_max: float) -> np.ndarray | int:
    """Sub-steps per interval of length ``h`` so that ``p_eff h / n_sub <= ph_max`` (a float
    ``p_eff`` takes scalar arithmetic, without numpy's overhead: the same numbers)."""
    if isinstance(p_eff, float):
        return max(1, math.ceil(h * p_eff / ph_max - 1e-9))
    return np.maximum(1, np.ceil(h * np.asarray(p_eff) / ph_max - 1e-9)).astype(np.int64)


@dataclass
class _Grid:
    kind: int
    amp: float
    tp: float
    t0: float
    uval: np.ndarray
    nodes: np.ndarray
    t_start: float
    h: float
    n_int: int
    u_peak: float  # max |ug''|/g over the excitation (before scaling)


def _grid(excitation, p_max: float, linear: bool, duration: float | None,
          ph_max: float = PH_MAX, pga: float | None = None) -> _Grid:
    empty = np.zeros(0)
    if isinstance(excitation, Record):
        n_int = excitation.npts - 1
        if duration is not None:
            n_int = min(n_int, max(1, math.ceil(duration / excitation.dt - 1e-9)))
        # node values in m/s^2, scaled by 1/g in the engine
        pga = excitation.pga if pga is None else pga
        return _Grid(engine.NODAL, 1.0 / G, 1.0, 0.0, excitation.acc, empty, excitation.t_start,
                     excitation.dt, n_int, pga / G)
    if isinstance(excitation, Pulse):
        u_peak = abs(excitation.ap) / G
        p_eff = p_max * math.sqrt(1.0 + u_peak)
        if linear:
            h_max = min(excitation.tp / LINEAR_STEPS_PER_TP, 0.05 / p_eff)
        else:
            h_max = min(excitation.tp / STEPS_PER_TP, ph_max / p_eff)
        t_end = None if duration is None else excitation.support[0] + duration
        nodes = _pulse_grid(excitation, h_max, t_end)
        return _Grid(excitation.kind, excitation.ap / G, excitation.tp, excitation.t0, empty,
                     nodes, nodes[0], 0.0, nodes.size - 1, u_peak)
    raise TypeError(f"excitation must be a pulses.Pulse or a pulses.Record, got {type(excitation).__name__}")


# --------------------------------------------------------------------------- model choice
def linear_error_estimate(alpha: float) -> float:
    """Measured bound on the linearised model's error in ``max|theta|/alpha`` for slenderness ``alpha``."""
    return LINEAR_ERROR_COEFF * alpha**2


def _choose_model(model: str, block: Block, tol: float) -> str:
    if model not in MODELS:
        raise ValueError(f"model must be one of {', '.join(MODELS)}; got {model!r}")
    if model != "auto":
        return model
    return "linear" if linear_error_estimate(block.alpha) <= tol else "fast"


# --------------------------------------------------------------------------- simulate
def simulate(block: Block, excitation=None, *, theta0: float = 0.0, omega0: float = 0.0,
             duration: float | None = None, model: str = "auto", tol: float = 1e-6,
             history: bool = True, zeno_tol: float = ZENO_TOL, method: str = "taylor",
             ph_max: float | None = None) -> RockingResult:
    """Rocking response of ``block`` to ``excitation``.

    Parameters
    ----------
    block : Block
    excitation : pulses.Pulse, pulses.Record or None
        Ground acceleration (m/s^2).  ``None``: free rocking from ``theta0``, ``omega0``.
    theta0, omega0 : float
        Initial rotation (rad) and angular velocity (rad/s) at the start of the excitation.
    duration : float, optional
        Length of history wanted (s, from the start of the excitation).  Shorter than the
        excitation: the excitation is cut there.  Longer: the free rocking after it is integrated
        too (the verdict is the energy rule's either way).  For free rocking without a duration the
        motion is followed until the block is at rest or overturns.
    model : {"auto", "fast", "linear", "reference"}
        ``"auto"``: no integration if the block never uplifts, the linearised model if its
        measured error (:func:`linear_error_estimate`) is within ``tol``, else ``"fast"``.
    tol : float
        Accepted error in ``max|theta|/alpha`` for ``model="auto"``.
    history : bool
        Keep ``t``, ``theta``, ``omega`` (set False to save memory on very long records).
    zeno_tol : float
        Post-impact ``|omega| / (p alpha)`` below which a Zeno sequence is summed in closed form.
    method : {"taylor", "rk8", "rk4"}
        Fast engine only: how each step is taken.  ``"taylor"`` (default): the Taylor series of
        the solution, summed to rounding level (exact to rounding for forcing linear over the
        step, and its polynomial locates impacts and peaks); ``"rk8"``: the 8th-order
        Dormand-Prince formula; ``"rk4"``: classical RK4 (both for comparison, see benchmarks).
    ph_max : float, optional
        Fast engine only: largest ``p_eff * h`` of a step (default :data:`PH_MAX`, or
        :data:`PH_MAX_RK4` for ``method="rk4"``); smaller means more sub-steps per sample.

    Returns
    -------
    RockingResult
    """
    if not isinstance(block, Block):
        raise TypeError("block must be a rocking.Block")
    for name, value in (("theta0", theta0), ("omega0", omega0)):
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value!r}")
    if abs(theta0) >= math.pi / 2:
        raise ValueError(f"theta0 must lie inside (-pi/2, pi/2), got {theta0!r}")
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be positive and finite, got {duration!r}")
    stepper = _check_method(method)
    if ph_max is None:
        ph_max = _default_ph_max(method)
    chosen = _choose_model(model, block, tol)
    at_rest = theta0 == 0.0 and omega0 == 0.0
    peak = None
    if excitation is not None:
        # a record's pga (m/s^2) in one compiled pass (numpy's abs then max: ~6 us on 4000 samples)
        peak = engine.abs_max(excitation.acc) if isinstance(excitation, Record) else abs(excitation.ap)
    if excitation is not None and at_rest and model in ("auto", "fast", "linear"):
        if peak / G <= block.tan_alpha:
            return _never_uplifts(block, excitation, duration, history)
    if chosen == "reference":
        from .reference import simulate_reference

        return simulate_reference(block, excitation, theta0=theta0, omega0=omega0,
                                  duration=duration, zeno_tol=zeno_tol)
    return _simulate_compiled(block, excitation, theta0, omega0, duration, chosen == "linear",
                              history, zeno_tol, stepper, ph_max, peak)


def _check_method(method: str) -> int:
    if method not in engine.METHODS:
        raise ValueError(f"method must be one of {', '.join(engine.METHODS)}; got {method!r}")
    return engine.METHODS[method]


def _default_ph_max(method: str) -> float:
    return PH_MAX_RK4 if method == "rk4" else PH_MAX


def _never_uplifts(block, excitation, duration, history):
    start, end = excitation.support
    if duration is not None:
        end = start + duration
    t = np.array([start, end]) if history else np.zeros(0)
    zeros = np.zeros_like(t)
    return RockingResult(False, False, 0.0, 0.0, np.zeros(0), 0, t, zeros, zeros.copy(), "rest",
                         "no uplift", False, block=block)


def _run_grid(grid: _Grid, block: Block, theta0, omega0, linear, history, zeno_tol,
              stop_at_rest=False, method=engine.TAYLOR, ph_max=PH_MAX):
    h = grid.h if grid.nodes.size == 0 else float(np.max(np.diff(grid.nodes)))
    n_sub = _n_sub(h, block.p * math.sqrt(1.0 + grid.u_peak), 0.05 if linear else ph_max)
    if linear and grid.kind in (engine.NODAL, engine.RECT, engine.FREE):
        n_sub = 1  # exact for forcing linear on each interval
    size = grid.n_int + 1 if history else 0
    hist_t, hist_th, hist_om = np.empty(size), np.empty(size), np.empty(size)
    impacts = np.empty(4096)
    out = engine.run(grid.kind, grid.amp, grid.tp, grid.t0, grid.uval, grid.nodes, grid.t_start,
                     grid.h, grid.n_int, n_sub, block.p, block.alpha, block.eta, theta0, omega0,
                     linear, zeno_tol, stop_at_rest, hist_t, hist_th, hist_om, impacts, history,
                     method)
    status, theta, omega, t_end, max_abs, n_imp, n_hist, uplifted = out
    if n_imp > impacts.size:  # rerun with room for every impact time (rare: long Zeno trains)
        impacts = np.empty(n_imp)
        out = engine.run(grid.kind, grid.amp, grid.tp, grid.t0, grid.uval, grid.nodes,
                         grid.t_start, grid.h, grid.n_int, n_sub, block.p, block.alpha, block.eta,
                         theta0, omega0, linear, zeno_tol, stop_at_rest, hist_t, hist_th, hist_om,
                         impacts, history, method)
        status, theta, omega, t_end, max_abs, n_imp, n_hist, uplifted = out
    if history:
        hist_t, hist_th, hist_om = hist_t[:n_hist], hist_th[:n_hist], hist_om[:n_hist]
    return (status, theta, omega, t_end, max_abs, n_imp, uplifted, impacts[:n_imp],
            hist_t, hist_th, hist_om)


#: ``p * h`` of the free-rocking grid (no forcing to resolve; RK4 energy drift ~1e-12 per cycle)
PH_FREE = 0.005


def _free_grid(block: Block, t_start: float, length: float, h_hint: float | None) -> _Grid:
    h = PH_FREE / block.p if h_hint is None else min(h_hint, PH_FREE / block.p)
    n = max(1, math.ceil(length / h - 1e-9))
    return _Grid(engine.FREE, 0.0, 1.0, 0.0, np.zeros(0), np.zeros(0), t_start, length / n, n, 0.0)


def _simulate_compiled(block, excitation, theta0, omega0, duration, linear, history, zeno_tol,
                       method=engine.TAYLOR, ph_max=PH_MAX, peak=None):
    name = "linear" if linear else "fast"
    if excitation is None:
        # free rocking: the energy rule already knows the verdict; integrate for the history
        over, peak = engine.energy_verdict(theta0, omega0, block.p, block.alpha, block.eta, linear)
        length = duration if duration is not None else _free_rocking_horizon(block)
        grid = _free_grid(block, 0.0, length, None)
        res = _run_grid(grid, block, theta0, omega0, linear, history, zeno_tol,
                        stop_at_rest=duration is None, method=method, ph_max=ph_max)
        status, theta, omega, t_end, max_abs, n_imp, uplifted, impacts, t, th, om = res
        if status == engine.OVERTURNED:
            over, verdict_by, t_over = True, "integration", t_end
        else:
            verdict_by, t_over = "energy rule", math.nan
            if status == engine.REST:
                verdict_by = "integration"
        max_abs = math.pi / 2 if over else max(max_abs, peak if status != engine.REST else 0.0)
        return _result(block, over, max_abs, impacts, n_imp, t, th, om, name, verdict_by,
                       uplifted or theta0 != 0 or omega0 != 0, t_over)

    grid = _grid(excitation, block.p, linear, duration, ph_max, peak)
    res = _run_grid(grid, block, theta0, omega0, linear, history, zeno_tol,
                    method=method, ph_max=ph_max)
    status, theta, omega, t_end, max_abs, n_imp, uplifted, impacts, t, th, om = res
    t_over = math.nan
    if status == engine.OVERTURNED:
        over, verdict_by, t_over = True, "integration", t_end
    elif status == engine.REST:
        over, verdict_by = False, "integration"
    else:
        over, peak = engine.energy_verdict(theta, omega, block.p, block.alpha, block.eta, linear)
        verdict_by = "energy rule"
        max_abs = math.pi / 2 if over else max(max_abs, peak)
    start, end = excitation.support
    if duration is not None and start + duration > t_end + 1e-12 and status != engine.OVERTURNED:
        # free rocking after the excitation, for the history only (the verdict stands)
        h_hint = excitation.dt if isinstance(excitation, Record) else excitation.tp / 50
        free = _free_grid(block, t_end, start + duration - t_end, h_hint)
        res2 = _run_grid(free, block, theta, omega, linear, history, zeno_tol,
                         method=method, ph_max=ph_max)
        status2, _, _, t_end2, max2, n2, _, imp2, t2, th2, om2 = res2
        if status2 == engine.OVERTURNED:
            t_over = t_end2
        if not over:
            max_abs = max(max_abs, max2)
        impacts = np.concatenate([impacts, imp2])
        n_imp += n2
        if history:
            t, th, om = (np.concatenate([a, b[1:]]) for a, b in ((t, t2), (th, th2), (om, om2)))
    return _result(block, over, max_abs, impacts, n_imp, t, th, om, name, verdict_by, uplifted,
                   t_over)


def _free_rocking_horizon(block: Block) -> float:
    """An upper bound (s) on how long free rocking lasts before it comes to rest.

    Each half-cycle lasts less than ``~ (2/p) * acosh(...)``; with the energy falling by ``r`` at
    every impact, ``log(zeno)/log(r)`` impacts reach the Zeno threshold.  Generous by design:
    ``stop_at_rest`` ends the integration as soon as the block settles.
    """
    n_impacts = math.log(ZENO_TOL) / math.log(max(block.eta, 1e-3)) + 10 if block.eta > 0 else 10
    return min(50.0 / block.p * n_impacts, 1e7 / block.p)


def _result(block, over, max_abs, impacts, n_imp, t, th, om, model, verdict_by, uplifted, t_over):
    max_abs = float(max_abs)
    return RockingResult(bool(over), bool(max_abs > block.alpha), max_abs, max_abs / block.alpha,
                         np.asarray(impacts, dtype=float), int(n_imp), t, th, om, model,
                         verdict_by, bool(uplifted), float(t_over), block=block)


# --------------------------------------------------------------------------- batch
#: smaller batches run one by one (the engine's own loop over a single run is tighter)
LANES_MIN_RUNS = 4


def _run_batch(g, amp, n_sub, p, alpha, eta, linear, stepper):
    """The engine over a batch: runs under a record with one Taylor step per sample go through the
    batch engine (:mod:`rocking.lanes`, several runs per core at once), the rest run one by one
    (:func:`rocking.engine.run_many`); the same model either way."""
    def one_by_one(m):
        return engine.run_many(g.kind, amp[m], g.tp, g.t0, g.uval, g.nodes, g.t_start, g.h,
                               g.n_int, n_sub[m], p[m], alpha[m], eta[m], linear, ZENO_TOL, stepper)

    def in_lanes(m):
        return run_lanes(amp[m], g.uval, g.t_start, g.h, g.n_int, p[m], alpha[m], eta[m], ZENO_TOL,
                         parallel=p[m].size >= engine.PARALLEL_MIN_RUNS)

    use = np.zeros(p.size, dtype=bool)
    if (g.kind == engine.NODAL and g.nodes.size == 0 and not linear
            and stepper == engine.TAYLOR and p.size >= LANES_MIN_RUNS):
        use = n_sub == 1
    if not use.any():
        return one_by_one(slice(None))
    if use.all():
        return in_lanes(slice(None))
    out = tuple(np.empty(p.size, dtype=d) for d in (np.bool_, float, np.int64, np.bool_))
    for m, fn in ((use, in_lanes), (~use, one_by_one)):
        for o, r in zip(out, fn(m)):
            o[m] = r
    return out


def simulate_many(blocks, excitation, scales=None, *, grid: bool = False,
                  model: str = "fast", method: str = "taylor") -> BatchResult:
    """Run one excitation against many blocks and/or many amplitude scalings, in compiled code.

    Parameters
    ----------
    blocks : Block or sequence of Block
    excitation : pulses.Pulse or pulses.Record
    scales : float or array_like, optional
        Factors on the excitation's acceleration (default 1).
    grid : bool
        False: ``blocks`` and ``scales`` broadcast pairwise (1-D result).  True: every block
        against every scale, results of shape ``(n_blocks, n_scales)``.
    model : {"fast", "linear"}
    method : {"taylor", "rk8", "rk4"}
        Stepping formula of the fast engine (see :func:`simulate`).

    Returns
    -------
    BatchResult
        Arrays ``overturned``, ``exceeded_alpha``, ``max_rotation`` (rad),
        ``max_rotation_ratio``, ``n_impacts``, ``uplifted``.
    """
    if model not in ("fast", "linear"):
        raise ValueError("simulate_many supports model='fast' or 'linear'")
    linear = model == "linear"
    blocks = [blocks] if isinstance(blocks, Block) else list(blocks)
    p = np.array([b.p for b in blocks], dtype=float)
    alpha = np.array([b.alpha for b in blocks], dtype=float)
    eta = np.array([b.eta for b in blocks], dtype=float)
    scales = np.atleast_1d(np.asarray(1.0 if scales is None else scales, dtype=float))
    if not np.all(np.isfinite(scales)):
        raise ValueError("scales must be finite")
    if grid:
        shape = (p.size, scales.size)
        p, alpha, eta = (np.repeat(a, scales.size) for a in (p, alpha, eta))
        scales = np.tile(scales, len(blocks))
    else:
        p, alpha, eta, scales = np.broadcast_arrays(p, alpha, eta, scales)
        shape = p.shape
    p, alpha, eta, scales = (np.ascontiguousarray(a, dtype=float).ravel()
                             for a in (p, alpha, eta, scales))
    stepper = _check_method(method)
    ph_max = _default_ph_max(method)
    g = _grid(excitation, float(p.max()), linear, None, ph_max)
    amp = g.amp * scales
    h = g.h if g.nodes.size == 0 else float(np.max(np.diff(g.nodes)))
    p_eff = p * np.sqrt(1.0 + g.u_peak * np.abs(scales))
    n_sub = _n_sub(h, p_eff, 0.05 if linear else ph_max)
    if linear and g.kind in (engine.NODAL, engine.RECT):
        n_sub[:] = 1
    over, max_abs, n_imp, up = _run_batch(g, amp, n_sub, p, alpha, eta, linear, stepper)
    ratio = max_abs / alpha
    return BatchResult(over.reshape(shape), (max_abs > alpha).reshape(shape),
                       max_abs.reshape(shape), ratio.reshape(shape), n_imp.reshape(shape),
                       up.reshape(shape), model)
