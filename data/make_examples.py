"""Build the bundled example records: near-fault-like accelerograms with known pulses.

Run from anywhere: ``python data/make_examples.py`` (or ``python -m pipeline.data.make_examples``).
It rewrites the ``*.sac`` files and ``examples.csv`` beside this script, deterministically (fixed
seeds), so the committed files can be checked by regenerating them.

Every record is a pulse of one of the paper's shapes (docs/theory.md section 3) added to band-limited
broadband motion (filtered Gaussian noise under a rise-plateau-decay envelope), plus one record
with broadband motion only (no pulse), as a control.  They are 25 s long at 100 Hz (2500 samples,
about 10 kB each), written as SAC with ``idep = iacc`` and the samples in nm/s^2, as the SAC
standard says (through :func:`pulses.write_sac`), so that ``pipeline run data/*.sac --block 7.5x1.8``
reads them with their units and no option.  The true pulse of each record is listed in
``examples.csv`` (shape, signed ap in g, Tp and t0 in s, Lp in m).
"""
from __future__ import annotations

import csv
import pathlib

import numpy as np
from scipy import signal

import pulses
from pulses import G, Record, make_pulse

HERE = pathlib.Path(__file__).resolve().parent

DT = 0.01  #: s, 100 Hz
DURATION = 25.0  #: s
#: band of the broadband motion, Hz
BAND = (0.4, 12.0)

#: (file stem, shape, ap in g, Tp in s, t0 in s, broadband RMS in g over its strong phase, seed)
EXAMPLES = [
    ("synth_sine_055g_0.9s", "sine", 0.55, 0.9, 7.0, 0.06, 11),
    ("synth_ricker_sym_045g_1.2s", "ricker-sym", 0.45, 1.2, 8.0, 0.05, 12),
    ("synth_ricker_anti_060g_1.5s", "ricker-anti", -0.60, 1.5, 9.0, 0.06, 13),
    ("synth_sine_085g_2.0s", "sine", -0.85, 2.0, 6.0, 0.07, 14),
    ("synth_broadband_only", None, 0.0, 0.0, 0.0, 0.08, 15),
]


def broadband(seed: int, rms_g: float, npts: int = int(round(DURATION / DT)) + 1) -> np.ndarray:
    """Band-limited noise (m/s^2) under a rise (2 s), plateau (to 10 s), decay envelope."""
    rng = np.random.default_rng(seed)
    white = rng.standard_normal(npts)
    sos = signal.butter(4, BAND, btype="bandpass", fs=1.0 / DT, output="sos")
    noise = signal.sosfiltfilt(sos, white)
    t = DT * np.arange(npts)
    env = np.where(t < 2.0, (t / 2.0) ** 2, np.where(t < 10.0, 1.0, np.exp(-(t - 10.0) / 4.0)))
    strong = (t >= 2.0) & (t < 10.0)
    noise *= env * (rms_g * G / np.sqrt(np.mean(noise[strong] ** 2)))
    # a short cosine taper at both ends so the record starts and ends at rest
    taper = signal.windows.tukey(npts, alpha=0.04)
    return noise * taper


def example(stem, shape, ap_g, tp, t0, rms_g, seed):
    """Samples (m/s^2) of one example record and its header fields."""
    acc = broadband(seed, rms_g)
    t = DT * np.arange(acc.size)
    if shape is not None:
        acc = acc + make_pulse(shape, ap_g * G, tp, t0)(t)
    return acc


def write_sac(path: pathlib.Path, acc: np.ndarray, stem: str, station: str) -> None:
    """Write ``acc`` (m/s^2) with :func:`pulses.write_sac`: idep = iacc, nm/s^2 (the SAC standard)."""
    record = Record(acc, DT, name=stem, metadata={"station": station, "component": "HNX",
                                                   "event": "synthetic"})
    tmp = path.with_name(path.name + ".tmp")
    pulses.write_sac(record, tmp)
    tmp.replace(path)


def main(out: pathlib.Path = HERE) -> list[pathlib.Path]:
    out = pathlib.Path(out)
    paths = []
    rows = []
    for i, (stem, shape, ap_g, tp, t0, rms_g, seed) in enumerate(EXAMPLES, start=1):
        acc = example(stem, shape, ap_g, tp, t0, rms_g, seed)
        path = out / f"{stem}.sac"
        write_sac(path, acc, stem, station=f"SYN{i}")
        paths.append(path)
        rows.append({
            "file": path.name, "shape": shape or "", "ap_g": f"{ap_g:g}" if shape else "",
            "tp_s": f"{tp:g}" if shape else "", "t0_s": f"{t0:g}" if shape else "",
            "lp_m": f"{abs(ap_g) * G * tp ** 2:.4g}" if shape else "",
            "broadband_rms_g": f"{rms_g:g}", "seed": seed,
            "pga_g": f"{np.max(np.abs(acc)) / G:.4f}", "dt_s": f"{DT:g}", "npts": acc.size,
        })
    with open(out / "examples.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]), lineterminator="\n")
        writer.writeheader()
        writer.writerows(rows)
    return paths


if __name__ == "__main__":
    for p in main():
        print(p)
