"""A pair's directions in passes (pipeline/batch/passes.py): the check above the search width and the
figures only where they decide, the same design width as ``--thorough``.

The synthetic pairs are those of tests/test_site.py (8 s, one-sine pulses in noise); the real
pairs (slow) are read from ``../shared`` and skipped without it."""
from __future__ import annotations

import csv

import pytest

from pipeline.batch import passes
from pipeline.batch.widths import CHECK_COLUMNS
from pipeline.cli import main as cli_main
from rocking.search import DEFAULT_SETTINGS

from .test_site import H, B, _pair

CHECK = list(CHECK_COLUMNS.names)
#: the check in rounds (the layout before the binned one; check_above switches it off or on)
ROUNDS = DEFAULT_SETTINGS.replace(check_layout="rounds")
#: what the check decides besides its own columns: the direction's design width (the search's
#: width where it found no failing width above it)
DESIGN = CHECK + ["design_width_m", "design_tan_alpha", "design_adequate"]
#: and what follows from the design width: the column's restitution, friction and checks there
DESIGN += ["design_eta", "design_friction_demand", "design_min_normal_force", "design_slides",
           "design_t_slide_s", "friction_width_m", "validity"]
#: and under a level (the default), the overturning design's width (its check runs where the
#: level's does) and max|theta|/alpha at both widths (the margin's columns)
LEVEL_DESIGN = DESIGN + ["overturning_width_m", "design_max_theta_ratio", "overturning_max_theta_ratio"]


def _rows(out):
    with open(out / "summary.csv", newline="") as fh:
        return list(csv.DictReader(fh))


def _design(rows) -> float:
    """The pair's design width: the widest design or failing width over its directions."""
    return max(max(float(r["design_width_m"]), float(r["widest_failing_width_m"] or 0.0)) for r in rows)


def _top(row) -> float:
    """The widest width the check of this row's direction would look at (rocking.widths)."""
    w = float(row["design_width_m"])
    return passes._bracket_step() * min(DEFAULT_SETTINGS.check_reach * w,
                                        float(row["height_m"]) * float(row["pga_g"]))


def _run(out, pair, *extra):
    return cli_main(["run", "--pair", *map(str, pair), "--out", str(out), "--quiet", *map(str, extra)])


def _same_answer(default, thorough):
    """The default's rows against ``--thorough``'s: the same design width; every checked direction
    identical; every unchecked one identical but for the check's columns, and its check could
    not have reached the design width (with ``--limit``: its width is the level's search width
    raised to at least the overturning design's search width)."""
    design = _design(thorough)
    DESIGN = LEVEL_DESIGN
    assert _design(default) == design
    by_dir = {r["direction_deg"]: r for r in thorough}
    n_checked = 0
    for r in default:
        ref = by_dir[r["direction_deg"]]
        if r["check_runs"] == ref["check_runs"]:
            n_checked += 1
            assert r == ref
        elif r["check_runs"] not in ("", "0"):  # its last round could not reach the design width
            n_checked += 1
            assert {k: v for k, v in r.items() if k not in DESIGN} == {k: v for k, v in ref.items() if k not in DESIGN}
            assert float(r["design_width_m"]) <= design and int(r["check_runs"]) < int(ref["check_runs"])
        else:
            assert {k: v for k, v in r.items() if k not in DESIGN} == {k: v for k, v in ref.items() if k not in DESIGN}
            assert r["failing_share"] == "" and r["widest_failing_width_m"] == ""
            assert r["search_width_m"] == ref["search_width_m"]
            if r["overturning_width_m"]:       # --limit: at least the overturning design's
                assert float(r["design_width_m"]) >= max(float(r["search_width_m"]),
                                                         float(r["overturning_width_m"]))
                assert float(r["overturning_width_m"]) <= float(ref["overturning_width_m"])
            else:   # the search width raised to 6 significant digits (run there)
                assert float(r["design_width_m"]) >= float(r["search_width_m"])
            assert _top(r) <= design * (1.0 + passes.MARGIN)
    return n_checked


def _d(index, checked, plotted, w, top, widest=None):
    return passes._Direction(index, checked, plotted, {"7.5x1.8": (w, top, widest)})


