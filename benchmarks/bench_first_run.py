"""First run after an install: how long the solver's compilation (numba) takes, and where it goes.

    python benchmarks/bench_first_run.py               # first calls, each in a fresh process
    python benchmarks/bench_first_run.py --functions   # also: compile time per compiled function
    python benchmarks/bench_first_run.py --demo        # also: the demo's run, fresh and warm

Every measurement runs in a new Python process with a new, empty ``NUMBA_CACHE_DIR`` (numba's
on-disk cache of machine code), as on a machine where the package was just installed; the child
reports wall-clock and CPU seconds (``time.process_time``: compilation is one thread, and CPU time
is what stays comparable on a busy machine).  Stages, in one process, in the order a user meets
them:

- ``import``: ``import pulses, rocking``;
- ``simulate_record``: the first ``rocking.simulate`` of a record (a bundled example record);
- ``simulate_pulse``: then the first ``rocking.simulate`` of a one-sine pulse;
- ``min_slenderness``: then the first exact minimum slenderness of a pulse (batch, one by one);
- ``required_width``: then the first verified width under a record (the batch engine in lanes);
- ``warm_*``: the same calls again in the same process (compiled).

``--demo``: ``pipeline run data/*.sac --block 7.5x1.8`` (what ``pipeline demo`` runs) in a fresh
process with an empty cache, then again with the cache it filled.
"""
from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys
import tempfile

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
functions = "--functions" in sys.argv
if functions:
    from numba.core import event
    class Recorder(event.Listener):
        def __init__(self):
            self.buf = []
        def on_start(self, ev):
            self.buf.append((time.process_time(), ev))
        def on_end(self, ev):
            self.buf.append((time.process_time(), ev))
    recorder = Recorder()
    event.register("numba:compile", recorder)
stage("import", lambda: __import__("rocking") and __import__("pulses"))
import glob, rocking, pulses
record = pulses.read_record(sorted(glob.glob(sys.argv[1] + "/data/*.sac"))[0])
block = rocking.Block.from_dimensions(7.5, 1.8)
pulse = pulses.OneSine(0.71 * pulses.G, 0.8)
calls = {
    "simulate_record": lambda: rocking.simulate(block, record),
    "simulate_pulse": lambda: rocking.simulate(block, pulse),
    "min_slenderness": lambda: rocking.min_slenderness(pulse, block.p),
    "required_width": lambda: rocking.required_width(7.5, record, rule="exact"),
}
for name, f in calls.items():
    stage(name, f)
for name, f in calls.items():
    stage("warm_" + name, f)
if functions:
    stack, spent = [], {}
    for t, ev in recorder.buf:
        d = ev.data
        key = d["dispatcher"].py_func.__module__ + "." + d["dispatcher"].py_func.__qualname__
        key += " " + str(tuple(str(a) for a in d["args"]))[:60]
        if ev.is_start:
            stack.append([key, t, 0.0])
        else:
            k, t0, inner = stack.pop()
            spent[k] = spent.get(k, 0.0) + (t - t0) - inner
            if stack:
                stack[-1][2] += t - t0
    out["functions_cpu_s"] = {k: round(v, 3) for k, v in sorted(spent.items(), key=lambda kv: -kv[1])}
    out["compiled_specialisations"] = len(spent)
print("RESULT " + json.dumps(out))
'''


def _fresh_env(cache):
    env = dict(os.environ, NUMBA_CACHE_DIR=cache, PYTHONPATH=str(ROOT))
    env.pop("NUMBA_DISABLE_JIT", None)
    return env


def first_calls(functions=False) -> dict:
    """The stages of the module doc in one fresh process with an empty cache."""
    with tempfile.TemporaryDirectory() as cache:
        args = [sys.executable, "-c", CHILD, str(ROOT)] + (["--functions"] if functions else [])
        res = subprocess.run(args, env=_fresh_env(cache), capture_output=True, text=True,
                             check=True)
    line = [x for x in res.stdout.splitlines() if x.startswith("RESULT ")][-1]
    out = json.loads(line[len("RESULT "):])
    out["stderr"] = res.stderr.strip().splitlines()[:3]
    return out


def _timed_run(cmd, env):
    import resource
    import time

    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {"wall_s": round(wall, 2), "cpu_s": round(cpu, 2)}


def demo() -> dict:
    """``pipeline run data/*.sac --block 7.5x1.8`` with an empty cache, then with the filled one."""
    records = sorted(str(p) for p in (ROOT / "data").glob("*.sac"))
    with tempfile.TemporaryDirectory() as tmp:
        cache = os.path.join(tmp, "cache")
        env = _fresh_env(cache)
        cmd = [sys.executable, "-m", "pipeline", "run", *records, "--block", "7.5x1.8",
               "--out", os.path.join(tmp, "out"), "--quiet"]
        return {"demo_fresh": _timed_run(cmd, env), "demo_warm": _timed_run(cmd, env)}


def run(functions=False, with_demo=False) -> dict:
    out = first_calls(functions)
    if with_demo:
        out.update(demo())
    return out


if __name__ == "__main__":
    result = run("--functions" in sys.argv[1:], "--demo" in sys.argv[1:])
    top = result.pop("functions_cpu_s", None)
    for key, value in result.items():
        print(f"{key:<26} {value}")
    if top:
        print("compile CPU s per function (exclusive of what it compiled inside), largest first:")
        for key, value in list(top.items())[:25]:
            print(f"  {value:7.2f}  {key}")
