"""Speed of the velocity-pulse classification: a pair of 40 s records at 200 Hz.

Floor (issue 13): at most 50 ms per pair.  The records are synthetic and the same every run
(seeded noise with a velocity pulse), so the work is that of a real near-fault pair: 51 coarse
scales on two components, five candidates with refinement and ten wavelets each.

Run: ``PYTHONPATH=. python benchmarks/bench_classify.py [--repeat N] [--against FILE]``.  Prints
the first call (caches of the wavelet and of the filters' spectra are filled then) and the
median and best of the following calls, wall-clock and process CPU time (on a machine shared
with other work the CPU time is the fairer number).  ``--against`` times another version of
``pulses/velocity.py`` (e.g. ``git show main:pulses/velocity.py > /tmp/old_velocity.py``) in
turn with this one, call by call, so that both see the same load.
"""
from __future__ import annotations

import argparse
import importlib.util
import math
import os
import sys
import statistics
import time

import numpy as np

from pulses import Record, classify_pulse

DT, DURATION = 0.005, 40.0


def make_pair(seed: int = 2007) -> tuple[Record, Record]:
    """Two 40 s components at 200 Hz: band-limited noise plus a 3 s velocity pulse at 35 deg."""
    rng = np.random.default_rng(seed)
    n = int(round(DURATION / DT))
    t = DT * np.arange(n)
    envelope = np.exp(-((t - 12.0) / 6.0) ** 2)
    pulse_v = 0.6 * np.sin(2 * np.pi * (t - 8.0) / 3.0) * ((t > 8.0) & (t < 11.0))  # m/s
    comps = []
    for k, share in enumerate((np.cos(np.radians(35)), np.sin(np.radians(35)))):
        noise = np.convolve(rng.normal(size=n), np.ones(8) / 8, mode="same") * envelope * 2.0  # m/s^2
        acc = noise + share * np.gradient(pulse_v, DT)
        comps.append(Record(acc, DT, f"synthetic-{k + 1}"))
    return comps[0], comps[1]


def calibration() -> float:
    """The workload ``benchmarks/common.py`` calibrates with: a 20,000-step Python loop (s, best of 5)."""
    def loop():
        s = 0.0
        for i in range(20000):
            s += math.sin(i)
        return s

    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        loop()
        best = min(best, time.perf_counter() - t0)
    return best


def load_version(path: str):
    """Another version of ``pulses/velocity.py`` as a module of the package ``pulses`` (its
    relative imports resolve to this checkout's modules)."""
    spec = importlib.util.spec_from_file_location("pulses._velocity_against", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


def cpu_times(classify, pair, calls: int) -> list[float]:
    """Process CPU time (s) of ``calls`` classifications of ``pair``."""
    times = []
    for _ in range(calls):
        c0 = time.process_time()
        classify(*pair)
        times.append(time.process_time() - c0)
    return times


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=21, help="timed calls after the first (default 21)")
    parser.add_argument("--against", metavar="FILE", help="another pulses/velocity.py, timed in turn with this one")
    args = parser.parse_args(argv)
    first, second = make_pair()
    t0, c0 = time.perf_counter(), time.process_time()
    result = classify_pulse(first, second)
    cold_wall, cold_cpu = time.perf_counter() - t0, time.process_time() - c0
    walls, cpus = [], []
    for _ in range(args.repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        classify_pulse(first, second)
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    print(f"load average {' '.join(f'{x:.1f}' for x in os.getloadavg())}; calibration "
          f"(20,000-step Python loop, as benchmarks/common.py): {1e3 * calibration():.2f} ms")
    print(f"pair of {DURATION:g} s records at {1 / DT:g} Hz ({first.npts} samples each): "
          f"pulse-like {result.is_pulse}, Tp {result.tp:.2f} s, orientation {result.orientation:.1f} deg")
    print(f"first call: {1e3 * cold_wall:.1f} ms wall, {1e3 * cold_cpu:.1f} ms CPU")
    print(f"median of {args.repeat}: {1e3 * statistics.median(walls):.1f} ms wall "
          f"(best {1e3 * min(walls):.1f}), {1e3 * statistics.median(cpus):.1f} ms CPU "
          f"(best {1e3 * min(cpus):.1f}); floor 50 ms")
    if args.against:
        other = load_version(args.against)
        other_result = other.classify_pulse(first, second)  # its caches filled too
        mine, theirs = [], []
        for i in range(args.repeat):  # alternate which goes first
            order = [(mine, classify_pulse), (theirs, other.classify_pulse)]
            for times, classify in (order if i % 2 == 0 else order[::-1]):
                times += cpu_times(classify, (first, second), 1)
        print(f"in turn with {args.against} ({args.repeat} calls each): this version "
              f"{1e3 * statistics.median(mine):.1f} ms CPU (best {1e3 * min(mine):.1f}), the other "
              f"{1e3 * statistics.median(theirs):.1f} ms (best {1e3 * min(theirs):.1f}); same result: "
              f"Tp {other_result.tp:.2f} s, PI {other_result.indicator:+.6f} "
              f"(this: {result.indicator:+.6f})")


if __name__ == "__main__":
    main()
