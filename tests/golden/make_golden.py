"""Record the solver's answers on fixed cases (run this file to regenerate ``golden.json``).

The answers in ``golden.json`` were recorded with the numba engine of commit 4fcd268, before the
solver was compiled with the package (issue 25); ``tests/test_golden.py`` checks the compiled core
against them.  Run with that commit installed:  ``python tests/golden/make_golden.py``
(the real records are read from ``../shared/records`` beside the checkout when present).

Cases: the reference pulses, the hard cases (verge of overturning, Zeno impacts, safe islands,
extreme slenderness, a long record), the other steppers and the linear model, batches (lanes and
one by one), real records (single runs, verified width, critical scale) and the demo's summary.
"""
from __future__ import annotations

import csv
import json
import math
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

import pulses
import rocking
from pulses import G, make_pulse
from pulses.fit.synthetic import synthetic_record
from rocking import Block

HERE = pathlib.Path(__file__).resolve().parent
TARGET = HERE / "golden.json"
RECORDS = HERE.parents[2] / "shared" / "records" / "raw"
#: real records run (single runs, verified width and critical scale of the 7.5 x 1.8 m column)
REAL = ["Rinaldi228.AT2", "NGA_no_1063_RRS228.AT2", "RSN77_SFERN_PUL164.AT2",
        "RSN181_IMPVALL.H_H-E06230.AT2", "RSN1084_NORTHR_SCS052.AT2", "RSN6_IMPVALL.I_I-ELC180.AT2"]
COLUMN = (7.5, 1.8)
TEMPLE = (9.0, 1.8)  # height, width of an ancient column (docs/theory.md section 1's p = 1.381 rad/s-ish)
#: history points kept per single run (evenly spaced indices of the history)
N_HISTORY = 24


def single(res) -> dict:
    n = res.t.size
    idx = np.unique(np.linspace(0, n - 1, N_HISTORY).astype(int)) if n else np.zeros(0, int)
    return {"overturned": bool(res.overturned), "max_rotation": float(res.max_rotation),
            "n_impacts": int(res.n_impacts), "uplifted": bool(res.uplifted),
            "t_overturn": None if math.isnan(res.t_overturn) else float(res.t_overturn),
            "model": res.model, "verdict_by": res.verdict_by,
            "t": res.t[idx].tolist(), "theta": res.theta[idx].tolist(),
            "impacts": res.impacts[:8].tolist()}


def batch(res) -> dict:
    return {"overturned": np.asarray(res.overturned).astype(int).tolist(),
            "max_rotation": np.asarray(res.max_rotation).tolist(),
            "n_impacts": np.asarray(res.n_impacts).tolist(),
            "uplifted": np.asarray(res.uplifted).astype(int).tolist()}


def pulse_cases(out):
    block = Block.from_dimensions(*COLUMN)
    for shape in ("sine", "ricker-sym", "ricker-anti"):
        for apg in (0.3, 0.71, 1.2, 2.5):
            for tp in (0.5, 0.8, 2.0):
                pulse = make_pulse(shape, apg * G, tp)
                out[f"pulse/{shape}/{apg}/{tp}"] = single(rocking.simulate(block, pulse, model="fast"))
    # rectangular-like step of the rectangular pulse kind, when offered
    for method in ("rk8", "rk4"):
        out[f"method/{method}"] = single(rocking.simulate(block, make_pulse("sine", 0.71 * G, 0.8),
                                                          model="fast", method=method))
    out["linear/sine"] = single(rocking.simulate(block, make_pulse("sine", 0.71 * G, 0.8),
                                                 model="linear"))
    out["free"] = single(rocking.simulate(block, None, theta0=0.5 * block.alpha, model="fast"))


