"""Speed against error: regenerate ``benchmarks/RESULTS.md`` and its plots on this machine.

    python -m benchmarks            # the full report (under 10 minutes on the 2-core machine)
    python -m benchmarks --quick    # a smaller version of every section (about 2-3 minutes)
    python benchmarks/run.py --only solver,linear   # some sections only (the report says which)
    python -m benchmarks --quick --out /tmp/bench   # write the report somewhere else

Every figure is measured in the same run, side by side; times are medians of repeated runs (or a
single run for the slow models, said so where it applies).  The machine (CPU, cores, load, Python
and library versions) is written at the top of the report, and a calibration timing is taken at
the start and at the end, so that drift of the machine's speed during the run is visible; the
headline speed figures are ratios measured interleaved, which drift cancels.

Sections:

``solver``      work-precision of every model and setting on (a) pulses, (b) real records,
                (c) near-overturning cases (wrong verdicts), the fast engine with each stepping
                method (``taylor``, the default; ``rk8``; ``rk4``); the log-log plot of time against
                error; the issue-2 ratio (fast, default method and rk8 side by side, against the
                usual approach on a 20 s, 200 Hz record).
``linear``      the linearised model's error against alpha, and where ``model="auto"`` switches.
``cost``        time against record length (10 s to 1 h) and against blocks in a batch;
                the 100 x 100 spectrum grid; ``pipeline simulate`` cold start.
``fit``         the pulse fitter: time against record length, error against noise and Tp.
``design``      issue 4's timings.
``pipeline``    ``pipeline run`` throughput against ``--jobs`` and record length.
"""
from __future__ import annotations

import argparse
import contextlib
import io
import math
import os
import pathlib
import platform
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

RECORDS_DIR = pathlib.Path(os.environ.get("ROCKING_RECORDS", ROOT.parent / "shared" / "records" / "raw"))

#: where RESULTS.md and the plots go (``--out``; default this folder)
OUT = HERE

SECTIONS = ("solver", "linear", "cost", "fit", "design", "pipeline")

T_START = time.perf_counter()


# =========================================================================== utilities
def log(msg: str) -> None:
    print(f"[{time.perf_counter() - T_START:7.1f} s] {msg}", flush=True)


class TStat(float):
    """A median time (s) that also carries the best (smallest) sample as ``.best``."""

    best = math.nan


def _tstat(times):
    out = TStat(statistics.median(times))
    out.best = min(times)
    return out


def per_call(fn, budget: float = 0.15, repeat: int = 5) -> float:
    """Median time (s) of one call of ``fn`` (a :class:`TStat`, with ``.best``); fast calls are
    looped so each sample is ~budget/repeat."""
    fn()  # warm-up (caches, first-call dispatch)
    t = time.perf_counter()
    fn()
    first = time.perf_counter() - t
    if first * repeat > 4 * budget:  # slow: a few single runs
        times = [first]
        for _ in range(max(0, min(repeat, int(budget * 4 / max(first, 1e-9))) - 1)):
            t = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t)
        return _tstat(times)
    number = max(1, int(budget / repeat / max(first, 1e-7)))
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t) / number)
    return _tstat(times)


def timed(fn):
    t = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t


def fmt_t(sec: float) -> str:
    if sec is None or not math.isfinite(sec):
        return "-"
    if sec < 1e-3:
        return f"{sec * 1e6:.0f} µs"
    if sec < 1.0:
        return f"{sec * 1e3:.3g} ms"
    return f"{sec:.3g} s"


def fmt_e(err: float) -> str:
    if err is None or (isinstance(err, float) and math.isnan(err)):
        return "-"
    if err == 0:
        return "0"
    return f"{err:.1e}"


