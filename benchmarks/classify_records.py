"""Velocity-pulse classification of every record and pair in ``../shared/records/raw``, next to
Shahi & Baker's published values (docs/validation-classification.md).

Run: ``PYTHONPATH=. python benchmarks/classify_records.py [RAW_DIR]`` (default
``../shared/records/raw``).  Prints a Markdown table and a summary; the table of docs/validation-classification.md is this
output.  Record numbers come from ``../shared/records/MANIFEST.md``; published values from
``../shared/notes/sb14_nga_west2_pulses.csv``.  Azimuths are the readers' (AT2 headers), and
for the two-column text files the directions the manifest states.  The last columns compare the velocity pulse's Tp with the best fitted acceleration
pulse (:func:`pulses.fit_pulse`) of the component in the pulse's direction.
"""
from __future__ import annotations

import csv
import math
import pathlib
import sys

import numpy as np

import pulses
from pulses.pairs import component
from pulses.velocity import integral_energy

ROOT = pathlib.Path(__file__).resolve().parents[1]
RAW = ROOT.parent / "shared" / "records" / "raw"
PUBLISHED = ROOT.parent / "shared" / "notes" / "sb14_nga_west2_pulses.csv"

#: (label, first, second or None, record number in the published table or None, note)
AT2 = [
    ("Rinaldi (Northridge)", "Rinaldi228.AT2", "Rinaldi318.AT2", 1063, ""),
    ("Pacoima Dam (San Fernando)", "RSN77_SFERN_PUL164.AT2", "haselREC_NGA-West2-Reduced/RSN77_2.AT2", 77, ""),
    ("El Centro #6 (Imperial Valley)", "RSN181_IMPVALL.H_H-E06230.AT2", "RSN181_IMPVALL.H_H-E06140.AT2", 181, ""),
    ("Lucerne (Landers)", "RSN879_LANDERS_LCN260.AT2", "RSN879_LANDERS_LCN345.AT2", 879,
     "components 85 deg apart"),
    ("Sylmar Converter (Northridge)", "RSN1084_NORTHR_SCS052.AT2", "RSN1084_NORTHR_SCS142.AT2", 1084, ""),
    ("Gilroy #6 (Coyote Lake)", "haselREC_NGA-West2-Reduced/RSN150_1.AT2",
     "haselREC_NGA-West2-Reduced/RSN150_2.AT2", 150, ""),
    ("Long Valley Dam (Mammoth Lakes)", "haselREC_NGA-West2-Reduced/RSN250_1.AT2",
     "haselREC_NGA-West2-Reduced/RSN250_2.AT2", 250, ""),
    ("Agrarias (Imperial Valley)", "haselREC_NGA-West2-Reduced/RSN159_1.AT2",
     "haselREC_NGA-West2-Reduced/RSN159_2.AT2", 159, ""),
    ("El Centro #4 (reference example)", "shahi_baker_examples/example1.AT2",
     "shahi_baker_examples/example2.AT2", 179, ""),
    ("Rinaldi 228, older processing", "NGA_no_1063_RRS228.AT2", None, 1063, "one component"),
    ("El Centro #9 (Imperial Valley 1940) 180", "RSN6_IMPVALL.I_I-ELC180.AT2", None, None,
     "non-pulse control; pair refused (lengths 26 apart)"),
    ("El Centro #9 270", "haselREC_NGA-West2-Reduced/RSN6_2.AT2", None, None, "non-pulse control"),
    ("Taft (Kern County)", "RSN15_KERN_TAF021.AT2", None, None, "non-pulse control"),
    ("Hollywood Stor (San Fernando)", "RSN68_SFERN_PEL090.AT2", None, None, "non-pulse control"),
    ("Tolmezzo (Friuli)", "RSN125_FRIULI.A_A-TMZ000.AT2", None, None, "non-pulse control"),
    ("Cholame #5 (Parkfield 1966)", "RSN30_PARKF_C05085.AT2", None, None, "not in the table"),
    ("K-NET AKT013", "obspy_test_data/test.knet", None, None, "weak far-field"),
]
#: two-column text files (cm/s^2, dt 0.005 s): label, file, azimuths of the columns, record number, note
TEXT = [
    ("KJMA (Kobe)", "base_isolation_benchmark/kobe.txt", (0.0, 90.0), 1106, ""),
    ("TCU068 (Chi-Chi)", "base_isolation_benchmark/jiji.txt", (0.0, 90.0), 1505, "column labels doubtful"),
    ("Rinaldi, third copy", "base_isolation_benchmark/rinaldi.txt", (228.0, 318.0), 1063, ""),
    ("Sylmar (Olive View?)", "base_isolation_benchmark/sylmar.txt", (0.0, 90.0), 1086, "station not verified"),
    ("Newhall (Fire Sta?)", "base_isolation_benchmark/newhall.txt", (None, None), 1044,
     "station not verified; FN/FP, no azimuths"),
    ("Erzincan", "base_isolation_benchmark/erzikan.txt", (0.0, 90.0), None, "not in the table (FEMA pulse set)"),
]


