"""Section 1 of RESULTS.md, the solver: speed against error.

Work-precision of every model and setting on (a) pulses, (b) real records, (c) near-overturning
cases (wrong verdicts), the fast engine with each stepping method (``taylor``, the default;
``rk8``; ``rk4``); the issue-2 ratio (fast, default method and rk8 side by side, against the
usual approach on a 20 s, 200 Hz record).
"""
from __future__ import annotations

import math
import statistics
import time

import numpy as np

from benchmarks.common import (USUAL_DEFAULT, blocks, default_method, fmt_e, fmt_t, headline_record, log,
                               method_label, per_call, steps_per_tp, timed)


class Setting:
    """One model and setting of the work-precision study.

    ``method``: the fast engine's stepper ("taylor", "rk8", "rk4"); ``res``: steps per pulse
    period (pulses) or sub-steps per sample (records); ``steps``: steps per pulse period when
    ``res`` is None (the ``ph_max`` sweeps on pulses; None = 200).
    """

    def __init__(self, label, family, kind, res=None, method="taylor", ph_max=None, usual=None, slow=False,
                 steps=None):
        self.label, self.family, self.kind, self.res = label, family, kind, res
        self.method, self.ph_max, self.usual, self.slow = method, ph_max, usual, slow
        self.steps = steps

    def run(self, block, exc):
        """(overturned, max|theta|/alpha)."""
        import rocking
        from pulses import G, Record

        if self.kind == "usual":
            from benchmarks.baseline import simulate_usual

            r = simulate_usual(block, exc, **self.usual)
            return r.overturned, r.max_rotation_ratio
        if self.kind in ("linear", "reference"):
            r = rocking.simulate(block, exc, model=self.kind, history=False)
            return r.overturned, r.max_rotation_ratio
        ph = self.ph_max
        if isinstance(exc, Record):
            if self.res is not None:  # res = sub-steps per sample
                ph = exc.dt * block.p * math.sqrt(1.0 + exc.pga / G) / self.res
            r = rocking.simulate(block, exc, model="fast", method=self.method, ph_max=ph, history=False)
            return r.overturned, r.max_rotation_ratio
        steps = self.res if self.res is not None else (self.steps or 200)
        with steps_per_tp(steps):
            r = rocking.simulate(block, exc, model="fast", method=self.method, ph_max=ph, history=False)
        return r.overturned, r.max_rotation_ratio


#: the fast engine's stepping methods in the work-precision study: (method, family label)
FAST_FAMILIES = (("taylor", "fast taylor"), ("rk8", "fast rk8"), ("rk4", "fast rk4"))


def settings(kind: str):
    """Settings for ``kind`` = "pulse" or "record"."""
    from rocking import solver

    out = []
    default_n, default_ph = solver.STEPS_PER_TP, solver.PH_MAX

    def dflt(value, default):
        return " (default)" if value == default else ""

    # per method: steps per Tp (pulses) or sub-steps per sample (records), and ph_max values; the
    # ph_max sweeps on pulses run at ``ph_steps`` steps per Tp (the default for taylor and rk8,
    # where the ph_max cap then binds for the longer pulses; 200 for rk4, which needs small steps)
    if kind == "pulse":
        plan = {"taylor": (sorted({4, 8, default_n, 50}), (0.1, default_ph, 0.5), default_n),
                "rk8": (sorted({12, default_n, 50, 200}), (0.1, 0.4), default_n),
                "rk4": ((200, 400, 800, 1600), (0.1, 0.025), 200)}
    else:
        plan = {"taylor": ((1, 2, 4), (0.1, 0.5), None),
                "rk8": ((1, 2, 4), (0.1, 0.4), None),
                "rk4": ((1, 2, 4, 8), (0.1, 0.025), None)}
    for method, family in FAST_FAMILIES:
        name = method_label(method)
        ress, phs, ph_steps = plan[method]
        ph_default = solver._default_ph_max(method)
        for n in ress:
            if kind == "pulse":
                label = f"{name}, {n} steps/Tp{dflt(n, default_n)}"
            else:
                label = f"{name}, {n} sub-step/sample{dflt(n, 1)}"
            out.append(Setting(label, family, "fast", res=n, method=method))
        for ph in phs:
            at = f" at {ph_steps} steps/Tp{dflt(ph_steps, default_n)}" if kind == "pulse" else ""
            out.append(Setting(f"{name}, ph_max {ph:g}{dflt(ph, ph_default)}{at}", family + " ph_max", "fast",
                               method=method, ph_max=ph, steps=ph_steps))
    out.append(Setting("linear", "linear", "linear"))
    out.append(Setting("reference (DOP853 rtol 1e-12, split at samples)", "reference", "reference", slow=True))
    out.append(Setting("usual: RK45 default tol (issue 2 baseline)", "usual RK45", "usual",
                       usual=USUAL_DEFAULT, slow=True))
    out.append(Setting("usual: RK45 rtol 1e-10 atol 1e-12", "usual RK45", "usual",
                       usual=dict(method="RK45", rtol=1e-10, atol=1e-12), slow=True))
    out.append(Setting("usual: DOP853 default tol", "usual DOP853", "usual",
                       usual=dict(method="DOP853", rtol=1e-3, atol=1e-6), slow=True))
    out.append(Setting("usual: DOP853 rtol 1e-10 atol 1e-12", "usual DOP853", "usual",
                       usual=dict(method="DOP853", rtol=1e-10, atol=1e-12), slow=True))
    return out


