"""Design of free-standing rocking columns (SPEC section 5; Makris & Vassiliou 2012, Section 5).

Closed forms
    :func:`eq31` (the paper's design rule), :func:`eq20` (the dimensional-argument form) and
    :func:`envelope_rule` (a conservative closed form derived here from the exact answers).
Exact answers (time-history analysis with the batch solver)
    :func:`min_slenderness` (Fig. 8), :func:`critical_amplitudes` (the overturning intervals and
    safe islands of Fig. 5) and :func:`required_width` (sizing a column of given height).

Overturning is not monotonic in either the amplitude or the slenderness, so every exact answer is
found by a scan fine enough to see the islands (denser just above the highest failure) followed by
bracketed refinement of every verdict change found (vectorised: all brackets of all problems are
cut together, one batch-solver call per step).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pulses import G, make_pulse

from .block import Block
from .frame import check_cap_mass_ratio, frame_p

#: failure criteria: which verdict of the solver counts as failure
CRITERIA = ("overturn", "exceed")
#: default number of uniformly spaced scan points (plus a geometric tail towards zero)
N_SCAN = 64
#: geometric tail below the uniform scan: the smallest uniform point divided by 2, 4, ... 2**N_TAIL
N_TAIL = 10
#: default relative width of the refined brackets
RTOL = 1e-9


# ---------------------------------------------------------------------------------------------
# closed forms
# ---------------------------------------------------------------------------------------------
def _out(value):
    value = np.asarray(value, dtype=float)
    return float(value) if value.ndim == 0 else value


def eq31(ap, tp, p):
    """Eq. 31, the paper's design rule: ``tan(alpha_min) = (ap/g) p Tp / (1 + p Tp)``.

    Parameters
    ----------
    ap : float or array
        Pulse acceleration amplitude, m/s^2 (its sign is irrelevant).
    tp : float or array
        Pulse period, s.
    p : float or array
        Frequency parameter of the block, rad/s.

    Returns the minimum ``tan(alpha)`` (float, or array when any input is an array).
    Rinaldi (0.71 g, 0.8 s, p = 1.381 rad/s) gives 0.373.
    """
    x = np.asarray(p, dtype=float) * np.asarray(tp, dtype=float)
    return _out(np.abs(np.asarray(ap, dtype=float)) / G * x / (1.0 + x))


def eq20(ap, tp, p, lam=1.0):
    """Eq. 20: ``tan(alpha_min) = (ap/g) (1 - exp(-lam p Tp))`` (``ap`` in m/s^2)."""
    x = np.asarray(p, dtype=float) * np.asarray(tp, dtype=float)
    return _out(np.abs(np.asarray(ap, dtype=float)) / G * -np.expm1(-float(lam) * x))


#: The envelope rule, per shape: ``("hill", n, c)`` for ``phi = x^n / (c + x^n)`` (Eq. 31 is
#: ``n = c = 1``) or ``("exp", lam)`` for Eq. 20's ``phi = 1 - exp(-lam x)``, with ``x = pTp``
#: and ``tan(alpha_min) = (ap/g) phi``.  ``None``: every realisable shape (one-sine, symmetric
#: and antisymmetric Ricker) at once.  Derived by ``python -m rocking.envelope`` from 3240 exact
#: minimum slenderness values (pTp 0.1-20 log-spaced, ap/g 0.1-1.5): for each exponent n the
#: largest conservative c, divided by 1.01 and rounded down; the n with the smallest median
#: over-design kept.  Checked on an offset grid (README "Design").
ENVELOPE = {
    None: ("hill", 2.5, 1.86),
    "sine": ("hill", 2.5, 1.86),
    "ricker-sym": ("hill", 1.75, 4.0),
    "ricker-anti": ("hill", 3.0, 5.13),
    "rect": ("exp", 2.0),
}
#: range over which the envelope was derived and checked conservative
ENVELOPE_RANGE = {"pTp": (0.1, 20.0), "ap/g": (0.1, 1.5)}


def envelope_rule(ap, tp, p, shape=None):
    """Conservative closed form derived from the exact answers (``rule="envelope"``).

    ``tan(alpha_min) = (ap/g) (pTp)^n / (c + (pTp)^n)``, a generalised Eq. 31 (which is
    ``n = c = 1``), with ``n = 2.5, c = 1.86`` for every realisable pulse (``shape=None``, the
    default: one-sine, symmetric and antisymmetric Ricker).  A shape name gives that shape's own
    coefficients (:data:`ENVELOPE`); the rectangular pulse, which is not realisable, takes Eq. 20's
    form with ``lambda = 2``.  Never above ``ap/g`` (no uplift).

    Valid over :data:`ENVELOPE_RANGE` (``0.1 <= pTp <= 20``, ``0.1 <= ap/g <= 1.5``) with ``eta``
    from Eq. 5: there it is never below the exact minimum slenderness (smallest margin 1 %), while
    its over-design is at most about 3x for ``pTp >= 1`` (Eq. 31 is up to 9 % short for the
    one-sine pulse and up to 33 % for the rectangular pulse).  For ``pTp < 1`` it is far above the
    exact answer of the Rickers, which barely rock such large blocks.
    """
    if shape not in ENVELOPE:
        raise ValueError(f"envelope_rule: unknown shape {shape!r}; choose one of "
                         f"{', '.join(str(s) for s in ENVELOPE)}")
    x = np.asarray(p, dtype=float) * np.asarray(tp, dtype=float)
    form = ENVELOPE[shape]
    if form[0] == "hill":
        _, n, c = form
        xn = x**n
        phi = xn / (c + xn)
    else:
        phi = -np.expm1(-form[1] * x)
    return _out(np.abs(np.asarray(ap, dtype=float)) / G * phi)


# ---------------------------------------------------------------------------------------------
# the batch solver, and the generic transition finder
# ---------------------------------------------------------------------------------------------
def _batch(blocks, excitation, scales=None, *, grid=False, model="fast"):
    """Call :func:`rocking.simulate_many` (looked up at call time: the solver is a sibling module)."""
    import rocking

    if model in ("fast", "linear"):
        return rocking.simulate_many(blocks, excitation, scales, grid=grid, model=model)
    # any other model (the slow "reference" yardstick): one simulate() per run
    blocks = [blocks] if isinstance(blocks, Block) else list(blocks)
    scales = np.atleast_1d(np.asarray(1.0 if scales is None else scales, dtype=float))
    if grid:
        shape = (len(blocks), scales.size)
        pairs = [(b, s) for b in blocks for s in scales]
    else:
        idx_b, idx_s = np.broadcast_arrays(np.arange(len(blocks)), np.arange(scales.size))
        shape = idx_b.shape
        pairs = [(blocks[i], scales[j]) for i, j in zip(idx_b.ravel(), idx_s.ravel())]
    runs = [rocking.simulate(b, excitation.scaled(float(s)), model=model, history=False)
            for b, s in pairs]

    class _Result:
        pass

    res = _Result()
    for name in ("overturned", "exceeded_alpha", "max_rotation", "max_rotation_ratio"):
        res.__dict__[name] = np.array([getattr(r, name) for r in runs]).reshape(shape)
    return res


def _failed(result, criterion):
    if criterion == "overturn":
        return np.asarray(result.overturned, dtype=bool)
    return np.asarray(result.exceeded_alpha, dtype=bool) | np.asarray(result.overturned, dtype=bool)


def _check_criterion(criterion):
    if criterion not in CRITERIA:
        raise ValueError(f"criterion must be one of {CRITERIA}, got {criterion!r}")


def _peak(excitation) -> float:
    """Peak absolute ground acceleration of a pulse or a record, m/s^2."""
    if hasattr(excitation, "pga"):
        return float(excitation.pga)
    return abs(float(excitation.ap))


@dataclass
class _Scan:
    """Outcome of a scan-and-refine over many independent 1-D problems."""

    brackets: list         # per problem: list of (lo, hi, fail_lo, fail_hi), refined, ascending
    runs: int              # number of solver runs
    calls: int             # number of batch-solver calls


#: top zone of the scan: above the highest failing point found, ``ZONE_POINTS`` more points over
#: ``ZONE_FRACTION`` of its value, repeated while failures keep turning up in the zone's upper
#: half (at most ``ZONE_ROUNDS`` times).  Failure slivers just above the main boundary (long
#: pulses) are thinner than the coarse step; ``python benchmarks/bench_design.py --brute`` checks
#: the result against a 3000-point brute-force scan (agreement 5e-4 relative on 240 hard cases).
ZONE_FRACTION = 0.15
ZONE_POINTS = 160
ZONE_ROUNDS = 4
#: points per bracket per refinement step (k-section: fewer batch calls than bisection)
KSECTION = 8


def _scan_refine(evaluate, x, known=None, rtol=RTOL, zone=True, refine="all", n_zone=None,
                 max_iter=100, ksection=KSECTION):
    """Scan every problem on its abscissae ``x`` and refine every verdict change.

    ``evaluate(idx, xs)`` returns the failure verdicts of problems ``idx`` at abscissae ``xs``
    (1-D arrays of equal length) in one batch.  ``known`` is an optional boolean mask of scan
    points whose verdict is known to be "survive" without running (e.g. above the uplift limit).
    With ``zone`` the region just above each problem's highest failing point is scanned densely
    (``n_zone`` points, default :data:`ZONE_POINTS`, see :data:`ZONE_FRACTION`).  Brackets are
    then cut in :data:`KSECTION` parts per step, all together, until narrower than ``rtol``
    relative; where a step reveals more than one change inside a bracket the highest is followed
    (so the top fail-to-survive transition is always the highest one found).  ``refine="top"``
    refines only each problem's top fail-to-survive bracket (``pipeline run``, which needs only
    the answer); the other changes are then reported at scan resolution.  ``ksection=2``
    (bisection) needs about half the runs of the default in twice as many batch calls: cheaper
    when only a few problems are refined at once.
    """
    n_zone = ZONE_POINTS if n_zone is None else int(n_zone)
    x = np.asarray(x, dtype=float)
    n_prob, n_pts = x.shape
    fail = np.zeros(x.shape, dtype=bool)
    run = np.ones(x.shape, dtype=bool) if known is None else ~np.asarray(known, dtype=bool)
    idx, col = np.nonzero(run)
    runs, calls = int(idx.size), 0
    if idx.size:
        fail[idx, col] = evaluate(idx, x[idx, col])
        calls += 1
    xs = [x[i] for i in range(n_prob)]
    fs = [fail[i] for i in range(n_prob)]
    if zone:
        top = x[:, -1]
        todo = [i for i in range(n_prob) if fs[i].any()]
        prev = {i: -np.inf for i in todo}
        for _ in range(ZONE_ROUNDS):
            pi, px = [], []
            for i in todo:
                xf = xs[i][np.nonzero(fs[i])[0][-1]]
                hi = min(top[i], xf * (1.0 + ZONE_FRACTION))
                z = xf + (hi - xf) * np.arange(1, n_zone + 1) / n_zone
                z = z[z < top[i]]
                prev[i] = (xf, hi)
                pi.append(np.full(z.size, i))
                px.append(z)
            if not pi:
                break
            pi, px = np.concatenate(pi), np.concatenate(px)
            if not px.size:
                break
            pf = np.asarray(evaluate(pi, px), dtype=bool)
            runs += int(px.size)
            calls += 1
            nxt = []
            for i in todo:
                sel = pi == i
                xx = np.concatenate([xs[i], px[sel]])
                ff = np.concatenate([fs[i], pf[sel]])
                order = np.argsort(xx, kind="stable")
                xs[i], fs[i] = xx[order], ff[order]
                xf0, hi = prev[i]
                new_top = xs[i][np.nonzero(fs[i])[0][-1]]
                if new_top > xf0 + 0.5 * (hi - xf0) and hi < top[i]:
                    nxt.append(i)
            todo = nxt
    # brackets: every change of verdict between neighbouring scan points
    prob, lo, hi, flo, fhi = [], [], [], [], []
    for i in range(n_prob):
        ch = np.nonzero(fs[i][1:] != fs[i][:-1])[0]
        prob.extend([i] * ch.size)
        lo.extend(xs[i][ch]), hi.extend(xs[i][ch + 1])
        flo.extend(fs[i][ch]), fhi.extend(fs[i][ch + 1])
    prob, lo, hi = np.array(prob, dtype=int), np.array(lo, dtype=float), np.array(hi, dtype=float)
    flo, fhi = np.array(flo, dtype=bool), np.array(fhi, dtype=bool)
    if refine == "top":
        # only the last fail->survive change of each problem; the rest stay at scan resolution
        top_mask = np.zeros(prob.size, dtype=bool)
        for i in np.unique(prob):
            cand = np.nonzero((prob == i) & flo & ~fhi)[0]
            if cand.size:
                top_mask[cand[-1]] = True
        rough = ~top_mask
        done_p, done_lo, done_hi = [prob[rough]], [lo[rough]], [hi[rough]]
        done_flo, done_fhi = [flo[rough]], [fhi[rough]]
        prob, lo, hi, flo, fhi = prob[top_mask], lo[top_mask], hi[top_mask], flo[top_mask], fhi[top_mask]
    else:
        done_p, done_lo, done_hi, done_flo, done_fhi = [], [], [], [], []
    k = int(ksection)
    frac = np.arange(1, k) / k
    for _ in range(max_iter):
        narrow = (hi - lo) <= rtol * np.abs(hi)
        done_p.append(prob[narrow]), done_lo.append(lo[narrow]), done_hi.append(hi[narrow])
        done_flo.append(flo[narrow]), done_fhi.append(fhi[narrow])
        keep = ~narrow
        prob, lo, hi, flo, fhi = prob[keep], lo[keep], hi[keep], flo[keep], fhi[keep]
        if not prob.size:
            break
        mids = lo[:, None] + (hi - lo)[:, None] * frac[None, :]          # (n, k-1)
        vm = np.asarray(evaluate(np.repeat(prob, k - 1), mids.ravel()), dtype=bool)
        runs += int(vm.size)
        calls += 1
        pts = np.concatenate([lo[:, None], mids, hi[:, None]], axis=1)   # (n, k+1)
        ver = np.concatenate([flo[:, None], vm.reshape(-1, k - 1), fhi[:, None]], axis=1)
        change = ver[:, 1:] != ver[:, :-1]                              # (n, k)
        bi = np.arange(prob.size)
        bj = (k - 1) - np.argmax(change[:, ::-1], axis=1)               # highest change
        lo, hi = pts[bi, bj], pts[bi, bj + 1]
        flo, fhi = ver[bi, bj], ver[bi, bj + 1]
    cat = lambda parts, dt: np.concatenate(parts).astype(dt) if parts else np.zeros(0, dt)
    prob, lo, hi = cat(done_p + [prob], int), cat(done_lo + [lo], float), cat(done_hi + [hi], float)
    flo, fhi = cat(done_flo + [flo], bool), cat(done_fhi + [fhi], bool)
    order = np.lexsort((lo, prob))
    brackets = [[] for _ in range(n_prob)]
    for m in order:
        brackets[prob[m]].append((float(lo[m]), float(hi[m]), bool(flo[m]), bool(fhi[m])))
    return _Scan(brackets=brackets, runs=runs, calls=calls)


def _scan_points(top, n_scan, n_tail=N_TAIL):
    """Scan abscissae on ``(0, top]``: a geometric tail towards 0, then ``n_scan`` uniform points."""
    top = np.asarray(top, dtype=float)[:, None]
    uniform = np.arange(1, n_scan + 1) / n_scan
    tail = uniform[0] * 2.0 ** -np.arange(n_tail, 0, -1)
    return top * np.concatenate([tail, uniform])[None, :]


# ---------------------------------------------------------------------------------------------
# exact minimum slenderness (Fig. 8)
# ---------------------------------------------------------------------------------------------
@dataclass
class MinSlenderness:
    """Exact minimum slenderness of a block of frequency parameter ``p`` under one excitation.

    Attributes
    ----------
    tan_alpha : float
        Smallest ``tan(alpha)`` for which the block survives at that slenderness and at every
        larger one (the upper, surviving end of the top refined bracket); 0 when no scanned
        slenderness failed.
    transitions : tuple of float
        Every ``tan(alpha)`` where the verdict changes, ascending (refined to ``rtol``).
    p : float
        Frequency parameter, rad/s.
    criterion : str
        ``"overturn"`` or ``"exceed"`` (|theta| passing alpha counts as failure).
    eq31 : float or None
        Eq. 31 for the same pulse and ``p`` (None for a record).
    uplift : float
        ``peak/g``: blocks at least this stocky never uplift (the upper end of the scan).
    runs : int
        Solver runs used.
    """

    tan_alpha: float
    transitions: tuple
    p: float
    criterion: str
    eq31: float | None
    uplift: float
    runs: int
    excitation: object = field(default=None, repr=False)
    #: for each transition: does the block fail just above it?
    fails_above: tuple = ()

    @property
    def alpha(self) -> float:
        """``atan(tan_alpha)``, rad."""
        return math.atan(self.tan_alpha)

    @property
    def safe_islands(self) -> list:
        """``(low, high)`` ranges of ``tan(alpha)`` below :attr:`tan_alpha` where the block survives."""
        t, up = list(self.transitions), list(self.fails_above)
        return [(t[i], t[i + 1]) for i in range(len(t) - 1) if not up[i] and up[i + 1]]


def _unit_pulse(shape, tp):
    return make_pulse(shape, 1.0, tp)


def min_slenderness_batch(shape, p_tp, ap_over_g, *, criterion="overturn", n_scan=N_SCAN,
                          n_zone=None, rtol=RTOL, model="fast", refine="all", ksection=KSECTION,
                          cap_mass_ratio=0.0):
    """Exact minimum slenderness for many ``(pTp, ap/g)`` points of one pulse shape at once.

    By the similarity law (SPEC section 4) the answer depends only on ``pTp`` and ``ap/g``, so
    every point is solved with ``Tp = 1 s`` and ``p = pTp``; all scans share one batch-solver call
    and all brackets are refined together.  Returns a list of :class:`MinSlenderness`.

    ``refine="top"`` refines only the transition that decides ``tan_alpha`` (the others, and so
    :attr:`MinSlenderness.safe_islands`, stay at scan resolution) and ``ksection=2`` refines by
    bisection: the same ``tan_alpha`` (to ``rtol``) from fewer runs, which is what
    ``pipeline run`` needs for a few blocks per record.  ``cap_mass_ratio``: a rocking frame
    (``p_tp`` is then the frame's ``p`` times ``Tp``; its ``eta`` at each slenderness).
    """
    _check_criterion(criterion)
    gamma = check_cap_mass_ratio(cap_mass_ratio)
    p_tp = np.atleast_1d(np.asarray(p_tp, dtype=float)).ravel()
    ap_over_g = np.atleast_1d(np.asarray(ap_over_g, dtype=float)).ravel()
    p_tp, ap_over_g = np.broadcast_arrays(p_tp, ap_over_g)
    if np.any(p_tp <= 0) or np.any(ap_over_g <= 0):
        raise ValueError("pTp and ap/g must be positive")
    pulse = _unit_pulse(shape, 1.0)
    scales = ap_over_g * G
    top = ap_over_g.copy()
    x = _scan_points(top, n_scan)
    known = np.zeros(x.shape, dtype=bool)
    known[:, -1] = True            # tan(alpha) = ap/g: never uplifts

    def evaluate(idx, tans):
        blocks = [Block(float(p_tp[i]), math.atan(t), cap_mass_ratio=gamma)
                  for i, t in zip(idx, tans)]
        return _failed(_batch(blocks, pulse, scales[idx], model=model), criterion)

    scan = _scan_refine(evaluate, x, known=known, rtol=rtol, zone=n_zone != 0, n_zone=n_zone,
                        refine=refine, ksection=ksection)
    out = []
    for i in range(p_tp.size):
        br = scan.brackets[i]
        transitions = tuple(0.5 * (lo + hi) for lo, hi, _, _ in br)
        tan_alpha = 0.0
        for lo, hi, flo, fhi in br:
            if flo and not fhi:
                tan_alpha = hi          # keep the last fail->survive change (brackets ascend)
        out.append(MinSlenderness(
            tan_alpha=tan_alpha, transitions=transitions, p=float(p_tp[i]), criterion=criterion,
            eq31=float(eq31(scales[i], 1.0, p_tp[i])), uplift=float(top[i]),
            runs=scan.runs if p_tp.size == 1 else 0, excitation=None,
            fails_above=tuple(fhi for _, _, _, fhi in br)))
    return out


def min_slenderness(pulse, p, *, criterion="overturn", n_scan=N_SCAN, n_zone=None, rtol=RTOL,
                    model="fast", cap_mass_ratio=0.0):
    """Exact minimum slenderness (SPEC section 5, the paper's Fig. 8).

    The smallest ``tan(alpha)`` for which a block of frequency parameter ``p`` survives
    ``pulse`` at that slenderness and at every larger one.  ``tan(alpha)`` is scanned on
    ``(0, peak/g]`` (``n_scan`` uniform points plus a geometric tail towards 0; a block with
    ``tan(alpha) >= peak/g`` never uplifts) and *every* change of verdict is refined by bisection
    to ``rtol`` relative, so overturning ranges above safe islands are not missed.

    Parameters
    ----------
    pulse : pulses.Pulse or pulses.Record
        The excitation (its amplitude in m/s^2).  For a pulse the similarity law is used
        (only ``pTp`` and ``ap/g`` matter).
    p : float
        Frequency parameter of the block, rad/s.
    criterion : {"overturn", "exceed"}
        What counts as failure: overturning, or ``|theta|`` passing ``alpha``.
    n_scan, n_zone, rtol : int, int, float
        Uniform scan points; points of the dense zone scanned just above the highest failure
        (default :data:`ZONE_POINTS`; 0 switches the zone off: about 3x fewer runs, but failure
        slivers thinner than the scan step above the main boundary, found at large pTp, may then
        be missed); relative width of the final brackets.
    model : str
        Solver model of :func:`rocking.simulate_many` (``"fast"`` or ``"reference"``).
    cap_mass_ratio : float
        A rocking frame (SPEC section 8): ``p`` is then the frame's (``block.p``) and ``eta``
        the frame's at each slenderness; 0, the lone column.

    Returns
    -------
    MinSlenderness
        with ``.tan_alpha`` and ``.transitions``.
    """
    _check_criterion(criterion)
    gamma = check_cap_mass_ratio(cap_mass_ratio)
    p = float(p)
    if not (math.isfinite(p) and p > 0):
        raise ValueError(f"p must be positive, got {p!r}")
    if getattr(pulse, "shape", "record") in ("rect", "sine", "ricker-sym", "ricker-anti"):
        if pulse.ap == 0:
            return MinSlenderness(0.0, (), p, criterion, 0.0, 0.0, 0, pulse)
        res = min_slenderness_batch(pulse.shape, p * pulse.tp, abs(pulse.ap) / G,
                                    criterion=criterion, n_scan=n_scan, n_zone=n_zone, rtol=rtol,
                                    model=model, cap_mass_ratio=cap_mass_ratio)[0]
        res.p, res.excitation = p, pulse
        return res
    # a record (or any excitation the solver accepts): scan tan(alpha) directly
    peak = _peak(pulse)
    top = np.array([peak / G])
    x = _scan_points(top, n_scan)
    known = np.zeros(x.shape, dtype=bool)
    known[:, -1] = True

    def evaluate(idx, tans):
        blocks = [Block(p, math.atan(t), cap_mass_ratio=gamma) for t in tans]
        return _failed(_batch(blocks, pulse, None, model=model), criterion)

    scan = _scan_refine(evaluate, x, known=known, rtol=rtol, refine="top", zone=n_zone != 0,
                        n_zone=n_zone)
    br = scan.brackets[0]
    tan_alpha = 0.0
    for lo, hi, flo, fhi in br:
        if flo and not fhi:
            tan_alpha = hi
    return MinSlenderness(tan_alpha, tuple(0.5 * (lo + hi) for lo, hi, _, _ in br), p, criterion,
                          None, float(top[0]), scan.runs, pulse,
                          fails_above=tuple(fhi for _, _, _, fhi in br))


# ---------------------------------------------------------------------------------------------
# critical amplitudes and safe islands (Fig. 5, one column)
# ---------------------------------------------------------------------------------------------
class CriticalAmplitudes(list):
    """List of ``(low, high)`` amplitude intervals (m/s^2) in which the block fails.

    The first ``low`` is the smallest overturning amplitude; the gaps between intervals are the
    safe islands (:attr:`safe_islands`).  A ``high`` equal to :attr:`up_to` means the interval
    runs on to the end of the scan.
    """

    def __init__(self, intervals, *, block, shape, tp, up_to, criterion, runs):
        super().__init__(intervals)
        self.block, self.shape, self.tp = block, shape, tp
        self.up_to, self.criterion, self.runs = up_to, criterion, runs

    @property
    def minimum(self) -> float | None:
        """Smallest failing amplitude, m/s^2 (None when none up to :attr:`up_to`)."""
        return self[0][0] if self else None

    @property
    def safe_islands(self) -> list:
        """``(low, high)`` amplitude ranges (m/s^2) of survival above the smallest failing one."""
        return [(self[i][1], self[i + 1][0]) for i in range(len(self) - 1)]


def critical_amplitudes(block, shape, tp, up_to=None, *, criterion="overturn", n_scan=400,
                        rtol=RTOL, model="fast"):
    """All the amplitude intervals (m/s^2) up to ``up_to`` in which ``block`` overturns.

    Parameters
    ----------
    block : Block
    shape : str
        ``"rect"``, ``"sine"``, ``"ricker-sym"`` or ``"ricker-anti"``.
    tp : float
        Pulse period, s.
    up_to : float, optional
        Largest amplitude examined, m/s^2; default ``6 g tan(alpha)`` (the top of Fig. 5).
    n_scan : int
        Uniform scan points between the uplift acceleration ``g tan(alpha)`` and ``up_to``;
        every verdict change is then bisected to ``rtol``.

    Returns
    -------
    CriticalAmplitudes
        A list of ``(low, high)`` pairs; ``.safe_islands`` gives the gaps between them.
    """
    _check_criterion(criterion)
    uplift = block.uplift_acceleration
    up_to = 6.0 * uplift if up_to is None else float(up_to)
    if not up_to > uplift:
        return CriticalAmplitudes([], block=block, shape=shape, tp=tp, up_to=up_to,
                                  criterion=criterion, runs=0)
    pulse = _unit_pulse(shape, float(tp))
    x = (uplift + (up_to - uplift) * np.linspace(0.0, 1.0, n_scan + 1))[None, :]
    known = np.zeros(x.shape, dtype=bool)
    known[0, 0] = True             # at the uplift acceleration itself nothing moves

    def evaluate(idx, amps):
        return _failed(_batch(block, pulse, np.asarray(amps), model=model), criterion)

    scan = _scan_refine(evaluate, x, known=known, rtol=rtol, zone=False)
    edges = []
    for lo, hi, flo, fhi in scan.brackets[0]:
        edges.append((0.5 * (lo + hi), fhi))      # value, failing above it?
    intervals, start = [], None
    for value, fails_above in edges:
        if fails_above:
            start = value
        elif start is not None:
            intervals.append((start, value))
            start = None
    if start is not None:
        intervals.append((start, up_to))
    return CriticalAmplitudes(intervals, block=block, shape=shape, tp=float(tp), up_to=up_to,
                              criterion=criterion, runs=scan.runs)


# ---------------------------------------------------------------------------------------------
# sizing a column of given height
# ---------------------------------------------------------------------------------------------
@dataclass
class RequiredWidth:
    """Width a column of given height needs.

    ``p`` depends on the width (``R = sqrt(H^2 + B^2)/2``), so the closed-form rules are solved
    as a fixed point in ``B`` (:attr:`iterations` steps); ``rule="exact"`` is the *verified
    width*: the smallest width that survives at that width and at every larger one, found by a
    scan over widths and bracketed refinement of every verdict change (:attr:`transitions`).
    """

    width: float
    height: float
    rule: str
    iterations: int
    method: str
    criterion: str = "overturn"
    transitions: tuple = ()
    runs: int = 0
    eta: float | None = None
    cap_mass_ratio: float = 0.0

    @property
    def tan_alpha(self) -> float:
        return self.width / self.height

    @property
    def block(self) -> Block:
        return Block.from_dimensions(self.height, self.width, self.eta,
                                     cap_mass_ratio=self.cap_mass_ratio)

    @property
    def p(self) -> float:
        return self.block.p

    @property
    def alpha(self) -> float:
        return math.atan2(self.width, self.height)


def _p_of(height, width, gamma=0.0):
    return frame_p(math.sqrt(3.0 * G / (4.0 * math.hypot(height / 2.0, width / 2.0))), gamma)


RULES = ("eq31", "envelope", "eq20", "exact")


def required_width(height, excitation, *, rule="eq31", criterion="overturn", eta=None,
                   shape=None, lam=1.0, n_scan=None, n_zone=None, rtol=RTOL, model="fast",
                   cap_mass_ratio=0.0):
    """The width (m) a column of full ``height`` (m) needs against ``excitation``.

    Parameters
    ----------
    height : float
        Full height H of the column, m.
    excitation : pulses.Pulse or pulses.Record
        The design pulse, or (``rule="exact"`` only) a whole record.
    rule : {"eq31", "envelope", "eq20", "exact"}
        ``"eq31"``/``"envelope"``/``"eq20"``: the closed form, solved as a fixed point in the
        width because ``p`` depends on it (``B = H tan(alpha_min(p(B)))``, a contraction; the
        iteration count is reported).  ``"exact"``: time-history analysis across widths (the
        *verified width*, see :class:`RequiredWidth`); works for pulses and records.
    criterion : {"overturn", "exceed"}
        Failure criterion of ``rule="exact"``.
    eta : float, optional
        Restitution for the exact rule (default Eq. 5 at each width).
    shape : str, optional
        Shape whose envelope factor to use with ``rule="envelope"`` (default: every shape).
    lam : float
        The lambda of Eq. 20 for ``rule="eq20"``.
    n_scan, n_zone, rtol : int, int, float
        ``rule="exact"``: scan points up to the no-uplift width ``H peak/g`` (pulse:
        :data:`N_SCAN` uniform; record: :data:`REC_SCAN` geometric), points of the dense zone
        just above the widest failing width (pulse: :data:`ZONE_POINTS` uniform, 0 switches it
        off; record: an optional extra zone of ``n_zone`` geometric widths, off by default, next
        to the fine zone of :data:`REC_FINE`, see :func:`_record_width`), and the relative width
        of the final bracket.  For a record only the top transition is refined
        (its verdicts may change hundreds of times with the width) and the widths scanned are
        chosen adaptively; the answer holds at the resolution stated in :func:`_record_width`.
    cap_mass_ratio : float
        The width of the columns of a rocking frame whose beam has this mass over the columns'
        total mass (SPEC section 8: the frame's ``p`` and ``eta`` at each width); 0, a lone column.

    Returns
    -------
    RequiredWidth
        ``.width``, ``.tan_alpha``, ``.p``, ``.rule``, ``.iterations``.
    """
    height = float(height)
    if not (math.isfinite(height) and height > 0):
        raise ValueError(f"height must be positive, got {height!r} m")
    if rule not in RULES:
        raise ValueError(f"rule must be one of {RULES}, got {rule!r}")
    gamma = check_cap_mass_ratio(cap_mass_ratio)
    if rule == "exact":
        return _exact_width(height, excitation, criterion=criterion, eta=eta, n_scan=n_scan,
                            rtol=rtol, model=model, n_zone=n_zone, gamma=gamma)
    if not hasattr(excitation, "tp") or not hasattr(excitation, "ap"):
        raise ValueError(f"rule={rule!r} needs a pulse (ap, Tp); for a whole record fit its pulse "
                         "first or use rule='exact'")
    ap, tp = abs(excitation.ap), excitation.tp
    if rule == "eq31":
        f = lambda p: eq31(ap, tp, p)
    elif rule == "eq20":
        f = lambda p: eq20(ap, tp, p, lam)
    else:
        f = lambda p: envelope_rule(ap, tp, p, shape)
    # B_{k+1} = H f(p(B_k)): f falls as B grows (p falls), so the map is monotone decreasing and
    # its slope is small (|dB'/dB| = H |f'(p)| |dp/dB| << 1 for columns); it converges in a few
    # steps.  Started from the no-uplift width H ap/g, an upper bound of the answer.
    width = height * ap / G
    for it in range(1, 201):
        new = height * f(_p_of(height, width, gamma))
        if abs(new - width) <= 1e-13 * max(height, 1.0):
            width = new
            break
        width = new
    else:  # pragma: no cover - the map is a strong contraction for any realistic column
        from scipy.optimize import brentq

        width = brentq(lambda b: b - height * f(_p_of(height, b, gamma)), 0.0, height * ap / G + 1e-300,
                       xtol=1e-14)
    return RequiredWidth(width=float(width), height=height, rule=rule, iterations=it,
                         method=f"fixed point of {rule} in B (p depends on B): "
                                f"{it} iterations", eta=eta, cap_mass_ratio=gamma)


def _exact_width(height, excitation, *, criterion, eta, n_scan, rtol, model, n_zone=None,
                 gamma=0.0):
    _check_criterion(criterion)
    top = height * _peak(excitation) / G       # wider than this the column never uplifts
    if top <= 0:
        return RequiredWidth(0.0, height, "exact", 0, "no ground motion", criterion,
                             cap_mass_ratio=gamma)

    def runs(widths):
        return _batch([Block.from_dimensions(height, float(b), eta, cap_mass_ratio=gamma)
                       for b in widths], excitation, None, model=model)

    def evaluate(idx, widths):
        return _failed(runs(widths), criterion)

    is_pulse = getattr(excitation, "shape", "record") in ("rect", "sine", "ricker-sym", "ricker-anti")
    if not is_pulse:
        def evaluate_record(widths):
            res = runs(widths)
            return _failed(res, criterion), np.asarray(res.max_rotation_ratio, dtype=float)

        res = _record_width(height, top, evaluate_record, criterion=criterion, eta=eta,
                            n_scan=REC_SCAN if n_scan is None else n_scan, rtol=rtol,
                            n_zone=REC_ZONE_POINTS if n_zone is None else n_zone)
        res.cap_mass_ratio = gamma
        return res
    x = _scan_points(np.array([top]), N_SCAN if n_scan is None else n_scan)
    known = np.zeros(x.shape, dtype=bool)
    known[:, -1] = True
    scan = _scan_refine(evaluate, x, known=known, rtol=rtol, refine="all", zone=n_zone != 0,
                        n_zone=n_zone)
    br = scan.brackets[0]
    width, n_iter = 0.0, scan.calls
    for lo, hi, flo, fhi in br:
        if flo and not fhi:
            width = hi
    return RequiredWidth(
        width=float(width), height=height, rule="exact", iterations=n_iter,
        method=(f"verified width: scan of {x.shape[1]} widths up to the no-uplift width "
                f"{top:.4g} m (denser just above the widest failure), then bracketed "
                f"refinement of {len(br)} verdict change(s) ({scan.runs} solver runs in "
                f"{scan.calls} batches)"),
        criterion=criterion, transitions=tuple(0.5 * (lo + hi) for lo, hi, _, _ in br),
        runs=scan.runs, eta=eta, cap_mass_ratio=gamma)


#: Verified width under a whole record (:func:`_record_width`): ``REC_SCAN`` widths geometric from
#: ``top REC_LOW`` to the no-uplift width ``top`` (neighbours 3.3 % apart with the defaults), plus
#: a tail of ``REC_TAIL`` widths halving towards zero.  ``REC_SPACING = "uniform"`` gives the former
#: scan (``REC_SCAN`` uniform widths up to ``top``; kept to compare, see benchmarks/bench_design.py).
REC_SCAN = 128
REC_LOW = 1.0 / 64
REC_TAIL = 4
REC_SPACING = "geometric"
#: fine zone above each candidate answer ``w``: every width of the fixed grid
#: ``top (1 + REC_FINE)^-k`` in ``(w, w (1 + REC_FINE_SPAN)]`` is run (0.05 % apart: failing
#: slivers of real records are often thinner than 0.2 %, and lie up to ~25 % above the main
#: transition; README "Design" has the measurements behind these numbers)
REC_FINE = 5e-4
REC_FINE_SPAN = 0.2
#: optional extra zone (``n_zone`` of required_width; off by default, the fine zone covers it):
#: ``n_zone`` widths ``w (1 + d)``, ``d`` geometric from ``REC_ZONE_FIRST`` to
#: ``REC_ZONE_FRACTION``.  ``REC_ZONE_FIRST / 4`` is also the bisection tolerance of candidates.
REC_ZONE_POINTS = 0
REC_ZONE_FIRST = 1e-3
REC_ZONE_FRACTION = 0.15
#: above the candidate, every gap between scanned widths wider than ``REC_GAP`` (relative) is
#: halved while either end came within ``REC_NEAR`` of tipping (``max|theta|/alpha >= REC_NEAR``):
#: isolated failing bands of real records sit where the block nearly overturns
REC_GAP = 0.01
REC_NEAR = 0.6
#: at most this many rounds (a failure found above the candidate moves it up: check again)
REC_ROUNDS = 12
#: the fine zone is run from its widest width down in batches of this many (one batch of the
#: batch engine's lanes per core), and stops at the first batch with a failure
REC_CHUNK = 32


def _record_width(height, top, evaluate, *, criterion, eta, n_scan, rtol, n_zone):
    """Verified width under a record: the smallest width above which every scanned width survives.

    A record's verdict can change hundreds of times with the width (slender columns rock
    chaotically; real records have isolated failing bands well above the main transition), so
    the answer is defined by the widths examined.  They are chosen to need few runs (a run that
    survives costs the whole record, and most runs here survive) while looking hardest where a
    failure is likely:

    1. ``REC_TAIL`` widths towards zero and ``n_scan`` widths geometric from ``top`` x
       :data:`REC_LOW` to the no-uplift width ``top`` (known to survive), one batch;
    2. the bracket above the widest failing width is bisected (so the highest change is the one
       followed) to :data:`REC_ZONE_FIRST` / 4 relative: the candidate ``w``;
    3. (if ``n_zone``) a zone above it: ``n_zone`` widths ``w (1 + d)``, ``d`` geometric from
       :data:`REC_ZONE_FIRST` to :data:`REC_ZONE_FRACTION`;
    4. the fine zone: every width of the fixed grid ``top (1 + REC_FINE)^-k`` between ``w`` and
       ``w (1 + REC_FINE_SPAN)`` not run yet (0.05 % apart, up to 20 % above ``w``), run from
       the widest down :data:`REC_CHUNK` at a time and stopped at the first batch with a
       failure (the widths below it cannot move the answer);
    5. above ``w``, every gap between scanned widths wider than :data:`REC_GAP` (relative) is
       halved, repeatedly, while either end reached ``max|theta|/alpha >= REC_NEAR``;
    6. a failure found in 3-5 moves the candidate up (back to 2; at most :data:`REC_ROUNDS`
       rounds); finally the top bracket is bisected to ``rtol`` relative.

    Resolution (the caveat): a failing band is found if it is wider than the gap between the
    scanned widths around it: 0.05 % of ``w`` up to 20 % above the answer, 1 % or less further
    up wherever the block came near tipping, 3.3 % where it rocked little.  Bands narrower than
    that can be missed, and so can they by any finite scan: slender columns under real records
    have failing slivers thinner than 0.05 %, and on 30 real cases a uniform 1500-width scan
    was itself up to 19 % below the highest failure a 6000-width scan found (README "Design"
    has the table).  Islands of survival below the widest failure never lower the answer; every
    verdict change among the scanned widths is in ``transitions`` (the top one refined, the
    others at scan resolution).
    ``tests/test_design.py`` checks the answer against dense brute-force scans.
    """
    if REC_SPACING == "geometric":
        low = REC_LOW
        xs = top * np.geomspace(low, 1.0, n_scan)
    else:
        low = 1.0 / n_scan
        xs = top * np.arange(1, n_scan + 1) / n_scan
    xs = np.concatenate([top * low * 2.0 ** -np.arange(REC_TAIL, 0, -1), xs])
    runs = calls = 0
    pts_x, pts_f, pts_r = [xs[-1:]], [np.zeros(1, dtype=bool)], [np.zeros(1)]  # top: no uplift

    def run(widths):
        nonlocal runs, calls
        widths = np.atleast_1d(np.asarray(widths, dtype=float))
        f, r = evaluate(widths)
        runs += widths.size
        calls += 1
        pts_x.append(widths)
        pts_f.append(np.asarray(f, dtype=bool))
        pts_r.append(np.asarray(r, dtype=float))
        return pts_f[-1]

    def scanned():
        x, f, r = np.concatenate(pts_x), np.concatenate(pts_f), np.concatenate(pts_r)
        order = np.argsort(x, kind="stable")
        return x[order], f[order], r[order]

    def run_down(widths):
        """Run ``widths`` from the widest down, :data:`REC_CHUNK` at a time, stopping after the
        first chunk with a failure: narrower widths cannot change the answer (it lies above the
        widest failure), so they are not run.  Returns whether any failed."""
        widths = np.sort(np.asarray(widths, dtype=float))[::-1]
        for k in range(0, widths.size, REC_CHUNK):
            if run(widths[k:k + REC_CHUNK]).any():
                return True
        return False

    def top_bracket():
        x, f, _ = scanned()
        if not f.any():
            return None
        j = np.nonzero(f)[0][-1]
        return x[j], x[j + 1]                     # x[-1] = top survives, so j + 1 exists

    def bisect(lo, hi, tol):
        while hi - lo > tol * hi:
            mid = 0.5 * (lo + hi)
            if run([mid])[0]:
                lo = mid
            else:
                hi = mid
        return lo, hi

    def near_gaps(w):
        """Midpoints of the gaps above ``w`` to halve (step 5)."""
        x, f, r = scanned()
        sel = x >= w
        x, r = x[sel], r[sel]
        wide = (x[1:] - x[:-1]) > REC_GAP * x[:-1]
        near = np.maximum(r[1:], r[:-1]) >= REC_NEAR
        m = np.nonzero(wide & near)[0]
        return 0.5 * (x[m] + x[m + 1])

    run(xs[:-1])
    fine_done = np.zeros(0)
    limited = False
    br = top_bracket()
    rounds = 0
    while br is not None and rounds < REC_ROUNDS:
        rounds += 1
        lo, hi = bisect(*br, max(REC_ZONE_FIRST / 4.0, rtol))
        found = False
        if n_zone > 0:
            z = hi * (1.0 + np.geomspace(REC_ZONE_FIRST, REC_ZONE_FRACTION, int(n_zone)))
            z = z[z < top]
            found = bool(z.size) and bool(run(z).any())
        if not found and REC_FINE > 0:
            # every width of the fixed fine grid top (1 + REC_FINE)^-k in (hi, hi (1 + REC_FINE_SPAN)]
            # not run yet (a later round only adds the part above the previous one)
            k_hi = math.floor(math.log(top / hi) / math.log1p(REC_FINE))
            k_lo = max(math.ceil(math.log(top / (hi * (1.0 + REC_FINE_SPAN))) / math.log1p(REC_FINE)), 1)
            z = top * (1.0 + REC_FINE) ** -np.arange(k_lo, k_hi + 1, dtype=float)
            z = np.setdiff1d(z[(z > hi) & (z < top)], fine_done)
            if z.size:
                fine_done = np.union1d(fine_done, z)
                found = run_down(z)
        while not found:
            mids = near_gaps(hi)
            if not mids.size:
                break
            found = bool(run(mids).any())
        if not found:
            break
        br = top_bracket()
    else:
        limited = br is not None   # failures were still being found above the candidate
    width = 0.0
    if br is not None:
        width = bisect(*top_bracket(), rtol)[1]
    x, f, _ = scanned()
    ch = np.nonzero(f[1:] != f[:-1])[0]
    transitions = tuple(float(t) for t in 0.5 * (x[ch] + x[ch + 1]))
    return RequiredWidth(
        width=float(width), height=height, rule="exact", iterations=calls,
        method=(f"verified width: scan of {xs.size} widths up to the no-uplift width {top:.4g} m, "
                f"then {rounds} round(s) of bisection above the widest failure and checks above "
                f"it (widths {REC_FINE:.2%} apart up to {REC_FINE_SPAN:.0%} above, "
                + (f"a zone of {int(n_zone)} widths up to {REC_ZONE_FRACTION:.0%} above, " if n_zone else "")
                + f"gaps halved to {REC_GAP:.0%} where the block nearly tipped"
                + ("; round limit reached" if limited else "")
                + f"); {runs} solver runs in {calls} batches"),
        criterion=criterion, transitions=transitions, runs=runs, eta=eta)
