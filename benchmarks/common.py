"""Helpers shared by the benchmark sections: the records folder, the real records, the blocks,
timing (:func:`per_call`, :func:`timed`), the calibration workload, the machine description, and
the number formats of the report.
"""
from __future__ import annotations

import contextlib
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

T_START = time.perf_counter()


# =========================================================================== utilities
def log(msg: str) -> None:
    print(f"[{time.perf_counter() - T_START:7.1f} s] {msg}", flush=True)


class TStat(float):
    """A median time (s) that also carries the best (smallest) sample as ``.best``."""

    best = math.nan


def tstat(times):
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
        return tstat(times)
    number = max(1, int(budget / repeat / max(first, 1e-7)))
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        for _ in range(number):
            fn()
        times.append((time.perf_counter() - t) / number)
    return tstat(times)


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
    import Cython
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
            "cython": Cython.__version__, "numpy": np.__version__, "scipy": scipy.__version__,
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


def default_method() -> str:
    """The default ``method`` of ``rocking.simulate`` (read from its signature)."""
    import inspect

    import rocking

    return inspect.signature(rocking.simulate).parameters["method"].default


def method_label(method: str) -> str:
    """``"fast taylor (default method)"`` for the default stepper of ``rocking.simulate``."""
    return f"fast {method}" + (" (default method)" if method == default_method() else "")


USUAL_DEFAULT = dict(method="RK45", rtol=1e-3, atol=1e-6)


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

