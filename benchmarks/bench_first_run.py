"""First run after an install: how long the solver's compilation (numba) takes, and where it goes.

    python benchmarks/bench_first_run.py               # first calls, each in a fresh process
    python benchmarks/bench_first_run.py --functions   # also: compile time per compiled function
    python benchmarks/bench_first_run.py --demo        # also: the demo's run, fresh and warm
    python benchmarks/bench_first_run.py --warm-up     # only: rocking.warm_up, then a run (below)
    python benchmarks/bench_first_run.py --root DIR [--variants default,jobs2]  # only the demo, of
                                                       # another checkout (before/after)

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
process with an empty cache, then again with the cache it filled: as ``pipeline demo`` runs it
(no ``--jobs``: records in one process, a cold cache compiled by one process per CPU,
``rocking.warm_up``), and with ``--jobs 1`` (compiled in the one process, as before the warm-up)
and ``--jobs 2`` (two workers that share the compilation).  CPU seconds are those of every
process of the run (the command's process tree, sampled every 0.1 s with psutil: helper
processes are not children the command waits for).

``--warm-up``: the full check that the warm-up covers a pipeline run: ``rocking.warm_up`` with
one helper per further CPU in a fresh process with an empty cache, then the demo's run (``--jobs
1``) in another process counting numba's compilations (``numba:compile`` events): 0 expected.
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


def _timed_run(cmd, env, cwd=None):
    """Wall-clock and CPU seconds of ``cmd`` and every process it starts (sampled)."""
    import time

    import psutil

    cpu = {}
    t = time.perf_counter()
    proc = subprocess.Popen(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)
    root = psutil.Process(proc.pid)
    while proc.poll() is None:
        try:
            tree = [root] + root.children(recursive=True)
        except psutil.Error:
            tree = []
        for p in tree:
            try:
                c = p.cpu_times()
                cpu[p.pid] = c.user + c.system
            except psutil.Error:
                pass
        time.sleep(0.1)
    wall = time.perf_counter() - t
    err = proc.stderr.read().decode(errors="replace")
    if proc.returncode != 0:
        raise RuntimeError(f"{cmd} failed ({proc.returncode}): {err[-2000:]}")
    return {"wall_s": round(wall, 2), "cpu_s": round(sum(cpu.values()), 2),
            "processes": len(cpu), "stderr_lines": len(err.splitlines())}


WARM_RUNS = 3  # the warm run's median of this many (it takes seconds; a busy machine varies)
DEMO_VARIANTS = {"default": [], "jobs1": ["--jobs", "1"], "jobs2": ["--jobs", "2"]}


def demo(root=ROOT, variants=tuple(DEMO_VARIANTS)) -> dict:
    """``pipeline run data/*.sac --block 7.5x1.8`` with an empty cache, then with the filled one;
    as ``pipeline demo`` runs it, with ``--jobs 1`` and with ``--jobs 2`` (``variants``)."""
    root = pathlib.Path(root)
    records = sorted(str(p) for p in (ROOT / "data").glob("*.sac"))
    out = {}
    for label in variants:
        jobs = DEMO_VARIANTS[label]
        with tempfile.TemporaryDirectory() as tmp:
            cache = os.path.join(tmp, "cache")
            env = _fresh_env(cache)
            env["PYTHONPATH"] = str(root)
            cmd = [sys.executable, "-m", "pipeline", "run", *records, "--block", "7.5x1.8",
                   "--out", os.path.join(tmp, "out"), "--force", *jobs]
            out[f"demo_{label}_fresh"] = _timed_run(cmd, env, cwd=tmp)
            warm = [_timed_run(cmd, env, cwd=tmp) for _ in range(WARM_RUNS)]
            out[f"demo_{label}_warm"] = {key: sorted(r[key] for r in warm)[WARM_RUNS // 2]
                                         for key in ("wall_s", "cpu_s")}  # medians
    return out


COUNT = r'''
import glob, json, sys, tempfile
from numba.core import event

compiled = []


class Count(event.Listener):
    def on_start(self, ev):
        f = ev.data["dispatcher"].py_func
        compiled.append(f.__module__ + "." + f.__qualname__)

    def on_end(self, ev):
        pass


event.register("numba:compile", Count())
from pipeline.batch import Column
from pipeline.runner import run

with tempfile.TemporaryDirectory() as out:
    run(sorted(glob.glob(sys.argv[1] + "/data/*.sac")), (Column(7.5, 1.8),), out, jobs=1,
        quiet=True)
print("RESULT " + json.dumps(compiled))
'''

WARM = r'''
import json, os, time
if __name__ == "__main__":
    import rocking

    t, c = time.perf_counter(), time.process_time()
    res = rocking.warm_up(helpers=len(os.sched_getaffinity(0)) - 1)
    print("RESULT " + json.dumps({"wall_s": round(time.perf_counter() - t, 2),
                                  "cpu_s_this_process": round(time.process_time() - c, 2),
                                  "compiled_here": res.compiled, "waited_s": round(res.waited, 2),
                                  "helpers": res.helpers, "failed": res.failed}))
'''


def warm_up_check() -> dict:
    """``rocking.warm_up`` with helpers in an empty cache, then the demo's run counting numba's
    compilations (0 expected: the warm-up's groups cover it)."""
    with tempfile.TemporaryDirectory() as tmp:
        env = _fresh_env(os.path.join(tmp, "cache"))
        script = os.path.join(tmp, "warm.py")
        with open(script, "w") as fh:
            fh.write(WARM)
        timed = _timed_run([sys.executable, script], env)
        res = subprocess.run([sys.executable, script], env=env, capture_output=True, text=True,
                             check=True)  # the cache is warm now: what a warm warm-up costs
        warm = json.loads(res.stdout.split("RESULT ", 1)[1])
        res = subprocess.run([sys.executable, "-c", COUNT, str(ROOT)], env=env,
                             capture_output=True, text=True, check=True)
        compiled = json.loads(res.stdout.split("RESULT ", 1)[1])
    return {"warm_up_fresh": timed, "warm_up_again": warm,
            "compilations_in_the_run_after_it": len(compiled),
            "compiled_in_the_run": sorted(set(compiled))[:10]}


def run(functions=False, with_demo=False, root=ROOT) -> dict:
    out = first_calls(functions)
    if with_demo:
        out.update(demo(root))
    return out


if __name__ == "__main__":
    argv = sys.argv[1:]
    if "--warm-up" in argv:
        for key, value in warm_up_check().items():
            print(f"{key:<34} {value}")
        sys.exit(0)
    variants = tuple(DEMO_VARIANTS)
    if "--variants" in argv:  # e.g. --variants default,jobs2
        variants = tuple(argv[argv.index("--variants") + 1].split(","))
    if "--root" in argv:  # only the demo, of another checkout
        for key, value in demo(argv[argv.index("--root") + 1], variants).items():
            print(f"{key:<26} {value}")
        sys.exit(0)
    result = run("--functions" in argv, "--demo" in argv)
    top = result.pop("functions_cpu_s", None)
    for key, value in result.items():
        print(f"{key:<26} {value}")
    if top:
        print("compile CPU s per function (exclusive of what it compiled inside), largest first:")
        for key, value in list(top.items())[:25]:
            print(f"  {value:7.2f}  {key}")
