"""Speed of the pulse fitter: all four shapes on one record.

``python benchmarks/bench_fit.py`` prints a dict; :func:`run` returns it.

- The issue's case: a 20 s record at 200 Hz (4001 samples; a one-sine pulse plus band-limited
  background motion at 15 % of ap), all four shapes (``fit_pulse(record)``, the default weighted
  least squares): median and best of repeated fits, in ms (target: under 15 ms), then the same
  with ``weighting="plain"`` named and with ``weighting="background"`` (keys ``..._weighted_...``);
  also the process CPU time of the same fits, less disturbed than the wall time by other jobs
  on a busy machine, and the ratio of the weighted fit's CPU time to the plain one's.
- Per shape on the same record.
- Record length 10, 20, 40, 80, 160 s at 200 Hz: median ms per fit and ms per 1000 samples (the
  cost must grow no faster than the length).
- Reading: ``read_record`` of Rinaldi228.AT2 when ``../shared`` is present.
"""
from __future__ import annotations

import pathlib
import platform
import time

import numpy as np


def _time(fn, repeat, clock=time.perf_counter):
    fn()  # warm-up (imports, FFT plans)
    times = []
    for _ in range(repeat):
        t0 = clock()
        fn()
        times.append(clock() - t0)
    return float(np.median(times)) * 1e3, float(np.min(times)) * 1e3


def run(repeat: int = 30) -> dict:
    """Measure the fitter; returns ``{name: value}`` (times in ms)."""
    from pulses import fit_pulse, read_record
    from pulses.fit.synthetic import synthetic_record

    out = {"python": platform.python_version(), "machine": platform.machine()}
    rec = synthetic_record("sine", 5.0, 1.0, 7.3, 20.0, 0.005, noise=0.15, seed=1)
    med, best = _time(lambda: fit_pulse(rec), repeat)
    out["fit_all_shapes_20s_200Hz_ms_median"] = med
    out["fit_all_shapes_20s_200Hz_ms_min"] = best
    out["fit_target_ms"] = 15.0
    out["fit_all_shapes_20s_200Hz_cpu_ms_median"] = _time(lambda: fit_pulse(rec), repeat, time.process_time)[0]
    plain = _time(lambda: fit_pulse(rec, weighting="plain"), repeat)
    out["fit_all_shapes_20s_200Hz_plain_ms_median"], out["fit_all_shapes_20s_200Hz_plain_ms_min"] = plain
    out["fit_all_shapes_20s_200Hz_plain_cpu_ms_median"] = _time(lambda: fit_pulse(rec, weighting="plain"), repeat,
                                                              time.process_time)[0]
    weighted = _time(lambda: fit_pulse(rec, weighting="background"), repeat)
    out["fit_all_shapes_20s_200Hz_weighted_ms_median"], out["fit_all_shapes_20s_200Hz_weighted_ms_min"] = weighted
    out["fit_all_shapes_20s_200Hz_weighted_cpu_ms_median"] = _time(
        lambda: fit_pulse(rec, weighting="background"), repeat, time.process_time)[0]
    out["fit_weighted_over_plain_cpu"] = (out["fit_all_shapes_20s_200Hz_weighted_cpu_ms_median"] /
                                          out["fit_all_shapes_20s_200Hz_plain_cpu_ms_median"])
    for shape in ("sine", "ricker-sym", "ricker-anti", "rect"):
        out[f"fit_{shape}_20s_200Hz_ms_median"] = _time(lambda: fit_pulse(rec, shapes=[shape]), repeat)[0]
    for duration in (10, 20, 40, 80, 160):
        r = synthetic_record("ricker-sym", 5.0, 1.5, 0.4 * duration, float(duration), 0.005, noise=0.15, seed=2)
        med, _ = _time(lambda: fit_pulse(r), max(5, repeat // 3))
        out[f"fit_all_shapes_{duration}s_ms_median"] = med
        out[f"fit_all_shapes_{duration}s_ms_per_1000_samples"] = med / (r.npts / 1000.0)
    shared = pathlib.Path(__file__).resolve().parents[1].parent / "shared" / "records" / "raw" / "Rinaldi228.AT2"
    if shared.is_file():
        out["read_rinaldi228_at2_ms_median"] = _time(lambda: read_record(shared), repeat)[0]
    return out


if __name__ == "__main__":
    for key, value in run().items():
        print(f"{key}: {value:.3f}" if isinstance(value, float) else f"{key}: {value}")
