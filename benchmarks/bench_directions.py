"""CPU per pair and direction of ``pipeline run --directions 36``, side by side with another version.

    PYTHONPATH=. python -m benchmarks.bench_directions --baseline ../wt-base [--pairs 4] [--jobs 1]

``--baseline`` is a checkout of the version to compare with (say ``git worktree add ../wt-base
6acf3f2``) with its own virtual environment in ``.venv`` (built as the README says); this checkout's
is the Python running the benchmark.  For each real pair of ``../shared/records/raw`` (Rinaldi,
RSN77, RSN181, RSN879, RSN1084, RSN159, RSN150, RSN250 are pulse-like, RSN6 and the El Centro #4
examples' RSN179 pair too by S&B14; the first ``--pairs`` of them), one after the other in this one
run, ``pipeline run --pair A B --directions 36 --block 7.5x1.8 --jobs J`` (38 directions) by:

- the baseline, default options and ``--thorough`` (where it has it: 0.4.0's default checked
  and drew every direction, as ``--thorough`` does now, and is compared with it);
- this version, default options (the check and the figures where they decide, pipeline/batch/passes.py);
- this version with ``--thorough`` (every direction checked and drawn).

Each run is a fresh process tree in a fresh ``--out``.  Its CPU: the main process's own
(``getrusage(RUSAGE_SELF)``, printed by a wrapper) and, for this version, every task's CPU as its
worker measured it (``cpu_seconds`` of ``--log``; a pool's forkserver workers are no children
``getrusage`` would count).  The side-by-side comparison runs with ``--jobs 1`` by default: every
task then runs in the main process and ``RUSAGE_SELF`` is the whole CPU of either version.  With
``--share-jobs J`` (default 2) this version's default run is repeated with ``--jobs J`` (and
with ``--dask local`` where ``--dask`` is given) to measure the main process's share of the CPU,
and at the end every pair is run in one batch with ``--jobs J`` by both versions: the main
process's CPU of each, and this version's share.

Reported per pair: CPU seconds per direction, by stage (the stages' times from ``--log``),
PNG bytes, and the answers compared:
the pair's design width (the widest design width or failing width the checks found, over its
directions) of the default against ``--thorough``'s, and whether every direction's design
width, verdicts and check columns equal the baseline's (``--thorough`` against its ``--thorough``,
the default against its default).
Then the projection for 10,000 pairs on 64 cores (at this machine's CPU per direction).  With
``--one-batch``, the pairs once more in one batch with ``--jobs 1`` by both versions: the CPU per
direction where a run's own costs (imports, the summary's figures, report.html) are shared by
its pairs, as when a database is screened.
"""
from __future__ import annotations

import argparse
import csv
import json
import pathlib
import subprocess
import sys
import tempfile

SHARED = pathlib.Path(__file__).resolve().parents[2] / "shared" / "records" / "raw"
_H = "haselREC_NGA-West2-Reduced/"
PAIRS = [("Rinaldi228.AT2", "Rinaldi318.AT2"), ("RSN77_SFERN_PUL164.AT2", _H + "RSN77_2.AT2"),
         ("RSN159", None), ("RSN181_IMPVALL.H_H-E06230.AT2", "RSN181_IMPVALL.H_H-E06140.AT2"),
         ("RSN1084_NORTHR_SCS052.AT2", "RSN1084_NORTHR_SCS142.AT2"), ("RSN6_IMPVALL.I_I-ELC180.AT2", _H + "RSN6_2.AT2"),
         ("RSN150", None), ("RSN250", None), ("RSN879_LANDERS_LCN260.AT2", "RSN879_LANDERS_LCN345.AT2"),
         ("shahi_baker_examples/example1.AT2", "shahi_baker_examples/example2.AT2")]
ARGS = ["--directions", "36", "--block", "7.5x1.8", "--quiet"]
#: runs ``pipeline`` in this process and prints the CPU of the main process and its pid
WRAPPER = ("import json, os, resource, sys\n"
           "from pipeline.cli import main\n"
           "code = main(sys.argv[1:])\n"
           "s = resource.getrusage(resource.RUSAGE_SELF)\n"
           "print(json.dumps({'code': code, 'self': s.ru_utime + s.ru_stime, 'pid': os.getpid()}))\n")
