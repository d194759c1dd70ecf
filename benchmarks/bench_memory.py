"""Issue 16, bounded memory and dask scaling of ``pipeline run``.

``python benchmarks/bench_memory.py [memory|scaling] [N]`` prints a dict.

memory (default N = 2000)
    N short records (8 s at 50 Hz, :func:`bench_pipeline.make_records`) in one batch, one process
    (``--jobs 1``, one column, one shape, no plots), run as a user runs it (a fresh ``pipeline run``
    process).  Its resident memory (psutil) is sampled as ``--log`` grows: the value when the log
    first holds 100 lines and when it holds N; the floor is ``rss_last - rss_100 <= 50 MB``.
scaling (default N = 40)
    N records of 20 s at 100 Hz on a local dask cluster started here (its workers warmed by a
    first small run, so compilation caches are loaded), with 1 and then 2 workers; and with
    ``--jobs 2`` (process pool).  Prints seconds, the speed-up 1 -> 2 workers (floor 1.8x), and
    the per-record overhead of ``--dask`` over ``--jobs`` with 2 processes each:
    (t_dask2 - t_jobs2) / N.  On a machine with fewer free cores than workers the speed-up cannot
    reach 2: ``cpu_count`` and the load average are printed with it.
"""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
sys.path.insert(0, str(HERE))

from bench_pipeline import make_records  # noqa: E402

ARGS = ["--block", "7.5x1.8", "--shapes", "sine", "--no-plots"]


def memory(n: int = 2000) -> dict:
    import psutil

    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        paths = make_records(tmp / "in", n, [8.0], dt=0.02)
        log = tmp / "log.jsonl"
        env = dict(os.environ, PYTHONPATH=str(HERE.parent))
        t0 = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-m", "pipeline", "run", str(tmp / "in"), *ARGS, "--jobs", "1",
                                 "--quiet", "--log", str(log), "--out", str(tmp / "out")],
                                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        ps = psutil.Process(proc.pid)
        samples = {}
        lines = 0
        while proc.poll() is None:
            try:
                with open(log, "rb") as fh:
                    lines = fh.read().count(b"\n")
            except OSError:
                lines = 0
            for mark in (100, 500, 1000, n):
                if lines >= mark and mark not in samples:
                    try:
                        samples[mark] = ps.memory_info().rss / 2**20
                    except psutil.Error:
                        pass
            time.sleep(0.05)
        seconds = time.perf_counter() - t0
        rss = {k: round(v, 1) for k, v in sorted(samples.items())}
        first, last = rss.get(100), rss.get(n)
        return {"records": n, "seconds": round(seconds, 1), "exit_status": proc.returncode,
                "rss_mb_after_record": rss,
                "growth_mb_100_to_last": None if first is None or last is None else round(last - first, 1)}


def _timed(paths, out, **kw):
    from pipeline.batch.tasks import Column, Options
    from pipeline.batch.runner import run

    t0 = time.perf_counter()
    run(paths, [Column(7.5, 1.8)], out, options=Options(shapes=("sine",), plots=False), quiet=True, **kw)
    return time.perf_counter() - t0


def scaling(n: int = 40) -> dict:
    import logging

    from dask.distributed import LocalCluster

    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        paths = make_records(tmp / "in", n, [20.0], dt=0.01)
        seconds = {}
        for workers in (1, 2):
            with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                              silence_logs=logging.ERROR) as cluster:
                address = cluster.scheduler_address
                _timed(paths[:2 * workers], tmp / f"warm{workers}", dask=address)  # caches loaded
                seconds[f"dask{workers}"] = _timed(paths, tmp / f"dask{workers}", dask=address)
        _timed(paths[:2], tmp / "warm-jobs", jobs=2)
        seconds["jobs2"] = _timed(paths, tmp / "jobs2", jobs=2)
        return {"records": n, "seconds": {k: round(v, 2) for k, v in seconds.items()},
                "speedup_dask_1_to_2": round(seconds["dask1"] / seconds["dask2"], 2),
                "dask_overhead_s_per_record": round((seconds["dask2"] - seconds["jobs2"]) / n, 4),
                "cpu_count": os.cpu_count(), "load_average": os.getloadavg()}


if __name__ == "__main__":
    what = sys.argv[1] if len(sys.argv) > 1 else "memory"
    count = int(sys.argv[2]) if len(sys.argv) > 2 else None
    fn = {"memory": memory, "scaling": scaling}[what]
    print(fn(count) if count else fn())