def test_the_check_goes_to_the_governing_direction_then_where_it_could_reach_the_design_width():
    group = {0: _d(0, False, False, 1.0, 2.0), 1: _d(1, False, False, 1.2, 2.4), 2: _d(2, False, False, 0.5, 1.0),
             3: _d(3, False, False, 1.2, 2.4)}
    # first the governing direction (the widest; the first of equal widths), with its figure
    assert passes._wanted(group, plots=True)[0] == {1: True}
    assert passes._wanted(group, plots=False)[0] == {1: False}
    # it found a failing width at 1.5 m: the design width; a check reaching up to 1.0 m cannot
    # change it, one reaching 2.0 m or 2.4 m can
    group[1] = _d(1, True, True, 1.2, 2.4, 1.5)
    assert passes._wanted(group, plots=True) == ({0: False, 3: False}, {"7.5x1.8": 1.5}, set())
    group[0], group[3] = _d(0, True, False, 1.0, 2.0), _d(3, True, False, 1.2, 2.4, 2.1)
    assert passes._wanted(group, plots=True)[0] == {}
    # a direction whose check could reach 2.1 m only if the design width were lower
    group[4] = _d(4, False, False, 1.05, 2.1 * (1.0 - 1e-3))
    assert passes._wanted(group, plots=True)[0] == {}


def test_a_governing_direction_checked_only_above_a_bound_is_checked_whole():
    # direction 1 was checked above the scouts' bound only (the separable layout) and governs:
    # it is computed again with its whole check, drawn or not
    group = {0: _d(0, False, False, 1.0, 2.0), 1: passes._Direction(1, True, False, {"7.5x1.8": (1.2, 2.4, None)},
                                                                  full=False)}
    for plots in (True, False):
        assert passes._wanted(group, plots=plots) == ({1: plots}, {}, {1})
    group[1].full = True
    assert passes._wanted(group, plots=False) == ({0: False}, {"7.5x1.8": 1.2}, set())


def test_scouts_first_then_the_others_checked_above_the_scouts_widest_width():
    from pipeline.batch.tasks import Column, Options, Task

    options = Options()
    cols = (Column(7.5, 1.8),)
    kinds = ["component-1", "even", "even", "pulse", "even", "even", "component-2", "even", "pulse-normal"]
    tasks = [Task(i, f"P_{i}", "a", cols, options, path2="b", direction=10.0 * i, direction_kind=k, pair="P")
             for i, k in enumerate(kinds)] + [Task(9, "lone", "c", cols, options)]
    first, held = passes.first_pass(tasks, options)
    # every 4th direction and those chosen for what they are go first, unchecked and undrawn
    assert held == {1, 2, 5, 7}
    assert all(not first[i].check and not first[i].plot for i in range(9)) and first[9] == tasks[9]
    plan = passes.Plan(options, held)
    for i in sorted(set(range(9)) - held):
        plan.note(first[i], [{"column": "7.5x1.8", "design_width_m": 0.5 + 0.1 * i, "height_m": 7.5,
                              "pga_g": 0.5, "widest_failing_width_m": None}])
    second = plan.next_pass(first)
    assert [t.index for t in second] == [1, 2, 5, 7]
    # each checked above 1.3 m, the scouts' widest design width (the binned check); the rounds
    # check is run where it could reach that far, its top allowed a bracket step above it
    below = 1.0 if DEFAULT_SETTINGS.check_layout == "bins" else passes._bracket_step()
    assert all(t.check and t.check_above == pytest.approx((1.3 / below,), rel=1e-5) for t in second)
    assert plan.held == set()