def machine() -> dict:
    import numba
    import scipy

    cpu = "unknown"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
                                capture_output=True, text=True).stdout.strip()
    except OSError:
        commit = "?"
    try:
        dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "--", "rocking", "pulses",
                                "pipeline"], capture_output=True, text=True).stdout.strip().splitlines()
        if dirty:
            commit += f" plus uncommitted changes in {len(dirty)} file(s) of rocking/, pulses/, pipeline/"
    except OSError:
        pass
    return {"cpu": cpu, "nproc": os.cpu_count(), "python": platform.python_version(),
            "numba": numba.__version__, "numpy": np.__version__, "scipy": scipy.__version__,
            "platform": platform.platform(), "commit": commit,
            "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}


def loadavg() -> str:
    try:
        return " / ".join(f"{x:.1f}" for x in os.getloadavg())
    except OSError:
        return "?"


@contextlib.contextmanager
def steps_per_tp(n):
    """Temporarily change the fast engine's steps per pulse period (a module constant)."""
    from rocking import solver

    old = solver.STEPS_PER_TP
    solver.STEPS_PER_TP = n
    try:
        yield
    finally:
        solver.STEPS_PER_TP = old


def blocks():
    from rocking import Block

    return {"Temple column 7.5x1.8 m": Block.from_dimensions(7.5, 1.8),
            "statue 2.0x0.4 m": Block.from_dimensions(2.0, 0.4)}


# --------------------------------------------------------------------------- records
#: (file under RECORDS_DIR, read_record keyword arguments); the text files state cm/s^2 and
#: dt = 0.005 s in their comments (MANIFEST.md); column 1 is the fault-normal component
RECORD_FILES = [
    ("Rinaldi228.AT2", {}),
    ("RSN77_SFERN_PUL164.AT2", {}),
    ("RSN181_IMPVALL.H_H-E06230.AT2", {}),
    ("RSN879_LANDERS_LCN260.AT2", {}),
    ("RSN1084_NORTHR_SCS052.AT2", {}),
    ("RSN6_IMPVALL.I_I-ELC180.AT2", {}),
    ("haselREC_NGA-West2-Reduced/RSN150_1.AT2", {}),
    ("haselREC_NGA-West2-Reduced/RSN159_1.AT2", {}),
    ("base_isolation_benchmark/erzikan.txt", {"units": "cm/s2", "dt": 0.005, "column": 1}),
    ("base_isolation_benchmark/kobe.txt", {"units": "cm/s2", "dt": 0.005, "column": 1}),
]


def load_records(n: int):
    import pulses

    out, notes = [], []
    if not RECORDS_DIR.is_dir():
        notes.append(f"real records not found at `{RECORDS_DIR}`: the record sections use synthetic records only")
        return out, notes
    for rel, kw in RECORD_FILES[:n]:
        path = RECORDS_DIR / rel
        if not path.is_file():
            notes.append(f"`{rel}` absent, skipped")
            continue
        try:
            rec = pulses.read_record(path, **kw)
        except Exception as exc:  # noqa: BLE001 - a broken reader is reported, not fatal
            notes.append(f"`{rel}` could not be read ({exc}), skipped")
            continue
        rec.name = pathlib.Path(rel).stem
        out.append(rec)
    return out, notes


def headline_record():
    """A 20 s record at 200 Hz: Rinaldi 228 (fault normal, 200 Hz copy), first 20 s."""
    import pulses
    from pulses import Record

    path = RECORDS_DIR / "base_isolation_benchmark" / "rinaldi.txt"
    if path.is_file():
        rec = pulses.read_record(path, units="cm/s2", dt=0.005, column=1)
        return Record(rec.acc[:4001], 0.005, name="Rinaldi 228 (rinaldi.txt FN), first 20 s, 200 Hz")
    # fallback: a synthetic near-fault record
    from pulses.synthetic import synthetic_record

    rec = synthetic_record("sine", 0.7 * pulses.G, 0.8, 6.0, 20.0, 0.005, noise=0.15, seed=3)
    rec.name = "synthetic one-sine 0.7 g, 0.8 s + 15 % noise, 20 s, 200 Hz"
    return rec


# =========================================================================== models
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


def _default_method() -> str:
    """The default ``method`` of ``rocking.simulate`` (read from its signature)."""
    import inspect

    import rocking

    return inspect.signature(rocking.simulate).parameters["method"].default


def _method_label(method: str) -> str:
    """``"fast taylor (default method)"`` for the default stepper of ``rocking.simulate``."""
    return f"fast {method}" + (" (default method)" if method == _default_method() else "")


USUAL_DEFAULT = dict(method="RK45", rtol=1e-3, atol=1e-6)


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
        name = _method_label(method)
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


def wp_table(res, ref_time):
    lines = ["| model / setting | runs | time per run: median (best) | max error | median error | wrong verdicts |",
             "|---|---|---|---|---|---|"]
    for label, r in res.items():
        if r["setting"].kind == "reference":
            lines.append(f"| {label} | {r['n']} | {fmt_t(ref_time)} | (the yardstick) | | |")
            continue
        e = r["errors"]
        best = f" ({fmt_t(r['best'])})" if not r["setting"].slow else " (one run)"
        lines.append(f"| {label} | {r['n']} | {fmt_t(r['time'])}{best} | {fmt_e(max(e) if e else math.nan)} | "
                     f"{fmt_e(statistics.median(e) if e else math.nan)} | {r['wrong']} |")
    return lines


# =========================================================================== solver section
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
    # threads): 200 widths of the column up to 20 % wider, as a verified-width search runs them
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
                method=_default_method(),
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


def plot_work_precision(results, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    floor = 1e-16
    default = _default_method()
    fig, axes = plt.subplots(1, len(results), figsize=(6.2 * len(results), 5.0), squeeze=False)
    colours = {"fast taylor": "C5", "fast taylor ph_max": "C5", "fast rk8": "C0", "fast rk8 ph_max": "C0",
               "fast rk4": "C1", "fast rk4 ph_max": "C1", "linear": "C2", "usual RK45": "C3", "usual DOP853": "C4"}
    markers = {"fast taylor": "o", "fast taylor ph_max": "s", "fast rk8": "o", "fast rk8 ph_max": "s",
               "fast rk4": "o", "fast rk4 ph_max": "s", "linear": "D", "usual RK45": "^", "usual DOP853": "v"}
    for ax, (title, (res, ref_time)) in zip(axes[0], results.items()):
        fams = {}
        for label, r in res.items():
            s = r["setting"]
            if s.kind == "reference" or not r["errors"]:
                continue
            fams.setdefault(s.family, []).append((max(max(r["errors"]), floor), r["time"], label, r["wrong"]))
        for fam, pts in fams.items():
            xs, ys = [p[0] for p in pts], [p[1] for p in pts]
            ax.plot(xs, ys, marker=markers.get(fam, "o"), color=colours.get(fam, "k"),
                    linestyle="-" if "ph_max" not in fam else "none", alpha=0.85,
                    label=fam.replace(f"fast {default}", f"fast {default} (default)"))
            for x, y, label, wrong in pts:
                if wrong:
                    ax.annotate(f"{wrong} wrong", (x, y), fontsize=7, color="red")
        ax.axhline(ref_time, color="k", linestyle=":", label="reference (time; error 0 by definition)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("max error of max|theta|/alpha against the reference")
        ax.set_ylabel("time per run (s)")
        ax.set_title(title)
        ax.grid(True, which="both", alpha=0.3)
        ax.axvline(1e-6, color="grey", linestyle="--", linewidth=0.8)
    axes[0][0].legend(fontsize=7, loc="best")
    fig.suptitle(f"Work-precision (errors below {floor:g} drawn at {floor:g})", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def section_solver(md, out, quick, records, rec_notes):
    from rocking import solver

    log("solver: headline (issue 2 ratio on a 20 s, 200 Hz record)")
    h = headline(quick)
    out["headline"] = h
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
    rres = None
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
    rtrans, rwrong = [], None
    if records and not quick:
        rt = record_transition(records[0])
        if rt:
            rtrans = [rt]
            rsets_t = [s for s in settings("record") if s.kind != "reference" and not _tight(s)]
            rwrong, rn_points, rdis = transition_study(rtrans, rsets_t)
            ref_disagree += rdis

    plots = {"(a) pulses, all shapes": (pres, pref_t)}
    if rres:
        plots["(b) real records"] = (rres, rref_t)
    plot_work_precision(plots, OUT / "work_precision.png")

    # ---------------------------------------------------------------- markdown
    md.append("## 1. The solver: speed against error\n")
    md.append("### Headline: the fast engine against the usual approach (issue 2)\n")
    md.append(f"Record: {h['record']}, scaled x{h['scale']:g} so that the Temple column (7.5 x 1.8 m) rocks "
              f"hard and survives ({h['npts']} samples; reference max|theta|/alpha = {h['ref_ratio']:.6f}, "
              f"{h['n_impacts']} impacts). The usual approach is `benchmarks/baseline.py`: scipy `solve_ivp` "
              "RK45 at default tolerances, `max_step` = dt, an impact event restarting the integration at "
              f"every impact ({h['usual_restarts']} restarts here), overturning at |theta| = pi/2. "
              f"Medians of {h['n_round']} interleaved rounds.\n")
    m = h["method"]
    md.append("| | time per run | error of max\\|theta\\|/alpha vs reference | usual approach's time / this |")
    md.append("|---|---|---|---|")
    md.append(f"| fast engine, default `method=\"{m}\"`, `simulate(..., history=False)` | {fmt_t(h['t_fast'])} "
              f"(best {fmt_t(h['t_fast_best'])}) | {fmt_e(h['e_fast'])} | **{h['speed_ratio']:.0f}x** |")
    md.append(f"| fast engine, `method=\"rk8\"` (the previous default), `history=False` | {fmt_t(h['t_rk8'])} "
              f"(best {fmt_t(h['t_rk8_best'])}) | {fmt_e(h['e_rk8'])} | {h['speed_ratio_rk8']:.0f}x |")
    md.append(f"| fast engine, `method=\"{m}\"`, `simulate(...)` with history | {fmt_t(h['t_fast_hist'])} | same as above | |")
    md.append(f"| fast engine in a batch (`simulate_many`, 200 blocks, 2 threads), per run, `method=\"{m}\"` / "
              f"`\"rk8\"` | {fmt_t(h['t_many'])} / {fmt_t(h['t_many_rk8'])} | same as above | |")
    md.append(f"| batch engine (`rocking.lanes`, runs stepped together), one core: 200 widths 1.8-2.16 m "
              f"(`simulate_many`), per run | {fmt_t(h['t_lanes'])} (the same runs one by one: "
              f"{fmt_t(h['t_one'])}) | same as above | {h['lanes_ratio']:.0f}x |")
    md.append(f"| usual approach (RK45 default) | {fmt_t(h['t_usual'])} (best {fmt_t(h['t_usual_best'])}) | "
              f"{fmt_e(h['e_usual'])} | 1 |")
    acc = "infinite (fast error is 0)" if math.isinf(h["acc_ratio"]) else f"{h['acc_ratio']:.2g}x"
    acc8 = "infinite (its error is 0)" if math.isinf(h["acc_ratio_rk8"]) else f"{h['acc_ratio_rk8']:.2g}x"
    md.append(f"\n**Speed ratio {h['speed_ratio']:.0f}x** with the default `method=\"{m}\"` (slowest round "
              f"{h['speed_ratio_min']:.0f}x; target 1000x); **accuracy ratio {acc}** (target 1000x). "
              f"With `method=\"rk8\"`, measured in the same rounds: {h['speed_ratio_rk8']:.0f}x (slowest round "
              f"{h['speed_ratio_rk8_min']:.0f}x), accuracy ratio {acc8}; rk8 takes {h['rk8_over_default']:.2f}x "
              f"the time of {m} (median over rounds).\n")

    md.append("### (a) Pulses of all shapes\n")
    md.append(f"{len(pcases)} cases: the four shapes on the Temple column (tan alpha = 0.24, p = 1.381 rad/s) at "
              "pTp = " + ", ".join(sorted({c[0].split()[1][4:] for c in pcases}, key=float)) +
              ", each at 60 % and 95 % of its smallest overturning amplitude (found by a fast scan), so the "
              "column rocks hard and survives. Error = |max|theta|/alpha - reference| over the cases where both survive; a different "
              "verdict is counted instead. Times are medians over the cases of each model's median time. "
              "The usual approach uses `max_step` = Tp/200 on pulses. The fast engine is measured with each "
              "stepping `method` (`taylor`: the Taylor series summed to rounding, the default; `rk8`: 8th-order "
              "Dormand-Prince, the previous default; `rk4`: classical RK4) against steps per Tp "
              f"(`rocking.solver.STEPS_PER_TP`, default {solver.STEPS_PER_TP}) and `ph_max` (default "
              f"{solver.PH_MAX:g}"
              + f", {solver.PH_MAX_RK4:g} for rk4" +
              "; the cap on p_eff h, which binds for the longer pulses), the `ph_max` sweeps at the steps per "
              "Tp their label says.\n")
    md += wp_table(pres, pref_t)
    if rres:
        md.append("\n### (b) Real records\n")
        md.append(f"{len(rcases)} cases: each record scaled to the strongest of PGA = 3, 2.5, 2, 1.6, 1.3 g tan alpha that "
                  "the block survives with max|theta|/alpha < 0.95 (chosen with the fast model). "
                  "Sub-steps per sample: the fast engine's `ph_max` set so that each sample interval "
                  "takes that many steps. The tight scipy variants ran on the first "
                  f"{2 if quick else 4} cases only (they take seconds each).\n")
        md += wp_table(rres, rref_t)
        md.append("\nCases: " + "; ".join(c[0] for c in rcases) + ".\n")
    for note in rec_notes:
        md.append(f"- note: {note}")
    md.append("\n![work-precision](work_precision.png)\n")

    md.append("### (c) Near an overturning transition: wrong verdicts\n")
    md.append("Transitions x* (first overturning ap/(g tan alpha) for pulses, first overturning scale for the "
              "record) found by a fast-model scan and bisection, then bisected again with the reference model "
              "to 1e-10 relative inside +-1e-5 of the fast answer; the fast model's transition differs from "
              "the reference's by the relative amount shown. Every model then judged the six points "
              "x*(1 +- d); the truth is the reference's verdict at each point "
              f"({ref_disagree} of {sum(n_points.values())} reference verdicts fell on the unexpected side).\n")
    md.append("| transition | x* (reference) | fast x*/x_ref - 1 | seconds to find |")
    md.append("|---|---|---|---|")
    for label, blk, make, x_ref, x_fast, sec in trans + rtrans:
        rel = x_fast / x_ref - 1
        rel_s = f"{rel:+.1e}" if abs(rel) > 2e-10 else f"{rel:+.1e} (within the 1e-10 bisection tolerance)"
        md.append(f"| {label} | {x_ref:.10g} | {rel_s} | {sec:.1f} |")
    md.append("")
    md.append("Pulses (each count is wrong verdicts / points at that distance):\n")
    md.append("| model / setting | wrong within 1e-2 | within 1e-4 | within 1e-6 |")
    md.append("|---|---|---|---|")
    for label, w in wrong.items():
        md.append(f"| {label} | {w[1e-2]} / {n_points[1e-2]} | {w[1e-4]} / {n_points[1e-4]} | "
                  f"{w[1e-6]} / {n_points[1e-6]} |")
    md.append("")
    if rwrong:
        md.append(f"The record ({rtrans[0][0]}; the tight scipy variants are left out, they take seconds per run):\n")
        md.append("| model / setting | wrong within 1e-2 | within 1e-4 | within 1e-6 |")
        md.append("|---|---|---|---|")
        for label, w in rwrong.items():
            md.append(f"| {label} | {w[1e-2]} / {rn_points[1e-2]} | {w[1e-4]} / {rn_points[1e-4]} | "
                      f"{w[1e-6]} / {rn_points[1e-6]} |")
        md.append("")
    out["pulses_wp"] = {k: dict(max_err=max(v["errors"]) if v["errors"] else None, time=v["time"], wrong=v["wrong"])
                        for k, v in pres.items()}
    if rres:
        out["records_wp"] = {k: dict(max_err=max(v["errors"]) if v["errors"] else None, time=v["time"],
                                     wrong=v["wrong"]) for k, v in rres.items()}
    out["transitions_wrong"] = wrong


# =========================================================================== linear section
def section_linear(md, out, quick, records):
    import rocking
    from pulses import G, make_pulse
    from rocking import Block
    from rocking.solver import LINEAR_ERROR_COEFF

    log("linear: error of the linearised model against alpha")
    p = 1.381
    tans = (0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5) if not quick else (0.01, 0.05, 0.2, 0.5)
    combos = [(1.0, 3.0), (2.0, 1.5), (4.0, 2.5)] if not quick else [(2.0, 1.5), (4.0, 2.5)]
    recs = records[:6] if not quick else records[:1]
    rows = []
    t_lin, t_fast = [], []
    for tan in tans:
        blk = Block.from_tan_alpha(p, tan)
        errs, wrong, n = [], 0, 0
        kinds = []  # (error, "pulse"/"record", label) per surviving case
        cases = []
        for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
            for ptp, ratio in combos:
                tp = ptp / p
                t0 = 0.0 if shape in ("rect", "sine") else 3.0 * tp
                cases.append(make_pulse(shape, ratio * G * tan, tp, t0))
        for rec in recs:
            cases.append(rec.scaled(1.5 * G * tan / rec.pga))
        for exc in cases:
            with steps_per_tp(400):  # the yardstick: fast at twice the default resolution
                truth = rocking.simulate(blk, exc, model="fast", history=False)
            lin = rocking.simulate(blk, exc, model="linear", history=False)
            n += 1
            if lin.overturned != truth.overturned:
                wrong += 1
            elif not truth.overturned:
                errs.append(abs(lin.max_rotation_ratio - truth.max_rotation_ratio))
                kinds.append((errs[-1], "record" if hasattr(exc, "dt") else "pulse",
                              getattr(exc, "name", None) if hasattr(exc, "dt") else repr(exc)))
        # one record and one pulse for speed
        exc = cases[5]
        t_lin.append(per_call(lambda: rocking.simulate(blk, exc, model="linear", history=False), 0.02, 3))
        t_fast.append(per_call(lambda: rocking.simulate(blk, exc, model="fast", history=False), 0.02, 3))
        alpha = blk.alpha
        emax = max(errs) if errs else math.nan
        ep = max([e for e, k, _ in kinds if k == "pulse"], default=math.nan)
        er = max([e for e, k, _ in kinds if k == "record"], default=math.nan)
        worst = max(kinds)[2] if kinds else ""
        rows.append(dict(tan=tan, alpha=alpha, n=n, wrong=wrong, emax=emax,
                         emed=statistics.median(errs) if errs else math.nan, coeff=emax / alpha**2,
                         cp=ep / alpha**2, cr=er / alpha**2, worst=worst))
        log(f"  tan alpha {tan}: max error {fmt_e(emax)}, error/alpha^2 {emax / alpha**2:.3g}, wrong {wrong}/{n}")
    # spot check against the reference at one slenderness
    blk = Block.from_tan_alpha(p, 0.05)
    exc = make_pulse("sine", 1.5 * G * 0.05, 2.0 / p)
    ref = rocking.simulate(blk, exc, model="reference", history=False)
    fst = rocking.simulate(blk, exc, model="fast", history=False)
    spot = abs(ref.max_rotation_ratio - fst.max_rotation_ratio)

    measured = max(r["coeff"] for r in rows if math.isfinite(r["coeff"]))
    out["linear"] = dict(rows=rows, measured_coeff=measured, coeff=LINEAR_ERROR_COEFF)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.2, 4.6))
    a = np.array([r["alpha"] for r in rows])
    ax.loglog(a, [r["cp"] * r["alpha"] ** 2 for r in rows], "o-", label="linear: max error, pulses")
    ax.loglog(a, [r["cr"] * r["alpha"] ** 2 for r in rows], "^-", label="linear: max error, records")
    ax.loglog(a, [r["emed"] for r in rows], "s--", label="linear: median error")
    aa = np.geomspace(a.min(), a.max(), 50)
    ax.loglog(aa, LINEAR_ERROR_COEFF * aa**2, "k:", label=f"bound used by auto: {LINEAR_ERROR_COEFF:g} alpha^2")
    for tol in (1e-6, 1e-4, 1e-2):
        ax.axhline(tol, color="grey", linewidth=0.6)
    ax.set_xlabel("alpha (rad)")
    ax.set_ylabel("error of max|theta|/alpha")
    ax.set_title("Linearised model against the nonlinear one")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "linear_error.png", dpi=110)
    plt.close(fig)

    md.append("## 2. The linearised model and `model=\"auto\"`\n")
    md.append(f"Error of the linearised model's max|theta|/alpha against the nonlinear fast engine at 400 "
              f"steps/Tp (which agrees with the reference to {fmt_e(spot)} on a spot check at tan alpha = 0.05 "
              "and to the figures of section 1 elsewhere), p = 1.381 rad/s, on the four shapes at (pTp, ap/(g tan alpha)) = "
              + ", ".join(f"({a:g}, {b:g})" for a, b in combos) +
              f" and {len(recs)} real record(s) at PGA = 1.5 g tan alpha. Verdict disagreements are counted apart.\n")
    md.append("| tan alpha | alpha (rad) | cases | max error | median error | max error / alpha^2: pulses | records | worst case | wrong verdicts | time linear / fast (one pulse) |")
    md.append("|---|---|---|---|---|---|---|---|---|---|")
    for r, tl, tf in zip(rows, t_lin, t_fast):
        md.append(f"| {r['tan']:g} | {r['alpha']:.4g} | {r['n']} | {fmt_e(r['emax'])} | {fmt_e(r['emed'])} | "
                  f"{r['cp']:.3g} | {r['cr']:.3g} | {r['worst']} | {r['wrong']} | {fmt_t(tl)} / {fmt_t(tf)} |")
    cp = max((r["cp"] for r in rows if math.isfinite(r["cp"])), default=math.nan)
    cr = max((r["cr"] for r in rows if math.isfinite(r["cr"])), default=math.nan)
    out["linear"].update(coeff_pulses=cp, coeff_records=cr)
    ok = measured <= LINEAR_ERROR_COEFF
    md.append("")
    md.append(f"`model=\"auto\"` uses the linearised model when `LINEAR_ERROR_COEFF * alpha**2 <= tol`, with "
              f"`LINEAR_ERROR_COEFF = {LINEAR_ERROR_COEFF:g}`. The largest measured error/alpha^2 is **{measured:.3g}**: "
              + ("the coefficient is an upper bound of every measured case." if ok else
                 f"**the coefficient is NOT an upper bound; the measured worst case is {measured:.3g}** "
                 f"(pulses alone: {cp:.3g}; records: {cr:.3g}). On pulses the error does grow like alpha^2; on long "
                 "broadband records with hundreds of small impacts the two models' impact sequences drift apart "
                 "(the fast engine and the reference agree there to 1e-10), so the error is not bounded by a "
                 "multiple of alpha^2 alone."))
    md.append("")
    md.append("| tol | auto switches to linear for alpha below | tan alpha below | a column 1 m wide would be taller than |")
    md.append("|---|---|---|---|")
    for tol in (1e-6, 1e-4, 1e-2):
        a_sw = math.sqrt(tol / LINEAR_ERROR_COEFF)
        md.append(f"| {tol:g} | {a_sw:.3g} rad | {math.tan(a_sw):.3g} | {1 / math.tan(a_sw):.3g} m |")
    md.append("\nSo at the default `tol = 1e-6` the linearised model is never chosen for a real column. It is "
              "slower than the nonlinear engine on pulses (table above: it takes 4000 chords per Tp) and about "
              "twice as fast on records (section 1b): it is kept for comparison, as issue 2 asks.\n")
    md.append("![linearised model error](linear_error.png)\n")


# =========================================================================== cost section
def section_cost(md, out, quick, records):
    import rocking
    from benchmarks.baseline import simulate_usual
    from pulses import G, Record, make_pulse

    blk = blocks()["Temple column 7.5x1.8 m"]
    log("cost: time against record length")
    # a 30 s chunk: Rinaldi 228 (or a synthetic record) at 200 Hz followed by 10 s of rest, tiled
    base = headline_record()
    chunk = np.concatenate([0.8 * base.acc, np.zeros(2000)])
    lengths = (10, 30, 120, 600, 3600) if not quick else (10, 30, 120, 600)
    usual_max = 120 if not quick else 30
    rows = []
    for L in lengths:
        n = int(L / 0.005) + 1
        acc = np.resize(chunk, n)
        rec = Record(acc, 0.005, name=f"{L} s")
        res, _ = timed(lambda: rocking.simulate(blk, rec, model="fast", history=False))
        tf = per_call(lambda: rocking.simulate(blk, rec, model="fast", history=False), budget=0.1, repeat=3)
        th = per_call(lambda: rocking.simulate(blk, rec, model="fast"), budget=0.1, repeat=3)
        tu = timed(lambda: simulate_usual(blk, rec, **USUAL_DEFAULT))[1] if L <= usual_max else math.nan
        rows.append(dict(L=L, npts=n, tf=tf, th=th, tu=tu, over=res.overturned, imp=res.n_impacts))
        log(f"  {L} s: fast {fmt_t(tf)}, with history {fmt_t(th)}, usual {fmt_t(tu)}")

    log("cost: blocks in a batch")
    pulse = make_pulse("sine", 0.5 * G, 1.0)
    rec20 = Record(0.8 * base.acc, 0.005)
    brows = []
    ns = (1, 10, 100, 1000, 10000) if not quick else (1, 10, 100, 1000)
    for N in ns:
        tans = np.linspace(0.05, 0.4, N) if N > 1 else np.array([0.2])
        bl = [rocking.Block.from_tan_alpha(blk.p, t) for t in tans]
        tp_ = per_call(lambda: rocking.simulate_many(bl, pulse), budget=0.1, repeat=3)
        tr_ = per_call(lambda: rocking.simulate_many(bl, rec20), budget=0.1, repeat=3) if N <= 2000 else math.nan
        brows.append(dict(N=N, tp=tp_, tr=tr_))
        log(f"  {N} blocks: pulse {fmt_t(tp_)}, record {fmt_t(tr_)}")

    log("cost: the 100 x 100 overturning-spectrum grid")
    alpha = math.radians(14.0)
    wp, ratio = np.linspace(0.5, 12.0, 100), np.linspace(1.0, 6.0, 100)
    rocking.overturning_spectrum(alpha, "sine", wp[:2], ratio[:2])
    spec = {}
    for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
        ts = [timed(lambda: rocking.overturning_spectrum(alpha, shape, wp, ratio))[1]
              for _ in range(3 if not quick else 1)]
        spec[shape] = _tstat(ts)
        log(f"  {shape}: {spec[shape]:.2f} s")
    import numba

    threads = numba.get_num_threads()
    spec1 = {}
    try:
        numba.set_num_threads(1)
        for shape in ("sine", "ricker-sym"):
            ts = [timed(lambda: rocking.overturning_spectrum(alpha, shape, wp, ratio))[1]
                  for _ in range(3 if not quick else 1)]
            spec1[shape] = _tstat(ts)
            log(f"  {shape}, one thread: {spec1[shape]:.2f} s")
    finally:
        numba.set_num_threads(threads)

    log("cost: `pipeline simulate` cold start")
    cold = None
    cmd = [sys.executable, "-m", "pipeline", "simulate", "--block", "7.5x1.8", "--pulse", "sine",
           "--ap", "0.71g", "--tp", "0.8"]
    probe = subprocess.run(cmd, capture_output=True, text=True, cwd=str(ROOT))
    if probe.returncode == 0:
        tc = [timed(lambda: subprocess.run(cmd, capture_output=True, text=True, cwd=str(ROOT)))[1]
              for _ in range(3 if quick else 5)]
        ti = [timed(lambda: subprocess.run([sys.executable, "-c", "import rocking, pulses"],
                                           capture_output=True, cwd=str(ROOT)))[1] for _ in range(3)]
        tpy = [timed(lambda: subprocess.run([sys.executable, "-c", "pass"], capture_output=True))[1]
               for _ in range(3)]
        cold = dict(t=statistics.median(tc), tmin=min(tc), imp=statistics.median(ti), py=statistics.median(tpy),
                    out=probe.stdout.strip().splitlines()[1].strip() if probe.stdout.count("\n") >= 1 else "")
        log(f"  cold start {cold['t']:.2f} s (import rocking+pulses {cold['imp']:.2f} s, bare python {cold['py']:.2f} s)")
    else:
        log("  `pipeline simulate` not available: " + (probe.stderr.strip().splitlines() or ["?"])[-1])

    out["cost"] = dict(length=rows, batch=brows, spectrum=spec, spectrum_1thread=spec1, cold=cold)

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.4))
    L = [r["L"] for r in rows]
    a1.loglog(L, [r["tf"] for r in rows], "o-", label="fast, history=False")
    a1.loglog(L, [r["th"] for r in rows], "s--", label="fast, with history")
    a1.loglog([r["L"] for r in rows if math.isfinite(r["tu"])], [r["tu"] for r in rows if math.isfinite(r["tu"])],
              "^-", label="usual approach (RK45)")
    a1.set_xlabel("record length (s) at 200 Hz")
    a1.set_ylabel("time per run (s)")
    a1.grid(True, which="both", alpha=0.3)
    a1.legend(fontsize=8)
    a1.set_title("Cost against record length (Temple column)")
    N = [r["N"] for r in brows]
    a2.loglog(N, [r["tp"] for r in brows], "o-", color="C0", label="one-sine pulse: median")
    a2.loglog(N, [r["tp"].best for r in brows], "o--", color="C0", alpha=0.6, label="one-sine pulse: best")
    fin = [r for r in brows if math.isfinite(r["tr"])]
    a2.loglog([r["N"] for r in fin], [r["tr"] for r in fin], "s-", color="C1", label="20 s record, 200 Hz: median")
    a2.loglog([r["N"] for r in fin], [r["tr"].best for r in fin], "s--", color="C1", alpha=0.6,
              label="20 s record, 200 Hz: best")
    a2.set_xlabel("blocks in one simulate_many call")
    a2.set_ylabel("time per call (s)")
    a2.grid(True, which="both", alpha=0.3)
    a2.legend(fontsize=8)
    a2.set_title("Cost against batch size")
    fig.tight_layout()
    fig.savefig(OUT / "cost.png", dpi=110)
    plt.close(fig)

    md.append("## 3. Cost growth\n")
    md.append(f"Record length: the first 20 s of {base.name} x0.8 followed by 10 s of rest, tiled to length, 200 Hz, "
              "the Temple column (it rocks in every 30 s chunk and never overturns). The usual approach was timed "
              f"up to {usual_max} s only (one run each).\n")
    md.append("| length | samples | fast, history=False | per 1000 samples | fast, with history | usual approach | impacts | overturned |")
    md.append("|---|---|---|---|---|---|---|---|")
    for r in rows:
        md.append(f"| {r['L']} s | {r['npts']} | {fmt_t(r['tf'])} | {fmt_t(r['tf'] / r['npts'] * 1000)} | "
                  f"{fmt_t(r['th'])} | {fmt_t(r['tu'])} | {r['imp']} | {r['over']} |")
    md.append("\nBlocks in one batch (`simulate_many`, compiled and parallel over the machine's cores; tan alpha spread "
              "over 0.05-0.4 at p = 1.381 rad/s):\n")
    md.append("| blocks | one-sine pulse (0.5 g, 1 s): median (best) | per block (best) | 20 s record at 200 Hz: median (best) | per block (best) |")
    md.append("|---|---|---|---|---|")
    for r in brows:
        md.append(f"| {r['N']} | {fmt_t(r['tp'])} ({fmt_t(r['tp'].best)}) | {fmt_t(r['tp'] / r['N'])} ({fmt_t(r['tp'].best / r['N'])}) | "
                  + (f"{fmt_t(r['tr'])} ({fmt_t(r['tr'].best)}) | {fmt_t(r['tr'] / r['N'])} ({fmt_t(r['tr'].best / r['N'])}) |"
                     if math.isfinite(r['tr']) else "- | - |"))
    md.append("\nUnder load the median of a parallel batch call can be 100x its best: the compiled "
              "parallel loop waits at its barrier for a thread the scheduler has parked (see the spectrum "
              "timings with one thread below).\n")
    md.append("\n![cost](cost.png)\n")
    md.append("### The 100 x 100 overturning-spectrum grid (issue 2: under 2 s)\n")
    md.append("`rocking.overturning_spectrum(14 deg, shape, 100 values of omega_p/p in 0.5-12, 100 values of "
              f"ap/(g tan alpha) in 1-6)`: 10,000 runs in one batch; median of {3 if not quick else 1}.\n")
    md.append(f"| shape | time, {threads} threads: median (best) | per run | one thread: median (best) |")
    md.append("|---|---|---|---|")
    for shape, t in spec.items():
        one = f"{spec1[shape]:.2f} s ({spec1[shape].best:.2f} s)" if shape in spec1 else "-"
        md.append(f"| {shape} | {t:.2f} s ({t.best:.2f} s) | {fmt_t(t / 1e4)} | {one} |")
    md.append("\n### `pipeline simulate` cold start (issue 2: under 2 s)\n")
    if cold:
        md.append(f"`pipeline simulate --block 7.5x1.8 --pulse sine --ap 0.71g --tp 0.8` in a fresh process "
                  f"(`python -m pipeline`, numba caches on disk): median **{cold['t']:.2f} s** (best {cold['tmin']:.2f} s) "
                  f"of {3 if quick else 5}; of which `import rocking, pulses` alone takes {cold['imp']:.2f} s and a bare "
                  f"Python start {cold['py']:.2f} s. Its answer: `{cold['out']}`.\n")
    else:
        md.append("`pipeline simulate` is not available in this checkout: not measured.\n")


