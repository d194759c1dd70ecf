"""The design width against an independent dense grid, performance levels, and its sensitivity.

    python benchmarks/bench_design_width.py                 # 1-4 min a seed on 2 cores; needs ../shared
    python benchmarks/bench_design_width.py --heights 7.5   # one column height
    python benchmarks/bench_design_width.py --sensitivity   # item 5: the check's seed, restitution
    python benchmarks/bench_design_width.py --identical     # a level reusing the overturning runs
        # against the same computed without them: the same answers?
    python benchmarks/bench_design_width.py --level 0.2 --runs-only   # another level R; only the
        # designs and their runs (no dense grid, no 0.5.0 search): the cost floors, ~2 min
    python benchmarks/bench_design_width.py --seeds record,1,2 --no-level --cache /tmp/dense --misses
        # the check's seed set to each ("record": the package's own); overturning only (~40 s a
        # seed once the dense grids are kept); where the misses lie

For every real record of ../shared/records (``raw/`` and its sub-folders, and the horizontal
components of ``peer_download/`` that are not in ``raw/``: the check was sized on ``raw/`` at
7.5 m, so those and the other heights are records and columns it was not tuned on), and each
column height, ``rocking.required_width(H, record, rule="exact")`` gives the search's first
transition ``w`` (``search_width``, called the verified width before 0.5) and the design width ``W``
(``width``).  An independent dense grid of ``DENSE`` linear widths in ``(w, min(SPAN w, top)]``
(``top``: the no-uplift width) counts the records with a failing width more than 1 % above ``w``
(today's answer) and more than 1 % above ``W``.  With ``limit=0.5``: the design width ``W_R`` is
run again (``rocking.simulate``): max|theta|/alpha <= 0.5, and ``W_R >= W``, ``W_R`` as
``pipeline run --limit`` computes it (``pipeline.batch.record.design_width``: the level, then its
overturning design where it can change it: the search, the check above the level's width).  Runs
per design width (search + check + refinement) are printed for both, and the solver runs of the
level with its overturning design (:func:`route_runs`).  ``--level R``: another level than 0.5.

``--sensitivity``: the design width with the check's seed changed (``SearchSettings.check_seed``,
``SEEDS``) and with the restitution ``ETA_FACTORS`` times Eq. 5 at each width (capped at 1), for
overturning and ``limit=0.5``: the spread of ``W`` relative to the package's own answer.
"""
from __future__ import annotations

import os
import pathlib
import sys
import time

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

SHARED = pathlib.Path(os.environ.get("ROCKING_RECORDS", ROOT.parent / "shared" / "records" / "raw"))
HEIGHTS = (7.5, 6.0)
DENSE = 6000
#: the dense grid spans (w, min(SPAN w, top)], the same whatever the design width
SPAN = 3.0
LEVEL = 0.5
SEEDS = (1, 2, 3, 4)


def _baseline():
    from rocking.search import SearchSettings

    # 0.5.0's search (fine zone 0.05 % apart up to 20 % above), no check: its answer is the width
    # the floors are measured against, and anchors the dense grid
    return SearchSettings(record_fine=5e-4, record_fine_span=0.2, check_runs=0)
ETA_FACTORS = (0.95, 0.975, 1.025, 1.05)


def record_paths():
    """The records: raw/*.AT2, raw/*/*.AT2 and the horizontal peer_download components not in raw."""
    paths = sorted(SHARED.glob("*.AT2")) + sorted(SHARED.glob("*/*.AT2"))
    have = {p.name for p in paths}
    peer = SHARED.parent / "peer_download"
    extra = [p for p in sorted(peer.glob("*.AT2"))
             if p.name not in have and not any(k in p.stem for k in ("UP", "DWN"))]
    return paths + extra


def _verdicts(height, record, widths):
    import rocking

    res = rocking.simulate_many([rocking.Block.from_dimensions(height, float(b)) for b in widths], record)
    return np.asarray(res.overturned, dtype=bool)