def _tight(s: Setting) -> bool:
    return s.kind == "usual" and s.usual["rtol"] < 1e-6


def work_precision(cases, sets, ref, n_tight, repeat):
    """For each setting: errors against ``ref`` and median time per run.

    ``cases``: list of (label, block, excitation); ``ref``: list of (overturned, ratio).
    Returns {label: dict(errors, wrong, time, n)}.
    """
    out = {}
    for s in sets:
        errs, wrong, times, n_both_over, n = [], 0, [], 0, 0
        for k, (label, block, exc) in enumerate(cases):
            if s.kind == "reference":
                break
            if _tight(s) and k >= n_tight:
                continue
            if s.slow:
                (over, ratio), sec = timed(lambda: s.run(block, exc))
            else:
                over, ratio = s.run(block, exc)
                sec = per_call(lambda: s.run(block, exc), budget=0.02, repeat=repeat)
            times.append(sec)
            n += 1
            r_over, r_ratio = ref[k]
            if over != r_over:
                wrong += 1
            elif over:
                n_both_over += 1
            else:
                errs.append(abs(ratio - r_ratio))
        bests = [getattr(t, "best", t) for t in times]
        out[s.label] = dict(errors=errs, wrong=wrong, time=statistics.median(times) if times else math.nan,
                            best=statistics.median(bests) if bests else math.nan,
                            n=n, both_over=n_both_over, setting=s)
    return out


def pulse_cases(quick):
    """Pulses of all shapes on the Temple column, at fractions of their first overturning amplitude.

    For each shape and pTp a scan with the fast batch solver finds the smallest overturning
    ``ap/(g tan alpha)``; the cases sit at 60 % and 95 % of it (strong rocking, surviving).
    """
    import rocking
    from pulses import G, make_pulse

    blk = blocks()["Temple column 7.5x1.8 m"]
    ptps = (1.0, 2.5, 6.0) if not quick else (1.0, 2.5)
    cases = []
    for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
        for ptp in ptps:
            tp = ptp / blk.p
            t0 = 0.0 if shape in ("rect", "sine") else 3.0 * tp
            unit = make_pulse(shape, G * blk.tan_alpha, tp, t0)
            xs = np.linspace(1.0, 12.0, 441)
            idx = np.flatnonzero(rocking.simulate_many(blk, unit, xs).overturned)
            x_over = xs[idx[0]] if idx.size else None
            ratios = [max(1.05, f * x_over) for f in (0.6, 0.95)] if x_over else [2.0, 4.0]
            for ratio in ratios:
                cases.append((f"{shape} pTp={ptp:g} ap/gtan={ratio:.3g}", blk, unit.scaled(ratio)))
    return cases


def record_cases(records, quick):
    """Each record on each block, scaled to the strongest of a few levels that the block survives."""
    import rocking
    from pulses import G

    cases = []
    bl = blocks()
    for i, rec in enumerate(records):
        for name, blk in bl.items():
            if name != "Temple column 7.5x1.8 m" and i >= (0 if quick else 2):
                continue
            chosen = None
            for level in (3.0, 2.5, 2.0, 1.6, 1.3):
                scale = level * G * blk.tan_alpha / rec.pga
                r = rocking.simulate(blk, rec.scaled(scale), model="fast", history=False)
                if not r.overturned and r.max_rotation_ratio < 0.95:
                    chosen = (level, scale)
                    break
            level, scale = chosen if chosen else (1.3, 1.3 * G * blk.tan_alpha / rec.pga)
            cases.append((f"{rec.name} x{scale:.3g} (PGA = {level:g} g tan alpha), {name.split()[0]}",
                          blk, rec.scaled(scale)))
    return cases


