"""The issue-16 floor for resuming ``pipeline run``: a 200-record batch killed with SIGKILL halfway
and run again computes only the records not yet written, and its outputs are byte-identical to an
uninterrupted run's.

``python benchmarks/bench_resume.py [N]`` (N records, default 200) prints a dict:

- ``seconds_whole``: the uninterrupted run (a fresh ``pipeline run`` process, ``--jobs 2``);
- ``written_when_killed``: reports the killed run had finished (its resume journal's entries);
- ``reused`` and ``computed`` as the second run's final line says them, and ``seconds_resumed``;
- ``identical``: every file of the two output folders has the same bytes.

Records: ``N`` synthetic 8 s records at 50 Hz (:func:`bench_pipeline.make_records`), one column,
one shape, no plots, so that the run is short; the kill comes when half the reports exist.
"""
from __future__ import annotations

import os
import pathlib
import re
import signal
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

from bench_pipeline import make_records  # noqa: E402

ARGS = ["--block", "7.5x1.8", "--shapes", "sine", "--no-plots", "--jobs", "2"]


def _tree(folder):
    folder = pathlib.Path(folder)
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _command(paths, out):
    env = dict(os.environ, PYTHONPATH=str(HERE.parent))
    return [sys.executable, "-m", "pipeline", "run", *paths, *ARGS, "--out", str(out)], env


def run(n: int = 200) -> dict:
    from pipeline.batch import resume

    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        paths = make_records(tmp / "in", n, [8.0], dt=0.02)
        cmd, env = _command(paths, tmp / "whole")
        t0 = time.perf_counter()
        subprocess.run(cmd, env=env, check=True, capture_output=True)
        whole = time.perf_counter() - t0

        out = tmp / "killed"
        cmd, env = _command(paths, out)
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        while len(list(out.glob("rec*.csv"))) < n // 2 and proc.poll() is None:
            time.sleep(0.01)
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        written = len(resume.Journal(out).entries)
        t0 = time.perf_counter()
        done = subprocess.run(cmd, env=env, capture_output=True, text=True)
        resumed = time.perf_counter() - t0
        a, b = _tree(tmp / "whole"), _tree(out)
        differ = sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))
        m = re.search(r"\((\d+) reused from an earlier run, (\d+) computed\)", done.stdout)
        return {
            "records": n,
            "seconds_whole": round(whole, 1),
            "killed_by": "SIGKILL",
            "written_when_killed": written,
            "reused": int(m.group(1)) if m else None,
            "computed": int(m.group(2)) if m else None,
            "seconds_resumed": round(resumed, 1),
            "identical": not differ,
            "files_differing": differ,
            "exit_status": done.returncode,
        }


if __name__ == "__main__":
    print(run(int(sys.argv[1]) if len(sys.argv) > 1 else 200))