# =========================================================================== fitter section
def section_fit(md, out, quick):
    log("fit: speed (benchmarks/bench_fit.py)")
    from benchmarks import bench_fit, fit_accuracy

    sp = bench_fit.run(repeat=10 if quick else 20)
    out["fit_speed"] = sp
    log(f"  20 s, 200 Hz, all shapes: {sp['fit_all_shapes_20s_200Hz_ms_median']:.1f} ms")
    log("fit: accuracy against noise and Tp (benchmarks/fit_accuracy.py)")
    n = 2 if quick else 4
    noises = (0.0, 0.05, 0.15, 0.30)
    tps = (0.5, 2.0) if quick else (0.2, 0.5, 1.0, 2.0, 5.0)
    lines = ["| noise | Tp (s) | cases | ap&Tp <3 % | <5 % | <15 % | shape | arrival | median err ap / Tp | "
             "limit ap / Tp | RMS/limit | search fails |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    acc = {}
    for k, noise in enumerate(noises):
        pooled = []
        for j, tp in enumerate(tps):
            rows = fit_accuracy.cases(noise, tp, n, seed=1000 * k + j)
            pooled += rows
            lines.append(fit_accuracy._line(f"{noise:.0%}", f"{tp:g}", fit_accuracy.summarise(rows)))
        s = fit_accuracy.summarise(pooled)
        acc[noise] = s
        lines.append(fit_accuracy._line(f"**{noise:.0%}**", "**all**", s))
        log(f"  noise {noise:.0%}: {len(pooled)} fits, within 5 %: {100 * s['5']:.0f} %, right shape {100 * s['shape']:.0f} %")
    out["fit_accuracy"] = {k: {kk: float(vv) for kk, vv in v.items()} for k, v in acc.items()}

    rinaldi = None
    path = RECORDS_DIR / "Rinaldi228.AT2"
    if path.is_file():
        import pulses

        rec = pulses.read_record(path)
        fit, sec = timed(lambda: pulses.fit_pulse(rec))
        sine = fit["sine"]
        rinaldi = (sine.ap_g, sine.tp, fit.best.shape, sec)

    md.append("## 4. The pulse fitter\n")
    md.append("Speed (`benchmarks/bench_fit.py`, medians; issue 3: all shapes on a 20 s, 200 Hz record under 15 ms, "
              "cost no worse than linear in length):\n")
    md.append("| record | all four shapes | per 1000 samples |")
    md.append("|---|---|---|")
    for d in (10, 20, 40, 80, 160):
        key = f"fit_all_shapes_{d}s_ms_median"
        if key in sp:
            md.append(f"| {d} s at 200 Hz | {sp[key]:.1f} ms | {sp[f'fit_all_shapes_{d}s_ms_per_1000_samples']:.2f} ms |")
    md.append(f"\nThe issue's case (one-sine + 15 % noise, 20 s at 200 Hz): median "
              f"**{sp['fit_all_shapes_20s_200Hz_ms_median']:.1f} ms**, best {sp['fit_all_shapes_20s_200Hz_ms_min']:.1f} ms; "
              "per shape: " + ", ".join(f"{s} {sp[f'fit_{s}_20s_200Hz_ms_median']:.1f} ms"
                                       for s in ("sine", "ricker-sym", "ricker-anti", "rect")) + ".\n")
    if rinaldi:
        md.append(f"Rinaldi 228 (NGA-West2 AT2): one-sine fit {rinaldi[0]:.3f} g, {rinaldi[1]:.3f} s (paper: 0.71 g, 0.8 s); "
                  f"best shape {rinaldi[2]}; {rinaldi[3] * 1e3:.0f} ms for all shapes.\n")
    md.append(f"Accuracy (`benchmarks/fit_accuracy.py`, {n} records per shape, Tp and noise level here; the README's "
              "table uses 10): each shape, random polarity, amplitude and arrival, background motion band-passed "
              "to 0.5-10 Hz at the stated RMS fraction of ap. Columns as in `fit_accuracy.py`'s docstring.\n")
    md += lines
    md.append("")


# =========================================================================== design section
def section_design(md, out, quick):
    import rocking
    from pulses import G, make_pulse
    from rocking.spectrum import CHART_APG, CHART_PTP

    log("design: issue 4 timings")
    res = {}
    rinaldi = make_pulse("sine", 0.71 * G, 0.8)
    rocking.min_slenderness(rinaldi, 1.381)
    for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
        pulse = make_pulse(shape, 0.71 * G, 0.8)
        res[f"min_slenderness {shape}"] = per_call(lambda: rocking.min_slenderness(pulse, 1.381), 0.5, 3)
        log(f"  min_slenderness {shape}: {fmt_t(res[f'min_slenderness {shape}'])}")
    import numba

    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        for shape in ("sine", "ricker-sym"):
            pulse = make_pulse(shape, 0.71 * G, 0.8)
            res[f"min_slenderness {shape} 1 thread"] = per_call(lambda: rocking.min_slenderness(pulse, 1.381), 0.5, 3)
            log(f"  min_slenderness {shape}, one thread: {fmt_t(res[f'min_slenderness {shape} 1 thread'])}")
    finally:
        numba.set_num_threads(threads)
    alpha = math.radians(14.0)
    wp, ratio = np.linspace(0.5, 12, 200), np.linspace(1, 6, 200)
    for shape in (("sine",) if quick else ("sine", "ricker-sym")):
        res[f"spectrum 200x200 {shape}"] = timed(lambda: rocking.overturning_spectrum(alpha, shape, wp, ratio))[1]
        log(f"  spectrum 200x200 {shape}: {res[f'spectrum 200x200 {shape}']:.2f} s")
    chart_shapes = ("sine",) if quick else ("rect", "sine", "ricker-sym", "ricker-anti")
    frame, sec = timed(lambda: rocking.slenderness_chart(chart_shapes, CHART_PTP, CHART_APG))
    res["chart"] = sec
    res["chart_shapes"] = len(chart_shapes)
    log(f"  chart ({len(chart_shapes)} shape(s) x 8 pTp x 20 ap/g): {sec:.1f} s")
    try:
        rw, sec_w = timed(lambda: rocking.required_width(7.5, rinaldi, rule="exact"))
        res["required_width exact (Rinaldi pulse)"] = sec_w
        res["_width"] = rw.width if hasattr(rw, "width") else None
    except Exception as exc:  # noqa: BLE001
        log(f"  required_width failed: {exc}")
    out["design"] = res

    md.append("## 5. Design timings (issue 4)\n")
    md.append("Measured here directly with the calls `benchmarks/bench_design.py` uses (that script also "
              "cross-checks the exact minimum slenderness against the reference model, which takes minutes: "
              "run it separately).\n")
    md.append("| task | time | target |")
    md.append("|---|---|---|")
    for shape in ("rect", "sine", "ricker-sym", "ricker-anti"):
        t = res[f"min_slenderness {shape}"]
        md.append(f"| exact minimum slenderness, {shape} 0.71 g, 0.8 s, p = 1.381: median (best) | "
                  f"{fmt_t(t)} ({fmt_t(t.best)}) | < 20 ms |")
        t1 = res.get(f"min_slenderness {shape} 1 thread")
        if t1 is not None:
            md.append(f"| the same with numba limited to one thread: median (best) | {fmt_t(t1)} ({fmt_t(t1.best)}) | |")
    for key, value in res.items():
        if key.startswith("spectrum"):
            md.append(f"| overturning {key} (one run) | {value:.2f} s | < 5 s |")
    if res["chart_shapes"] == 4:
        md.append(f"| Fig. 8 chart, 4 shapes x 8 pTp x 20 ap/g (one run) | {res['chart']:.1f} s | < 60 s |")
    else:
        md.append(f"| Fig. 8 chart, 1 shape (sine) x 8 pTp x 20 ap/g (one run; quick mode) | {res['chart']:.1f} s "
                  f"| < 15 s (a quarter of 60 s) |")
    if "required_width exact (Rinaldi pulse)" in res:
        md.append(f"| required width, exact rule, H = 7.5 m, Rinaldi pulse (one run) | "
                  f"{fmt_t(res['required_width exact (Rinaldi pulse)'])} | |")
    md.append("")


# =========================================================================== pipeline section
def section_pipeline(md, out, quick):
    """`pipeline run` end to end, with the helpers of ``benchmarks/bench_pipeline.py``.

    The issue's case (40 records; ``quick``: 8): the synthetic SAC records of ``bench_pipeline``
    (a pulse of each shape plus broadband motion, 20-40 s at 100 Hz) and its two columns,
    ``--no-plots``; ``bench_pipeline.run()`` adds plots and the time per stage.
    """
    import tempfile

    from benchmarks import bench_pipeline as bp

    n = 8 if quick else 40
    res = {}
    log(f"pipeline: `pipeline run` on {n} records, --jobs 1 and 2")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        recs = bp.make_records(tmp / "recs", n, durations=[20.0, 25.0, 30.0, 35.0, 40.0])
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            bp._timed_main(["run", *recs[:2], *bp.COLUMNS, "--out", str(tmp / "warm"), "--no-plots", "-q"])
            for jobs in (1, 2):
                secs, code = bp._timed_main(["run", *recs, *bp.COLUMNS, "--out", str(tmp / f"o{jobs}"),
                                             "--no-plots", "-q", "--jobs", str(jobs)])
                res[f"warm_jobs{jobs}"] = n / secs
                res[f"code_jobs{jobs}"] = code
        log(f"  warm: {res['warm_jobs1']:.2f} records/s with --jobs 1, {res['warm_jobs2']:.2f} with --jobs 2")
        cold, code = bp._timed_cold(["run", *recs, *bp.COLUMNS, "--out", str(tmp / "c2"), "--no-plots",
                                     "-q", "--jobs", "2"])
        res["cold_jobs2"] = n / cold
        log(f"  cold (fresh process), --jobs 2: {res['cold_jobs2']:.2f} records/s")
        cold1, code = bp._timed_cold(["run", *recs, *bp.COLUMNS, "--out", str(tmp / "c1"), "--no-plots",
                                      "-q", "--jobs", "1"])
        res["cold_jobs1"] = n / cold1
        log(f"  cold (fresh process), --jobs 1: {res['cold_jobs1']:.2f} records/s")
        env = dict(os.environ, NUMBA_NUM_THREADS="1")
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "pipeline", "run", *recs, *bp.COLUMNS, "--out", str(tmp / "c2t1"),
                        "--no-plots", "-q", "--jobs", "2"], capture_output=True, env=env, cwd=str(ROOT))
        res["cold_jobs2_t1"] = n / (time.perf_counter() - t0)
        log(f"  cold, --jobs 2, NUMBA_NUM_THREADS=1: {res['cold_jobs2_t1']:.2f} records/s")
        # compared between the two fresh processes (they load the same code; the in-process run
        # may hold modules loaded before another engineer's edit of the working tree)
        res["identical"] = all((tmp / "c1" / f).read_bytes() == (tmp / "c2" / f).read_bytes()
                               for f in ("summary.csv", "failures.csv") if (tmp / "c1" / f).exists())
        per_len = {}
        for duration in ((10.0, 40.0) if quick else (10.0, 20.0, 40.0, 80.0)):
            lrecs = bp.make_records(tmp / f"len{duration:g}", 2 if quick else 4, durations=[duration],
                                    seed=1)
            with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
                secs, _ = bp._timed_main(["run", *lrecs, *bp.COLUMNS, "--out", str(tmp / f"l{duration:g}"),
                                          "--no-plots", "-q"])
            per_len[duration] = secs / len(lrecs)
            log(f"  {duration:g} s records: {per_len[duration]:.2f} s per record (--jobs 1)")
    res["per_length"] = per_len
    out["pipeline"] = res
    md.append("## 6. `pipeline run` throughput (issue 5)\n")
    md.append(f"{n} synthetic near-fault SAC records of 20-40 s at 100 Hz made by `benchmarks/bench_pipeline.py` "
              "(a pulse of each shape plus broadband motion), two columns (`--block 7.5x1.8 --block 6x1.2`), "
              "`--no-plots`, one run each: warm = in this process after a warm-up on two records (worker "
              "processes start from a fork server of their own), cold = a fresh `python -m pipeline` process, "
              "as a user runs it. Target: at least 20 records/s with `--jobs 2`.\n")
    md.append("| | --jobs 1 | --jobs 2 |")
    md.append("|---|---|---|")
    md.append(f"| warm, records/s | {res['warm_jobs1']:.2f} | {res['warm_jobs2']:.2f} |")
    md.append(f"| cold, records/s | {res['cold_jobs1']:.2f} | {res['cold_jobs2']:.2f} |")
    md.append(f"| cold, records/s, `NUMBA_NUM_THREADS=1` | - | {res['cold_jobs2_t1']:.2f} |")
    md.append(f"| exit status | {res['code_jobs1']} | {res['code_jobs2']} |")
    md.append(f"\nSpeed-up from 1 to 2 jobs (warm): {res['warm_jobs2'] / res['warm_jobs1']:.2f}x; "
              f"summary.csv and failures.csv of the two cold runs (--jobs 1 and 2) identical: {res['identical']}.\n")
    md.append(f"| record length (100 Hz), {len(lrecs)} records each, --jobs 1 | " + " | ".join(f"{d:g} s" for d in per_len) + " |")
    md.append("|---|" + "---|" * len(per_len))
    md.append("| seconds per record | " + " | ".join(f"{v:.2f}" for v in per_len.values()) + " |")
    md.append("")