def samples_key(record) -> str:
    """The record's samples and time step, hashed: two files of the same component (RSN77_2 and
    the PEER download's RSN77_SFERN_PUL254) count once."""
    import hashlib

    h = hashlib.sha256(np.ascontiguousarray(record.acc, dtype="<f8").tobytes())
    h.update(repr(float(record.dt)).encode())
    return h.hexdigest()[:16]


def dense_failures(height, record, w, top, cache=None):
    """The failing widths (m) of the dense grid of ``DENSE`` linear widths in ``(w, min(SPAN w,
    top)]``; ``cache``: a folder where they are kept by record, height and ``w`` (the grid depends
    on nothing else), so that runs with other check settings or seeds reuse it."""
    x = np.linspace(w, min(SPAN * w, top), DENSE + 1)[1:]
    path = None
    if cache is not None:
        path = pathlib.Path(cache) / f"{samples_key(record)}_{height:g}_{w:.17g}_{DENSE}_{SPAN:g}.npy"
        if path.is_file():
            return np.load(path)
    fx = x[_verdicts(height, record, x)]
    if path is not None:
        path.parent.mkdir(parents=True, exist_ok=True)
        np.save(path, fx)
    return fx


def sliver_width(height, record, b, step):
    """How thin the failing sliver at ``b`` is: the failing stretch around ``b``, found by
    widening steps of ``step`` m (relative width of the failing run of a 21-point grid)."""
    x = b + step * np.arange(-10, 11) / 10.0
    f = _verdicts(height, record, x)
    run = np.nonzero(f)[0]
    return (x[run].max() - x[run].min() + step / 10.0) / b if run.size else 0.0


def route_runs(level, over):
    """Solver runs of a level's design width as ``pipeline run --limit`` computes it
    (:func:`pipeline.batch.record.design_width`): the level's own and those of the overturning
    design it computed (the part it computed: its search and its check above the level's width);
    before 0.7.1 (no ``overturning_design``), the whole overturning design ``over`` first."""
    inner = getattr(level, "overturning_design", None)
    if inner is None:
        return over.total_runs + level.solver_runs
    return level.solver_runs + inner.solver_runs


def measure(paths, heights, settings=None, cache=None, level=True, misses=False, dense=True):
    import dataclasses

    import pulses
    import rocking
    from pipeline.batch.widths import design_width
    from pulses import G
    from rocking.search import DEFAULT_SETTINGS

    settings = settings or DEFAULT_SETTINGS
    global BASELINE
    BASELINE = _baseline()      # a global: measure() is the only user

    rows = []
    for path in paths:
        record = pulses.read_record(str(path))
        for H in heights:
            t = time.perf_counter()
            over = rocking.required_width(H, record, rule="exact", settings=settings)
            t_over = time.perf_counter() - t
            t = time.perf_counter()
            # the level alone (0.6.0's pipeline run --limit), and pipeline run --limit's path: the
            # overturning design, then the level given it (its runs reused)
            alone = (rocking.required_width(H, record, rule="exact", limit=LEVEL, settings=settings)
                     if level else over)
            t = time.perf_counter()
            half = design_width(record, None, H, 0.0, LEVEL, settings) if level else over
            t_half = time.perf_counter() - t
            # the reference: the search of 0.5.0 alone (its first transition, today's search
            # width), whatever the settings measured
            base = (rocking.required_width(H, record, rule="exact", settings=BASELINE) if dense
                    else dataclasses.replace(over, runs=over.runs))
            w = base.search_width
            W = over.width
            top = H * record.pga / G
            fx = dense_failures(H, record, w, top, cache) if dense else np.zeros(0)
            widest = float(fx.max()) if fx.size else None
            ratio = max((rocking.simulate(rocking.Block.from_dimensions(H, h.width), record,
                                          history=False).max_rotation_ratio if level else 0.0)
                        for h in (alone, half))
            if misses and widest and widest > 1.01 * W:
                far = fx[fx > 1.01 * W]
                step = (min(SPAN * w, top) - w) / DENSE
                thin = [sliver_width(H, record, b, step) for b in far[:5]]
                print(f"  MISS {path.stem} H {H:g}: W {W:.5f}; {far.size} dense failures above "
                      f"1.01 W at W x " + " ".join(f"{b / W:.4f}" for b in far[:12])
                      + "; sliver widths (rel.) " + " ".join(f"{t:.1e}" for t in thin), flush=True)
            row = dict(record=path.stem, key=samples_key(record), height=H, w=w, W=W, widest_dense=widest,
                       far_old=bool(widest and widest > 1.01 * w),
                       far_new=bool(widest and widest > 1.01 * W),
                       # within the span the check covers: (w, 2 w] today, (W, 2 W] now
                       far_old_2=bool(np.any((fx > 1.01 * w) & (fx <= 2.0 * w))),
                       far_new_2=bool(np.any((fx > 1.01 * W) & (fx <= 2.0 * W))),
                       runs=over.total_runs, runs_today=base.runs + 1500,
                       w_search=over.search_width,
                       W_half=half.width, ratio_half=float(ratio), runs_half=half.total_runs,
                       W_over_half=half.overturning_width if level else W,
                       solver_half=half.solver_runs,
                       # widths answered from the other design's batches (either way round)
                       shared_half=half.shared_runs + getattr(getattr(half, "overturning_design", None),
                                                              "shared_runs", 0),
                       route=route_runs(half, over) if level else over.total_runs,
                       W_alone=alone.width, runs_alone=alone.total_runs,
                       t_over=t_over, t_half=t_half)
            rows.append(row)
            print(f"{path.stem:28s} H {H:4.1f}: w {w:.4f} W {W:.4f} (+{(W / w - 1) * 100:5.2f} %) "
                  f"dense widest {'-' if widest is None else f'{widest:.4f}'} | R={LEVEL:g} {half.width:.4f} "
                  f"ratio {ratio:.3f} | runs {over.total_runs}/{half.total_runs}/{row['route']} "
                  f"{t_over:.1f}/{t_half:.1f} s", flush=True)
    return rows


