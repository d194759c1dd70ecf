"""Warm speed of the compiled core against the numba engine it replaced (issue 25), in one run.

    python benchmarks/bench_compiled_vs_numba.py [--old-python PATH] [--rounds N]

``--old-python``: the Python of an environment where the numba engine (commit 4fcd268) is
installed, e.g. ``git worktree add ../old 4fcd268 && python -m venv ../venv-old &&
../venv-old/bin/pip install -e ../old``; default ``../venv-old/bin/python`` beside this checkout.
This checkout's package is run by the Python running this script.

Each engine runs in its own process, alternately, ``--rounds`` times (the machine is shared: a
round of each close together sees the same load).  In each process every case is called once
first (numba loads or compiles its code then; nothing happens for the compiled core), then timed:
CPU seconds (``time.process_time``, all threads) per call, median of repeated calls.  Cases:
the public API on the Rinaldi 228 record (``../shared/records``; a bundled record if absent):
a record run with history, a pulse run, a batch of 64 widths, the exact minimum slenderness of
a pulse, the exact required width under the record, the critical scale; and ``pipeline run``
of the bundled records (``--jobs 1 --no-plots``, warm: CPU seconds of the whole command).
Printed: a markdown table, best of the rounds' medians for each engine, and the ratio.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
RECORD = ROOT.parent / "shared" / "records" / "raw" / "Rinaldi228.AT2"

CHILD = r'''
import json, pathlib, statistics, sys, time
import numpy as np
import pulses, rocking
from pulses import G, make_pulse
path = pathlib.Path(sys.argv[1])
if path.is_file():
    rec = pulses.read_record(path)
else:
    import pipeline.data
    rec = pulses.read_record(sorted(pathlib.Path(pipeline.data.__file__).parent.glob("*.sac"))[0])
block = rocking.Block.from_dimensions(7.5, 1.8)
pulse = make_pulse("sine", 0.71 * G, 0.8)
top = 7.5 * rec.pga / G
widths = [rocking.Block.from_dimensions(7.5, float(w)) for w in top * np.geomspace(0.2, 1.0, 64)]
cases = {
    "record run (simulate, history)": (lambda: rocking.simulate(block, rec), 20),
    "pulse run (simulate)": (lambda: rocking.simulate(block, pulse), 200),
    "batch of 64 widths (simulate_many)": (lambda: rocking.simulate_many(widths, rec), 10),
    "exact min slenderness (pulse)": (lambda: rocking.min_slenderness(pulse, 1.381), 5),
    "exact required width (record)": (lambda: rocking.required_width(7.5, rec, rule="exact"), 3),
    "critical scale (record)": (lambda: rocking.critical_scale(block, rec, up_to=3.0), 3),
}
out = {}
for name, (f, n) in cases.items():
    f()  # numba: loads (or compiles) its code here
    ts = []
    for _ in range(n):
        c = time.process_time()
        f()
        ts.append(time.process_time() - c)
    out[name] = statistics.median(ts)
print(json.dumps(out))
'''


def child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def pipeline_run(python: str) -> float:
    """CPU seconds of a warm ``pipeline run`` of the bundled records, one process."""
    sacs = sorted((ROOT / "data").glob("*.sac"))
    with tempfile.TemporaryDirectory() as tmp:
        cmd = [python, "-m", "pipeline", "run", *map(str, sacs), "--block", "7.5x1.8", "--jobs",
               "1", "--no-plots", "--out", tmp + "/warm"]
        subprocess.run(cmd, check=True, capture_output=True, cwd=tmp)  # warm caches
        cmd[-1] = tmp + "/timed"
        c = child_cpu()
        subprocess.run(cmd, check=True, capture_output=True, cwd=tmp)
        return child_cpu() - c


def one(python: str) -> dict:
    out = subprocess.run([python, "-c", CHILD, str(RECORD)], check=True, capture_output=True,
                         text=True, cwd=tempfile.gettempdir())
    res = json.loads(out.stdout)
    res["pipeline run, 5 bundled records (CPU s)"] = pipeline_run(python)
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--old-python", default=str(ROOT.parent / "venv-old" / "bin" / "python"))
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args(argv)
    new, old = {}, {}
    for r in range(args.rounds):
        for python, store in ((args.old_python, old), (sys.executable, new)):
            for k, v in one(python).items():
                store.setdefault(k, []).append(v)
        print(f"round {r + 1} done; load {os.getloadavg()}", file=sys.stderr, flush=True)
    print(f"record: {RECORD.name if RECORD.is_file() else 'bundled'}; rounds: {args.rounds}; "
          f"load at the end {' '.join(f'{x:.2f}' for x in os.getloadavg())}\n")
    print("| case | numba engine (4fcd268) | compiled core | compiled / numba |")
    print("| --- | --- | --- | --- |")
    for k in new:
        a, b = min(old[k]), min(new[k])
        unit = "s" if "CPU s" in k else "ms"
        f = 1.0 if unit == "s" else 1e3
        print(f"| {k} | {a * f:.3f} {unit} | {b * f:.3f} {unit} | {b / a:.2f} |")


if __name__ == "__main__":
    main()