def reference_results(cases):
    import rocking

    out, times = [], []
    for label, block, exc in cases:
        r, sec = timed(lambda: rocking.simulate(block, exc, model="reference", history=False))
        out.append((r.overturned, r.max_rotation_ratio))
        times.append(sec)
    return out, statistics.median(times)


def find_transitions(quick):
    """Overturning transitions: amplitude (pulses) or scale (record) where the verdict changes.

    A scan with the fast batch solver brackets the first overturning amplitude; the fast model
    bisects it to 1e-12; the reference model then bisects inside +-1e-5 of that to 1e-10, and
    its answer is the transition.  Returns a list of (label, block, make(x), x_star, seconds).
    """
    import rocking
    from pulses import G, make_pulse

    blk = blocks()["Temple column 7.5x1.8 m"]
    specs = []
    ptps = (1.105, 4.0) if not quick else (1.105,)
    for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
        for ptp in ptps:
            tp = ptp / blk.p
            t0 = 0.0 if shape in ("rect", "sine") else 3.0 * tp
            unit = make_pulse(shape, G * blk.tan_alpha, tp, t0)  # x = ap / (g tan alpha)
            specs.append((f"{shape}, pTp = {ptp:g}", unit))
    out = []
    for label, unit in specs:
        t_case = time.perf_counter()
        xs = np.linspace(1.0, 12.0, 441)
        over = rocking.simulate_many(blk, unit, xs).overturned
        idx = np.flatnonzero(over)
        if idx.size == 0 or idx[0] == 0:
            continue
        lo, hi = xs[idx[0] - 1], xs[idx[0]]
        make = (lambda x, unit=unit: unit.scaled(x))

        def verdict(x, model):
            return rocking.simulate(blk, make(x), model=model, history=False).overturned

        found = _fast_and_reference_transition(verdict, lo, hi)
        if found is None:
            log(f"  {label}: reference does not bracket the fast transition within 1e-5; skipped")
            continue
        x_fast, x_ref = found
        out.append((label, blk, make, x_ref, x_fast, time.perf_counter() - t_case))
        log(f"  transition {label}: ap/(g tan alpha) = {x_ref:.10f} (fast: {x_fast / x_ref - 1:+.1e} rel.)")
    return out


def _bisect(fails, lo, hi, rtol):
    """Narrow ``[lo, hi]`` (``fails(lo)`` False, ``fails(hi)`` True) to ``rtol``; the midpoint."""
    while hi - lo > rtol * hi:
        mid = 0.5 * (lo + hi)
        if fails(mid):
            hi = mid
        else:
            lo = mid
    return 0.5 * (lo + hi)


def _fast_and_reference_transition(verdict, lo, hi):
    """The overturning transition in ``[lo, hi]`` by the fast model (to 1e-12), then by the
    reference inside +-1e-5 of it (to 1e-10): ``(x_fast, x_ref)``, or None if the reference does
    not change its verdict there."""
    x_fast = _bisect(lambda x: verdict(x, "fast"), lo, hi, 1e-12)
    lo, hi = x_fast * (1 - 1e-5), x_fast * (1 + 1e-5)
    if verdict(lo, "reference") or not verdict(hi, "reference"):
        return None
    return x_fast, _bisect(lambda x: verdict(x, "reference"), lo, hi, 1e-10)


def record_transition(rec):
    """Scale of ``rec`` at which the Temple column first overturns (same procedure)."""
    import rocking

    blk = blocks()["Temple column 7.5x1.8 m"]
    from pulses import G

    t_case = time.perf_counter()
    base = G * blk.tan_alpha / rec.pga
    xs = base * np.linspace(1.0, 6.0, 251)
    over = rocking.simulate_many(blk, rec, xs).overturned
    idx = np.flatnonzero(over)
    if idx.size == 0 or idx[0] == 0:
        return None
    lo, hi = xs[idx[0] - 1], xs[idx[0]]

    def verdict(x, model):
        return rocking.simulate(blk, rec.scaled(x), model=model, history=False).overturned

    found = _fast_and_reference_transition(verdict, lo, hi)
    if found is None:
        return None
    x_fast, x_ref = found
    log(f"  transition {rec.name}: scale {x_ref:.10f} (fast: {x_fast / x_ref - 1:+.1e} rel.)")
    return (f"{rec.name} (record scale)", blk, (lambda x: rec.scaled(x)), x_ref, x_fast,
            time.perf_counter() - t_case)