#: the check's columns and the verdicts compared row by row
COMPARED = ["design_width_m", "overturns", "eq31_width_m", "eq31_width_overturns", "failing_share",
            "widest_failing_width_m", "check_runs", "pulse_shape", "pulse_ap_g", "pulse_tp_s"]


def pair_paths(spec):
    a, b = spec
    if b is None:  # haselREC's RSN<n>_1 / _2
        a, b = f"{_H}{a}_1.AT2", f"{_H}{a}_2.AT2"
    return str(SHARED / a), str(SHARED / b)


def run_one(python, pair, out, jobs, extra=(), log=False) -> dict:
    """One ``pipeline run`` as a fresh process tree: its CPU (``main``: the main process's own,
    ``cpu``: the whole run's; with ``log``, ``stages``: seconds per stage summed over the tasks)."""
    pairs = [pair] if isinstance(pair[0], str) else pair   # one pair, or a batch of them
    argv = [python, "-c", WRAPPER, "run", *[a for p in pairs for a in ("--pair", *p)], *ARGS, "--out", str(out), *extra]
    argv += ["--jobs", str(jobs)] if jobs else []
    logfile = pathlib.Path(str(out) + ".jsonl")
    if log:
        argv += ["--log", str(logfile)]
    # run from the output's folder: from a checkout, ``-c`` would import that checkout's package
    res = subprocess.run(argv, capture_output=True, text=True, check=False, cwd=pathlib.Path(out).parent)
    line = [ln for ln in res.stdout.splitlines() if ln.startswith("{")]
    if not line:
        raise RuntimeError(f"{' '.join(argv)} failed: {res.stderr[-2000:]}")
    got = json.loads(line[-1])
    got["main"], got["cpu"], got["stages"] = got["self"], got["self"], {}
    if log:
        entries = [json.loads(ln) for ln in logfile.read_text(encoding="utf-8").splitlines()]
        here = [e for e in entries if str(e.get("worker") or "").endswith(f":{got['pid']}")]
        away = [e for e in entries if e not in here]
        got["main"] = got["self"] - sum(e["cpu_seconds"] for e in here)   # its own, without tasks
        got["cpu"] = got["self"] + sum(e["cpu_seconds"] for e in away)
        for e in entries:
            for k, v in e.get("stages", {}).items():
                got["stages"][k] = got["stages"].get(k, 0.0) + v
        got["tasks"] = len(entries)
    got["png_bytes"] = sum(p.stat().st_size for p in pathlib.Path(out).rglob("*.png"))
    got["rows"] = list(csv.DictReader(open(pathlib.Path(out) / "summary.csv", encoding="utf-8")))
    return got


#: a column's former names, in versions compared with (0.4.0 wrote ``verified_width_m``)
FORMER = {"design_width_m": "verified_width_m"}


def _col(row, name):
    return row[name] if name in row else row.get(FORMER.get(name, name), "")


def design_width(rows) -> float:
    """The pair's design width: the widest design or failing width over its directions (m); None
    where no direction has a row."""
    if not rows:
        return None
    return max(max(float(_col(r, "design_width_m")), float(_col(r, "widest_failing_width_m") or 0.0))
               for r in rows)


def same_rows(a, b) -> bool:
    """Every direction's :data:`COMPARED` columns equal (as written)."""
    key = lambda r: (r.get("pair"), r["direction_deg"], r["column"])
    ra, rb = {key(r): r for r in a}, {key(r): r for r in b}
    return ra.keys() == rb.keys() and all(_col(ra[k], c) == _col(rb[k], c) for k in ra for c in COMPARED)


def has_thorough(python) -> bool:
    """Whether that version's ``pipeline run`` has ``--thorough`` (0.4.0 had not: its default
    checked and drew every direction, which ``--thorough`` does now)."""
    res = subprocess.run([python, "-m", "pipeline", "run", "--help"], capture_output=True, text=True,
                         check=False, cwd=tempfile.gettempdir())
    return "--thorough" in res.stdout


