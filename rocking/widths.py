"""Sizing a column of given height (docs/theory.md section 5): the width it needs by a closed-form rule
(solved as a fixed point in the width, since ``p`` depends on it) or by time-history analysis
(the *design width*, under a pulse or a whole record)."""
from __future__ import annotations

import dataclasses
import hashlib
import math
from dataclasses import dataclass, field

import numpy as np

from pulses import G, SHAPES

from . import scan, searches
from .block import Block, Blocks, _p_alpha
from .bodies import RECTANGULAR, Body, check_frame
from .frame import check_cap_mass_ratio, frame_p
from .closed_forms import envelope_rule, eq20, eq31
from .search import (DEFAULT_SETTINGS, _batch, _check_criterion, _failed, _peak, _scan_points,
                     _scan_refine, check_limit)


@dataclass
class RequiredWidth:
    """Width a column of given height needs.

    ``p`` depends on the width (``R = sqrt(H^2 + B^2)/2``), so the closed-form rules are solved
    as a fixed point in ``B`` (:attr:`iterations` steps); ``rule="exact"`` searches by
    time-history analysis for the smallest width that survives at that width and at every larger
    one, by a scan over widths and bracketed refinement of every verdict change
    (:attr:`transitions`; the answer is :attr:`search_width`).
    Under a record, failing slivers thinner than the scan's resolution can lie above it (the
    response is chaotic near the verge of overturning): a check of jittered widths above it
    reports what it finds (:attr:`failing_share`, :attr:`widest_failing_width`; docs/slivers.md).

    :attr:`width` is the *design width*: at least every width the search and the check found to
    fail, refined just above the widest of them (:attr:`search_width` is the search's first
    transition, a diagnostic); with a vertical record, the wider of the designs for the horizontal
    motion alone and with the vertical (:attr:`governed_by`).  With a performance level
    :attr:`limit` R, a width fails where ``max|theta|/alpha`` exceeds R (or the column overturns).

    Examples
    --------
    >>> import rocking, pulses
    >>> w = rocking.required_width(7.5, pulses.OneSine(0.71 * pulses.G, 0.8), rule="eq31")
    >>> w.rule, round(w.tan_alpha, 4) == round(w.width / 7.5, 4)
    ('eq31', True)
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
    #: every width examined survived, down to :attr:`width` (the narrowest examined): the
    #: answer is at most that width (the search halves the width down to ``2**-DOWN_HALVINGS``
    #: of the scan's narrowest before it gives up looking for a failure)
    below_scan: bool = False
    #: the check above the search width (a record's ``rule="exact"`` only; docs/slivers.md): the
    #: share of the checked widths that fail (``None``: not checked), the widest of them (m;
    #: ``None`` where none failed), the number of widths checked (runs on top of :attr:`runs`),
    #: and the widest width checked (m)
    failing_share: float | None = None
    widest_failing_width: float | None = None
    check_runs: int = 0
    check_top: float | None = None
    #: the widths checked (m, ascending) and whether each failed (for the barcode figure)
    check_widths: np.ndarray | None = field(default=None, repr=False, compare=False)
    check_failed: np.ndarray | None = field(default=None, repr=False, compare=False)
    #: the performance level: a width fails where ``max|theta|/alpha > limit`` (None: overturning,
    #: or :attr:`criterion`)
    limit: float | None = None
    #: the search's answer (m): the smallest width above which every width the search examined
    #: survives (called the verified width before 0.5); :attr:`width` is at least this
    search_width: float | None = None
    #: solver runs of the refinement above the widest failing width (on top of :attr:`runs` and
    #: :attr:`check_runs`)
    refine_runs: int = 0
    #: with a vertical record: ``"horizontal"`` where the horizontal motion alone asks for the
    #: wider design, ``"with vertical"`` where the horizontal motion together with the vertical
    #: does (ties: ``"horizontal"``); None without a vertical
    governed_by: str | None = None
    #: with a vertical record: the design widths (m) for the horizontal motion alone and with the
    #: vertical (:attr:`width` is the larger)
    horizontal_width: float | None = None
    vertical_width: float | None = None
    #: with a vertical record: the answer of the other motion, whole (a RequiredWidth)
    other: "RequiredWidth | None" = field(default=None, repr=False, compare=False)
    #: a level designed with its overturning design (``overturning=``): that design's width (m;
    #: with a vertical, the wider of the two motions'); :attr:`width` is at least it.  With
    #: ``overturning=True`` that design is checked only above the level's own design width
    #: (:attr:`overturning_above`): where it is wider it is the whole overturning design width,
    #: and where not, the whole one lies between it and :attr:`overturning_above`
    overturning_width: float | None = None
    #: ``overturning=True``: the level's own design width (m) above which its overturning design
    #: was checked (None where a whole overturning design was given, or without a level)
    overturning_above: float | None = None
    #: ``overturning=True``: that overturning design (its search, its check above
    #: :attr:`overturning_above`), with its own runs (:attr:`solver_runs`, on top of this one's)
    overturning_design: "RequiredWidth | None" = field(default=None, repr=False, compare=False)
    #: widths of :attr:`total_runs` that the overturning design had run in the same batch (same
    #: column, record and solver: the same computation), answered from it, not run again (with
    #: ``overturning=True``, the overturning design answers from the level's batches as well)
    shared_runs: int = 0
    #: a record's overturning design: every batch it ran, in order, as ``(widths, overturned,
    #: max|theta|/alpha)`` arrays (a level given this design reuses the same batches)
    outcomes: tuple | None = field(default=None, repr=False, compare=False)
    #: what the runs depend on (record and vertical hashed, height, restitution, frame, model):
    #: a level may reuse only the runs of the same inputs
    inputs: tuple | None = field(default=None, repr=False, compare=False)
    #: the column's shape (:mod:`rocking.bodies`): the width is a cylinder's diameter
    body: Body = field(default=RECTANGULAR, compare=False)
    #: a restitution band (``eta=`` a band :class:`rocking.restitution.Restitution`;
    #: :mod:`rocking.band`): the single values run (ends included), the design width of each (m),
    #: the value whose design width governs (the widest; ties: the lowest restitution), and each
    #: value's whole design (this answer's other fields are the governing value's)
    restitution_values: tuple = ()
    restitution_widths: tuple = ()
    restitution_governing: object = None
    band_designs: tuple = field(default=(), repr=False, compare=False)

    @property
    def total_runs(self) -> int:
        """Widths run by the search, the check and the refinement together (of which
        :attr:`shared_runs` were answered by the overturning design's runs: :attr:`solver_runs`)."""
        return int(self.runs) + int(self.check_runs) + int(self.refine_runs)

    @property
    def solver_runs(self) -> int:
        """Solver runs this design made itself: :attr:`total_runs` less :attr:`shared_runs`."""
        return self.total_runs - int(self.shared_runs)

    @property
    def tan_alpha(self) -> float:
        return self.width / self.height

    def as_dict(self) -> dict:
        """Every field but the check's arrays, with ``tan_alpha`` and ``p``: plain, JSON-safe
        numbers (widths and heights in m, ``p`` in rad/s).

        Examples
        --------
        >>> import rocking, pulses
        >>> w = rocking.required_width(7.5, pulses.make_pulse("sine", 3.0, 1.0), rule="eq31")
        >>> d = w.as_dict()
        >>> d["rule"], round(d["width"], 3) == round(w.width, 3)
        ('eq31', True)
        """
        from pulses.export import fields_dict

        return fields_dict(self, properties=("tan_alpha", "p"))

    def to_frame(self):
        """The check above the search width, one row per width checked (``width_m``,
        ``failed``); empty where there was no check."""
        import pandas as pd

        widths = np.asarray(self.check_widths if self.check_widths is not None else [], dtype=float)
        failed = np.asarray(self.check_failed if self.check_failed is not None else [], dtype=bool)
        return pd.DataFrame({"width_m": widths, "failed": failed})

    @property
    def block(self) -> Block:
        """The column at the design width (under a restitution band, with the value that governed)."""
        eta = self.restitution_governing if self.restitution_values else self.eta
        return Block.from_dimensions(self.height, self.width, eta, cap_mass_ratio=self.cap_mass_ratio,
                                     body=self.body)

    @property
    def p(self) -> float:
        return self.block.p

    @property
    def alpha(self) -> float:
        return math.atan2(self.width, self.height)


def _p_of(height, width, gamma=0.0, body=RECTANGULAR):
    if not body.is_rectangular:
        return _p_alpha(height, width, gamma, body)[0]
    return frame_p(math.sqrt(3.0 * G / (4.0 * math.hypot(height / 2.0, width / 2.0))), gamma)


RULES = ("eq31", "envelope", "eq20", "exact")


def required_width(height, excitation, *, rule="eq31", criterion="overturn", eta=None,
                   shape=None, lam=1.0, n_scan=None, n_zone=None, rtol=None, model="fast",
                   settings=DEFAULT_SETTINGS, cap_mass_ratio=0.0, vertical=None, limit=None,
                   horizontal=None, overturning=None, body=None, band_values=None):
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
        *design width*, see :class:`RequiredWidth`); works for pulses and records.
    criterion : {"overturn", "exceed"}
        Failure criterion of ``rule="exact"`` (``limit`` takes precedence).
    eta : float or rocking.restitution.Restitution, optional
        Restitution for the exact rule: a velocity ratio ``eta``, or a
        :class:`~rocking.restitution.Restitution` (a factor of Eq. 5 at each width, an ``eta`` or
        an ``r``; default Eq. 5 at each width).  A band (``Restitution.parse("0.95:1.05")``)
        gives the design covering it: ``band_values`` values (default
        :data:`rocking.band.BAND_VALUES`), ends included, each designed, the widest governing
        (``.restitution_values``, ``.restitution_widths``, ``.restitution_governing``).
    limit : float, optional
        ``rule="exact"``: the performance level R in (0, 1]: the design keeps ``max|theta|/alpha
        <= R`` (a width fails where it exceeds R or the column overturns); None (default):
        overturning, the paper's question.
    overturning : RequiredWidth or True, optional
        With ``limit`` under a record: its overturning design (same column, record, ``vertical``),
        or True: computed where it can change the level's (search, check above the level's width);
        the level with each motion is at least its overturning width (docs/design.md, "Performance levels").
    shape, lam : str (optional), float
        ``rule="envelope"``: the shape whose factor to use (default every shape); Eq. 20's lambda.
    n_scan, n_zone, rtol : int, int, float, optional
        ``rule="exact"``: scan points up to the no-uplift width ``H peak/g`` (pulse: uniform;
        record: geometric), points of the dense zone just above the widest failing width (0
        switches it off; for a record an extra zone, off by default) and the relative width of
        the final bracket; each overrides its field of ``settings``.  For a record only the top
        transition is refined, on adaptively chosen widths (resolution: :func:`_record_width`).
    settings : rocking.search.SearchSettings
        Settings of the exact searches (default :data:`rocking.search.DEFAULT_SETTINGS`).
    cap_mass_ratio : float
        The width of the columns of a rocking frame whose beam has this mass over the columns'
        total mass (docs/theory.md section 8: the frame's ``p`` and ``eta`` at each width); 0, a lone column.
    vertical : pulses.Record, optional
        ``rule="exact"`` under a record: its upward vertical acceleration on the same time axis
        (docs/theory.md section 10): every run uses the compiled engine with it; the no-uplift
        width is ``H max|ag|/(g + av)``; a vertical reaching -g (free flight) is refused.
    body : rocking.bodies.Body or str, optional
        The column's shape: rectangular (default) or ``"cylinder"`` (the width is its diameter;
        its ``p`` and impact rule, docs/theory.md "Bodies").

    Returns
    -------
    RequiredWidth
        ``.width``, ``.tan_alpha``, ``.p``, ``.rule``, ``.iterations``.

    Examples
    --------
    >>> import pulses, rocking
    >>> pulse = pulses.OneSine(ap=0.5 * pulses.G, tp=1.0)
    >>> [round(rocking.required_width(7.5, pulse, rule=r).width, 3) for r in ("eq31", "exact")]
    [2.17, 1.736]
    """
    from . import band

    eta = band.plain(eta)
    if band.is_band(eta):
        if rule != "exact":
            raise ValueError(f"rule={rule!r} does not depend on the restitution: a band goes with "
                             "rule='exact'")
        kw = dict(rule=rule, criterion=criterion, shape=shape, lam=lam, n_scan=n_scan,
                  n_zone=n_zone, rtol=rtol, model=model, settings=settings,
                  cap_mass_ratio=cap_mass_ratio, vertical=vertical, limit=limit, body=body)
        return band.required_width(height, excitation, eta, band_values, horizontal, overturning, kw)
    gamma, limit = check_cap_mass_ratio(cap_mass_ratio), check_limit(limit)
    body = Body.parse(body)
    check_frame(body, gamma)
    if not body.has_dimensions:
        raise ValueError("required_width: a custom body has no width to vary; check it as it "
                         "stands (rocking.simulate, rocking.eq31 at its p)")
    height = _check_arguments(height, rule, overturning, limit, vertical, excitation)
    if rule == "exact":
        kw = dict(criterion=criterion, eta=eta, n_scan=n_scan, rtol=rtol, model=model,
                  n_zone=n_zone, settings=settings, gamma=gamma, limit=limit, body=body)
        if vertical is None:
            return _exact_width(height, excitation, overturning=overturning, **kw)
        over_h, over_v = _motions(overturning, horizontal)
        return governing(horizontal or _exact_width(height, excitation, overturning=over_h, **kw),
                         _exact_width(height, excitation, vertical=vertical, overturning=over_v, **kw))
    if vertical is not None:
        raise ValueError("a vertical record goes with rule='exact' under a record")
    if not hasattr(excitation, "tp") or not hasattr(excitation, "ap"):
        raise ValueError(f"rule={rule!r} needs a pulse (ap, Tp); for a whole record fit its pulse "
                         "first or use rule='exact'")
    return _closed_form_width(height, excitation, rule, shape, lam, eta, gamma, body)


def _closed_form_width(height, excitation, rule, shape, lam, eta, gamma, body) -> RequiredWidth:
    """A closed form ``rule`` solved as a fixed point in the width (:func:`required_width`)."""
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
        new = height * f(_p_of(height, width, gamma, body))
        if abs(new - width) <= 1e-13 * max(height, 1.0):
            width = new
            break
        width = new
    else:  # pragma: no cover - the map is a strong contraction for any realistic column
        from scipy.optimize import brentq

        width = brentq(lambda b: b - height * f(_p_of(height, b, gamma, body)), 0.0,
                       height * ap / G + 1e-300,
                       xtol=1e-14)
    return RequiredWidth(width=float(width), height=height, rule=rule, iterations=it,
                         method=f"fixed point of {rule} in B (p depends on B): "
                                f"{it} iterations", eta=eta, cap_mass_ratio=gamma, body=body)


def _check_arguments(height, rule, overturning, limit, vertical, excitation) -> float:
    """``height`` as a float; ValueError for a bad height or rule, or where ``overturning=``
    cannot apply (see :func:`required_width`)."""
    height = float(height)
    if not (math.isfinite(height) and height > 0):
        raise ValueError(f"height must be positive, got {height!r} m")
    if rule not in RULES:
        raise ValueError(f"rule must be one of {RULES}, got {rule!r}")
    given = overturning is not None and overturning is not True
    if overturning is not None and (rule != "exact" or limit is None
                                    or (given and overturning.limit is not None)
                                    or (given and (vertical is None) != (overturning.governed_by is None))
                                    or getattr(excitation, "shape", "record") in SHAPES):
        raise ValueError("overturning= goes with rule='exact' under a record and a limit: True, or "
                         "the overturning design (limit=None) of the same column and record, with "
                         "the vertical where vertical= is given (and only there)")
    return height


def _motions(overturning, horizontal):
    """The overturning designs ``(horizontal motion alone, with the vertical)`` of a
    :func:`governing` answer (``(None, None)`` without one, ``(True, True)`` for True); ValueError
    where ``horizontal`` (the level's horizontal answer) was not designed given the same."""
    if overturning is None:
        return None, None
    if overturning is True:
        if horizontal is not None and horizontal.overturning_above is None:
            raise ValueError("horizontal= with overturning=True: the level's horizontal answer "
                             "designed with overturning=True too")
        return True, True
    pair = (overturning, overturning.other)
    over_h, over_v = pair if overturning.governed_by == "horizontal" else pair[::-1]
    if horizontal is not None and horizontal.overturning_width != over_h.width:
        raise ValueError("horizontal= with overturning=: the level's horizontal answer designed "
                         "given the horizontal overturning design (required_width(..., "
                         "overturning=)) of the same record")
    return over_h, over_v


def governing(horizontal, with_vertical):
    """The answer of the two designs (horizontal motion alone, and with the vertical) that asks
    for the wider column, with :attr:`RequiredWidth.governed_by`, both widths and the other answer
    (:attr:`RequiredWidth.other`) set.  Ties go to the horizontal motion."""
    vertical_governs = with_vertical.width > horizontal.width
    res, other = (with_vertical, horizontal) if vertical_governs else (horizontal, with_vertical)
    overs = [w.overturning_width for w in (horizontal, with_vertical)]
    return dataclasses.replace(
        res, governed_by="with vertical" if vertical_governs else "horizontal",
        horizontal_width=float(horizontal.width), vertical_width=float(with_vertical.width),
        other=other, overturning_width=None if None in overs else max(overs),
        method=res.method + (f"; governed by the {'horizontal motion with the vertical' if vertical_governs else 'horizontal motion alone'}"
                             f" ({horizontal.width:.6g} m alone, {with_vertical.width:.6g} m "
                             f"with the vertical)"))


def _uplift_ratio(record, vertical) -> float:
    """``max |ag| / (g + av)`` over the record's samples (``tan(alpha)`` of the widest column that
    uplifts with the vertical); RockingInputError where ``g + av`` reaches 0."""
    import numpy as np

    from .errors import RockingInputError

    if not hasattr(record, "pga") or getattr(vertical, "acc", None) is None \
            or np.shape(vertical.acc) != np.shape(record.acc):
        raise RockingInputError("a vertical record goes with a horizontal record of the same samples")
    gravity = G + np.asarray(vertical.acc, dtype=float)
    if np.min(gravity) <= 0.0:
        raise RockingInputError(f"the vertical reaches {np.max(-vertical.acc) / G:.3g} g downward: "
                                "the block would leave the ground, which the rocking model does "
                                "not describe; no design width can be found")
    return float(np.max(np.abs(record.acc) / gravity))


def _exact_width(height, excitation, *, criterion, eta, n_scan, rtol, model, n_zone=None,
                 settings=DEFAULT_SETTINGS, gamma=0.0, vertical=None, limit=None, overturning=None,
                 body=RECTANGULAR):
    _check_criterion(criterion)
    # wider than this the column never uplifts
    top = height * (_peak(excitation) / G if vertical is None else _uplift_ratio(excitation, vertical))
    if top <= 0:
        return RequiredWidth(0.0, height, "exact", 0, "no ground motion", criterion,
                             cap_mass_ratio=gamma, limit=limit, search_width=0.0, body=body)

    def run_widths(widths):  # not `runs`: that name counts the runs below
        blocks = Blocks.from_dimensions(height, widths, eta, cap_mass_ratio=gamma, body=body)
        if vertical is not None:
            import rocking

            return rocking.simulate_many(blocks, excitation, vertical=vertical)
        # verdicts and peaks only: each run stops once they are final (the same answers)
        return _batch(blocks, excitation, None, model=model, until_final=True)

    is_pulse = getattr(excitation, "shape", "record") in SHAPES
    if not is_pulse:
        inputs = (searches.digest(excitation.acc), float(excitation.dt),
                  None if vertical is None else (searches.digest(vertical.acc), float(vertical.dt)),
                  float(height), eta, float(gamma), model) + _body_key(body)
        runs = _Runs(run_widths, None if overturning is True else overturning, inputs)
        settings = settings.replace(record_scan=n_scan, rtol=rtol, record_zone_points=n_zone)
        res = _record_design(height, excitation, top, runs, criterion=criterion, eta=eta,
                             gamma=gamma, limit=limit, model=model, vertical=vertical,
                             settings=settings, overturning=overturning, body=body)
        res.inputs, res.body = inputs, body
        return res
    res = _pulse_width(height, top, lambda idx, widths: _failed(run_widths(widths), criterion, limit),
                       settings.replace(n_scan=n_scan, zone_points=n_zone, rtol=rtol))
    res.criterion, res.eta, res.cap_mass_ratio, res.limit = criterion, eta, gamma, limit
    res.search_width, res.body = res.width, body
    return res


def _body_key(body) -> tuple:
    """What a body adds to the keys of a search's runs and seeds: nothing for the rectangle (its
    keys, seeds and so its numbers are those of a package that knew no other body)."""
    return () if body.is_rectangular else (repr(body),)


class _Runs:
    """The solver runs of one record's exact design: ``outcomes(widths)`` gives whether each width
    of a batch overturned and its max|theta|/alpha.  A batch the overturning design
    (``overturning``, same ``inputs``) ran, the same widths in the same order, is answered from
    its :attr:`RequiredWidth.outcomes`, the others are run; it counts the widths so answered and
    keeps every batch.

    Only whole batches are shared: a run's last bits depend on its batch (its lanes share their
    Taylor order, its forcing grid follows its stiffest block), so the same width run in another
    batch agrees only to rounding, and the check's later stages, which rank widths by
    max|theta|/alpha, could then pick other widths (measured: 1 of 62 cases).  The same batch is
    the same computation, so the answer is the same as without the sharing, bit for bit.  The
    batch both designs run is the search's geometric scan (131 widths), the fine zone's blocks
    where their zones overlap (:func:`_run_down`), and the single widths
    at either end of their bisections where they meet."""

    def __init__(self, run_widths, overturning, inputs):
        self.run_widths, self.shared, self.inputs = run_widths, 0, inputs
        self.known = {}
        if overturning is not None and overturning.outcomes is not None:
            if overturning.inputs != inputs:
                raise ValueError("overturning= is the design of another record, vertical, column "
                                 "or model: the overturning design of the same ones")
            self.share(overturning.outcomes)
        self.log = []

    def share(self, batches):
        """Answer from now on each of ``batches`` (``(widths, overturned, max|theta|/alpha)``, run
        for the same inputs) from it where the same widths come again in the same order."""
        self.known.update((x.tobytes(), (o, r)) for x, o, r in batches)

    def outcomes(self, widths):
        widths = np.ascontiguousarray(widths, dtype=float)
        hit = self.known.get(widths.tobytes())
        if hit is not None:
            self.shared += widths.size
            over, ratio = hit
        else:
            res = self.run_widths(widths)
            over = np.asarray(res.overturned, dtype=bool).copy()
            ratio = np.asarray(res.max_rotation_ratio, dtype=float).copy()
        self.log.append((widths.copy(), over, ratio))
        return over.copy(), ratio.copy()


def _record_design(height, excitation, top, runs, *, criterion, eta, gamma, limit, model, vertical,
                   settings, overturning, body=RECTANGULAR):
    """The design width under a record: the search (kept between calls, :mod:`rocking.searches`),
    the check above it, and with ``overturning`` (a design, or True: :func:`_overturning_above`)
    at least that design's width."""
    def evaluate_record(widths):
        # max|theta|/alpha over the level (1 for overturning): the search's and the check's
        # "near failure" thresholds then hold for any level
        if criterion == "exceed" and limit is None:   # needs exceeded_alpha: no sharing
            res = runs.run_widths(widths)
            return _failed(res, criterion), np.asarray(res.max_rotation_ratio, dtype=float)
        over, ratio = runs.outcomes(widths)
        failed = over if limit is None else over | (ratio > limit)
        return failed, ratio / (limit or 1.0)

    def search():
        out = _record_search(height, top, evaluate_record, criterion=criterion, eta=eta, settings=settings)
        out[0].shared_runs, out[0].outcomes = runs.shared, tuple(runs.log)   # kept with it
        return out

    res, seen = searches.remembered(  # a batch's later pass: the same search (rocking.searches)
        searches.key(excitation, vertical, settings, height, criterion, eta, gamma, limit, model,
                     *_body_key(body)), search)
    shared, runs.shared, runs.log = res.shared_runs, 0, list(res.outcomes or ())
    res.cap_mass_ratio, res.limit, res.search_width, res.body = gamma, limit, res.width, body
    if vertical is not None:
        res.method += "; with the vertical record (compiled engine, fast-vertical)"
    if limit is not None:
        res.method += f"; a width fails where max|theta|/alpha > {limit:g}"
    reach = min(settings.check_reach * res.width, top)
    binned = settings.check_layout == "bins"   # separable: it runs only above check_above itself
    if not res.below_scan and settings.check_runs > 0 and (binned or reach > settings.check_above):
        seed = settings.check_seed
        if seed is None:
            seed = _record_seed(excitation, height, criterion, eta, gamma, limit, body)
        check = _check_bins if binned else _check_rounds
        seen = check(res, top, evaluate_record, settings, seed, seen)
    if overturning is True:
        overturning = _overturning_above(res, height, excitation, top, runs, eta=eta, gamma=gamma,
                                         model=model, vertical=vertical, settings=settings,
                                         body=body)
    if overturning is not None:
        res.overturning_width = float(overturning.width)
        if overturning.width > res.width:
            # a width that overturns fails every level: one run at the overturning design width,
            # and a bisection above it where that width exceeds the level
            _at_least(res, overturning, evaluate_record, seen, settings)
    seen = _on_digits(res, top, evaluate_record, seen, settings)
    res.shared_runs = shared + runs.shared
    # the batches run, for a level given this design (none kept otherwise: they serve no other)
    res.outcomes = tuple(runs.log) if limit is None and criterion == "overturn" else None
    return res


def _pulse_width(height, top, evaluate, settings):
    """A pulse's search width (scan and refinement of every verdict change)."""
    x = _scan_points(np.array([top]), settings.n_scan, settings.n_tail)
    known = np.zeros(x.shape, dtype=bool)
    known[:, -1] = True
    scan = _scan_refine(evaluate, x, settings, known=known, refine="all",
                        zone=settings.zone_points != 0)
    br = scan.brackets[0]
    width, n_iter, runs, below_scan = 0.0, scan.calls, scan.runs, False
    for lo, hi, flo, fhi in br:
        if flo and not fhi:
            width = hi
    if width == 0.0:
        # nothing scanned failed: look below the narrowest width, halving, for a failure
        down = x[0, 0] * 2.0 ** -np.arange(1, DOWN_HALVINGS + 1)
        failed = np.asarray(evaluate(np.zeros(down.size, dtype=int), down), dtype=bool)
        n_iter, runs = n_iter + 1, runs + down.size
        if failed.any():
            lo = down[np.nonzero(failed)[0][0]]
            hi = 2.0 * lo                       # examined (scan or halving): survives
            while hi - lo > settings.rtol * hi:
                mid = 0.5 * (lo + hi)
                if evaluate(np.zeros(1, dtype=int), np.array([mid]))[0]:
                    lo = mid
                else:
                    hi = mid
                n_iter, runs = n_iter + 1, runs + 1
            width = hi
        else:
            width, below_scan = down[-1], True
    return RequiredWidth(
        width=float(width), height=height, rule="exact", iterations=n_iter,
        method=(f"search width: scan of {x.shape[1]} widths up to the no-uplift width "
                f"{top:.4g} m (denser just above the widest failure), then bracketed "
                f"refinement of {len(br)} verdict change(s) ({scan.runs} solver runs in "
                f"{scan.calls} batches)"
                + ("; no width examined failed: the answer is at most this width"
                   if below_scan else "")),
        transitions=tuple(0.5 * (lo + hi) for lo, hi, _, _ in br), runs=runs,
        below_scan=below_scan)


def _first_runs(settings) -> int:
    n = int(settings.check_runs)
    return n - int(round(settings.check_follow * n))


def check_widths(width, top, settings=DEFAULT_SETTINGS, seed=0):
    """The widths (m, ascending) of the first stage of the check above a search ``width``
    (docs/slivers.md).

    ``settings.check_runs`` less the later stages' share (``settings.check_follow``, see
    :func:`follow_widths`) widths in ``(width, hi]``, ``hi = min(settings.check_span width,
    top)`` (``top``: the no-uplift width, above which nothing rocks): a share
    ``settings.check_near`` of them uniform in ``log d``, ``d = B / width - 1`` from
    ``settings.check_first`` to ``hi / width - 1`` (failing slivers cluster just above the
    search width: ``benchmarks/bench_slivers.py``), the others uniform in ``B`` over the whole
    span.  Each part is *jittered*: one uniformly random point in each of its equal strata, drawn
    from ``numpy.random.default_rng(seed)``, so that the widths are spread evenly, never lie on
    the search's fixed grid, and are the same for the same seed.  Empty where ``hi <= width``.
    """
    from . import binned   # the binned layout's first stage is this one

    return binned.first_widths(width, min(settings.check_span * width, top), settings, seed)


def follow_widths(width, top, widths, ratio, failed, n, settings=DEFAULT_SETTINGS, seed=0,
                  stage=1):
    """The ``n`` widths (m, ascending) of one later stage of the check (docs/slivers.md).

    They are spread over ``settings.check_bins`` equal bins of the span in proportion to
    ``q ** settings.check_power``, ``q`` the standard deviation of ``min(max|theta|/alpha, 1)``
    (``ratio``) over the ``widths`` run so far in the bin (those outside the span are left
    out), divided by the largest bin's, and 1 in
    a bin where one of them ``failed``: failing slivers far above the search width are isolated
    jumps of the response, found where it is irregular from one width to the next (or next to a
    failure), not where the block merely rocks hard.  Uniform where no bin varies.  Each bin's
    widths are jittered within it (``seed`` as for :func:`check_widths`; ``stage`` numbers the
    stream, one per stage)."""
    hi = min(settings.check_span * width, top)
    if n <= 0 or not hi > width * (1.0 + settings.check_first):
        return np.zeros(0)
    k = int(settings.check_bins)
    edges = np.linspace(width, hi, k + 1)
    widths = np.asarray(widths, dtype=float)
    inside = (widths > width) & (widths <= hi)
    ratio = np.minimum(np.asarray(ratio, dtype=float), 1.0)[inside]
    failed = np.asarray(failed, dtype=bool)[inside]
    idx = np.clip(np.searchsorted(edges, widths[inside]) - 1, 0, k - 1)
    count = np.maximum(np.bincount(idx, minlength=k), 1)
    mean = np.bincount(idx, weights=ratio, minlength=k) / count
    spread = np.sqrt(np.maximum(np.bincount(idx, weights=ratio * ratio, minlength=k) / count
                                - mean * mean, 0.0))
    q = spread / spread.max() if spread.max() > 0 else np.zeros(k)
    q[np.bincount(idx[failed], minlength=k) > 0] = 1.0
    weight = q ** settings.check_power
    weight = weight / weight.sum() if weight.sum() > 0 else np.full(k, 1.0 / k)
    share = weight * n
    alloc = np.floor(share).astype(int)
    alloc[np.argsort(alloc - share, kind="stable")[:n - alloc.sum()]] += 1   # largest remainders
    rng = np.random.default_rng([seed, stage])
    x = [edges[j] + (edges[j + 1] - edges[j]) * (np.arange(a) + rng.random(a)) / a
         for j, a in enumerate(alloc) if a > 0]
    return np.sort(np.concatenate(x))


def _record_seed(record, height, criterion, eta, gamma, limit=None, body=RECTANGULAR) -> int:
    """A seed made from the record's samples and the column (the same run, the same check)."""
    h = hashlib.sha256(np.ascontiguousarray(record.acc, dtype="<f8").tobytes())
    key = (float(record.dt), float(height), criterion, eta, float(gamma)) + _body_key(body)
    h.update(repr(key if limit is None else key + (float(limit),)).encode())
    return int.from_bytes(h.digest()[:8], "little")


def _check_rounds(res, top, evaluate, settings, seed, seen):
    """The check above the search's answer in ``settings.check_rounds`` rounds sharing
    ``settings.check_runs``: each checks above the design width so far (its span starts there)
    and raises it above the widest failing width found (:func:`_raise_to_failures`); the later
    rounds measure the spread over every width run before them.  Stores the outcome in ``res``;
    returns every width run ``(widths, failed, ratio)``."""
    rounds = int(settings.check_rounds)
    left = int(settings.check_runs)
    xs, fs, rs = (np.asarray(v) for v in seen)
    cx, cf = np.zeros(0), np.zeros(0, dtype=bool)
    base_method, notes = res.method, []
    # the last refinement's runs come out of the check's budget too (a bracket up to 1.6 % of the
    # width bisected to design_rtol), so that search + check + refinement stay within today's
    reserve = max(0, math.ceil(math.log2(0.016 / settings.design_rtol)))
    left = max(left - reserve, 0)
    for k in range(rounds):
        if k and min(settings.check_span ** (rounds - k) * res.width, top) <= settings.check_above:
            break  # the rounds left could not reach above check_above (SearchSettings)
        n = left // (rounds - k)
        left -= n
        before = res.refine_runs
        x, f, r = _add_check(res, top, evaluate, settings.replace(check_runs=n), seed + k,
                             (xs, fs, rs))
        notes.append(f"{x.size} widths from {res.width:.6g} m up to "
                     f"{min(settings.check_span * res.width, top):.6g} m, {int(f.sum())} failed")
        cx, cf = np.concatenate([cx, x]), np.concatenate([cf, f])
        xs, fs, rs = np.concatenate([xs, x]), np.concatenate([fs, f]), np.concatenate([rs, r])
        res.check_widths, res.check_failed = cx, cf
        _raise_to_failures(res, evaluate, (xs, fs), settings)
        left = max(left - (res.refine_runs - before), 0)     # a round's refinement: from the rest
    _store_check(res, (cx, cf), (xs, fs), min(settings.check_span * res.width, top),
                 base_method + f"; check above it in {rounds} round(s): " + "; ".join(notes))
    return xs, fs, rs


def _check_bins(res, top, evaluate, settings, seed, seen):
    """The check above the search's answer laid out bin by bin (:mod:`rocking.binned`; separable
    in a threshold: only the bins above ``settings.check_above`` run), then the design width raised
    above the widest failing width found (:func:`_raise_to_failures`).  Stores the outcome in
    ``res``; returns every width run ``(widths, failed, ratio)``."""
    from . import binned

    xs, fs, rs = (np.asarray(v) for v in seen)
    above = float(settings.check_above)
    if res.limit:   # the ratios are over the level: their spread is measured in max|theta|/alpha
        settings = settings.replace(check_scale=settings.check_scale / res.limit)
    (cx, cf, cr), hi = binned.check(res.width, top, evaluate, (xs, fs, rs), settings, seed, above)
    if not cx.size:   # no bin above check_above: as unchecked (the search's runs are above w)
        return xs, fs, rs
    xs, fs, rs = np.concatenate([xs, cx]), np.concatenate([fs, cf]), np.concatenate([rs, cr])
    _raise_to_failures(res, evaluate, (xs, fs), settings)
    where = f"above {above:.6g} m " if above > res.search_width else ""
    _store_check(res, (cx, cf), (xs, fs), hi,
                 res.method + f"; check above it in bins of {settings.check_bin_width:.2%} of it up "
                 f"to {hi:.6g} m: {cx.size} widths {where}run, {int(cf.sum())} failed")
    return xs, fs, rs


def _store_check(res, checked, seen, hi, method) -> None:
    """The check's outcome in ``res``: ``checked`` ``(widths, failed)`` the check ran, ``seen``
    every width run with its verdict, ``hi`` the span's top (m)."""
    cx, cf = (np.asarray(v) for v in checked)
    xs, fs = (np.asarray(v) for v in seen)
    order = np.argsort(cx, kind="stable")
    res.check_widths, res.check_failed = cx[order], cf[order].astype(bool)
    res.check_runs = int(cx.size)
    res.check_top = float(hi)
    res.failing_share = float(cf.mean()) if cx.size else 0.0
    known = np.concatenate([xs[fs.astype(bool)], [res.widest_failing_width or 0.0]])
    above = known[known > res.search_width]
    res.widest_failing_width = float(above.max()) if above.size else None
    res.method = method + (f"; design width {res.width:.6g} m, just above the widest "
                           f"failing width {res.widest_failing_width:.6g} m"
                           if res.widest_failing_width else "")


def _overturning_above(res, height, excitation, top, runs, *, eta, gamma, model, vertical,
                       settings, body=RECTANGULAR):
    """The overturning design of the level ``res`` (its search and check done, ``runs`` its runs)
    where it can change the level's answer: its search (answered from the level's batches where
    they coincide: the geometric scan, the fine zone's blocks where the two zones overlap), and
    its binned check only above the level's width
    (``check_above``).  That check is separable in a threshold (:mod:`rocking.binned`): it runs
    exactly the whole check's widths above it, so the design width is the whole overturning
    design's wherever that exceeds the level's, and at most the level's where not (then the
    whole one is too: docs/design.md, "Performance levels").  The rounds layout, not separable,
    is checked whole.  Sets ``res.overturning_above`` and ``res.overturning_design``."""
    own = _Runs(runs.run_widths, None, runs.inputs)
    own.share(runs.log)
    if settings.check_layout == "bins":
        settings = settings.replace(check_above=max(float(settings.check_above), float(res.width)))
    over = _record_design(height, excitation, top, own, criterion="overturn", eta=eta, gamma=gamma,
                          limit=None, model=model, vertical=vertical, settings=settings,
                          overturning=None, body=body)
    runs.share(over.outcomes)   # the level's run at its width and a bisection above: maybe run there
    res.overturning_above, res.overturning_design = float(res.width), over
    return over


def _at_least(res, overturning, evaluate, seen, settings) -> None:
    """A level's design ``res`` made at least the overturning design ``overturning`` (whose
    widest failing width overturned, so fails the level too): its width is run under the level;
    if it survives it is the design width, else the bracket above it is bisected
    (:func:`_raise_to_failures`, ``seen``: every width the level ran)."""
    x = np.array([float(overturning.width)])
    f, r = evaluate(x)
    res.refine_runs += 1
    known = overturning.widest_failing_width
    if not bool(np.asarray(f)[0]):
        res.width = float(x[0])
        res.widest_failing_width = max(res.widest_failing_width or 0.0, known or 0.0) or None
    else:
        xs, fs = (np.concatenate([np.asarray(seen[0], dtype=float), x]),
                  np.concatenate([np.asarray(seen[1], dtype=bool), np.asarray(f, dtype=bool)]))
        _raise_to_failures(res, evaluate, (xs, fs), settings)
    res.method += (f"; at least the overturning design width {overturning.width:.6g} m (a width "
                   f"that overturns fails every level)")


def _add_check(res, top, evaluate, settings, seed, seen=None):
    """One round of the check above ``res.width`` (``evaluate(widths)``: verdicts and
    max|theta|/alpha, one batch per stage): ``(widths, failed, ratio)`` in the order run.
    ``seen``: ``(widths, failed, ratio)`` already run; those above ``res.width`` join the later
    stages' measure of the spread at no cost."""
    x = check_widths(res.width, top, settings, seed)
    f, r = evaluate(x) if x.size else (np.zeros(0, dtype=bool), np.zeros(0))
    f, r = np.asarray(f, dtype=bool), np.asarray(r, dtype=float)
    if seen is None:
        seen = (np.zeros(0), np.zeros(0, dtype=bool), np.zeros(0))
    above = np.asarray(seen[0], dtype=float) > res.width
    sx, sf, sr = (np.asarray(v)[above] for v in seen)
    left = int(settings.check_runs) - _first_runs(settings)
    n_zoom = min(int(round(settings.check_zoom * int(settings.check_runs))), left)
    left -= n_zoom
    stages = int(settings.check_stages)
    for stage in range(1, stages + 1):
        n = left // (stages - stage + 1)
        left -= n
        y = follow_widths(res.width, top, np.concatenate([x, sx]), np.concatenate([r, sr]),
                          np.concatenate([f, sf.astype(bool)]), n, settings, seed, stage)
        if y.size:
            fy, ry = evaluate(y)
            x, f, r = (np.concatenate([x, y]), np.concatenate([f, np.asarray(fy, dtype=bool)]),
                       np.concatenate([r, np.asarray(ry, dtype=float)]))
    y = zoom_widths(res.width, top, np.concatenate([x, sx]), np.concatenate([r, sr]),
                    np.concatenate([f, sf.astype(bool)]), n_zoom, settings, seed)
    if y.size:
        fy, ry = evaluate(y)
        x, f, r = (np.concatenate([x, y]), np.concatenate([f, np.asarray(fy, dtype=bool)]),
                   np.concatenate([r, np.asarray(ry, dtype=float)]))
    return x, f, r


def zoom_widths(width, top, widths, ratio, failed, n, settings=DEFAULT_SETTINGS, seed=0):
    """The ``n`` widths (m, ascending) of the check's last stage (docs/slivers.md): around the
    surviving widths of the span that came nearest to failing (largest ``ratio``,
    max|theta|/alpha over the level), ``settings.check_zoom_points`` jittered widths each within
    ``settings.check_zoom_width`` relative (a failing sliver is often a cluster of thinner ones
    flanked by widths that rock nearly as hard: Imperial Valley El Centro 180 at 6 m fails on
    15 % of a stretch of 1.3e-4 of the width 5.7 % above the design width, the widths around it
    reaching 0.8-0.9 against 0.7 further off).  Peaks closer than two zoom widths count once."""
    hi = min(settings.check_span * width, top)
    k = int(settings.check_zoom_points)
    if n <= 0 or k <= 0 or not hi > width * (1.0 + settings.check_first):
        return np.zeros(0)
    widths, ratio = np.asarray(widths, dtype=float), np.asarray(ratio, dtype=float)
    keep = (widths > width) & (widths <= hi) & ~np.asarray(failed, dtype=bool)
    widths, ratio = widths[keep], ratio[keep]
    d = settings.check_zoom_width
    peaks = []
    for j in np.argsort(-ratio, kind="stable"):
        if len(peaks) * k >= n:
            break
        if all(abs(widths[j] / b - 1.0) > 2.0 * d for b in peaks):
            peaks.append(float(widths[j]))
    if not peaks:
        return np.zeros(0)
    rng = np.random.default_rng([seed, int(settings.check_stages) + 1])
    x = [b * (1.0 + d * (2.0 * (np.arange(k) + rng.random(k)) / k - 1.0)) for b in peaks]
    x = np.concatenate(x)
    return np.sort(x[(x > width) & (x <= hi)])[:n]


def _raise_to_failures(res, evaluate, seen, settings) -> None:
    """Raise ``res.width`` above every width found to fail: where one of ``seen`` (``(widths,
    failed)``, every width run) failed above it, bisect the bracket from the widest failing width
    up to the next width run (which survived) to ``settings.design_rtol`` relative and take its
    surviving end; widths found failing by the bisection move the bracket up."""
    x, f = np.asarray(seen[0], dtype=float), np.asarray(seen[1], dtype=bool)
    if not (f & (x > res.width)).any():
        return
    lo = float(x[f].max())
    hi = float(np.min(x[x > lo]))           # run, and survived (lo is the widest failure)
    while hi - lo > settings.design_rtol * hi:
        mid = 0.5 * (lo + hi)
        failed = bool(np.asarray(evaluate(np.array([mid]))[0])[0])
        res.refine_runs += 1
        lo, hi = (mid, hi) if failed else (lo, mid)
    res.width, res.widest_failing_width = hi, lo


def digits_up(width: float, digits: int) -> float:
    """The narrowest number of ``digits`` significant digits at or above ``width`` (> 0)."""
    w = float(f"{width:.{digits}g}")
    if w < width:
        w = float(f"{w + 10.0 ** (math.floor(math.log10(w)) - digits + 1):.{digits}g}")
    return w


def _on_digits(res, top, evaluate, seen, settings):
    """``res.width`` raised to the narrowest width of ``settings.design_digits`` significant digits
    at or above it that survives (SearchSettings: the reports print that many, so the width they
    print is one that was run); returns ``seen`` with the runs added.  A width above the no-uplift
    width ``top`` survives without a run (nothing uplifts there)."""
    if res.below_scan or not res.width > 0:
        return seen
    x, f, r = np.asarray(seen[0], dtype=float), np.asarray(seen[1], dtype=bool), np.asarray(seen[2], dtype=float)
    while True:
        w = digits_up(res.width, int(settings.design_digits))
        if w == res.width:
            break
        if w > top:
            res.width = w
            break
        failed, ratio = (np.asarray(v) for v in evaluate(np.array([w])))
        res.refine_runs += 1
        x, f, r = np.append(x, w), np.append(f, bool(failed[0])), np.append(r, float(ratio[0]))
        if not failed[0]:
            res.width = w
            break
        # the no-uplift width survives: the bracket's end where nothing wider was run
        _raise_to_failures(res, evaluate, (np.append(x, top), np.append(f, False)), settings)
    return x, f, r


#: how far below the scan's narrowest width (in halvings) the search looks for a failure
#: when nothing scanned failed
DOWN_HALVINGS = 40


def _record_width(height, top, evaluate, *, criterion, eta, settings=DEFAULT_SETTINGS):
    """The search width under a record (:func:`_record_search`'s answer without its widths)."""
    return _record_search(height, top, evaluate, criterion=criterion, eta=eta, settings=settings)[0]


def _record_search(height, top, evaluate, *, criterion, eta, settings=DEFAULT_SETTINGS):
    """The search width under a record: the smallest width above which every scanned width survives.
    Returns ``(RequiredWidth, (widths, failed, ratio))``, the second the widths run (ascending)
    with their verdicts and ``max|theta|/alpha``.

    A record's verdict can change hundreds of times with the width (slender columns rock
    chaotically; real records have isolated failing bands well above the main transition), so
    the answer is defined by the widths examined.  They are chosen to need few runs (a run that
    survives costs the whole record, and most runs here survive) while looking hardest where a
    failure is likely:

    The fields named below are those of ``settings`` (:class:`rocking.search.SearchSettings`).

    1. ``record_tail`` widths towards zero and ``record_scan`` widths geometric from ``top`` x
       ``record_low`` to the no-uplift width ``top`` (known to survive), one batch;
    2. the bracket above the widest failing width is bisected (so the highest change is the one
       followed) to ``record_zone_first`` / 4 relative: the candidate ``w``;
    3. (if ``record_zone_points``) a zone above it: that many widths ``w (1 + d)``, ``d`` geometric from
       ``record_zone_first`` to ``record_zone_fraction``;
    4. the fine zone: every width of the fixed grid ``top (1 + record_fine)^-k`` between ``w`` and
       ``w (1 + record_fine_span)`` not run yet (0.05 % apart, up to 20 % above ``w``), run from
       the widest down a block of ``record_chunk`` grid indices at a time and stopped at the
       first batch with a failure (the widths below it cannot move the answer);
    5. above ``w``, every gap between scanned widths wider than ``record_gap`` (relative) is
       halved, repeatedly, while either end reached ``max|theta|/alpha >= record_near``;
    6. a failure found in 3-5 moves the candidate up (back to 2; at most ``record_rounds``
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
    s = settings
    xs = _scan_widths(top, s)
    pts = scan.Points(lambda w: tuple(np.asarray(v, dtype=dt) for v, dt in zip(evaluate(w), (bool, float))),
                      xs[-1])  # top: no uplift
    pts.add(xs[:-1])
    br = _top_bracket(pts)
    narrowest = xs[0]
    for _ in range(DOWN_HALVINGS // 10):
        if br is not None:
            break
        # nothing scanned failed: halve below the narrowest width, ten at a time, until a width
        # fails (a tall column survives more than its scan's floor, top / 1024, suggests)
        down = narrowest * 2.0 ** -np.arange(1, 11)
        pts.add(down)
        narrowest = down[-1]
        br = _top_bracket(pts)
    br, rounds, limited = _rounds(pts, br, top, s)
    width, below_scan = narrowest, True
    if br is not None:
        width, below_scan = scan.bisect(pts, *_top_bracket(pts), s.rtol, fails_low=True)[1], False
    x, f, _ = pts.sorted()
    ch = np.nonzero(f[1:] != f[:-1])[0]
    transitions = tuple(float(t) for t in 0.5 * (x[ch] + x[ch + 1]))
    return RequiredWidth(
        width=float(width), height=height, rule="exact", iterations=pts.calls,
        method=_method(xs.size, top, rounds, limited, below_scan, pts, s),
        criterion=criterion, transitions=transitions, runs=pts.runs, eta=eta,
        below_scan=below_scan), pts.sorted()


def _scan_widths(top, s):
    """Step 1's widths, narrowest first, the no-uplift width ``top`` last."""
    n_scan = s.record_scan
    if s.record_spacing == "geometric":
        low = s.record_low
        xs = top * np.geomspace(low, 1.0, n_scan)
    else:
        low = 1.0 / n_scan
        xs = top * np.arange(1, n_scan + 1) / n_scan
    return np.concatenate([top * low * 2.0 ** -np.arange(s.record_tail, 0, -1), xs])


def _rounds(pts, br, top, s):
    """Steps 2-6: ``(top bracket or None, rounds, limited)``."""
    n_zone, rtol = s.record_zone_points, s.rtol
    fine_done = np.zeros(0)
    rounds = 0
    while br is not None and rounds < s.record_rounds:
        rounds += 1
        lo, hi = scan.bisect(pts, *br, max(s.record_zone_first / 4.0, rtol), fails_low=True)
        found = False
        if n_zone > 0:
            z = hi * (1.0 + np.geomspace(s.record_zone_first, s.record_zone_fraction, int(n_zone)))
            z = z[z < top]
            found = bool(z.size) and bool(pts.add(z).any())
        if not found and s.record_fine > 0:
            # every width of the fixed fine grid top (1 + s.record_fine)^-k in (hi, hi (1 + s.record_fine_span)]
            # not run yet (a later round only adds the part above the previous one)
            k_hi = math.floor(math.log(top / hi) / math.log1p(s.record_fine))
            k_lo = max(math.ceil(math.log(top / (hi * (1.0 + s.record_fine_span))) / math.log1p(s.record_fine)), 1)
            k = np.arange(k_lo, k_hi + 1)
            z = top * (1.0 + s.record_fine) ** -k.astype(float)
            keep = (z > hi) & (z < top) & ~np.isin(z, fine_done)
            z, k = z[keep], k[keep]
            if z.size:
                fine_done = np.union1d(fine_done, z)
                found = _run_down(pts, z, k // s.record_chunk)
        while not found:
            mids = _near_gaps(pts, hi, s)
            if not mids.size:
                break
            found = bool(pts.add(mids).any())
        if not found:
            return br, rounds, False
        br = _top_bracket(pts)
    return br, rounds, br is not None   # limited: failures were still being found above the candidate


def _run_down(pts, widths, groups) -> bool:
    """Run ``widths`` from the widest down, a group at a time (``groups``: each width's, numbered
    from the widest), stopping after the first group with a failure: narrower widths cannot
    change the answer (it lies above the widest failure), so they are not run.  Returns whether
    any failed.

    The groups are fixed blocks of the fine grid (its index over ``record_chunk``), not counted
    from where a zone starts: two searches of the same column and record (a level's and its
    overturning design's) whose zones overlap then run the same batches there, which the second
    answers from the first (:class:`_Runs`: only a whole batch is the same computation)."""
    order = np.argsort(widths)[::-1]
    widths, groups = np.asarray(widths, dtype=float)[order], np.asarray(groups)[order]
    for g in np.unique(groups):
        if pts.add(widths[groups == g]).any():
            return True
    return False


def _top_bracket(pts):
    x, f, _ = pts.sorted()
    if not f.any():
        return None
    j = np.nonzero(f)[0][-1]
    return x[j], x[j + 1]                     # x[-1] = top survives, so j + 1 exists


def _near_gaps(pts, w, s):
    """Midpoints of the gaps above ``w`` to halve (step 5)."""
    x, f, r = pts.sorted()
    sel = x >= w
    x, r = x[sel], r[sel]
    wide = (x[1:] - x[:-1]) > s.record_gap * x[:-1]
    near = np.maximum(r[1:], r[:-1]) >= s.record_near
    m = np.nonzero(wide & near)[0]
    return 0.5 * (x[m] + x[m + 1])


def _method(n_scanned, top, rounds, limited, below_scan, pts, s) -> str:
    n_zone = s.record_zone_points
    return (f"search width: scan of {n_scanned} widths up to the no-uplift width {top:.4g} m, "
            f"then {rounds} round(s) of bisection above the widest failure and checks above "
            f"it (widths {s.record_fine:.2%} apart up to {s.record_fine_span:.0%} above, "
            + (f"a zone of {int(n_zone)} widths up to {s.record_zone_fraction:.0%} above, " if n_zone else "")
            + f"gaps halved to {s.record_gap:.0%} where the block nearly tipped"
            + ("; round limit reached" if limited else "")
            + ("; no width examined failed: the answer is at most this width"
               if below_scan else "")
            + f"); {pts.runs} solver runs in {pts.calls} batches")

