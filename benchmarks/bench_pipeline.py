"""Throughput of ``pipeline run`` end to end: records per second against --jobs and record length.

``python benchmarks/bench_pipeline.py`` prints a dict; :func:`run` returns it.

- 40 synthetic near-fault records of 20-40 s at 100 Hz (a pulse of each shape plus broadband
  motion, written as SAC), two columns each (``--block 7.5x1.8 --block 6x1.2``), ``--no-plots``,
  with ``--jobs 1`` and ``--jobs 2``: records/s, warm (in-process, compilation caches loaded) and
  cold (a fresh ``pipeline`` process, as a user runs it).
- The same with plots, ``--jobs 2``.
- Record length: 4 records each of 10, 20, 40, 80 s, ``--jobs 1``: seconds per record.
- Where the time goes: median seconds per record in each stage (fit, exact slenderness, design
  width, time histories, plot), 10 records, one process.

Every run is one repeat by default (``run(repeats=...)``): on this machine the whole takes minutes.
"""
from __future__ import annotations

import os
import pathlib
import platform
import subprocess
import sys
import tempfile
import time

import numpy as np

COLUMNS = ["--block", "7.5x1.8", "--block", "6x1.2"]
SHAPES = ["sine", "ricker-sym", "ricker-anti"]


def make_records(folder, n, durations, dt=0.01, seed=0):
    """``n`` SAC records with durations cycling through ``durations`` (s)."""
    import pulses
    from pulses import G

    from scipy import signal

    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    sos = signal.butter(4, (0.4, 12.0), btype="bandpass", fs=1.0 / dt, output="sos")
    paths = []
    for k in range(n):
        duration = durations[k % len(durations)]
        npts = int(round(duration / dt)) + 1
        t = dt * np.arange(npts)
        noise = signal.sosfiltfilt(sos, rng.standard_normal(npts))
        noise *= 0.06 * G / np.std(noise) * np.exp(-((t - 0.3 * duration) / (0.3 * duration)) ** 2)
        ap = rng.uniform(0.25, 0.8) * G * rng.choice([-1.0, 1.0])
        tp = rng.uniform(0.4, 2.5)
        t0 = rng.uniform(0.2, 0.5) * duration
        acc = noise + pulses.make_pulse(SHAPES[k % 3], ap, tp, t0)(t)
        path = folder / f"rec{k:03d}_{duration:g}s.sac"
        pulses.write_sac(pulses.Record(acc, dt, name=path.stem), path)
        paths.append(str(path))
    return paths


def stage_split(paths, plots=True) -> dict:
    """Median seconds per record spent in each stage (``process_record``'s ``seconds``), one process."""
    from pipeline.batch.record import process_record
    from pipeline.batch.tasks import Column, Options
    from pipeline.batch.runner import make_tasks

    tasks = make_tasks(paths, [Column(7.5, 1.8), Column(6.0, 1.2)], Options(plots=plots))
    process_record(tasks[0])  # warm-up
    per = [process_record(t)["seconds"] for t in tasks]
    keys = sorted({k for d in per for k in d})
    return {k: round(float(np.median([d.get(k, 0.0) for d in per])), 4) for k in keys}


def _timed_main(argv):
    from pipeline.cli import main

    t0 = time.perf_counter()
    code = main(argv)
    return time.perf_counter() - t0, code


def _timed_cold(argv):
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-m", "pipeline", *argv], capture_output=True, text=True)
    return time.perf_counter() - t0, proc.returncode


def run(n_records: int = 40, repeats: int = 1, cold: bool = True, plots: bool = True,
        lengths=(10.0, 20.0, 40.0, 80.0), per_length: int = 4) -> dict:
    """Measure; return (and print) a dict of records/s and seconds per record."""
    results = {"machine": f"{platform.machine()} {os.cpu_count()} CPUs, Python {platform.python_version()}",
               "load_average_at_start": round(os.getloadavg()[0], 2)}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        recs = make_records(tmp / "recs", n_records, durations=[20.0, 25.0, 30.0, 35.0, 40.0])
        results["records"] = f"{n_records} SAC records, 20-40 s at 100 Hz, two columns each"
        # warm-up: loads the compilation caches in this process
        _timed_main(["run", *recs[:2], *COLUMNS, "--out", str(tmp / "warm"), "--no-plots", "-q"])
        for jobs in (1, 2):
            best = min(_timed_main(["run", *recs, *COLUMNS, "--out", str(tmp / f"o{jobs}"), "--no-plots",
                                    "-q", "--jobs", str(jobs)])[0] for _ in range(repeats))
            results[f"warm_jobs{jobs}_records_per_s"] = round(len(recs) / best, 3)
        results["speedup_jobs2_over_jobs1_warm"] = round(
            results["warm_jobs2_records_per_s"] / results["warm_jobs1_records_per_s"], 2)
        if cold:
            secs, code = _timed_cold(["run", *recs, *COLUMNS, "--out", str(tmp / "c2"), "--no-plots",
                                      "-q", "--jobs", "2"])
            results["cold_jobs2_records_per_s"] = round(len(recs) / secs, 3)
        if plots:
            secs, _ = _timed_main(["run", *recs, *COLUMNS, "--out", str(tmp / "plots"), "-q", "--jobs", "2"])
            results["warm_jobs2_with_plots_records_per_s"] = round(len(recs) / secs, 3)
        results["jobs1_jobs2_identical"] = all(
            (tmp / "o1" / f).read_bytes() == (tmp / "o2" / f).read_bytes() for f in ("summary.csv", "failures.csv"))
        results["median_seconds_per_record_by_stage"] = stage_split(recs[:10])
        by_length = {}
        for duration in lengths:
            lrecs = make_records(tmp / f"len{duration:g}", per_length, durations=[duration], seed=1)
            secs = min(_timed_main(["run", *lrecs, *COLUMNS, "--out", str(tmp / f"l{duration:g}"),
                                    "--no-plots", "-q"])[0] for _ in range(repeats))
            by_length[f"{duration:g}s"] = round(secs / len(lrecs), 3)
        results["jobs1_seconds_per_record_by_length"] = by_length
    print(results)
    return results


if __name__ == "__main__":
    run()
