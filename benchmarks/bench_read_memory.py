"""Memory and time of reading a large record: a 200 MB text file (issue 19, item 5).

``python benchmarks/bench_read_memory.py [--mb 200] [--format text|at2]`` writes a record of about
that size into a temporary folder, reads it with :func:`pulses.read_record` in a fresh
subprocess, and prints a dict: the file's size and samples, the subprocess's peak resident memory
(``resource.getrusage(RUSAGE_SELF).ru_maxrss`` measured inside it, before and after the read) and
the reading time.  :func:`run` returns the dict.

The text record has a time column and an acceleration column (``0.005000,-1.234567e+02``, 26
bytes a row on average): 200 MB is 7.6 million samples, under the 10^7 that
:data:`pulses.formats.MAX_SAMPLES` allows.  The AT2 record has five numbers a line (76 bytes):
152 MB is 10^7 samples.  The target: well under 1 GB of peak memory (the reader before blocks of
lines: 5.6 GB for 200 MB of text).

Measured (2 shared cores, load about 10): text 200 MB, 7.6 M samples: peak 315 MB, 22.7 s; AT2
152 MB, 10^7 samples: peak 295 MB, 14.5 s; the reader before blocks of lines, text 19 MB: peak
508 MB, 20.4 s (the new one: 113 MB, 2.1 s).
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]

#: rows written per call while making the file (bounded memory in the writer too)
_WRITE_ROWS = 200_000

_CHILD = r"""
import json, resource, sys, time
import numpy as np
import pulses
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0 = time.perf_counter()
kw = json.loads(sys.argv[2])
rec = pulses.read_record(sys.argv[1], **kw)
seconds = time.perf_counter() - t0
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"npts": rec.npts, "dt": rec.dt, "pga_m_s2": rec.pga, "seconds": seconds,
                  "rss_kb_before": before, "rss_kb_after": after}))
"""


def write_text(path: pathlib.Path, megabytes: float, dt: float = 0.005) -> int:
    """A time and acceleration (cm/s^2) CSV of about ``megabytes`` MB; returns its rows."""
    rows = int(megabytes * 1e6 / 26.2)  # 26.2 bytes a row on average
    rng = np.random.default_rng(1)
    with open(path, "w") as fh:
        fh.write("# time (s), acceleration (cm/s^2)\ntime,acc\n")
        for start in range(0, rows, _WRITE_ROWS):
            n = min(_WRITE_ROWS, rows - start)
            t = (start + np.arange(n)) * dt
            acc = 300.0 * np.sin(2 * np.pi * t / 1.5) * rng.uniform(0.5, 1.0, n)
            np.savetxt(fh, np.column_stack([t, acc]), fmt=["%.6f", "%.6e"], delimiter=",")
    return rows


def write_at2(path: pathlib.Path, megabytes: float, dt: float = 0.005) -> int:
    """A PEER AT2 file (five numbers a line, in g) of about ``megabytes`` MB; returns NPTS."""
    npts = int(megabytes * 1e6 / 15) // 5 * 5
    rng = np.random.default_rng(1)
    with open(path, "w") as fh:
        fh.write("PEER NGA STRONG MOTION DATABASE RECORD\nBenchmark, 1/1/2000, Nowhere, 90\n"
                 f"ACCELERATION TIME SERIES IN UNITS OF G\nNPTS={npts:8d}, DT= {dt:.4f} SEC\n")
        for start in range(0, npts, _WRITE_ROWS):
            n = min(_WRITE_ROWS, npts - start)
            acc = 0.3 * np.sin(2 * np.pi * (start + np.arange(n)) * dt / 1.5) * rng.uniform(0.5, 1.0, n)
            np.savetxt(fh, acc.reshape(-1, 5), fmt="%15.7E", delimiter="")
    return npts


def run(megabytes: float = 200.0, fmt: str = "text") -> dict:
    """Write the record, read it in a subprocess; returns ``{name: value}``."""
    with tempfile.TemporaryDirectory() as folder:
        if fmt == "at2":
            path = pathlib.Path(folder) / "big.AT2"
            count = write_at2(path, megabytes)
            kwargs = {}
        else:
            path = pathlib.Path(folder) / "big.csv"
            count = write_text(path, megabytes)
            kwargs = {"units": "cm/s2"}
        pythonpath = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
        env = dict(os.environ, PYTHONPATH=pythonpath)
        done = subprocess.run([sys.executable, "-c", _CHILD, str(path), json.dumps(kwargs)],
                              capture_output=True, text=True, env=env, check=True)
        child = json.loads(done.stdout.strip().splitlines()[-1])
        size = path.stat().st_size
    return {"format": fmt, "file_MB": round(size / 1e6, 1), "samples_written": count,
            "samples_read": child["npts"], "read_s": round(child["seconds"], 2),
            "peak_rss_MB": round(child["rss_kb_after"] / 1024, 1),
            "rss_before_read_MB": round(child["rss_kb_before"] / 1024, 1),
            "read_cost_MB": round((child["rss_kb_after"] - child["rss_kb_before"]) / 1024, 1),
            "bytes_of_memory_per_byte_of_file": round(child["rss_kb_after"] * 1024 / size, 2)}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mb", type=float, default=200.0, help="size of the record file, MB")
    parser.add_argument("--format", choices=("text", "at2"), default="text")
    args = parser.parse_args(argv)
    print(run(args.mb, args.format))
    return 0


if __name__ == "__main__":
    sys.exit(main())
