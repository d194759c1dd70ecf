"""Peak memory of a long, finely sampled record: dt 1e-4 s, 2e6 samples (issue 24, item 7).

``python benchmarks/bench_classify_memory.py [classify|run] [--samples N] [--dt S]`` writes a
synthetic record (a one-sine pulse of 0.4 g, Tp 1 s, at 20 s, in a stationary background of
0.05 g, seeded) as SAC into a temporary folder and, in a fresh subprocess, either classifies it
(:func:`pulses.classify_pulse`, default) or processes it with ``pipeline run --block 7.5x1.8
--shapes sine --no-plots --jobs 1``.  Prints a dict: samples, dt, the subprocess's peak resident
memory (``ru_maxrss`` of the child, from :func:`resource.getrusage` ``RUSAGE_CHILDREN``) and its
wall time.  :func:`run` returns the dict.

Target: at most 2 GB of peak memory for the record the reading limits accept.

Measured on 2 shared cores (load 10 to 12, so the times are 5 to 10 times an idle machine's),
peak resident memory of the child process:

| record | code | classify | ``pipeline run`` |
|---|---|---|---|
| dt 1e-4 s, 2e6 samples | before (issue 24, measured by the issue) | - | 12.9 GB, 80 s |
| dt 1e-4 s, 2e6 samples | now | 802 MB, 726 s | 947 MB, 659 s, exit 0 |
| dt 1e-3 s, 2e5 samples | before (a saved copy of the earlier ``pulses/velocity.py``, ``--module``) | 1369 MB, 52 s | - |
| dt 1e-3 s, 2e5 samples | now | 300 MB, 33 s | - |

The earlier code at dt 1e-4 s was not run again here: its filter caches alone would have held
about 11 GB on a machine shared with other jobs.  What went: the (51, n) maps of coefficients
and power (1.6 GB for one component, 2.4 GB for a pair at 2e6 samples), the filter spectra cached
16 sets at a time (1.1 GB a set) and up to 4096 refined filters of up to 6 MB each; now the map
is kept as four arrays of n and every filter cache is bounded in bytes
(:data:`pulses.db4.FILTER_CACHE_BYTES`, :data:`pulses.db4.SPECTRUM_CACHE_BYTES`).  The
candidates and their numbers are the same, bit for bit.
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
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]

_CLASSIFY = r"""
import importlib, sys
import pulses
classify = importlib.import_module(sys.argv[2]).classify_pulse
rec = pulses.read_record(sys.argv[1])
res = classify(rec)
print(res.is_pulse, res.tp, res.indicator)
"""


def make_record(path, n: int, dt: float, seed: int = 24) -> None:
    import pulses

    rng = np.random.default_rng(seed)
    t = dt * np.arange(n)
    acc = 0.05 * pulses.G * rng.standard_normal(n)
    # smooth the background to about 10 Hz and bring it back to 0.05 g rms
    width = max(1, int(0.05 / dt))
    acc = np.convolve(acc, np.ones(width) / width, mode="same")
    acc *= 0.05 * pulses.G / np.sqrt(np.mean(acc * acc))
    tp, t0 = 1.0, 20.0
    inside = (t >= t0) & (t < t0 + tp)
    acc[inside] += 0.4 * pulses.G * np.sin(2 * np.pi * (t[inside] - t0) / tp)
    pulses.write_sac(pulses.Record(acc, dt, name="long"), path)


def run(mode: str = "classify", samples: int = 2_000_000, dt: float = 1e-4,
        module: str = "pulses.velocity") -> dict:
    with tempfile.TemporaryDirectory(prefix="bench-classify-memory-") as tmp:
        path = pathlib.Path(tmp) / "long.sac"
        make_record(path, samples, dt)
        if mode == "classify":
            cmd = [sys.executable, "-c", _CLASSIFY, str(path), module]
        else:
            cmd = [sys.executable, "-m", "pipeline", "run", str(path), "--block", "7.5x1.8", "--shapes",
                   "sine", "--no-plots", "--jobs", "1", "-q", "--out", str(pathlib.Path(tmp) / "out")]
        env = dict(os.environ, PYTHONPATH=str(ROOT))
        start = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
        seconds = time.perf_counter() - start
        peak_kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    return {"mode": mode, "samples": samples, "dt": dt, "exit": proc.returncode,
            "peak_rss_mb": round(peak_kb / 1024.0, 1), "seconds": round(seconds, 1),
            "output": (proc.stdout + proc.stderr).strip()[-300:]}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mode", nargs="?", choices=["classify", "run"], default="classify")
    ap.add_argument("--samples", type=int, default=2_000_000)
    ap.add_argument("--dt", type=float, default=1e-4)
    ap.add_argument("--module", default="pulses.velocity",
                    help="classify: the module whose classify_pulse is measured (a saved copy of an "
                         "earlier version, to compare)")
    args = ap.parse_args(argv)
    print(json.dumps(run(args.mode, args.samples, args.dt, args.module)))


if __name__ == "__main__":
    main()