def hard_cases(out):
    block = Block.from_dimensions(*COLUMN)
    # verge of overturning: the critical amplitude of a one-sine pulse, and runs 1e-6 either side
    ca = rocking.critical_amplitudes(block, "sine", 0.8, up_to=12 * block.uplift_acceleration)
    out["verge/critical_amplitudes"] = {"intervals": [list(map(float, iv)) for iv in ca],
                                        "islands": [list(map(float, iv)) for iv in ca.safe_islands]}
    a = ca.minimum
    for f in (1 - 1e-6, 1 + 1e-6):
        out[f"verge/run/{f}"] = single(rocking.simulate(block, make_pulse("sine", a * f, 0.8),
                                                        model="fast"))
    # safe islands in slenderness (symmetric Ricker, Rinaldi-like pulse on the Temple column's p)
    ms = rocking.min_slenderness(make_pulse("ricker-sym", 0.71 * G, 1.25), 1.381)
    out["islands/min_slenderness"] = {"tan_alpha": float(ms.tan_alpha),
                                      "transitions": list(map(float, ms.transitions))}
    msb = rocking.min_slenderness_batch("sine", [1.1, 3.0], [0.3, 0.8])
    out["islands/min_slenderness_batch"] = [float(m.tan_alpha) for m in msb]
    # Zeno sequences: a block coming to rest after many impacts (free, and after a weak pulse)
    out["zeno/free"] = single(rocking.simulate(block, None, theta0=0.9 * block.alpha, model="fast"))
    out["zeno/pulse"] = single(rocking.simulate(block, make_pulse("sine", 0.3 * G, 0.3), model="fast"))
    out["zeno/eta0.95"] = single(rocking.simulate(Block(block.p, block.alpha, 0.95), None,
                                                  theta0=0.8 * block.alpha, model="fast"))
    # extreme slenderness
    for tan in (0.002, 0.01, 0.8):
        b = Block.from_tan_alpha(1.381, tan)
        pulse = make_pulse("sine", 3.0 * tan * G, 1.0)
        out[f"slender/{tan}"] = single(rocking.simulate(b, pulse, model="fast"))
    # records: synthetic near-fault records, one long
    rec = synthetic_record("sine", 0.5 * G, 1.0, 4.0, 14.0, dt=0.01, noise=0.3, seed=11)
    out["synthetic/single"] = single(rocking.simulate(Block.from_dimensions(6.0, 0.7), rec, model="fast"))
    long = synthetic_record("ricker-sym", 0.6 * G, 1.5, 10.0, 300.0, dt=0.005, noise=0.4, seed=3)
    out["long/single"] = single(rocking.simulate(Block.from_dimensions(6.0, 0.9), long, model="fast"))
    # batches: 75 widths under a record (lanes) and one by one; scalings of a pulse
    height = 6.0
    widths = height * rec.pga / G * np.geomspace(0.05, 1.3, 75)
    blocks = [Block.from_dimensions(height, float(w)) for w in widths]
    out["batch/lanes"] = batch(rocking.simulate_many(blocks, rec))
    out["batch/one_by_one"] = batch(rocking.simulate_many(blocks, rec, lanes=False))
    out["batch/long_lanes"] = batch(rocking.simulate_many(blocks[::5], long))
    out["batch/pulse_scales"] = batch(rocking.simulate_many(block, make_pulse("ricker-anti", G, 0.9),
                                                            np.linspace(0.2, 3.0, 40)))
    out["width/synthetic"] = float(rocking.required_width(height, rec, rule="exact").width)


def real_cases(out):
    if not RECORDS.is_dir():
        print(f"real records absent ({RECORDS}): skipped", file=sys.stderr)
        return
    block = Block.from_dimensions(*COLUMN)
    for name in REAL:
        rec = pulses.read_record(RECORDS / name)
        out[f"real/{name}/single"] = single(rocking.simulate(block, rec, model="fast"))
        out[f"real/{name}/scaled1.5"] = single(rocking.simulate(block, rec.scaled(1.5), model="fast"))
        rw = rocking.required_width(COLUMN[0], rec, rule="exact")
        # the numba engine answered the search's first transition (now search_width; width is the
        # design width above every failing width found, issue 33)
        out[f"real/{name}/width"] = {"width": float(getattr(rw, "search_width", rw.width)),
                                     "transitions": list(map(float, rw.transitions))}
        cs = rocking.critical_scale(block, rec, up_to=3.0)
        out[f"real/{name}/critical_scale"] = None if cs.scale is None else float(cs.scale)


def demo(out):
    with tempfile.TemporaryDirectory() as tmp:
        # --limit none: the verge of overturning, the design width the golden answers describe
        subprocess.run([sys.executable, "-m", "pipeline", "demo", "--jobs", "1", "--no-plots", "--limit", "none"],
                       cwd=tmp, check=True, capture_output=True)
        with open(pathlib.Path(tmp) / "demo-output" / "summary.csv", newline="") as f:
            out["demo/summary"] = list(csv.DictReader(f))


def collect(real: bool = True, with_demo: bool = True) -> dict:
    """Every case's answers, by name."""
    out = {}
    pulse_cases(out)
    hard_cases(out)
    if real:
        real_cases(out)
    if with_demo:
        demo(out)
    return out


def main():
    out = collect()
    TARGET.write_text(json.dumps(out, indent=0, sort_keys=True) + "\n", encoding="utf-8")
    print(f"{len(out)} cases written to {TARGET} ({TARGET.stat().st_size / 1e3:.0f} kB)")


if __name__ == "__main__":
    main()