def test_a_pair_goes_on_to_its_next_pass_while_another_pairs_tasks_are_out():
    # a batch finishes a pair while the workers still keep its searches (pipeline.batch.memo): a
    # pair whose results are all in gets its next pass at once, not after every other pair's
    from pipeline.batch.tasks import Column, Options, Task

    options = Options()
    cols = (Column(7.5, 1.8),)
    kinds = ["component-1", "even", "even", "pulse"]
    tasks = [Task(4 * j + i, f"{name}_{i}", "a", cols, options, path2="b", direction=10.0 * i,
                  direction_kind=k, pair=name)
             for j, name in enumerate(("A", "B")) for i, k in enumerate(kinds)]
    first, held = passes.first_pass(tasks, options)
    assert held == {1, 2, 5, 6}
    plan = passes.Plan(options, held)
    scouts = [t for t in first if t.index not in held]
    plan.sent(scouts)
    row = lambda w: [{"column": "7.5x1.8", "design_width_m": w, "height_m": 7.5, "pga_g": 0.5,
                      "widest_failing_width_m": None}]
    plan.note(first[0], row(1.0))
    assert plan.next_pass(first) == []              # A's pulse direction is still out
    plan.note(first[4], row(1.1))
    plan.note(first[3], row(1.2))                   # A's scouts are in, B's pulse direction is out
    second = plan.next_pass(first)
    assert [t.index for t in second] == [1, 2] and plan.held == {5, 6}
    assert all(t.check_above == pytest.approx((1.2,), rel=1e-5) for t in second)
    assert plan.next_pass(first) == []              # nothing new came in
    plan.sent(second)
    plan.note(first[7], row(0.9))                   # B's scouts are in: its held directions next
    assert [t.index for t in plan.next_pass(first)] == [5, 6] and plan.held == set()


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    return _pair(tmp_path_factory.mktemp("passes"), "STP", 0.45, 0.3, 1)


def test_default_gives_the_thorough_design_width_figures_where_they_inform(pair, tmp_path):
    args = ("--block", f"{H}x{B}", "--directions", "6")
    assert _run(tmp_path / "thorough", pair, *args, "--thorough", "--no-plots") == 0
    assert _run(tmp_path / "default", pair, *args) == 0
    default, thorough = _rows(tmp_path / "default"), _rows(tmp_path / "thorough")
    assert len(default) == len(thorough) >= 6
    assert 1 <= _same_answer(default, thorough) <= len(default)
    # one record figure and at most one barcode: the governing direction's (pairs.csv)
    with open(tmp_path / "default" / "pairs.csv", newline="") as fh:
        (gov,) = list(csv.DictReader(fh))
    figures = sorted(p.name for p in (tmp_path / "default" / "plots").glob("*deg.png"))
    assert figures == [f"{gov['record']}.png"]
    assert len(list((tmp_path / "default" / "plots").glob("widths/*.png"))) <= 1
    # a second run computes nothing and changes no file
    before = {p: p.read_bytes() for p in (tmp_path / "default").rglob("*") if p.is_file()}
    assert _run(tmp_path / "default", pair, *args) == 0
    after = {p: p.read_bytes() for p in (tmp_path / "default").rglob("*") if p.is_file()}
    assert before == after


@pytest.mark.slow
@pytest.mark.parametrize("how", [("--jobs", "2"), ("--dask", "local", "--jobs", "2")], ids=["pool", "dask"])
def test_a_pairs_directions_sent_in_chunks_give_the_serial_runs_files(how, pair, tmp_path, monkeypatch):
    # three records a submission (a pair's directions share their files' bytes under dask); the
    # passes' tasks arrive in other orders, and every file is the one-process run's
    if "--dask" in how:
        pytest.importorskip("dask.distributed")
    from pipeline.batch import worker

    monkeypatch.setattr(worker, "chunk_size", lambda queued, jobs: min(3, queued))
    args = ("--block", f"{H}x{B}", "--directions", "6")
    assert _run(tmp_path / "one", pair, *args) == 0
    assert _run(tmp_path / "chunks", pair, *args, *how) == 0
    files = lambda out: {p.relative_to(out): p.read_bytes() for p in out.rglob("*")
                         if p.is_file()}
    assert files(tmp_path / "chunks") == files(tmp_path / "one")


@pytest.mark.slow
def test_a_level_gives_the_thorough_design_width_and_its_overturning_design(pair, tmp_path):
    """`--limit 0.5` on a pair in 6 directions: the pair's design width is --thorough's; every
    direction's design width is at least its overturning design width (overturning_width_m), and
    design.csv's is the widest over the directions, below the pair's design width."""
    args = ("--block", f"{H}x{B}", "--directions", "6", "--limit", "0.5", "--no-plots")
    assert _run(tmp_path / "thorough", pair, *args, "--thorough") == 0
    assert _run(tmp_path / "default", pair, *args) == 0
    default, thorough = _rows(tmp_path / "default"), _rows(tmp_path / "thorough")
    assert 1 <= _same_answer(default, thorough) <= len(default)
    for r in default + thorough:
        assert float(r["design_width_m"]) >= float(r["overturning_width_m"]) > 0
    for out, rows in (("default", default), ("thorough", thorough)):
        with open(tmp_path / out / "design.csv", newline="") as fh:
            (row,) = list(csv.DictReader(fh))
        assert float(row["overturning_width_m"]) == max(float(r["overturning_width_m"]) for r in rows)
        assert float(row["overturning_width_m"]) <= float(row["design_width_m"])


