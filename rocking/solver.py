"""``simulate`` and ``simulate_many``: the rocking response of a block to a pulse or a record.

Model only what the case needs (docs/theory.md section 2):

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

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np

from pulses import G, Pulse, Record

from . import engine
from .block import Block, Blocks
from ._common import (ZENO_TOL, BatchResult, RockingResult, _free_rocking_horizon,
                      _pulse_extrema, _result)
from .errors import RockingInputError
from .lanes import run_batch, run_lanes, run_many
from .reference_vertical import VerticalRockingResult, check_axes, simulate_vertical_reference

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
#: steps of the linearised model per pulse period (its forcing is the chord of each step)
LINEAR_STEPS_PER_TP = 4000

MODELS = ("auto", "fast", "linear", "reference")  # "auto", then the keys of MODEL_RUNNERS


# --------------------------------------------------------------------------- grids
def _pulse_pieces(pulse: Pulse, h_max: float, t_end: float | None):
    """The pieces of a pulse's grid: breakpoints and extrema ``a -> b``, each cut into ``n`` equal
    steps no longer than ``h_max``; and the grid's end time."""
    start, end = pulse.support
    if t_end is not None:
        end = min(end, t_end)
    marks = np.array(sorted({start, end, *[x for x in _pulse_extrema(pulse) if start < x < end]}))
    a, b = marks[:-1], marks[1:]
    n = np.maximum(1, np.ceil((b - a) / h_max - 1e-9)).astype(np.int64)
    return a, b, n, end


def _pulse_grid_size(pulse: Pulse, h_max: float, t_end: float | None = None) -> int:
    """Number of intervals of :func:`_pulse_grid` (without building it)."""
    return int(_pulse_pieces(pulse, h_max, t_end)[2].sum())


def _pulse_grid(pulse: Pulse, h_max: float, t_end: float | None = None, first: int = 0,
                last: int | None = None) -> np.ndarray:
    """Nodes over the pulse's support: breakpoints and extrema, subdivided into steps <= h_max;
    nodes ``first .. last`` of it only when given (a long pulse is run a part at a time)."""
    a, b, n, end = _pulse_pieces(pulse, h_max, t_end)
    total = int(n.sum())
    last = total if last is None else min(int(last), total)
    idx = np.arange(first, last)                      # every node but the last
    ends = np.cumsum(n)
    piece = np.searchsorted(ends, idx, side="right")  # piece of each node
    k = idx - (ends - n)[piece]                       # its index inside the piece
    nodes = np.empty(idx.size + 1)
    nodes[:-1] = a[piece] + (b - a)[piece] * (k / n[piece])
    if last == total:
        nodes[-1] = end
    else:
        pl = int(np.searchsorted(ends, last, side="right"))
        nodes[-1] = a[pl] + (b - a)[pl] * ((last - (ends - n)[pl]) / n[pl])
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
    #: a pulse grid too long to build at once (more than :data:`PART_INTERVALS` intervals):
    #: ``(pulse, h_max, t_end, h_longest)``, its nodes made a part at a time (``nodes`` empty)
    lazy: tuple | None = None


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
        return _pulse_grid_of(excitation, float(p_max), bool(linear), duration, float(ph_max))
    raise TypeError(f"excitation must be a pulses.Pulse or a pulses.Record, got {type(excitation).__name__}")


