"""First run after an install: `pip install .`, then the first calls and the first `pipeline demo`.

    python benchmarks/bench_first_run.py             # first calls and the demo, fresh and warm
    python benchmarks/bench_first_run.py --install   # also: `pip install .` in a fresh venv

The solver is compiled when the package is built (Cython, ``setup.py``), so a first run has
nothing left to compile: what is measured is what a user meets.  ``--install`` makes a fresh
virtual environment in a temporary folder and times ``pip install .`` of this checkout there
(wheels of the dependencies from pip's cache, the core compiled), then runs everything below
with that environment's Python.  Stages, each first in a new process, in the order a user
meets them:

- ``import``: ``import rocking`` alone, then ``import pulses, rocking, pipeline``;
- ``simulate_record``, ``simulate_pulse``, ``min_slenderness``, ``required_width``: the first
  call of each in one process, then ``warm_*``: the same calls again;
- ``demo``: ``pipeline demo`` in a fresh folder, twice (the first after the install, then warm).

Times are wall-clock seconds of the whole process (and CPU seconds of the calls), one line of
JSON per stage; the machine is shared, so read them with its load average (printed).
"""
from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[1]

CHILD = r'''
import json, sys, time
clock = lambda: (time.perf_counter(), time.process_time())
out = {}
def stage(name, f):
    w, c = clock()
    value = f()
    w2, c2 = clock()
    out[name] = {"wall_s": round(w2 - w, 3), "cpu_s": round(c2 - c, 3)}
    return value
stage("import", lambda: __import__("rocking"))
import pulses, rocking, pipeline
from pulses import G, make_pulse
import pipeline.data, pathlib
rec = pulses.read_record(sorted(pathlib.Path(pipeline.data.__file__).parent.glob("*.sac"))[0])
block = rocking.Block.from_dimensions(7.5, 1.8)
calls = {
    "simulate_record": lambda: rocking.simulate(block, rec.scaled(3.0)),
    "simulate_pulse": lambda: rocking.simulate(block, make_pulse("sine", 0.71 * G, 0.8)),
    "min_slenderness": lambda: rocking.min_slenderness(make_pulse("sine", 0.71 * G, 0.8), 1.381),
    "required_width": lambda: rocking.required_width(7.5, rec, rule="exact"),
}
for name, f in calls.items():
    stage(name, f)
for name, f in calls.items():
    stage("warm_" + name, f)
print(json.dumps(out))
'''


def _timed(cmd, **kw) -> float:
    t = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True, **kw)
    return time.perf_counter() - t


def measure(python: str) -> dict:
    res = {"loadavg": " ".join(f"{x:.2f}" for x in os.getloadavg())}
    res["import_rocking_s"] = min(_timed([python, "-c", "import rocking"]) for _ in range(3))
    res["import_all_s"] = min(_timed([python, "-c", "import pulses, rocking, pipeline"])
                              for _ in range(3))
    res["python_start_s"] = min(_timed([python, "-c", "pass"]) for _ in range(3))
    out = subprocess.run([python, "-c", CHILD], check=True, capture_output=True, text=True)
    res["stages"] = json.loads(out.stdout)
    with tempfile.TemporaryDirectory() as tmp:
        res["demo_first_s"] = _timed([python, "-m", "pipeline", "demo"], cwd=tmp)
        res["demo_warm_s"] = _timed([python, "-m", "pipeline", "demo", "--out", "again"], cwd=tmp)
    res["demo_first_over_warm"] = res["demo_first_s"] / res["demo_warm_s"]
    return res


def install() -> tuple[str, float, str]:
    """A fresh virtual environment with this checkout installed; (python, seconds, folder)."""
    folder = tempfile.mkdtemp(prefix="rocking-first-run-")
    subprocess.run([sys.executable, "-m", "venv", folder], check=True)
    python = str(pathlib.Path(folder) / "bin" / "python")
    seconds = _timed([python, "-m", "pip", "install", "-q", str(ROOT)])
    return python, seconds, folder


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    python, res = sys.executable, {}
    if "--install" in argv:
        python, seconds, folder = install()
        res["pip_install_s"] = round(seconds, 1)
        res["venv"] = folder
    res.update(measure(python))
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