def test_plots_all_draws_every_direction_and_no_plots_none(pair, tmp_path):
    args = ("--block", f"{H}x{B}", "--directions", "2")
    assert _run(tmp_path / "all", pair, *args, "--plots", "all") == 0
    n = len(_rows(tmp_path / "all"))
    assert len(list((tmp_path / "all" / "plots").glob("*deg.png"))) == n
    assert _run(tmp_path / "none", pair, *args, "--no-plots") == 0
    assert not (tmp_path / "none" / "plots").exists() or not list((tmp_path / "none" / "plots").rglob("*.png"))


@pytest.mark.slow
@pytest.mark.parametrize("names", [("Rinaldi228.AT2", "Rinaldi318.AT2"),
                                   ("haselREC_NGA-West2-Reduced/RSN159_1.AT2",
                                    "haselREC_NGA-West2-Reduced/RSN159_2.AT2")])
def test_real_pairs_default_design_width_is_the_thorough_one(shared_records, names, tmp_path):
    pair = [shared_records / n for n in names]
    for p in pair:
        if not p.is_file():
            pytest.skip(f"real record not available: {p}")
    args = ("--block", "7.5x1.8", "--directions", "12", "--no-plots")
    assert _run(tmp_path / "thorough", pair, *args, "--thorough") == 0
    assert _run(tmp_path / "default", pair, *args) == 0
    assert _same_answer(_rows(tmp_path / "default"), _rows(tmp_path / "thorough")) >= 1


def test_check_above_switches_the_rounds_check_off_only_where_its_top_is_not_above_it():
    import importlib.resources

    import pulses
    import rocking

    record = pulses.read_record(str(importlib.resources.files("pipeline.data") / "synth_sine_055g_0.9s.sac"))
    s = ROUNDS
    full = rocking.required_width(7.5, record, rule="exact", settings=s)
    # the widest width the check's rounds could reach: each round's span is at most check_span
    # times the width the one before left, and nothing rocks above the no-uplift width
    reach = min(s.check_span ** s.check_rounds * full.search_width, 7.5 * record.pga / pulses.G)
    assert full.check_runs > 0 and reach > full.search_width
    off = rocking.required_width(7.5, record, rule="exact", settings=s.replace(check_above=reach))
    assert (off.search_width, off.check_runs, off.failing_share) == (full.search_width, 0, None)
    # below what the last round from the search's width reaches: every round runs
    last = min(s.check_span * full.search_width, 7.5 * record.pga / pulses.G)
    on = rocking.required_width(7.5, record, rule="exact", settings=s.replace(check_above=last * (1.0 - 1e-9)))
    assert (on.width, on.check_runs, on.failing_share, on.widest_failing_width) == \
        (full.width, full.check_runs, full.failing_share, full.widest_failing_width)


def test_the_rounds_check_stops_after_a_round_when_the_rounds_left_could_not_reach_check_above():
    import importlib.resources

    import pulses
    import rocking

    record = pulses.read_record(str(importlib.resources.files("pipeline.data") / "synth_sine_055g_0.9s.sac"))
    s = ROUNDS
    full = rocking.required_width(7.5, record, rule="exact", settings=s)
    top = 7.5 * record.pga / pulses.G
    # above what a second round from the search's width could reach, below what two could: the
    # first round runs (its share of the runs) and, where it raised nothing that far, no second
    above = min(s.check_span * full.search_width, top) * (1.0 + 1e-9)
    one = rocking.required_width(7.5, record, rule="exact", settings=s.replace(check_above=above))
    assert one.search_width == full.search_width
    if one.width == one.search_width:  # the first round found no failing width: one round only
        assert 0 < one.check_runs <= full.check_runs // s.check_rounds + 1
    else:
        assert 0 < one.check_runs <= full.check_runs