@functools.lru_cache(maxsize=64)
def _pulse_grid_of(excitation: Pulse, p_max: float, linear: bool, duration: float | None,
                   ph_max: float) -> _Grid:
    """The grid of a pulse (:func:`_grid`), kept for the next call with the same pulse and
    block: a search over slenderness asks for it a dozen times (the nodes are only read)."""
    empty = np.zeros(0)
    u_peak = abs(excitation.ap) / G
    p_eff = p_max * math.sqrt(1.0 + u_peak)
    if linear:
        h_max = min(excitation.tp / LINEAR_STEPS_PER_TP, 0.05 / p_eff)
    else:
        h_max = min(excitation.tp / STEPS_PER_TP, ph_max / p_eff)
    t_end = None if duration is None else excitation.support[0] + duration
    n_int = _pulse_grid_size(excitation, h_max, t_end)
    if n_int > PART_INTERVALS:
        a, b, n, _ = _pulse_pieces(excitation, h_max, t_end)
        return _Grid(excitation.kind, excitation.ap / G, excitation.tp, excitation.t0, empty,
                     empty, float(a[0]), 0.0, n_int, u_peak,
                     lazy=(excitation, h_max, t_end, float(np.max((b - a) / n))))
    nodes = _pulse_grid(excitation, h_max, t_end)
    nodes.setflags(write=False)
    return _Grid(excitation.kind, excitation.ap / G, excitation.tp, excitation.t0, empty,
                 nodes, nodes[0], 0.0, nodes.size - 1, u_peak)