def _unique(rows, name):
    """Cases counted once per record's samples and height (``name`` true on any copy)."""
    seen = {}
    for r in rows:
        seen[(r["key"], r["height"])] = seen.get((r["key"], r["height"]), False) or bool(r[name])
    return sum(seen.values()), len(seen)


def table(rows, dense=True):
    n = len(rows)
    old = sum(r["far_old"] for r in rows)
    new = sum(r["far_new"] for r in rows)
    (old_u, n_u), (new_u, _) = _unique(rows, "far_old"), _unique(rows, "far_new")
    raised = sum(r["W"] > r["w"] for r in rows)
    bad_half = [r for r in rows if r["ratio_half"] > LEVEL]
    below = [r for r in rows if r["W_half"] < r["W"] or r["W_half"] < r["W_over_half"]]
    below_alone = [r for r in rows if r["W_alone"] < r["W"]]
    runs_a = np.array([r["runs_alone"] for r in rows])
    runs = np.array([r["runs"] for r in rows])
    today = np.array([r["runs_today"] for r in rows])
    runs_h = np.array([r["runs_half"] for r in rows])
    solver_h = np.array([r["solver_half"] for r in rows])
    route = np.array([r["route"] for r in rows])
    shared_h = np.array([r["shared_half"] for r in rows])
    up = np.array([r["W"] / r["w"] - 1 for r in rows]) * 100
    lines = [
        f"{n} cases (records x heights); dense grid {DENSE} linear widths in (w, min({SPAN:g} w, top)].",
        f"- failing widths more than 1 % above the search's answer w (today's width): {old} cases; "
        f"more than 1 % above the design width W: {new} cases",
        f"- counted once per record's samples ({n_u} cases): above 1.01 w {old_u}; above 1.01 W "
        f"{new_u} (" + ", ".join(f"{r['record']} {r['height']:g} m" for r in rows if r["far_new"]) + ")",
        f"- within the check's span: failing widths in (1.01 w, 2 w]: "
        f"{sum(r['far_old_2'] for r in rows)} cases; in (1.01 W, 2 W]: "
        f"{sum(r['far_new_2'] for r in rows)} cases ("
        + ", ".join(f"{r['record']} {r['height']:g} m" for r in rows if r["far_new_2"]) + ")",
        f"- W above w on {raised} cases (median +{np.median(up[up > 0]) if raised else 0:.2f} %, "
        f"max +{up.max():.2f} %)",
        f"- limit {LEVEL}: max|theta|/alpha above {LEVEL} at W_R (alone or given W) on "
        f"{len(bad_half)} cases ({', '.join(r['record'] for r in bad_half) or 'none'}); W_R below W: "
        f"alone on {len(below_alone)}"
        + "".join(f" ({r['record']} {r['height']:g} m: {r['W_alone']:.5f} < {r['W']:.5f})" for r in below_alone)
        + f", through pipeline run --limit's path (the level, then its overturning design where it can "
        f"change it) on {len(below)}",
        f"- runs per level width alone: median {np.median(runs_a):.0f} (max {runs_a.max()})",
        f"- runs per design width: overturning median {np.median(runs):.0f} (max {runs.max()}), "
        f"today's search + check median {np.median(today):.0f} (max {today.max()}); "
        f"limit {LEVEL} given W median {np.median(runs_h):.0f} (max {runs_h.max()}) widths, of which "
        f"run: median {np.median(solver_h):.0f} (shared between the level and its overturning design: median "
        f"{np.median(shared_h):.0f}); the level with its overturning design (pipeline run --limit, "
        f"route_runs): "
        f"median {np.median(route):.0f} solver runs (max {route.max()}; at most the overturning "
        f"design's on {int(np.sum(route <= runs))} of {n})",
    ]
    return lines if dense else [f"{n} cases (records x heights), no dense grid (--runs-only)."] + lines[-3:]


