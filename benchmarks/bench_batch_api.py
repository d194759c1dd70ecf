"""The batch from Python against the command line: ``pipeline.design(records, jobs=2)`` and
``pipeline run --jobs 2`` on the same 10 records, side by side in one process, alternated.

``python benchmarks/bench_batch_api.py [repeats]`` prints a dict; :func:`run` returns it.

- 10 synthetic near-fault SAC records of 20-40 s at 100 Hz (``bench_pipeline.make_records``: a
  pulse of each shape plus broadband motion), the two columns of ``bench_pipeline``.
- Each repeat runs both, in alternating order (the machine's load drifts; alternating shares the
  drift), each into a fresh folder so that nothing is reused: ``pipeline run --no-plots --jobs 2
  --out DIR -q`` (in this process, as ``pipeline.cli.main``) and ``pipeline.design(..., jobs=2)``
  (``out=None``: no plots, a private temporary folder).
- Beside it, with ``--jobs 1`` (every record in this process), the CPU time of this process
  (``time.process_time``, all its threads): what each way costs whatever the machine's load,
  which on a shared machine moves the wall times by tens of percent from one run to the next.
- Reported: the wall times, each repeat's ratio ``design / pipeline run`` and their median (the
  floor: within 10 %), the ratio of the best times, and whether the design tables are the same
  cell for cell (``design.csv`` against the DataFrame).
"""
from __future__ import annotations

import contextlib
import csv
import io
import math
import pathlib
import statistics
import sys
import tempfile
import time

HERE = pathlib.Path(__file__).resolve().parent
if str(HERE.parent) not in sys.path:
    sys.path.insert(0, str(HERE.parent))

N_RECORDS = 10
JOBS = 2


def _cli(recs, out):
    from benchmarks.bench_pipeline import COLUMNS
    from pipeline.cli import main

    t0 = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = main(["run", *recs, *COLUMNS, "--out", str(out), "--no-plots", "-q", "--jobs", str(JOBS)])
    return time.perf_counter() - t0, code


def _api(recs, jobs=JOBS):
    import pipeline

    t0 = time.perf_counter()
    res = pipeline.design(recs, blocks=["7.5x1.8", "6x1.2"], jobs=jobs)
    return time.perf_counter() - t0, res


def cpu_jobs1(recs, tmp, repeats):
    """``(pipeline run CPU s, design CPU s)`` per repeat, ``--jobs 1``, alternated."""
    from benchmarks.bench_pipeline import COLUMNS
    from pipeline.cli import main

    out = []
    for k in range(repeats):
        t = time.process_time()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            main(["run", *recs, *COLUMNS, "--out", str(tmp / f"cpu{k}"), "--no-plots", "-q", "--jobs", "1"])
        c = time.process_time() - t
        t = time.process_time()
        _api(recs, jobs=1)
        out.append((c, time.process_time() - t))
    return out


def _same_table(path, frame) -> bool:
    from pipeline.reports.cells import fmt

    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.reader(fh))

    def cell(v):
        return "" if v is None or (isinstance(v, float) and math.isnan(v)) else fmt(v)

    return rows == [list(frame.columns)] + [[cell(v) for v in r] for r in frame.itertuples(index=False)]


def run(repeats: int = 3) -> dict:
    from benchmarks.bench_pipeline import make_records

    cli, api, same = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        recs = make_records(tmp / "recs", N_RECORDS, durations=[20.0, 25.0, 30.0, 35.0, 40.0])
        _cli(recs[:1], tmp / "warm")  # imports and first-call costs (pandas for the API), for both
        _api(recs[:1])
        for k in range(repeats):
            order = ("cli", "api") if k % 2 == 0 else ("api", "cli")
            for which in order:
                if which == "cli":
                    secs, code = _cli(recs, tmp / f"cli{k}")
                    cli.append(secs)
                else:
                    secs, res = _api(recs)
                    api.append(secs)
            same.append(_same_table(tmp / f"cli{k}" / "design.csv", res.design) and code == res.exit_code)
        cpu = cpu_jobs1(recs, tmp, repeats)
    # the machine's load drifts between repeats: each repeat's two runs are compared, and the
    # median of those ratios is the measure (the best times' ratio beside it)
    ratios = [x / y for x, y in zip(api, cli)]
    ratio = statistics.median(ratios)
    return {"records": N_RECORDS, "jobs": JOBS, "repeats": repeats, "pipeline_run_s": [round(x, 2) for x in cli],
            "design_s": [round(x, 2) for x in api], "ratios": [round(r, 3) for r in ratios],
            "median_ratio": round(ratio, 3), "best_ratio": round(min(api) / min(cli), 3),
            "within_10_percent": abs(ratio - 1.0) <= 0.10, "same_design_table": all(same),
            "cpu_jobs1_pipeline_run_s": [round(c, 2) for c, _ in cpu], "cpu_jobs1_design_s": [round(a, 2) for _, a in cpu],
            "cpu_jobs1_median_ratio": round(statistics.median(a / c for c, a in cpu), 3)}


if __name__ == "__main__":
    print(run(int(sys.argv[1]) if len(sys.argv) > 1 else 3))
