"""rocking.warm_up: processes share the solver's compilation, and its groups cover a pipeline run."""
from __future__ import annotations

import json
import os
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[1]
DATA = ROOT / "data"

# three small compiled functions: two entry points sharing a leaf
MODULE = '''
from numba import njit


@njit(cache=True)
def leaf(x):
    return x * 2.0 + 1.0


@njit(cache=True)
def top1(x):
    return leaf(x) + 1.0


@njit(cache=True)
def top2(x):
    return leaf(x) - 1.0


def group1():
    assert top1(1.0) == 4.0


def group2():
    assert top2(1.0) == 2.0
'''

# one process of the test: runs the named group with the lock folder shared with the other, and
# reports which functions it started compiling and what warm_up said.  The first process holds
# the leaf's lock for a while after compiling it (its cache is written once the lock is
# released); the second starts only once the first holds it.
DRIVER = '''
import json, os, pathlib, sys, time
from numba.core import event

role, folder, out = sys.argv[1:4]
folder = pathlib.Path(folder)
starts = []


class Watch(event.Listener):
    def on_start(self, ev):
        starts.append(ev.data["dispatcher"].py_func.__qualname__)

    def on_end(self, ev):
        if role != "second" and ev.data["dispatcher"].py_func.__qualname__ == "leaf":
            (folder / "leaf-compiled").touch()
            if role == "dies":
                os._exit(3)  # dies holding the leaf's lock
            time.sleep(1.5)


event.register("numba:compile", Watch())
import warmtest_mod as m
from rocking.warmup import _run_groups

if role == "second":
    while not (folder / "leaf-compiled").exists():
        time.sleep(0.01)
    groups = {"group2": m.group2}
else:
    groups = {"group1": m.group1}
res = _run_groups(groups, shared=folder, packages=("warmtest_mod.",))
pathlib.Path(out).write_text(json.dumps({"starts": starts, "compiled": res.compiled,
                                         "waited": res.waited, "failed": res.failed}))
'''


def _processes(tmp_path, first_role):
    (tmp_path / "warmtest_mod.py").write_text(MODULE)
    (tmp_path / "driver.py").write_text(DRIVER)
    folder = tmp_path / "locks"
    folder.mkdir()
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "cache"),
               PYTHONPATH=os.pathsep.join([str(tmp_path), str(ROOT)]))
    env.pop("NUMBA_DISABLE_JIT", None)
    procs = [subprocess.Popen([sys.executable, str(tmp_path / "driver.py"), role, str(folder),
                               str(tmp_path / f"{role}.json")], env=env)
             for role in (first_role, "second")]
    codes = [p.wait(timeout=120) for p in procs]
    return codes, [json.loads((tmp_path / f"{r}.json").read_text()) if (tmp_path / f"{r}.json").exists()
                   else None for r in (first_role, "second")]


def test_a_function_being_compiled_elsewhere_is_loaded_not_compiled_again(tmp_path):
    """The second process meets the leaf while the first compiles it: it leaves its group, waits,
    and loads the leaf from numba's cache (compiling only its own entry point)."""
    codes, (first, second) = _processes(tmp_path, "first")
    assert codes == [0, 0]
    assert first["compiled"] == 2 and sorted(set(first["starts"])) == ["leaf", "top1"]
    assert first["failed"] == [] and second["failed"] == []
    # the second compiled top2 only: its one start of the leaf is the compilation it abandoned
    # on seeing the lock (a second start would be a compilation of its own)
    assert second["compiled"] == 1
    assert second["starts"].count("leaf") == 1
    # it waited for the first's 1.5 s hold of the lock (less what it spent starting up)
    assert second["waited"] > 0.3


def test_the_lock_of_a_process_that_died_is_taken_over(tmp_path):
    """A process that dies while it holds a lock does not stop the others: its lock is free."""
    codes, (dead, second) = _processes(tmp_path, "dies")
    assert codes[0] == 3 and codes[1] == 0 and dead is None
    assert second["failed"] == []
    # the leaf's cache was never written (the process died before that), so it is compiled here
    assert second["compiled"] == 2


COVERAGE = '''
import json, sys, glob, tempfile
from numba.core import event
from numba.extending import is_jitted

import rocking


def signatures():
    out = {}
    for name, mod in list(sys.modules.items()):
        if name == "rocking" or name.startswith("rocking."):
            for attr, obj in list(vars(mod).items()):
                if is_jitted(obj):
                    out[f"{name}.{attr}"] = sorted(map(str, obj.signatures))
    return out


compiled = []


class Count(event.Listener):
    def on_start(self, ev):
        compiled.append(ev.data["dispatcher"].py_func.__qualname__)

    def on_end(self, ev):
        pass


res = rocking.warm_up()
before = signatures()
from pipeline.batch import Column
from pipeline.runner import run

event.register("numba:compile", Count())
with tempfile.TemporaryDirectory() as out:
    run(sorted(glob.glob(sys.argv[1] + "/*.sac")), (Column(7.5, 1.8),), out, jobs=1, quiet=True)
after = signatures()
new = {k: sorted(set(v) - set(before.get(k, []))) for k, v in after.items()}
print("RESULT " + json.dumps({"new": {k: v for k, v in new.items() if v}, "compiled": compiled,
                              "failed": res.failed, "before": sum(map(len, before.values()))}))
'''


def test_warm_up_covers_a_pipeline_run():
    """After rocking.warm_up, the demo's pipeline run calls no compiled function of rocking with
    types the warm-up did not (each would be a compilation on a fresh install: the full check
    with an empty cache is benchmarks/bench_first_run.py --warm-up)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    env.pop("NUMBA_DISABLE_JIT", None)
    proc = subprocess.run([sys.executable, "-c", COVERAGE, str(DATA)], env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr
    res = json.loads(proc.stdout.split("RESULT ", 1)[1])
    assert res["failed"] == []
    assert res["before"] >= 2  # the entry points (the single-run engine, the batch kernel) at least
    assert res["new"] == {}
    assert res["compiled"] == []


def test_unknown_group_is_refused():
    import rocking

    with pytest.raises(ValueError, match="unknown warm-up group"):
        rocking.warm_up(["simulate", "nonsense"])