def measure(baseline, n_pairs, jobs, share_jobs, dask, only=None) -> list[dict]:
    base_python = str(pathlib.Path(baseline) / ".venv" / "bin" / "python")
    base_thorough = has_thorough(base_python)
    runs_of = [("baseline", base_python, (), jobs, False), ("default", sys.executable, (), jobs, True),
               ("thorough", sys.executable, ("--thorough",), jobs, True)]
    if base_thorough:
        runs_of.append(("baseline-thorough", base_python, ("--thorough",), jobs, False))
    if share_jobs:
        runs_of.append((f"default-jobs{share_jobs}", sys.executable, (), share_jobs, True))
    if dask:
        runs_of.append(("default-dask", sys.executable, ("--dask", "local"), share_jobs or 2, True))
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        chosen = [p for p in PAIRS if only is None or any(o in p[0] for o in only)][:n_pairs]
        for k, spec in enumerate(chosen):
            pair = pair_paths(spec)
            runs = {name: run_one(py, pair, pathlib.Path(tmp) / f"{k}-{name}", j, extra, log)
                    for name, py, extra, j, log in runs_of}
            # a version that wrote no row (0.4.0 refuses some pairs) is counted per direction of this one
            n = max(len(r["rows"]) for r in runs.values())
            entry = {"pair": pathlib.Path(pair[0]).stem, "directions": n,
                     # 0.4.0 refuses pairs whose lengths differ by more than 20 samples
                     "baseline_refused": not runs["baseline"]["rows"]}
            for name, r in runs.items():
                # without --log (the baseline) the main process's own share is not known
                entry[name] = {"cpu_per_direction": r["cpu"] / n,
                               "main_share": None if r.get("tasks") is None else r["main"] / r["cpu"],
                               "png_mb": r["png_bytes"] / 1e6, "design_width": design_width(r["rows"]),
                               "exit": r["code"], "tasks": r.get("tasks"),
                               "stages_per_direction": {k: round(v / n, 4) for k, v in sorted(r["stages"].items())},
                               "checked": sum(row["check_runs"] not in ("", "0") for row in r["rows"])}
            entry["thorough_rows_equal_baseline"] = same_rows(
                runs["thorough"]["rows"], runs["baseline-thorough" if base_thorough else "baseline"]["rows"])
            entry["default_rows_equal_baseline"] = same_rows(runs["default"]["rows"], runs["baseline"]["rows"])
            entry["default_design_equals_thorough"] = (entry["default"]["design_width"]
                                                       == entry["thorough"]["design_width"])
            print(json.dumps(entry), flush=True)
            out.append(entry)
    return out