def transition_study(trans, sets):
    """Wrong verdicts per model at x* (1 +- d), d = 1e-2, 1e-4, 1e-6; truth = the reference there."""
    import rocking

    deltas = (1e-2, 1e-4, 1e-6)
    wrong = {s.label: {d: 0 for d in deltas} for s in sets if s.kind != "reference"}
    n_points = {d: 0 for d in deltas}
    ref_disagree = 0
    for label, blk, make, x_ref, x_fast, _ in trans:
        for d in deltas:
            for sign in (-1, 1):
                exc = make(x_ref * (1 + sign * d))
                truth = rocking.simulate(blk, exc, model="reference", history=False).overturned
                if truth != (sign > 0):
                    ref_disagree += 1
                n_points[d] += 1
                for s in sets:
                    if s.kind == "reference":
                        continue
                    over, _ = s.run(blk, exc)
                    if over != truth:
                        wrong[s.label][d] += 1
    return wrong, n_points, ref_disagree


def headline(quick):
    """Issue 2: the fast engine against the usual approach on a 20 s record at 200 Hz."""
    import rocking
    from benchmarks.baseline import simulate_usual

    rec = headline_record()
    blk = blocks()["Temple column 7.5x1.8 m"]
    scale = 1.0
    for scale in (1.0, 0.9, 0.8, 0.7, 0.6, 0.5):
        r = rocking.simulate(blk, rec.scaled(scale), model="fast", history=False)
        if not r.overturned:
            break
    exc = rec.scaled(scale)
    ref = rocking.simulate(blk, exc, model="reference", history=False)
    fast = rocking.simulate(blk, exc, model="fast", history=False)  # the default method
    rk8 = rocking.simulate(blk, exc, model="fast", method="rk8", history=False)  # the previous default
    usual = simulate_usual(blk, exc, **USUAL_DEFAULT)
    n_round = 3 if quick else 7
    t_fast, t_fast_hist, t_usual, t_many, t_rk8, t_many_rk8 = [], [], [], [], [], []
    for _ in range(n_round):  # interleaved, so the ratios see the same machine state
        t_fast.append(per_call(lambda: rocking.simulate(blk, exc, model="fast", history=False),
                               budget=0.05, repeat=3))
        t_rk8.append(per_call(lambda: rocking.simulate(blk, exc, model="fast", method="rk8", history=False),
                              budget=0.05, repeat=3))
        t_fast_hist.append(per_call(lambda: rocking.simulate(blk, exc, model="fast"), budget=0.05, repeat=3))
        t_many.append(timed(lambda: rocking.simulate_many([blk] * 200, exc))[1] / 200)
        t_many_rk8.append(timed(lambda: rocking.simulate_many([blk] * 200, exc, method="rk8"))[1] / 200)
        t_usual.append(timed(lambda: simulate_usual(blk, exc, **USUAL_DEFAULT))[1])
    # batch engine (rocking.lanes) against the same runs one by one, one core (< 256 runs: no
    # threads): 200 widths of the column up to 20 % wider, as a width search runs them
    wide = [rocking.Block.from_dimensions(7.5, 1.8 * (1.0 + 0.2 * k / 199)) for k in range(200)]
    t_lanes, t_one = [], []
    for _ in range(max(2, n_round // 2)):
        t_lanes.append(timed(lambda: rocking.simulate_many(wide, exc))[1] / 200)
        t_one.append(timed(lambda: rocking.simulate_many(wide, exc, lanes=False))[1] / 200)
    ratios = [u / f for u, f in zip(t_usual, t_fast)]
    ratios_rk8 = [u / f for u, f in zip(t_usual, t_rk8)]
    e_fast = abs(fast.max_rotation_ratio - ref.max_rotation_ratio)
    e_rk8 = abs(rk8.max_rotation_ratio - ref.max_rotation_ratio)
    e_usual = abs(usual.max_rotation_ratio - ref.max_rotation_ratio)
    return dict(record=rec.name, scale=scale, npts=exc.npts, ref_ratio=ref.max_rotation_ratio,
                ref_over=ref.overturned, n_impacts=ref.n_impacts, fast_ratio=fast.max_rotation_ratio,
                usual_ratio=usual.max_rotation_ratio, usual_restarts=usual.n_restarts,
                method=default_method(),
                t_fast=statistics.median(t_fast), t_fast_best=min(t.best for t in t_fast),
                t_usual_best=min(t_usual), t_fast_hist=statistics.median(t_fast_hist),
                t_many=statistics.median(t_many), t_usual=statistics.median(t_usual),
                t_lanes=statistics.median(t_lanes), t_one=statistics.median(t_one),
                lanes_ratio=statistics.median(t_usual) / statistics.median(t_lanes),
                speed_ratio=statistics.median(ratios), speed_ratio_min=min(ratios),
                e_fast=e_fast, e_usual=e_usual,
                acc_ratio=(e_usual / e_fast) if e_fast > 0 else math.inf, n_round=n_round,
                t_rk8=statistics.median(t_rk8), t_rk8_best=min(t.best for t in t_rk8),
                t_many_rk8=statistics.median(t_many_rk8), e_rk8=e_rk8,
                speed_ratio_rk8=statistics.median(ratios_rk8), speed_ratio_rk8_min=min(ratios_rk8),
                rk8_over_default=statistics.median([r / f for r, f in zip(t_rk8, t_fast)]),
                acc_ratio_rk8=(e_usual / e_rk8) if e_rk8 > 0 else math.inf)


def measure(quick, records, rec_notes):
    """Section 1: the headline ratio, work-precision on pulses and records, verdicts near transitions.

    ``records``: the real records (:func:`benchmarks.common.load_records`); ``rec_notes``: what
    happened to the absent ones.  Returns plain data for :func:`benchmarks.results.solver_section`.
    """
    from rocking import solver

    log("solver: headline (issue 2 ratio on a 20 s, 200 Hz record)")
    h = headline(quick)
    log(f"  fast ({h['method']}) {fmt_t(h['t_fast'])}, rk8 {fmt_t(h['t_rk8'])}, usual {fmt_t(h['t_usual'])}, "
        f"ratio {h['speed_ratio']:.0f}x (rk8: {h['speed_ratio_rk8']:.0f}x); errors fast {fmt_e(h['e_fast'])}, "
        f"rk8 {fmt_e(h['e_rk8'])}, usual {fmt_e(h['e_usual'])}")

    log("solver: (a) pulses of all shapes: reference")
    pcases = pulse_cases(quick)
    pref, pref_t = reference_results(pcases)
    log(f"  {len(pcases)} pulse cases, reference median {fmt_t(pref_t)}; the other models ...")
    psets = settings("pulse")
    pres = work_precision(pcases, psets, pref, n_tight=len(pcases) if not quick else 4, repeat=3)
    for s in psets:
        if s.kind == "reference":
            pres[s.label]["n"] = len(pcases)

    log("solver: (b) real records: reference")
    rcases = record_cases(records, quick)
    rres, rref_t = None, None
    if rcases:
        rref, rref_t = reference_results(rcases)
        log(f"  {len(rcases)} record cases, reference median {fmt_t(rref_t)}; the other models ...")
        rsets = settings("record")
        rres = work_precision(rcases, rsets, rref, n_tight=2 if quick else 4, repeat=3)
        for s in rsets:
            if s.kind == "reference":
                rres[s.label]["n"] = len(rcases)

    log("solver: (c) near-overturning cases: transitions")
    trans = find_transitions(quick)
    tsets = [s for s in settings("pulse") if s.kind != "reference"]
    log(f"  {len(trans)} transitions; verdicts of every model at x*(1 +- 1e-2, 1e-4, 1e-6) ...")
    wrong, n_points, ref_disagree = transition_study(trans, tsets)
    rtrans, rwrong, rn_points = [], None, None
    if records and not quick:
        rt = record_transition(records[0])
        if rt:
            rtrans = [rt]
            rsets_t = [s for s in settings("record") if s.kind != "reference" and not _tight(s)]
            rwrong, rn_points, rdis = transition_study(rtrans, rsets_t)
            ref_disagree += rdis

    return dict(headline=h, pulse_cases=[c[0] for c in pcases], pulses=plain_results(pres), pulses_ref_time=pref_t,
                record_cases=[c[0] for c in rcases], records=plain_results(rres) if rres else None,
                records_ref_time=rref_t, record_notes=list(rec_notes), n_tight_records=2 if quick else 4,
                transitions=[dict(label=label, x_ref=x_ref, x_fast=x_fast, seconds=sec)
                             for label, blk, make, x_ref, x_fast, sec in trans + rtrans],
                wrong=wrong, n_points=n_points, ref_disagree=ref_disagree,
                record_wrong=rwrong, record_n_points=rn_points,
                steps_per_tp=solver.STEPS_PER_TP, ph_max=solver.PH_MAX, ph_max_rk4=solver.PH_MAX_RK4)


def plain_results(res):
    """:func:`work_precision`'s results with each :class:`Setting` replaced by what the report needs."""
    return {label: dict({k: v for k, v in r.items() if k != "setting"}, kind=r["setting"].kind,
                        family=r["setting"].family, slow=r["setting"].slow)
            for label, r in res.items()}