class _ScaledEta:
    """A stand-in for ``rocking.Block`` whose ``from_dimensions`` gives ``factor`` times Eq. 5's
    restitution (capped at 1): the sensitivity to the restitution, measured without a new API."""

    def __init__(self, block_cls, factor):
        self.cls, self.factor = block_cls, factor

    def from_dimensions(self, height, width, eta=None, **kw):
        from rocking.block import eta_housner
        import math

        eta = min(1.0, self.factor * eta_housner(math.atan2(width, height))) if eta is None else eta
        return self.cls.from_dimensions(height, width, eta, **kw)


def sensitivity(paths, heights):
    import pulses
    import rocking
    from rocking import widths as rw
    from rocking.search import DEFAULT_SETTINGS

    lines = ["| record | H (m) | level | W (m) | seeds: W / W0 - 1 (%) | restitution x "
             + ", ".join(f"{f:g}" for f in ETA_FACTORS) + ": W / W0 - 1 (%) |", "|---|---|---|---|---|---|"]
    for path in paths:
        record = pulses.read_record(str(path))
        for H in heights:
            for level in (None, LEVEL):
                base = rocking.required_width(H, record, rule="exact", limit=level).width
                by_seed = [rocking.required_width(H, record, rule="exact", limit=level,
                                                  settings=DEFAULT_SETTINGS.replace(check_seed=s)).width
                           for s in SEEDS]
                by_eta = []
                for factor in ETA_FACTORS:
                    real = rw.Block
                    rw.Block = _ScaledEta(real, factor)
                    try:
                        by_eta.append(rocking.required_width(H, record, rule="exact", limit=level).width)
                    finally:
                        rw.Block = real
                pct = lambda v: " ".join(f"{(x / base - 1) * 100:+.2f}" for x in v)
                lines.append(f"| {path.stem} | {H:g} | {'overturn' if level is None else level} | "
                             f"{base:.4f} | {pct(by_seed)} | {pct(by_eta)} |")
                print(lines[-1], flush=True)
    return lines


