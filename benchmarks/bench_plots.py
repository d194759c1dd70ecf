"""Cost of the plots of ``pipeline run``: seconds per record figure and for the summary figure.

``python benchmarks/bench_plots.py [--repeat N]`` prints a dict; :func:`run` returns it.

The five bundled example records (``data/*.sac``), each with two columns (``--block 7.5x1.8
--block 6x1.2``: two rotation-history panels, up to four fitted pulses): each record is processed
once (fit, verification), then its figure drawn ``repeat`` times in this process: the median of
the records' medians, wall and CPU seconds, and the part spent building the figure (artists, no
pixels; the rest is ``savefig``: rendering and PNG compression).  A record figure is drawn by the
worker that processed the record, so ``--jobs N`` spreads this cost over N processes.
"""
from __future__ import annotations

import argparse
import os
import pathlib
import platform
import time

import numpy as np

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


def _median_seconds(fn, repeat):
    """Median (wall, CPU of this process) seconds of ``fn()``: on a loaded machine the CPU time
    is the figure's cost, the wall time also counts waiting for a core."""
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return float(np.median(wall)), float(np.median(cpu))


def run(repeat: int = 5) -> dict:
    """Measure; return (and print) a dict of seconds and PNG sizes."""
    import matplotlib

    from pipeline.reports.figures import record as plots
    from pipeline.batch.record import _process
from pipeline.batch.tasks import Column, Options
    from pipeline.batch.runner import make_tasks

    paths = sorted(str(p) for p in DATA.glob("*.sac"))
    tasks = make_tasks(paths, [Column(7.5, 1.8), Column(6.0, 1.2)], Options())
    parts = [(t.record_id, *_process(t)[1]) for t in tasks]
    plots.record_figure_png(*parts[0])  # warm-up: fonts found and loaded once per process
    build, total, sizes = [], [], []
    for p in parts:
        build.append(_median_seconds(lambda: plots.record_figure(*p), repeat))
        total.append(_median_seconds(lambda: plots.record_figure_png(*p), repeat))
        sizes.append(len(plots.record_figure_png(*p)))
    build, total = np.array(build), np.array(total)
    fig = plots.record_figure(*parts[0])
    width, height = (round(v) for v in fig.get_size_inches() * plots.DPI)
    rows = [{"column_kind": "block", "tan_alpha": 0.24, "governing_eq31_tan_alpha": 0.2 + 0.02 * k,
             "design_tan_alpha": 0.18 + 0.03 * k, "overturns": k % 2 == 0,
             "eq31_width_tan_alpha": 0.2 + 0.02 * k, "eq31_width_overturns": k % 3 == 0}
            for k in range(10)]
    summary = _median_seconds(lambda: plots.summary_figure_png(rows), repeat)
    results = {
        "machine": f"{platform.machine()} {os.cpu_count()} CPUs, Python {platform.python_version()}",
        "matplotlib": matplotlib.__version__,
        "load_average_at_start": round(os.getloadavg()[0], 2),
        "records": len(parts), "repeat": repeat,
        "record_figure_px": f"{width} x {height}",
        "record_figure_s": round(float(np.median(total[:, 0])), 4),
        "record_figure_cpu_s": round(float(np.median(total[:, 1])), 4),
        "record_figure_cpu_s_max": round(float(total[:, 1].max()), 4),
        "of_which_building_cpu_s": round(float(np.median(build[:, 1])), 4),
        "record_png_kB": round(float(np.median(sizes)) / 1000, 1),
        "summary_figure_s": round(summary[0], 4),
        "summary_figure_cpu_s": round(summary[1], 4),
    }
    print(results)
    return results


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="draws per record (median taken)")
    run(parser.parse_args().repeat)