# =========================================================================== calibration and main
def calibration():
    """A fixed small workload: the fast engine on the headline record, and a pure-Python loop."""
    import rocking

    rec = headline_record()
    blk = blocks()["Temple column 7.5x1.8 m"]
    exc = rec.scaled(0.8)
    t_eng = per_call(lambda: rocking.simulate(blk, exc, model="fast", history=False), 0.1, 5)

    def py():
        s = 0.0
        for i in range(20000):
            s += math.sin(i)
        return s

    t_py = per_call(py, 0.1, 5)
    return t_eng, t_py


def write_report(md_sections, mach, load0, cal0, quick, only, total=None, load1=None, cal1=None):
    head = ["# Speed and accuracy: the benchmark report", "",
            "Generated by `python -m benchmarks" + (" --quick" if quick else "") +
            (f" --only {','.join(only)}" if only else "") + "` (`benchmarks/run.py`); every number below was measured "
            "in this one run on this machine. Regenerate it with the same command.", "",
            "## Machine", "",
            f"- CPU: {mach['cpu']}, {mach['nproc']} cores visible (`nproc`); {mach['platform']}",
            f"- Python {mach['python']}, numba {mach['numba']}, numpy {mach['numpy']}, scipy {mach['scipy']}",
            f"- commit {mach['commit']}, run started {mach['date']}",
            f"- load average (1/5/15 min) at the start: {load0}" + (f", at the end: {load1}" if load1 else ""),
            "- The machine is shared with other test runs, so single timings are noisy: times are medians of "
            "repeated runs, and the headline speed ratio is measured interleaved (both sides in each round).",
            f"- Calibration (fast engine on the 20 s, 200 Hz headline record x0.8, Temple column; a 20,000-step "
            f"Python loop): at the start {fmt_t(cal0[0])} and {fmt_t(cal0[1])}"
            + (f"; at the end {fmt_t(cal1[0])} and {fmt_t(cal1[1])} (drift x{cal1[0] / cal0[0]:.2f} and "
               f"x{cal1[1] / cal0[1]:.2f})" if cal1 else "") + ".",
            ]
    if total is not None:
        head.append(f"- Total run time of this report: {total:.0f} s.")
    head.append("")
    text = "\n".join(head + sum(([*s, ""] for s in md_sections), []))
    (OUT / "RESULTS.md").write_text(text)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller version of every section")
    ap.add_argument("--only", help="comma-separated sections: " + ",".join(SECTIONS))
    ap.add_argument("--out", help="folder for RESULTS.md and the plots (default: benchmarks/)")
    args = ap.parse_args(argv)
    global OUT
    if args.out:
        OUT = pathlib.Path(args.out)
        OUT.mkdir(parents=True, exist_ok=True)
    only = [s.strip() for s in args.only.split(",")] if args.only else None
    if only:
        bad = [s for s in only if s not in SECTIONS]
        if bad:
            ap.error(f"unknown section(s) {bad}; choose from {', '.join(SECTIONS)}")
    todo = only or list(SECTIONS)
    quick = args.quick

    import matplotlib

    matplotlib.use("Agg")
    log(f"benchmarks{' (quick)' if quick else ''}: sections {', '.join(todo)}; warming up the compiled code")
    import rocking  # noqa: F401  (load the numba caches before timing)

    mach = machine()
    load0 = loadavg()
    cal0 = calibration()
    log(f"calibration: engine {fmt_t(cal0[0])}, python loop {fmt_t(cal0[1])}; load {load0}")
    records, notes = load_records(3 if quick else len(RECORD_FILES))
    log(f"{len(records)} real records loaded" + (f" ({'; '.join(notes)})" if notes else ""))
    sections = {}
    results = {}
    funcs = {
        "solver": lambda md: section_solver(md, results, quick, records, notes),
        "linear": lambda md: section_linear(md, results, quick, records),
        "cost": lambda md: section_cost(md, results, quick, records),
        "fit": lambda md: section_fit(md, results, quick),
        "design": lambda md: section_design(md, results, quick),
        "pipeline": lambda md: section_pipeline(md, results, quick),
    }
    for name in todo:
        md = []
        t0 = time.perf_counter()
        try:
            funcs[name](md)
        except Exception as exc:  # noqa: BLE001 - one broken section must not lose the others
            import traceback

            traceback.print_exc()
            md.append(f"## Section `{name}` failed\n\n`{type(exc).__name__}: {exc}`\n")
        md.append(f"*(section measured in {time.perf_counter() - t0:.0f} s)*")
        sections[name] = md
        ordered = [sections[k] for k in SECTIONS if k in sections]
        write_report(ordered, mach, load0, cal0, quick, only)
        log(f"section {name} done; RESULTS.md written")
    cal1 = calibration()
    total = time.perf_counter() - T_START
    ordered = [sections[k] for k in SECTIONS if k in sections]
    write_report(ordered, mach, load0, cal0, quick, only, total=total, load1=loadavg(), cal1=cal1)
    log(f"done in {total:.0f} s: {OUT / 'RESULTS.md'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