def summary(entries) -> dict:
    import numpy as np

    def mean(name, what):
        values = [e[name][what] for e in entries if e[name][what] is not None]
        return float(np.mean(values)) if values else None

    refused = [e["pair"] for e in entries if e["baseline_refused"]]
    entries = [e for e in entries if not e["baseline_refused"]]   # compared where both answer
    names = [k for k in entries[0] if isinstance(entries[0][k], dict)]
    res = {name: {"cpu_per_direction": mean(name, "cpu_per_direction"), "png_mb_per_pair": mean(name, "png_mb"),
                  "main_share": mean(name, "main_share"),
                  # 10,000 pairs of 38 directions on 64 cores, at this machine's speed per core
                  "hours_10000_pairs_64_cores": mean(name, "cpu_per_direction") * 38 * 10_000 / 64 / 3600}
           for name in names}
    stages = {}
    for e in entries:
        for k, v in e["default"]["stages_per_direction"].items():
            stages[k] = stages.get(k, 0.0) + v / len(entries)
    res["default"]["stages_per_direction"] = {k: round(v, 4) for k, v in sorted(stages.items(), key=lambda kv: -kv[1])}
    res["speed_up_default"] = res["baseline"]["cpu_per_direction"] / res["default"]["cpu_per_direction"]
    res["pairs_compared"], res["baseline_refused"] = len(entries), refused
    res["design_widths_equal"] = all(e["default_design_equals_thorough"] for e in entries)
    res["thorough_equal_baseline"] = all(e["thorough_rows_equal_baseline"] for e in entries)
    res["default_equal_baseline"] = all(e["default_rows_equal_baseline"] for e in entries)
    return res


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=True, help="checkout of the version compared with (its .venv)")
    ap.add_argument("--pairs", type=int, default=4, help=f"pairs measured (at most {len(PAIRS)}; default 4)")
    ap.add_argument("--jobs", type=int, default=1, help="--jobs of the compared runs (default 1: "
                    "every task in the main process, whose getrusage is then the whole CPU)")
    ap.add_argument("--share-jobs", type=int, default=2, help="--jobs of a further default run measuring "
                    "the main process's share (0: none; default 2)")
    ap.add_argument("--dask", action="store_true", help="also a default run with --dask local")
    ap.add_argument("--one-batch", action="store_true", help="also the pairs in one batch with --jobs 1 "
                    "by both versions (CPU per direction as a database is screened)")
    ap.add_argument("--only", help="comma-separated names: the pairs whose first file's name holds one "
                    "(e.g. RSN159,RSN1084), at most --pairs of them")
    args = ap.parse_args(argv)
    only = args.only.split(",") if args.only else None
    entries = measure(args.baseline, args.pairs, args.jobs, args.share_jobs, args.dask, only)
    res = summary(entries)
    if args.share_jobs:
        res["batch"] = batch(args.baseline, args.pairs, args.share_jobs)
    if args.one_batch:
        res["one_batch"] = one_batch(args.baseline, args.pairs)
    print(json.dumps(res, indent=1))


def batch(baseline, n_pairs, jobs) -> dict:
    """The main process's CPU on one batch of the ``n_pairs`` pairs with ``--jobs J``: this version's
    (and its share of the run's CPU, its workers' from ``--log``) and the baseline's (its own
    seconds only: a pool's workers are not its children to getrusage)."""
    pairs = [pair_paths(spec) for spec in PAIRS[:n_pairs]]
    with tempfile.TemporaryDirectory() as tmp:
        this = run_one(sys.executable, pairs, pathlib.Path(tmp) / "this", jobs, (), True)
        base = run_one(str(pathlib.Path(baseline) / ".venv" / "bin" / "python"), pairs,
                       pathlib.Path(tmp) / "base", jobs, (), False)
    return {"pairs": n_pairs, "jobs": jobs, "tasks": this["tasks"], "main_cpu_s": this["main"],
            "cpu_s": this["cpu"], "main_share": this["main"] / this["cpu"],
            "cpu_per_direction": this["cpu"] / len(this["rows"]), "baseline_main_cpu_s": base["main"],
            "rows_equal_baseline": same_rows(this["rows"], base["rows"])}


def one_batch(baseline, n_pairs) -> dict:
    """CPU per direction of the ``n_pairs`` pairs screened in one batch with ``--jobs 1`` by both
    versions (every task in the main process: ``getrusage`` is the whole CPU), as a database is
    screened: what a run pays once (imports, the summary's figures, report.html) is shared by its
    pairs instead of charged to each."""
    pairs = [pair_paths(spec) for spec in PAIRS[:n_pairs]]
    with tempfile.TemporaryDirectory() as tmp:
        this = run_one(sys.executable, pairs, pathlib.Path(tmp) / "this", 1, (), False)
        base = run_one(str(pathlib.Path(baseline) / ".venv" / "bin" / "python"), pairs,
                       pathlib.Path(tmp) / "base", 1, (), False)
    n = len(this["rows"])
    return {"pairs": n_pairs, "directions": n, "cpu_per_direction": this["cpu"] / n,
            "baseline_cpu_per_direction": base["cpu"] / len(base["rows"]),
            "speed_up": (base["cpu"] / len(base["rows"])) / (this["cpu"] / n),
            "png_mb_per_pair": this["png_bytes"] / 1e6 / n_pairs,
            "baseline_png_mb_per_pair": base["png_bytes"] / 1e6 / n_pairs}


if __name__ == "__main__":
    main()