# --------------------------------------------------------------------------- model choice
def linear_error_estimate(alpha: float) -> float:
    """Measured bound on the linearised model's error in ``max|theta|/alpha`` for slenderness ``alpha``.

    Examples
    --------
    >>> import rocking
    >>> round(rocking.linear_error_estimate(0.2) / rocking.linear_error_estimate(0.1), 6)   # grows as alpha^2
    4.0
    """
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
             ph_max: float | None = None, vertical: Record | None = None) -> RockingResult:
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
    vertical : pulses.Record, optional
        Upward ground acceleration (m/s^2) on the excitation's time axis (a PEER ``DWN`` file
        negated first), docs/theory.md section 10.  The compiled engine takes it (model
        ``"fast-vertical"``, Taylor steps; the result is a
        :class:`rocking.reference_vertical.VerticalRockingResult` with ``lifts_off`` and
        ``t_lift_off``: where ``g + av < 0`` the block leaves the ground and the run stops
        there); ``model="reference"`` answers with the independent reference integrator
        (:func:`rocking.simulate_vertical_reference`, ``"reference-vertical"``, slow).  Records
        only, the block starting at rest; not with ``model="linear"``.  The history ends with
        the record (a longer ``duration`` is not filled with free rocking; the verdict after the
        record is the energy rule's, as without a vertical).

    Returns
    -------
    RockingResult

    Examples
    --------
    >>> import rocking, pulses
    >>> res = rocking.simulate(rocking.Block.from_dimensions(7.5, 1.8), pulses.make_pulse("sine", 4.9, 1.0))
    >>> res.overturned, round(res.max_rotation_ratio, 2), res.model
    (False, 0.79, 'fast')
    """
    if vertical is not None:
        if not isinstance(excitation, Record) or theta0 != 0.0 or omega0 != 0.0:
            raise RockingInputError("simulate: a vertical record goes with a horizontal pulses.Record "
                                    "and the block at rest")
        if model == "reference":
            return simulate_vertical_reference(block, excitation, vertical, duration=duration,
                                               zeno_tol=zeno_tol)
        if model not in ("auto", "fast") or method != "taylor":
            raise RockingInputError("simulate: with a vertical record the model is 'fast' (Taylor "
                                    "steps) or 'reference'")
        return _simulate_vertical(block, excitation, vertical, duration, history, zeno_tol,
                                  ph_max, model, tol)
    if not isinstance(block, Block):
        raise TypeError("block must be a rocking.Block")
    for name, value in (("theta0", theta0), ("omega0", omega0)):
        if not math.isfinite(value):
            raise ValueError(f"{name} must be finite, got {value!r}")
    if abs(theta0) >= math.pi / 2:
        raise ValueError(f"theta0 must lie inside (-pi/2, pi/2), got {theta0!r}")
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be positive and finite, got {duration!r}")
    if excitation is None and theta0 == 0.0 and omega0 == 0.0:
        raise RockingInputError("simulate: no excitation and the block at rest: pass a "
                                "pulses.Pulse or pulses.Record, or theta0/omega0 for free rocking")
    if excitation is not None and not isinstance(excitation, (Pulse, Record)):
        raise RockingInputError("simulate: excitation must be a pulses.Pulse, a pulses.Record or "
                                f"None (free rocking), got {type(excitation).__name__}")
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
    return MODEL_RUNNERS[chosen](block, excitation, theta0, omega0, duration, history, zeno_tol,
                                 stepper, ph_max, peak)


def _run_fast(block, excitation, theta0, omega0, duration, history, zeno_tol, stepper, ph_max,
              peak):
    return _simulate_compiled(block, excitation, theta0, omega0, duration, False, history,
                              zeno_tol, stepper, ph_max, peak)


def _run_linear(block, excitation, theta0, omega0, duration, history, zeno_tol, stepper, ph_max,
                peak):
    return _simulate_compiled(block, excitation, theta0, omega0, duration, True, history,
                              zeno_tol, stepper, ph_max, peak)


def _run_reference(block, excitation, theta0, omega0, duration, history, zeno_tol, stepper,
                   ph_max, peak):
    from .reference import simulate_reference

    return simulate_reference(block, excitation, theta0=theta0, omega0=omega0, duration=duration,
                              zeno_tol=zeno_tol)


#: the models :func:`simulate` answers with, by name (``"auto"`` chooses among them); each takes
#: ``(block, excitation, theta0, omega0, duration, history, zeno_tol, stepper, ph_max, peak)``
#: (``stepper``: an engine method code, :data:`rocking.engine.METHODS`; ``peak``: the
#: excitation's peak acceleration, m/s^2, or None) and returns a :class:`RockingResult`
MODEL_RUNNERS = {"fast": _run_fast, "linear": _run_linear, "reference": _run_reference}


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
              stop_at_rest=False, method=engine.TAYLOR, ph_max=PH_MAX, vertical=None):
    if grid.lazy is not None:
        h = grid.lazy[3]
    else:
        h = grid.h if grid.nodes.size == 0 else float(np.max(np.diff(grid.nodes)))
    g_max = 1.0 if vertical is None else vertical[2]  # largest effective gravity over g
    n_sub = _n_sub(h, block.p * math.sqrt(g_max + grid.u_peak), 0.05 if linear else ph_max)
    if linear and grid.kind in (engine.NODAL, engine.RECT, engine.FREE):
        n_sub = 1  # exact for forcing linear on each interval
    if grid.lazy is not None or (grid.kind == engine.FREE and grid.n_int > PART_INTERVALS):
        return _run_in_parts(grid, block, theta0, omega0, linear, history, zeno_tol,
                             stop_at_rest, method, n_sub)
    size = grid.n_int + 1 if history else 0
    hist_t, hist_th, hist_om = np.empty(size), np.empty(size), np.empty(size)
    impacts = np.empty(4096)
    args = (_engine_forcing(grid), grid.uval, engine.Grid(grid.t_start, grid.h, n_sub), grid.nodes,
            grid.n_int, engine.Rocker(block.p, block.alpha, block.eta),
            engine.Settings(linear, method, zeno_tol, stop_at_rest, history),
            (hist_t, hist_th, hist_om))
    start = engine.Start(0, theta0, omega0, -math.inf)
    vert = None if vertical is None else vertical[:2]
    out = engine.run(*args, impacts, start, vert)
    status, theta, omega, t_end, max_abs, n_imp, n_hist, uplifted, _ = out
    if n_imp > impacts.size:  # rerun with room for every impact time (rare: long Zeno trains)
        impacts = np.empty(n_imp)
        out = engine.run(*args, impacts, start, vert)
        status, theta, omega, t_end, max_abs, n_imp, n_hist, uplifted, _ = out
    if history:
        hist_t, hist_th, hist_om = hist_t[:n_hist], hist_th[:n_hist], hist_om[:n_hist]
    return (status, theta, omega, t_end, max_abs, n_imp, uplifted, impacts[:n_imp],
            hist_t, hist_th, hist_om)


def _engine_forcing(grid: _Grid) -> engine.Forcing:
    """The engine's :class:`rocking.engine.Forcing` of a grid."""
    return engine.Forcing(grid.kind, grid.amp, grid.tp, grid.t0)


#: longest stretch of intervals integrated at once: longer grids (a pulse of a very long period,
#: free rocking of a block that hardly loses energy) are built and run a part at a time, so that
#: memory stays bounded (a part's nodes and history: 32 MB), and the run stops as soon as the
#: answer is known (overturned, or at rest with no forcing left that could uplift the block)
PART_INTERVALS = 1 << 20


def _can_uplift_after(grid: _Grid, t: float, tan_alpha: float) -> bool:
    """Whether the forcing after ``t`` reaches the uplift threshold anywhere."""
    if grid.lazy is None:
        return False  # free rocking: no forcing
    pulse, _, t_end, _ = grid.lazy
    start, end = pulse.support
    end = end if t_end is None else min(end, t_end)
    times = [max(t, start), end] + [x for x in _pulse_extrema(pulse) if t < x < end]
    return max(abs(float(pulse(x))) for x in times) / G > tan_alpha


def _run_in_parts(grid, block, theta0, omega0, linear, history, zeno_tol, stop_at_rest, method,
                  n_sub):
    """:func:`_run_grid` a part of :data:`PART_INTERVALS` intervals at a time, each part starting
    from the state the previous one ended in."""
    theta, omega, rest_until = theta0, omega0, -math.inf
    max_abs, uplifted, status = abs(theta0), False, engine.REST
    impacts, hists, n_imp, t_end = [], [], 0, grid.t_start
    for j0 in range(0, grid.n_int, PART_INTERVALS):
        j1 = min(j0 + PART_INTERVALS, grid.n_int)
        if grid.lazy is not None:
            pulse, h_max, t_stop, _ = grid.lazy
            nodes = _pulse_grid(pulse, h_max, t_stop, j0, j1)
            first, n_end, t_start = 0, j1 - j0, nodes[0]
        else:
            nodes, first, n_end, t_start = grid.nodes, j0, j1, grid.t_start
        size = j1 - j0 + 1 if history else 0
        hist = np.empty(size), np.empty(size), np.empty(size)
        imp = np.empty(4096)
        out = engine.run(_engine_forcing(grid), grid.uval, engine.Grid(t_start, grid.h, n_sub),
                         nodes, n_end, engine.Rocker(block.p, block.alpha, block.eta),
                         engine.Settings(linear, method, zeno_tol, stop_at_rest, history), hist,
                         imp, engine.Start(first, theta, omega, rest_until))
        status, theta, omega, t_end, mx, ni, n_hist, up, rest_until = out
        max_abs, uplifted = max(max_abs, mx), uplifted or up
        impacts.append(imp[:min(ni, imp.size)])
        n_imp += ni
        if history:
            hists.append(tuple(a[:n_hist] if not hists else a[1:n_hist] for a in hist))
        if status == engine.OVERTURNED or (stop_at_rest and status == engine.REST):
            break
        if (status == engine.REST and rest_until <= t_end
                and not _can_uplift_after(grid, t_end, block.tan_alpha)):
            # at rest, and nothing left that could move the block: the rest is known
            last = _pulse_grid(*grid.lazy[:3], grid.n_int, grid.n_int)[-1] if grid.lazy else \
                grid.t_start + grid.n_int * grid.h
            if history:
                hists.append((np.array([last]), np.zeros(1), np.zeros(1)))
            t_end = last
            break
    impacts = np.concatenate(impacts) if impacts else np.zeros(0)
    if history:
        t, th, om = (np.concatenate([h[i] for h in hists]) for i in range(3))
    else:
        t = th = om = np.zeros(0)
    return status, theta, omega, t_end, max_abs, n_imp, uplifted, impacts, t, th, om


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


def _simulate_vertical(block, record, vertical, duration, history, zeno_tol, ph_max, model, tol):
    """The compiled engine under horizontal ``record`` and upward ``vertical`` (docs/theory.md
    section 10): model ``"fast-vertical"``.  A vertical that is zero over the run is no vertical:
    the horizontal-only model answers (its result bit for bit, its ``model`` named)."""
    if not isinstance(block, Block):
        raise TypeError("block must be a rocking.Block")
    if not isinstance(vertical, Record):
        raise RockingInputError("simulate: vertical must be a pulses.Record, got "
                                f"{type(vertical).__name__}")
    if duration is not None and not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be positive and finite, got {duration!r}")
    vertical = check_axes(record, vertical)
    n = record.npts if duration is None else min(record.npts,
                                                 max(1, math.ceil(duration / record.dt - 1e-9)) + 1)
    vval = engine.as_input(vertical.acc)
    quiet, g_min, g_max, zero, u_max = engine.vertical_bounds(record.acc, vval, 1.0 / G, 1.0 / G,
                                                              block.tan_alpha, n)
    if zero:
        out = simulate(block, record, duration=duration, model=model, tol=tol, history=history,
                       zeno_tol=zeno_tol, ph_max=ph_max)
        return VerticalRockingResult(**{f: getattr(out, f) for f in out.__dataclass_fields__})
    if quiet:  # |ag| <= (g + av) tan(alpha) at every sample: no uplift, no lift-off
        start, end = record.support
        t = np.array([start, end if duration is None else start + duration]) if history else \
            np.zeros(0)
        return VerticalRockingResult(False, False, 0.0, 0.0, np.zeros(0), 0, t, np.zeros_like(t),
                                     np.zeros_like(t), "rest", "no uplift", False, block=block,
                                     min_effective_gravity=g_min)
    ph_max = PH_MAX if ph_max is None else ph_max
    grid = _grid(record, block.p, False, duration, ph_max, u_max)
    g_max = max(1.0, g_max)
    res = _run_grid(grid, block, 0.0, 0.0, False, history, zeno_tol, method=engine.TAYLOR,
                    ph_max=ph_max, vertical=(vval, 1.0 / G, g_max))
    status, theta, omega, t_end, max_abs, n_imp, uplifted, impacts, t, th, om = res
    t_over, t_lift, lifts = math.nan, math.nan, status == engine.LIFTOFF
    if status == engine.OVERTURNED:
        over, verdict_by, t_over = True, "integration", t_end
    elif lifts:
        # the block leaves the ground: the model ends there (overturned: not before it)
        over, verdict_by, t_lift = False, "lifts off", t_end
    elif status == engine.REST:
        over, verdict_by = False, "integration"
    else:  # after the records the vertical is zero: the energy rule as without it
        over, peak = engine.energy_verdict(theta, omega, block.p, block.alpha, block.eta, False)
        verdict_by = "energy rule"
        max_abs = math.pi / 2 if over else max(max_abs, peak)
    max_abs = float(max_abs)
    return VerticalRockingResult(bool(over), bool(max_abs > block.alpha), max_abs,
                                 max_abs / block.alpha, impacts, int(n_imp), t, th, om,
                                 "fast-vertical", verdict_by, bool(uplifted), float(t_over),
                                 block=block, lifts_off=lifts, t_lift_off=t_lift,
                                 min_effective_gravity=g_min)


# --------------------------------------------------------------------------- batch
#: smaller batches run one by one (the engine's own loop over a single run is tighter)
LANES_MIN_RUNS = 4


def _run_batch(g, amp, n_sub, p, alpha, eta, linear, stepper, threads=None, lanes=True,
               until_final=False):
    """The engine over a batch: runs under a record with one Taylor step per sample go through the
    batch engine in lanes (:mod:`rocking.lanes`, several runs per core at once), the rest run one
    by one (:func:`rocking.lanes.run_many`); the same model either way."""
    def one_by_one(m):
        return run_many(g.kind, amp[m], g.tp, g.t0, g.uval, g.nodes, g.t_start, g.h, g.n_int,
                        n_sub[m], p[m], alpha[m], eta[m], linear, ZENO_TOL, stepper, threads)

    def in_lanes(m):
        return run_lanes(amp[m], g.uval, g.t_start, g.h, g.n_int, p[m], alpha[m], eta[m], ZENO_TOL,
                         threads, until_final=until_final)

    use = np.zeros(p.size, dtype=bool)
    if (lanes and g.kind == engine.NODAL and g.nodes.size == 0 and not linear
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


def _batch_vertical(excitation, vertical, model, method):
    """``(vval, g_min, g_max)`` of a batch's vertical record (``av/g`` on the record's samples and
    the extremes of ``1 + av/g``), checked; None when the vertical is zero."""
    if not isinstance(excitation, Record) or not isinstance(vertical, Record):
        raise RockingInputError("simulate_many: a vertical record goes with a horizontal "
                                "pulses.Record")
    if model != "fast" or method != "taylor":
        raise RockingInputError("simulate_many: with a vertical record the model is 'fast' "
                                "with Taylor steps")
    vval = engine.as_input(check_axes(excitation, vertical).acc)
    _, g_min, g_max, zero, _ = engine.vertical_bounds(excitation.acc, vval, 1.0 / G, 1.0 / G,
                                                      0.0, excitation.npts)
    return None if zero else (vval, g_min, g_max)


def _block_arrays(blocks):
    """``(p, alpha, eta)`` arrays of a Block, a sequence of them or a :class:`rocking.Blocks`."""
    if isinstance(blocks, Blocks):
        return blocks.p, blocks.alpha, blocks.eta
    blocks = [blocks] if isinstance(blocks, Block) else list(blocks)
    return tuple(np.array([getattr(b, k) for b in blocks], dtype=float) for k in ("p", "alpha", "eta"))


def _runs(blocks, scales, grid):
    """``(p, alpha, eta, scales, shape)``: :func:`simulate_many`'s runs as flat arrays, block by
    scale (``grid``) or broadcast pairwise, and the shape its results take."""
    p, alpha, eta = _block_arrays(blocks)
    n_blocks = p.size
    scales = np.atleast_1d(np.asarray(1.0 if scales is None else scales, dtype=float))
    if not np.all(np.isfinite(scales)):
        raise ValueError("scales must be finite")
    if grid:
        shape = (p.size, scales.size)
        p, alpha, eta = (np.repeat(a, scales.size) for a in (p, alpha, eta))
        scales = np.tile(scales, n_blocks)
    else:
        p, alpha, eta, scales = np.broadcast_arrays(p, alpha, eta, scales)
        shape = p.shape
    p, alpha, eta, scales = (np.ascontiguousarray(a, dtype=float).ravel()
                             for a in (p, alpha, eta, scales))
    return p, alpha, eta, scales, shape


def simulate_many(blocks, excitation, scales=None, *, grid: bool = False,
                  model: str = "fast", method: str = "taylor",
                  threads: int | None = None, lanes: bool = True,
                  vertical: Record | None = None, until_final: bool = False) -> BatchResult:
    """Run one excitation against many blocks and/or many amplitude scalings, in compiled code.

    Parameters
    ----------
    blocks : Block, sequence of Block, or rocking.Blocks
    excitation : pulses.Pulse or pulses.Record
    scales : float or array_like, optional
        Factors on the excitation's acceleration (default 1).
    grid : bool
        False: ``blocks`` and ``scales`` broadcast pairwise (1-D result).  True: every block
        against every scale, results of shape ``(n_blocks, n_scales)``.
    model : {"fast", "linear"}
    method : {"taylor", "rk8", "rk4"}
        Stepping formula of the fast engine (see :func:`simulate`).
    threads : int, optional
        Threads sharing the batch (default ``rocking.lanes.get_threads()``: one per CPU from 256
        runs on, else 1; worker processes that already share the cores pass 1).
    lanes : bool
        False: every run one by one instead of the batch engine's lanes (the same answers).
    vertical : pulses.Record, optional
        Upward ground acceleration (m/s^2) on the record's time axis, scaled with it (docs/theory.md
        section 10): runs one by one in the compiled engine (model ``"fast-vertical"``), with
        ``lifts_off`` and ``t_lift_off``; a zero vertical is no vertical (bit for bit).
    until_final : bool
        Stop each run of the batch engine's lanes once its verdict and ``max|theta|`` can no
        longer change (what the ground can still give it, bounded by its energy; the design
        searches): the same ``overturned``, ``exceeded_alpha``, ``max_rotation`` and
        ``uplifted``, in less time; ``n_impacts`` then counts the impacts up to the stop.

    Returns
    -------
    BatchResult
        Arrays ``overturned``, ``exceeded_alpha``, ``max_rotation`` (rad), ``max_rotation_ratio``.

    Examples
    --------
    >>> import pulses, rocking
    >>> column = rocking.Block.from_dimensions(7.5, 1.8)
    >>> batch = rocking.simulate_many(column, pulses.OneSine(0.3 * pulses.G, 1.0), scales=[1, 2, 4])
    >>> batch.overturned.tolist()
    [False, True, True]
    """
    if model not in ("fast", "linear"):
        raise ValueError("simulate_many supports model='fast' or 'linear'")
    vval = None
    if vertical is not None:
        bounds = _batch_vertical(excitation, vertical, model, method)
        if bounds is None:  # a zero vertical is no vertical
            out = simulate_many(blocks, excitation, scales, grid=grid, model=model,
                                method=method, threads=threads, lanes=lanes)
            none = np.zeros(out.overturned.shape, dtype=bool)
            return dataclasses.replace(out, lifts_off=none, t_lift_off=np.full(none.shape, np.nan))
        vval, g_min, g_max = bounds
    linear = model == "linear"
    p, alpha, eta, scales, shape = _runs(blocks, scales, grid)
    stepper = _check_method(method)
    ph_max = _default_ph_max(method)
    g = _grid(excitation, float(p.max()), linear, None, ph_max)
    if g.lazy is not None:
        raise RockingInputError(
            f"simulate_many: the pulse needs {g.n_int} steps (Tp = {excitation.tp:g} s), more "
            f"than a batch holds ({PART_INTERVALS}); run its blocks one by one with simulate")
    amp = g.amp * scales
    h = g.h if g.nodes.size == 0 else float(np.max(np.diff(g.nodes)))
    g_hi = 1.0
    if vval is not None:  # the largest effective gravity of each run (the vertical scaled too)
        g_hi = np.maximum(1.0, np.maximum(1.0 + scales * (g_max - 1.0), 1.0 + scales * (g_min - 1.0)))
    p_eff = p * np.sqrt(g_hi + g.u_peak * np.abs(scales))
    n_sub = _n_sub(h, p_eff, 0.05 if linear else ph_max)
    if linear and g.kind in (engine.NODAL, engine.RECT):
        n_sub[:] = 1
    if vval is not None:
        over, max_abs, n_imp, up, t_lift = run_batch(
            False, g.kind, amp, g.tp, g.t0, g.uval, g.nodes, g.t_start, g.h, g.n_int, n_sub, p,
            alpha, eta, False, ZENO_TOL, stepper, threads, vval=vval)
        lifts = ~np.isnan(t_lift)
        return BatchResult(over.reshape(shape), (max_abs > alpha).reshape(shape),
                           max_abs.reshape(shape), (max_abs / alpha).reshape(shape),
                           n_imp.reshape(shape), up.reshape(shape), "fast-vertical",
                           lifts.reshape(shape), t_lift.reshape(shape))
    over, max_abs, n_imp, up = _run_batch(g, amp, n_sub, p, alpha, eta, linear, stepper, threads,
                                          lanes, until_final)
    ratio = max_abs / alpha
    return BatchResult(over.reshape(shape), (max_abs > alpha).reshape(shape),
                       max_abs.reshape(shape), ratio.reshape(shape), n_imp.reshape(shape),
                       up.reshape(shape), model)
