"""The exact searches over pulses (docs/theory.md section 5): minimum slenderness (the paper's Fig. 8) and
the amplitude intervals of overturning with their safe islands (Fig. 5, one column), by
time-history analysis with the batch solver (:mod:`rocking.search`)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pulses import G, SHAPES, make_pulse

from .block import Blocks
from .frame import check_cap_mass_ratio
from .closed_forms import eq31
from .search import (DEFAULT_SETTINGS, _batch, _check_criterion, _failed, _peak, _scan_points,
                     _scan_refine)


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

    Examples
    --------
    >>> import rocking, pulses
    >>> ms = rocking.min_slenderness(pulses.OneSine(0.71 * pulses.G, 0.8), 1.381)
    >>> ms.criterion, ms.transitions[-1] <= ms.tan_alpha
    ('overturn', True)
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
    #: the restitution (None: Eq. 5); under a band, the single value whose answer governs (the
    #: largest ``tan_alpha`` of the band's values, :mod:`rocking.band`)
    eta: object = None
    #: under a band: the band, and the number of its values run (0: no band)
    band: object = None
    band_runs: int = 0

    @property
    def alpha(self) -> float:
        """``atan(tan_alpha)``, rad."""
        return math.atan(self.tan_alpha)

    def as_dict(self) -> dict:
        """The fields (not the excitation) and ``alpha``: plain, JSON-safe numbers.

        Examples
        --------
        >>> import rocking, pulses
        >>> m = rocking.min_slenderness(pulses.make_pulse("sine", 3.0, 1.0), p=1.5)
        >>> sorted(m.as_dict())[:4]
        ['alpha', 'band', 'band_runs', 'criterion']
        """
        from pulses.export import fields_dict

        return fields_dict(self, skip=("excitation",), properties=("alpha",))

    @property
    def safe_islands(self) -> list:
        """``(low, high)`` ranges of ``tan(alpha)`` below :attr:`tan_alpha` where the block survives."""
        t, up = list(self.transitions), list(self.fails_above)
        return [(t[i], t[i + 1]) for i in range(len(t) - 1) if not up[i] and up[i + 1]]


def _unit_pulse(shape, tp):
    return make_pulse(shape, 1.0, tp)


def min_slenderness_batch(shape, p_tp, ap_over_g, *, criterion="overturn", n_scan=None,
                          n_zone=None, rtol=None, model="fast", refine="all", ksection=None,
                          settings=DEFAULT_SETTINGS, cap_mass_ratio=0.0, body=None, eta=None):
    """Exact minimum slenderness for many ``(pTp, ap/g)`` points of one pulse shape at once.

    By the similarity law (docs/theory.md section 4) the answer depends only on ``pTp`` and ``ap/g``, so
    every point is solved with ``Tp = 1 s`` and ``p = pTp``; all scans share one batch-solver call
    and all brackets are refined together.  Returns a list of :class:`MinSlenderness`.

    ``refine="top"`` refines only the transition that decides ``tan_alpha`` (the others, and so
    :attr:`MinSlenderness.safe_islands`, stay at scan resolution) and ``ksection=2`` refines by
    bisection: the same ``tan_alpha`` (to ``rtol``) from fewer runs, which is what
    ``pipeline run`` needs for a few blocks per record.  ``n_scan``, ``n_zone``, ``rtol`` and
    ``ksection`` override the fields of ``settings`` (:class:`rocking.search.SearchSettings`).
    ``body`` (:mod:`rocking.bodies`): the impact rule at each slenderness is that body's.
    ``eta``: the restitution, as :func:`min_slenderness`'s.

    Examples
    --------
    >>> import rocking
    >>> res = rocking.min_slenderness_batch("sine", [1.0, 2.0], [0.5, 0.5])    # pTp, ap/g
    >>> [round(r.tan_alpha, 4) for r in res]
    [0.1221, 0.3383]
    """
    from . import band

    eta = band.plain(eta)
    if band.is_band(eta):
        kw = dict(criterion=criterion, n_scan=n_scan, n_zone=n_zone, rtol=rtol, model=model,
                  refine=refine, ksection=ksection, settings=settings, cap_mass_ratio=cap_mass_ratio,
                  body=body)
        return band.band_slenderness(lambda v: min_slenderness_batch(shape, p_tp, ap_over_g, eta=v, **kw), eta)
    _check_criterion(criterion)
    gamma = check_cap_mass_ratio(cap_mass_ratio)
    settings = settings.replace(n_scan=n_scan, zone_points=n_zone, rtol=rtol, ksection=ksection)
    p_tp = np.atleast_1d(np.asarray(p_tp, dtype=float)).ravel()
    ap_over_g = np.atleast_1d(np.asarray(ap_over_g, dtype=float)).ravel()
    p_tp, ap_over_g = np.broadcast_arrays(p_tp, ap_over_g)
    if np.any(p_tp <= 0) or np.any(ap_over_g <= 0):
        raise ValueError("pTp and ap/g must be positive")
    pulse = _unit_pulse(shape, 1.0)
    scales = ap_over_g * G
    top = ap_over_g.copy()
    x = _scan_points(top, settings.n_scan, settings.n_tail)
    known = np.zeros(x.shape, dtype=bool)
    known[:, -1] = True            # tan(alpha) = ap/g: never uplifts

    def evaluate(idx, tans):
        blocks = Blocks.from_tan_alpha(p_tp[idx], tans, eta, cap_mass_ratio=gamma, body=body)
        return _failed(_batch(blocks, pulse, scales[idx], model=model), criterion)

    scan = _scan_refine(evaluate, x, settings, known=known, zone=settings.zone_points != 0,
                        refine=refine)
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
            fails_above=tuple(fhi for _, _, _, fhi in br), eta=eta))
    return out


def min_slenderness(pulse, p, *, criterion="overturn", n_scan=None, n_zone=None, rtol=None,
                    model="fast", settings=DEFAULT_SETTINGS, cap_mass_ratio=0.0, body=None, eta=None):
    """Exact minimum slenderness (docs/theory.md section 5, the paper's Fig. 8).

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
    n_scan, n_zone, rtol : int, int, float, optional
        Uniform scan points; points of the dense zone scanned just above the highest failure
        (0 switches the zone off: about 3x fewer runs, but failure
        slivers thinner than the scan step above the main boundary, found at large pTp, may then
        be missed); relative width of the final brackets.  Each overrides its field of
        ``settings``.
    model : str
        Solver model of :func:`rocking.simulate_many` (``"fast"`` or ``"reference"``).
    settings : rocking.search.SearchSettings
        Scan settings (default :data:`rocking.search.DEFAULT_SETTINGS`).
    cap_mass_ratio : float
        A rocking frame (docs/theory.md section 8): ``p`` is then the frame's (``block.p``) and ``eta`` the
        frame's at each slenderness; 0, the lone column.
    body : rocking.bodies.Body or str, optional
        The body's shape (default rectangular): ``eta`` at each slenderness is its impact rule.
    eta : float or rocking.restitution.Restitution, optional
        The restitution at impact: a velocity ratio, or a
        :class:`~rocking.restitution.Restitution` (a factor of Eq. 5 at each slenderness, an
        ``eta``, an ``r``); default Eq. 5.  A band gives the answer covering it (the largest
        ``tan_alpha`` of its :data:`rocking.band.BAND_VALUES` values; ``.eta`` the value that
        governed, ``.band_runs`` how many were run).

    Returns
    -------
    MinSlenderness
        with ``.tan_alpha`` and ``.transitions``.

    Examples
    --------
    >>> import rocking, pulses
    >>> ms = rocking.min_slenderness(pulses.OneSine(0.71 * pulses.G, 0.8), 1.381)
    >>> round(ms.tan_alpha, 4)                 # exact; Eq. 31 asks for 0.3727
    0.1989
    """
    from . import band

    _check_criterion(criterion)
    gamma = check_cap_mass_ratio(cap_mass_ratio)
    eta = band.plain(eta)
    if band.is_band(eta) and getattr(pulse, "shape", "record") not in SHAPES:
        kw = dict(criterion=criterion, n_scan=n_scan, n_zone=n_zone, rtol=rtol, model=model,
                  settings=settings, cap_mass_ratio=cap_mass_ratio, body=body)
        return band.band_slenderness(lambda v: [min_slenderness(pulse, p, eta=v, **kw)], eta)[0]
    p = float(p)
    if not (math.isfinite(p) and p > 0):
        raise ValueError(f"p must be positive, got {p!r}")
    if getattr(pulse, "shape", "record") in SHAPES:
        if pulse.ap == 0:
            return MinSlenderness(0.0, (), p, criterion, 0.0, 0.0, 0, pulse)
        res = min_slenderness_batch(pulse.shape, p * pulse.tp, abs(pulse.ap) / G,
                                    criterion=criterion, n_scan=n_scan, n_zone=n_zone, rtol=rtol,
                                    model=model, settings=settings,
                                    cap_mass_ratio=cap_mass_ratio, body=body, eta=eta)[0]
        res.p, res.excitation = p, pulse
        return res
    # a record (or any excitation the solver accepts): scan tan(alpha) directly
    settings = settings.replace(n_scan=n_scan, zone_points=n_zone, rtol=rtol)
    peak = _peak(pulse)
    top = np.array([peak / G])
    x = _scan_points(top, settings.n_scan, settings.n_tail)
    known = np.zeros(x.shape, dtype=bool)
    known[:, -1] = True

    def evaluate(idx, tans):
        blocks = Blocks.from_tan_alpha(np.full(len(tans), p), tans, eta, cap_mass_ratio=gamma,
                                       body=body)
        return _failed(_batch(blocks, pulse, None, model=model), criterion)

    scan = _scan_refine(evaluate, x, settings, known=known, refine="top",
                        zone=settings.zone_points != 0)
    br = scan.brackets[0]
    tan_alpha = 0.0
    for lo, hi, flo, fhi in br:
        if flo and not fhi:
            tan_alpha = hi
    return MinSlenderness(tan_alpha, tuple(0.5 * (lo + hi) for lo, hi, _, _ in br), p, criterion,
                          None, float(top[0]), scan.runs, pulse,
                          fails_above=tuple(fhi for _, _, _, fhi in br), eta=eta)


# ---------------------------------------------------------------------------------------------
# critical amplitudes and safe islands (Fig. 5, one column)
# ---------------------------------------------------------------------------------------------
class CriticalAmplitudes(list):
    """List of ``(low, high)`` amplitude intervals (m/s^2) in which the block fails.

    The first ``low`` is the smallest overturning amplitude; the gaps between intervals are the
    safe islands (:attr:`safe_islands`).  A ``high`` equal to :attr:`up_to` means the interval
    runs on to the end of the scan.

    Examples
    --------
    >>> import rocking
    >>> amps = rocking.critical_amplitudes(rocking.Block.from_dimensions(7.5, 1.2), "sine", 1.0)
    >>> len(amps), amps.shape
    (1, 'sine')
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

    def as_dict(self) -> dict:
        """The intervals, islands and settings: plain, JSON-safe numbers (m/s^2, s)."""
        from pulses.export import plain

        return plain({"shape": self.shape, "tp": self.tp, "up_to": self.up_to, "criterion": self.criterion,
                      "runs": self.runs, "minimum": self.minimum, "intervals": list(self),
                      "safe_islands": self.safe_islands, "p": self.block.p, "alpha": self.block.alpha})

    def to_frame(self):
        """One row per failing interval: ``low_m_s2``, ``high_m_s2``."""
        import pandas as pd

        return pd.DataFrame(list(self), columns=["low_m_s2", "high_m_s2"])


def critical_amplitudes(block, shape, tp, up_to=None, *, criterion="overturn", n_scan=400,
                        rtol=None, model="fast", settings=DEFAULT_SETTINGS):
    """All the amplitude intervals (m/s^2) up to ``up_to`` in which ``block`` overturns.

    Parameters
    ----------
    block : Block
    shape : str
        A name of :data:`pulses.SHAPES` (the shapes of docs/theory.md section 2).
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

    Examples
    --------
    >>> import rocking, pulses
    >>> amps = rocking.critical_amplitudes(rocking.Block.from_dimensions(7.5, 1.2), "sine", 1.0)
    >>> round(amps.minimum / pulses.G, 3), amps.safe_islands
    (0.317, [])
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

    scan = _scan_refine(evaluate, x, settings.replace(rtol=rtol), known=known, zone=False)
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

