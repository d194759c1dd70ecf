"""Speed against error: regenerate ``benchmarks/RESULTS.md`` and its plots on this machine.

    python -m benchmarks            # the full report (under 10 minutes on the 2-core machine)
    python -m benchmarks --quick    # a smaller version of every section (about 2-3 minutes)
    python -m benchmarks --only solver,linear       # some sections only (the report says which)
    python -m benchmarks --quick --out /tmp/bench   # write the report somewhere else

Every figure is measured in the same run, side by side; times are medians of repeated runs (or a
single run for the slow models, said so where it applies).  The machine (CPU, cores, load, Python
and library versions) is written at the top of the report, and a calibration timing is taken at
the start and at the end, so that drift of the machine's speed during the run is visible; the
headline speed figures are ratios measured interleaved, which drift cancels.

Layout: one module per section (``sec_solver``, ``sec_linear``, ``sec_cost``, ``sec_fit``,
``sec_design``, ``sec_pipeline``), each with a ``measure(...)`` returning plain data;
``results.py`` writes RESULTS.md and the plots from that data; ``common.py`` holds the shared
helpers (records folder, real records, timing, calibration, machine description).

Sections:

``solver``      work-precision of every model and setting on (a) pulses, (b) real records,
                (c) near-overturning cases (wrong verdicts), the fast engine with each stepping
                method (``taylor``, the default; ``rk8``; ``rk4``); the log-log plot of time against
                error; the issue-2 ratio (fast, default method and rk8 side by side, against the
                usual approach on a 20 s, 200 Hz record).
``linear``      the linearised model's error against alpha, and where ``model="auto"`` switches.
``cost``        time against record length (10 s to 1 h) and against blocks in a batch;
                the 100 x 100 spectrum grid; ``pipeline simulate`` cold start.
``fit``         the pulse fitter: time against record length, error against noise and Tp.
``design``      issue 4's timings.
``pipeline``    ``pipeline run`` throughput against ``--jobs`` and record length.
"""
from __future__ import annotations

import argparse
import pathlib
import sys
import time

from benchmarks import common, results
from benchmarks.common import RECORD_FILES, calibration, fmt_t, load_records, loadavg, log, machine
from benchmarks.results import SECTIONS


def measure_all(todo, quick, records, notes, report):
    """Measure the sections ``todo`` in turn; ``report(measured)`` is called after each one.

    Returns {name: dict(data=..., error=None or "Type: message", seconds=s)}.
    """
    from benchmarks import sec_cost, sec_design, sec_fit, sec_linear, sec_pipeline, sec_solver

    funcs = {
        "solver": lambda: sec_solver.measure(quick, records, notes),
        "linear": lambda: sec_linear.measure(quick, records),
        "cost": lambda: sec_cost.measure(quick),
        "fit": lambda: sec_fit.measure(quick),
        "design": lambda: sec_design.measure(quick),
        "pipeline": lambda: sec_pipeline.measure(quick),
    }
    measured = {}
    for name in todo:
        t0 = time.perf_counter()
        data, error = None, None
        try:
            data = funcs[name]()
        except Exception as exc:  # noqa: BLE001 - one broken section must not lose the others
            import traceback

            traceback.print_exc()
            error = f"{type(exc).__name__}: {exc}"
        measured[name] = dict(data=data, error=error, seconds=time.perf_counter() - t0)
        report(measured)
        log(f"section {name} done; RESULTS.md written")
    return measured


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="smaller version of every section")
    ap.add_argument("--only", help="comma-separated sections: " + ",".join(SECTIONS))
    ap.add_argument("--out", help="folder for RESULTS.md and the plots (default: benchmarks/)")
    args = ap.parse_args(argv)
    out = common.HERE
    if args.out:
        out = pathlib.Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
    only = [s.strip() for s in args.only.split(",")] if args.only else None
    if only:
        bad = [s for s in only if s not in SECTIONS]
        if bad:
            ap.error(f"unknown section(s) {bad}; choose from {', '.join(SECTIONS)}")
    todo = only or list(SECTIONS)
    quick = args.quick

    import matplotlib

    matplotlib.use("Agg")
    log(f"benchmarks{' (quick)' if quick else ''}: sections {', '.join(todo)}; warming up the compiled code")
    import rocking  # noqa: F401  (import before timing)

    mach = machine()
    load0 = loadavg()
    cal0 = calibration()
    log(f"calibration: engine {fmt_t(cal0[0])}, python loop {fmt_t(cal0[1])}; load {load0}")
    records, notes = load_records(3 if quick else len(RECORD_FILES))
    log(f"{len(records)} real records loaded" + (f" ({'; '.join(notes)})" if notes else ""))
    measured = measure_all(todo, quick, records, notes,
                           lambda m: results.write_report(out, m, mach, load0, cal0, quick, only))
    cal1 = calibration()
    total = time.perf_counter() - common.T_START
    results.write_report(out, measured, mach, load0, cal0, quick, only, total=total, load1=loadavg(), cal1=cal1)
    log(f"done in {total:.0f} s: {out / 'RESULTS.md'}")
    return 0


if __name__ == "__main__":  # not in the worker processes of `pipeline run --jobs N` (forkserver)
    sys.exit(main())