def _published():
    with open(PUBLISHED, newline="") as fh:
        return {int(r["rsn"]): r for r in csv.DictReader(fh)}


def _at2(raw, name):
    return pulses.read_record(raw / name)


def _text(raw, name, column, azimuth):
    record = pulses.read_record(raw / name, format="text", units="cm/s2", dt=0.005, column=column)
    if azimuth is not None:
        record.metadata["azimuth"] = azimuth
    return record


def _axis_difference(a, b):
    d = (a - b) % 180.0
    return min(d, 180.0 - d)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    raw = pathlib.Path(argv[0]) if argv else RAW
    published = _published()
    cases = [(label, _at2(raw, a), _at2(raw, b) if b else None, rsn, note) for label, a, b, rsn, note in AT2]
    cases += [(label, _text(raw, f, 1, az[0]), _text(raw, f, 2, az[1]), rsn, note)
              for label, f, az, rsn, note in TEXT]
    print("| record | pulse-like | PI | Tp (s) | PGV (cm/s) | azimuth (deg) | published Tp / PGV / azimuth "
          "| velocity Tp / fitted acceleration-pulse Tp | note |")
    print("|---|---|---|---|---|---|---|---|---|")
    ratios, d_pi = [], []
    for label, first, second, rsn, note in cases:
        result = pulses.classify_pulse(first, second)
        other = pulses.classify_pulse(first, second, energy=integral_energy)
        d_pi.append(abs(other.indicator - result.indicator))
        assert other.is_pulse == result.is_pulse, label
        az = "-" if result.azimuth is None else f"{result.azimuth:.0f}"
        pub = published.get(rsn) if rsn else None
        if pub:
            p_az = float(pub["orientation_north_deg"])
            ptxt = f"{float(pub['tp_s']):.2f} / {float(pub['pgv_cm_s']):.1f} / {p_az:.0f}"
            if result.azimuth is not None and second is not None:
                ptxt += f" ({_axis_difference(result.azimuth, p_az):.1f} off)"
        else:
            ptxt = "not listed"
        direction = component(first, second, result.orientation) if second is not None else first
        fit = pulses.fit_pulse(direction).best
        ratio = result.tp / fit.tp
        if result.is_pulse:
            ratios.append(ratio)
        name = label + ("" if second is not None else " (one component)")
        verdict = "yes" if result.is_pulse else ("no (late)" if result.late and result.indicator > 0 else "no")
        print(f"| {name} | {verdict} | {result.indicator:+.1f} | {result.tp:.2f} | "
              f"{100 * result.pgv:.1f} | {az} | {ptxt} | {ratio:.2f} ({fit.shape}, {fit.tp:.2f} s) | {note} |")
    print()
    print(f"velocity Tp / acceleration-pulse Tp on the pulse-like rows: median {np.median(ratios):.2f}, "
          f"range {min(ratios):.2f}-{max(ratios):.2f} ({len(ratios)} rows)")
    print(f"energy ratio from sums of v^2 instead of the db4 approximation coefficients: PI changes by "
          f"at most {max(d_pi):.3f} (median {np.median(d_pi):.4f}); no verdict changes")
    return 0


if __name__ == "__main__":
    sys.exit(main())
