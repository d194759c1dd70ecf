"""Section 6 of RESULTS.md: ``pipeline run`` throughput against ``--jobs`` and record length."""
from __future__ import annotations

import contextlib
import io
import pathlib

from benchmarks.common import log


def measure(quick):
    """`pipeline run` end to end, with the helpers of ``benchmarks/bench_pipeline.py``.

    The issue's case (40 records; ``quick``: 8): the synthetic SAC records of ``bench_pipeline``
    (a pulse of each shape plus broadband motion, 20-40 s at 100 Hz) and its two columns,
    ``--no-plots``; ``bench_pipeline.run()`` adds plots and the time per stage.  Returns plain
    data for :func:`benchmarks.results.pipeline_section`.
    """
    import tempfile

    from benchmarks import bench_pipeline as bp

    n = 8 if quick else 40
    res = {}
    log(f"pipeline: `pipeline run` on {n} records, --jobs 1 and 2")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = pathlib.Path(tmp)
        recs = bp.make_records(tmp / "recs", n, durations=[20.0, 25.0, 30.0, 35.0, 40.0])
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            bp._timed_main(["run", *recs[:2], *bp.COLUMNS, "--out", str(tmp / "warm"), "--no-plots", "-q"])
            for jobs in (1, 2):
                secs, code = bp._timed_main(["run", *recs, *bp.COLUMNS, "--out", str(tmp / f"o{jobs}"),
                                             "--no-plots", "-q", "--jobs", str(jobs)])
                res[f"warm_jobs{jobs}"] = n / secs
                res[f"code_jobs{jobs}"] = code
        log(f"  warm: {res['warm_jobs1']:.2f} records/s with --jobs 1, {res['warm_jobs2']:.2f} with --jobs 2")
        cold, code = bp._timed_cold(["run", *recs, *bp.COLUMNS, "--out", str(tmp / "c2"), "--no-plots",
                                     "-q", "--jobs", "2"])
        res["cold_jobs2"] = n / cold
        log(f"  cold (fresh process), --jobs 2: {res['cold_jobs2']:.2f} records/s")
        cold1, code = bp._timed_cold(["run", *recs, *bp.COLUMNS, "--out", str(tmp / "c1"), "--no-plots",
                                      "-q", "--jobs", "1"])
        res["cold_jobs1"] = n / cold1
        log(f"  cold (fresh process), --jobs 1: {res['cold_jobs1']:.2f} records/s")
        # compared between the two fresh processes (they load the same code; the in-process run
        # may hold modules loaded before another engineer's edit of the working tree)
        res["identical"] = all((tmp / "c1" / f).read_bytes() == (tmp / "c2" / f).read_bytes()
                               for f in ("summary.csv", "failures.csv") if (tmp / "c1" / f).exists())
        per_len = {}
        for duration in ((10.0, 40.0) if quick else (10.0, 20.0, 40.0, 80.0)):
            lrecs = bp.make_records(tmp / f"len{duration:g}", 2 if quick else 4, durations=[duration],
                                    seed=1)
            with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
                secs, _ = bp._timed_main(["run", *lrecs, *bp.COLUMNS, "--out", str(tmp / f"l{duration:g}"),
                                          "--no-plots", "-q"])
            per_len[duration] = secs / len(lrecs)
            log(f"  {duration:g} s records: {per_len[duration]:.2f} s per record (--jobs 1)")
    res["per_length"] = per_len
    res["n"] = n
    res["n_per_length"] = len(lrecs)
    return res