def identical(paths, heights):
    """``--identical``: the level given its overturning design with its runs reused against the
    same without them (every width run again): the same design width, search width, widest
    failing width and widths checked on every case?  And the level first, its overturning design
    computed where it can change it (``overturning=True``, ``pipeline run --limit``): the same
    design width as given the whole overturning design, and that design where it is wider?"""
    import dataclasses

    import pulses
    import rocking

    same, same_first, n, shared, total, lines = 0, 0, 0, [], [], []
    for path in paths:
        record = pulses.read_record(str(path))
        for H in heights:
            over = rocking.required_width(H, record, rule="exact")
            kw = dict(rule="exact", limit=LEVEL)
            a = rocking.required_width(H, record, overturning=over, **kw)
            b = rocking.required_width(H, record, overturning=dataclasses.replace(over, outcomes=None), **kw)
            ok = (a.width == b.width and a.search_width == b.search_width
                  and a.widest_failing_width == b.widest_failing_width and a.total_runs == b.total_runs
                  and np.array_equal(a.check_widths, b.check_widths)
                  and np.array_equal(a.check_failed, b.check_failed))
            c = rocking.required_width(H, record, overturning=True, **kw)
            first = c.width == a.width and (c.overturning_width == over.width
                                            or c.overturning_width <= c.overturning_above)
            n, same, same_first = n + 1, same + ok, same_first + first
            shared.append(a.shared_runs)
            total.append(a.total_runs)
            print(f"{path.stem:28s} H {H:4.1f}: {'same' if ok else 'DIFFERENT'} {a.width:.6f} "
                  f"{b.width:.6f}; shared {a.shared_runs} of {a.total_runs}; the level first: "
                  f"{'same' if first else 'DIFFERENT'} {c.width:.6f}", flush=True)
    lines.append(f"level {LEVEL} with the overturning design's runs reused against without: the same "
                 f"answer on {same} of {n} cases; widths shared median {np.median(shared):.0f} of "
                 f"{np.median(total):.0f}")
    lines.append(f"the level first (overturning=True) against given the whole overturning design: "
                 f"the same design width, and the same overturning design where it is wider than "
                 f"the level's own, on {same_first} of {n} cases")
    return lines


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    heights = HEIGHTS
    global LEVEL
    if "--level" in argv:          # the performance level R measured (default 0.5)
        LEVEL = float(argv[argv.index("--level") + 1])
    if "--heights" in argv:
        heights = tuple(float(h) for h in argv[argv.index("--heights") + 1].split(","))
    if not SHARED.is_dir():
        print(f"no records at {SHARED} (set $ROCKING_RECORDS)")
        return 1
    paths = record_paths()
    if "--only" in argv:
        only = set(argv[argv.index("--only") + 1].split(","))
        paths = [p for p in paths if p.stem in only]
    if "--sensitivity" in argv:
        print("\n".join(sensitivity(paths, heights)))
        return 0
    if "--identical" in argv:
        print("\n".join(identical(paths, heights)))
        return 0
    from rocking.search import DEFAULT_SETTINGS

    settings = DEFAULT_SETTINGS
    if "--settings" in argv:       # e.g. --settings check_rounds=3,check_runs=1500
        pairs = (kv.split("=") for kv in argv[argv.index("--settings") + 1].split(","))
        settings = DEFAULT_SETTINGS.replace(**{k: (int if getattr(DEFAULT_SETTINGS, k) is None
                                                   else type(getattr(DEFAULT_SETTINGS, k)))(v)
                                               for k, v in pairs})
    # --cache DIR: keep the dense grids there (they depend on the search's width only)
    cache = argv[argv.index("--cache") + 1] if "--cache" in argv else None
    # --seeds 1,2,3: the check's seed (SearchSettings.check_seed) set to each in turn
    # ("record": the package's own seed, made from the record and the column)
    seeds = ([None if k == "record" else int(k) for k in argv[argv.index("--seeds") + 1].split(",")]
             if "--seeds" in argv else [settings.check_seed])
    for seed in seeds:
        if len(seeds) > 1 or seed is not None:
            print(f"check seed {'record' if seed is None else seed}:")
        rows = measure(paths, heights, settings.replace(check_seed=seed), cache=cache,
                       level="--no-level" not in argv, misses="--misses" in argv,
                       dense="--runs-only" not in argv)
        print("\n".join(table(rows, "--runs-only" not in argv)), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
