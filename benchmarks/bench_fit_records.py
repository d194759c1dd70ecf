"""CPU per call of ``pulses.fit_pulse`` on real records and directions of real pairs, this version
side by side with another one in the same process.

    PYTHONPATH=. python -m benchmarks.bench_fit_records [--baseline REV] [--rounds 3]

``REV`` is a git revision of this repository (default :data:`BASELINE`, the fit before issue 34's
work on it): its ``pulses/`` is extracted with ``git archive`` into a temporary folder and imported
as a second package, ``pulses_baseline`` (the package imports only itself, relatively).

Cases: every AT2 record of ``../shared/records/raw`` (one direction each) and :data:`ANGLES` (12
directions) of each pair of :data:`PAIRS`: ``pipeline run --directions`` fits a pair's directions
one after the other, as here.  Each round fits every case with both versions, back to back (which
goes first alternates), and takes each call's CPU time (``time.process_time``); the medians are
over cases and rounds.  The answers are compared call by call: the ranking of the shapes, the
weighting, and the largest relative difference of ``ap``, ``Tp``, ``t0`` and ``score`` of any
candidate.
"""
from __future__ import annotations

import argparse
import importlib
import io
import math
import pathlib
import subprocess
import sys
import tarfile
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from benchmarks.common import RECORDS_DIR  # noqa: E402

#: the fit before issue 34's work on it (the branch point of that work)
BASELINE = "f11ec62"
#: pairs whose directions are fitted (both files in RECORDS_DIR)
PAIRS = (("RSN1084_NORTHR_SCS052.AT2", "RSN1084_NORTHR_SCS142.AT2"),
         ("RSN181_IMPVALL.H_H-E06140.AT2", "RSN181_IMPVALL.H_H-E06230.AT2"),
         ("RSN879_LANDERS_LCN260.AT2", "RSN879_LANDERS_LCN345.AT2"))
#: directions of each pair, degrees from its first component towards its second
ANGLES = tuple(range(0, 180, 15))


def baseline_package(rev: str, folder: pathlib.Path):
    """``pulses/`` of git revision ``rev``, imported as the package ``pulses_baseline``."""
    tar = subprocess.run(["git", "archive", rev, "pulses"], cwd=ROOT, capture_output=True, check=True).stdout
    with tarfile.open(fileobj=io.BytesIO(tar)) as archive:
        archive.extractall(folder, filter="data")
    (folder / "pulses").rename(folder / "pulses_baseline")
    sys.path.insert(0, str(folder))
    return importlib.import_module("pulses_baseline")


def cases():
    """``(kind, record)``: every AT2 record of RECORDS_DIR (``"record"``), then the directions
    of each pair (``"direction"``)."""
    import pulses

    out = [("record", pulses.read_record(p)) for p in sorted(RECORDS_DIR.glob("*.AT2"))]
    for a, b in PAIRS:
        if (RECORDS_DIR / a).is_file() and (RECORDS_DIR / b).is_file():
            first, second = pulses.read_pair(RECORDS_DIR / a, RECORDS_DIR / b)
            out += [("direction", pulses.component(first, second, float(theta))) for theta in ANGLES]
    return out


def difference(old, new) -> dict:
    """Largest relative differences of the candidates' ``ap``, ``tp``, ``t0``, ``score``, and
    whether the ranking and the weighting are the same."""
    out = {"same_ranking": [c.shape for c in old.candidates] == [c.shape for c in new.candidates],
           "same_weighting": old.weighting == new.weighting}
    for key in ("ap", "tp", "t0", "score"):
        out[key] = max(abs(getattr(c, key) - getattr(new[c.shape], key)) / max(abs(getattr(c, key)), 1e-300)
                       for c in old.candidates)
    return out


def run(rev: str = BASELINE, rounds: int = 3) -> dict:
    """Both versions on every case, ``rounds`` times; returns medians (s per call) and the answers'
    differences."""
    import pulses

    with tempfile.TemporaryDirectory() as tmp:
        base = baseline_package(rev, pathlib.Path(tmp))
        todo = cases()
        times = {"baseline": {"record": [], "direction": []}, "this": {"record": [], "direction": []}}
        worst = {"ap": 0.0, "tp": 0.0, "t0": 0.0, "score": 0.0}
        same = True
        for k in range(rounds):
            for j, (kind, record) in enumerate(todo):
                order = [("baseline", base), ("this", pulses)][::1 if (j + k) % 2 else -1]
                fits = {}
                for name, package in order:
                    t0 = time.process_time()
                    fits[name] = package.fit_pulse(record)
                    times[name][kind].append(time.process_time() - t0)
                d = difference(fits["baseline"], fits["this"])
                same = same and d["same_ranking"] and d["same_weighting"]
                worst = {key: max(worst[key], d[key]) for key in worst}
        sys.path.remove(tmp)
    out = {"baseline": rev, "rounds": rounds, "records": sum(kind == "record" for kind, _ in todo),
           "directions": sum(kind == "direction" for kind, _ in todo),
           "same_ranking_and_weighting": same, "max_rel_difference": worst}
    for name in ("baseline", "this"):
        for kind in ("record", "direction"):
            out[f"{name}_{kind}_s"] = float(np.median(times[name][kind])) if times[name][kind] else math.nan
        out[f"{name}_all_s"] = float(np.median(times[name]["record"] + times[name]["direction"]))
    out["ratio_all"] = out["baseline_all_s"] / out["this_all_s"]
    return out


def lines(r: dict) -> list[str]:
    """RESULTS.md's lines for :func:`run`'s result."""
    w = r["max_rel_difference"]
    rows = [(f"{r['records']} AT2 records", "record"),
            (f"{r['directions']} directions of {r['directions'] // len(ANGLES)} pairs", "direction")]
    md = [f"CPU per `fit_pulse` call on real records (`benchmarks/bench_fit_records.py`: this version and "
          f"commit {r['baseline']}, the fit before issue 34, in one process, back to back; medians over "
          f"{r['rounds']} rounds):\n",
          "| cases | before | now | ratio |",
          "|---|---|---|---|"]
    for label, kind in rows:
        before, now = r[f"baseline_{kind}_s"], r[f"this_{kind}_s"]
        md.append(f"| {label} | {before * 1e3:.1f} ms | {now * 1e3:.1f} ms | {before / now:.2f}x |")
    md.append(f"| all | {r['baseline_all_s'] * 1e3:.1f} ms | {r['this_all_s'] * 1e3:.1f} ms | "
              f"**{r['ratio_all']:.2f}x** |")
    same = "the same in every call" if r["same_ranking_and_weighting"] else "DIFFERENT"
    md.append(f"\nAnswers: ranking and weighting {same}; largest relative difference of any candidate's "
              f"ap {w['ap']:.1e}, Tp {w['tp']:.1e}, t0 {w['t0']:.1e}, score {w['score']:.1e}.\n")
    return md


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--baseline", default=BASELINE, help=f"git revision to compare with (default {BASELINE})")
    parser.add_argument("--rounds", type=int, default=3, help="times every case is fitted by each version (default 3)")
    args = parser.parse_args(argv)
    print("\n".join(lines(run(args.baseline, args.rounds))))


if __name__ == "__main__":
    main()
