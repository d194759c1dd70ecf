"""The design width (no width the package found failing lies above it) and performance levels
(``limit``: max|theta|/alpha <= R) of ``rocking.required_width`` and ``rocking.critical_scale``,
checked against independent runs of ``rocking.simulate``."""
from __future__ import annotations

import math

import numpy as np
import pytest

import pulses
import rocking
from rocking import Block
from rocking.search import DEFAULT_SETTINGS, check_limit

from .conftest import shared_record
from .vertical_cases import DOWNLOAD


def _ratio(height, width, record, vertical=None):
    res = rocking.simulate(Block.from_dimensions(height, width), record, vertical=vertical,
                           history=False)
    return bool(res.overturned), float(res.max_rotation_ratio)


@pytest.mark.parametrize("bad", [0.0, -0.5, 1.01, float("nan"), "half"])
def test_limit_out_of_range_is_refused(bad):
    with pytest.raises(ValueError, match="limit"):
        check_limit(bad)
    with pytest.raises(ValueError, match="limit"):
        rocking.required_width(7.5, pulses.Record(np.zeros(10), 0.01), rule="exact", limit=bad)


def test_design_width_is_above_every_failing_width():
    """Kern County, Taft 021 (real, 7.5 m): the check finds a failing width 10 % above the
    search's first transition (0.5836 m against 0.6427 m); the design width lies just above it
    (bisected to design_rtol), survives, and its own failing end overturns."""
    rec = pulses.read_record(shared_record("RSN15_KERN_TAF021.AT2"))
    res = rocking.required_width(7.5, rec, rule="exact")
    assert res.widest_failing_width is not None
    assert res.widest_failing_width > 1.05 * res.search_width       # far above the search's answer
    assert res.widest_failing_width < res.width
    # refined just above it: within design_rtol (plus one bisection step)
    # the bracket bisected to design_rtol, its end raised to 6 significant digits (one unit more)
    unit = 10.0 ** (math.floor(math.log10(res.width)) - DEFAULT_SETTINGS.design_digits + 1)
    assert res.width - res.widest_failing_width <= unit + 2 * DEFAULT_SETTINGS.design_rtol * res.width
    assert not _ratio(7.5, res.width, rec)[0]
    assert _ratio(7.5, res.widest_failing_width, rec)[0]
    # every width the check ran above the design width survived
    assert not res.check_failed[res.check_widths > res.width].any()
    assert 0 < res.refine_runs <= 25 and res.total_runs == res.runs + res.check_runs + res.refine_runs
    assert res.check_runs <= _most(res, rec)


def _most(res, rec) -> int:
    """The most widths the default (binned) check can run above ``res``'s search width: its number
    varies with the record (docs/slivers.md); the median over 62 cases is within the former 1500."""
    from rocking import binned

    hi = binned.span_top(res.search_width, res.height * rec.pga / pulses.G, DEFAULT_SETTINGS)
    return binned.most_runs(res.search_width, hi, DEFAULT_SETTINGS)


def test_level_half():
    """limit=0.5 on Pacoima Dam 164 (real, 7.5 m): the design width keeps max|theta|/alpha <= 0.5
    under the record (an independent run), a width 0.1 % narrower exceeds it or a failing width
    found lies just below, and it is at least the overturning design width."""
    rec = pulses.read_record(shared_record("RSN77_SFERN_PUL164.AT2"))
    over = rocking.required_width(7.5, rec, rule="exact")
    half = rocking.required_width(7.5, rec, rule="exact", limit=0.5)
    assert half.limit == 0.5 and over.limit is None
    toppled, ratio = _ratio(7.5, half.width, rec)
    assert not toppled and ratio <= 0.5
    assert half.width >= over.width
    assert _ratio(7.5, half.search_width * (1 - 1e-6), rec)[1] > 0.5 or half.widest_failing_width
    # the check's runs within what its layout allows (their number varies with the record)
    for res in (half, over):
        assert 0 < res.check_runs <= _most(res, rec)


def test_vertical_governs_the_design():
    """With a vertical (the PEER download's Pacoima Dam, 7.5 m): the answer is the wider of the
    horizontal-only and the with-vertical designs, and says which; passing the horizontal answer
    gives the same result without recomputing it."""
    h1 = pulses.read_record(str(DOWNLOAD / "RSN77_SFERN_PUL164.AT2")) if DOWNLOAD.is_dir() else None
    if h1 is None:
        pytest.skip(f"the PEER download is absent: {DOWNLOAD}")
    h2 = pulses.read_record(str(DOWNLOAD / "RSN77_SFERN_PUL254.AT2"))
    v = pulses.read_record(str(DOWNLOAD / "RSN77_SFERN_PULDWN.AT2"))
    h1, h2, up = pulses.check_triplet(h1, h2, v, "RSN77_SFERN_PULDWN.AT2")
    for rec in (h1, h2):
        alone = rocking.required_width(7.5, rec, rule="exact")
        both = rocking.required_width(7.5, rec, rule="exact", vertical=up, horizontal=alone)
        assert both.horizontal_width == alone.width
        assert both.width == max(both.horizontal_width, both.vertical_width)
        assert both.governed_by == ("with vertical" if both.vertical_width > alone.width else "horizontal")
        assert not _ratio(7.5, both.width, rec, vertical=up)[0]
        assert not _ratio(7.5, both.width, rec)[0]


@pytest.mark.parametrize("limit", [0.5, 0.1])
def test_critical_scale_for_a_level(limit):
    """The scale at which max|theta|/alpha first exceeds R (Pacoima Dam 164 on a 7.5 x 1.8 m
    column): just below it the ratio is at most R, at it above R (independent runs); below the
    overturning scale."""
    rec = pulses.read_record(shared_record("RSN77_SFERN_PUL164.AT2"))
    block = Block.from_dimensions(7.5, 1.8)
    cs = rocking.critical_scale(block, rec, limit=limit)
    assert cs.limit == limit and cs.scale is not None
    below = rocking.simulate(block, rec.scaled(cs.scale * (1 - 1e-5)), history=False)
    at = rocking.simulate(block, rec.scaled(cs.scale), history=False)
    assert below.max_rotation_ratio <= limit < at.max_rotation_ratio
    assert cs.scale < rocking.critical_scale(block, rec).scale
    with pytest.raises(ValueError, match="limit"):
        rocking.fragility([cs, cs], limit=None)
    assert rocking.fragility([cs, rocking.critical_scale(block, rec.scaled(0.8), limit=limit)],
                             limit=limit).limit == limit


def test_pipeline_design_limit(capsys):
    """`pipeline design --limit 0.5 --json`: the level's exact width, which keeps max|theta|/alpha
    <= 0.5 under the pulse (an independent run) and is wider than the overturning one; a level
    outside (0, 1] is a one-line argument error (exit 2)."""
    import json

    from pipeline.cli import main

    args = ["design", "--height", "7.5", "--pulse", "sine", "--ap", "0.71g", "--tp", "0.8"]
    assert main(args + ["--limit", "0.5", "--json"]) == 0
    rules = json.loads(capsys.readouterr().out)["rules"]
    w = rules["level"]["required_width_m"]
    assert rules["level"]["limit"] == 0.5 and w > rules["exact"]["required_width_m"]
    pulse = pulses.make_pulse("sine", 0.71 * pulses.G, 0.8)
    assert _ratio(7.5, w, pulse)[1] <= 0.5
    assert main(args + ["--limit", "1.5"]) == 2
    assert "--limit" in capsys.readouterr().err


@pytest.mark.slow
def test_pipeline_run_limit(tmp_path):
    """`pipeline run --limit 0.5` on a bundled record: design.csv and summary.csv carry the level,
    its design width keeps max|theta|/alpha <= 0.5 under the record (an independent run) and is
    at least the overturning run's; the printed suite line states the level."""
    import csv
    import importlib.resources

    from pipeline.cli import main

    path = str(importlib.resources.files("pipeline.data") / "synth_sine_055g_0.9s.sac")
    widths = {}
    # the verge alone (--limit none), the level named, and the default (the same level)
    for name, extra in (("over", ["--limit", "none"]), ("half", ["--limit", "0.5"]), ("default", [])):
        out = tmp_path / name
        assert main(["run", path, "--block", "7.5x1.8", "--out", str(out), "--no-plots", "-q"] + extra) == 0
        row = next(csv.DictReader(open(out / "design.csv")))
        widths[name] = float(row["design_width_m"])
        assert row["design_limit"] == ("" if name == "over" else "0.5")
        widths[name + " overturning"] = row["overturning_width_m"]
    rec = pulses.read_record(path)
    assert not _ratio(7.5, widths["half"], rec)[0] and _ratio(7.5, widths["half"], rec)[1] <= 0.5
    assert widths["half"] >= widths["over"]
    # the level's run computed the overturning design where it could change the level's: here the
    # level governs (2.158 m against 1.683 m when measured), so what it established is at most the
    # overturning run's design width (6 digits) and the level's; blank without a level
    assert float(widths["half overturning"]) <= min(float(f"{widths['over']:g}"), widths["half"])
    assert widths["over overturning"] == ""
    assert widths["default"] == widths["half"] and widths["default overturning"] == widths["half overturning"]


def test_fragility_table_counts_failures_at_the_level_in_their_own_column():
    """fragility.csv: without a level the records that fail count as overturned; with --limit R
    (critical scales where max|theta|/alpha first exceeds R) they go to n_failed_at_level and
    n_overturned is blank (a level's critical scale does not say the column overturns)."""
    from pipeline.reports.suite import fragility_tables

    def rows(limit):
        # four records of one column, three with a critical scale (log-moments: a fit exists)
        return [dict(column="7.5x0.8", pair=f"r{k}", column_kind="block", critical_scale=s,
                     fragility_up_to=4.0, uplift_scale=0.3, pga_g=0.4, design_limit=limit)
                for k, s in enumerate((1.2, 1.8, 2.5, None))]

    (over,), _, _ = fragility_tables(rows(None))
    (level,), _, _ = fragility_tables(rows(0.5), limit=0.5)
    assert over["n_overturned"] == 3 and over["n_failed_at_level"] is None
    assert level["n_overturned"] is None and level["n_failed_at_level"] == 3
    assert over["n_records"] == level["n_records"] == 4
    assert over["median_scale"] is not None and not over["error"]


def test_level_given_the_overturning_design_is_at_least_it():
    """Kern County, Taft 021 (real, 6 m), check seed 3: the level 0.5's own design (0.560261 m when
    measured) falls below the overturning design (0.560393 m: its check found an overturning sliver
    the level's check, with other widths, did not sample).  Given the overturning design, the
    level's width is at least it by construction (a width that overturns fails every level), it
    keeps max|theta|/alpha <= 0.5 under the record (an independent run), and it cost at most a
    bisection more than the level alone.  With ``overturning=True`` (the level first, then the
    overturning design where it can change it: ``pipeline run --limit``'s route) the answer is
    the same, the overturning design computed inside is the independent one where it governs,
    and the whole costs fewer solver runs than the overturning design followed by the level."""
    rec = pulses.read_record(shared_record("RSN15_KERN_TAF021.AT2"))
    s = DEFAULT_SETTINGS.replace(check_seed=3)
    over = rocking.required_width(6.0, rec, rule="exact", settings=s)
    alone = rocking.required_width(6.0, rec, rule="exact", limit=0.5, settings=s)
    given = rocking.required_width(6.0, rec, rule="exact", limit=0.5, settings=s, overturning=over)
    assert given.width >= over.width and given.width >= alone.width
    toppled, ratio = _ratio(6.0, given.width, rec)
    assert not toppled and ratio <= 0.5
    # the same search and check as alone; at most one run at the overturning width and a
    # bisection to design_rtol of a bracket above it (log2(1/1e-6) = 20 halvings)
    assert given.runs == alone.runs and given.check_runs == alone.check_runs
    assert given.total_runs - alone.total_runs <= 1 + 20
    if alone.width >= over.width:                       # nothing to add: the same answer
        assert given.width == alone.width
    # the level first: the overturning design's check above the level's width (separable) finds
    # what the whole check finds there, so where it governs it is the same design, bit for bit
    first = rocking.required_width(6.0, rec, rule="exact", limit=0.5, settings=s, overturning=True)
    inner = first.overturning_design
    assert first.overturning_above == pytest.approx(alone.width, rel=1e-5)  # before its 6 digits
    assert (first.width, first.widest_failing_width) == (given.width, given.widest_failing_width)
    if over.width > first.overturning_above:            # it governs (seed 3 when measured)
        assert first.overturning_width == over.width == inner.width
        assert inner.search_width == over.search_width and inner.check_runs < over.check_runs
    assert first.solver_runs + inner.solver_runs < over.total_runs + given.solver_runs


def test_overturning_true_goes_with_a_level_under_a_record_only():
    """``overturning=True`` needs a level under a record; a horizontal answer given with it must
    have been designed with it too (one-line errors)."""
    rec = pulses.Record(np.sin(np.linspace(0, 20, 2000)) * 3.0, 0.01)
    for kw in (dict(limit=None), dict(limit=0.5, rule="eq31")):
        rule = kw.pop("rule", "exact")
        with pytest.raises(ValueError, match="overturning="):
            rocking.required_width(7.5, rec, rule=rule, overturning=True, **kw)
    up = pulses.Record(np.zeros(2000), 0.01)
    with pytest.raises(ValueError, match="horizontal="):
        rocking.required_width(7.5, rec, rule="exact", limit=0.5, vertical=up, overturning=True,
                               horizontal=rocking.RequiredWidth(0.5, 7.5, "exact", 0, "test", limit=0.5))


@pytest.mark.parametrize("kw", [dict(limit=None), dict(limit=0.5, rule="eq31"),
                                dict(limit=0.5, vertical="same")])
def test_overturning_design_goes_with_a_level_only(kw):
    rec = pulses.Record(np.sin(np.linspace(0, 20, 2000)) * 3.0, 0.01)
    over = rocking.RequiredWidth(0.5, 7.5, "exact", 0, "test")
    kw = dict(kw)
    rule = kw.pop("rule", "exact")
    if kw.get("vertical") == "same":
        kw["vertical"] = pulses.Record(np.zeros(2000), 0.01)
    with pytest.raises(ValueError, match="overturning="):
        rocking.required_width(7.5, rec, rule=rule, overturning=over, **kw)


@pytest.mark.slow
def test_level_reuses_the_overturning_runs_and_answers_the_same():
    """Kern County, Taft 021 (real, 6 m): a level given its overturning design answers from that
    design's outcomes every batch it ran (the record search's geometric scan is the same batch of
    widths for both criteria, and every run gives overturned and max|theta|/alpha).  The answer
    is the same, bit for bit, as the level computed given the same design without its runs, and
    the runs it made itself are fewer by the widths shared, at least the scan's."""
    import dataclasses

    rec = pulses.read_record(shared_record("RSN15_KERN_TAF021.AT2"))
    over = rocking.required_width(6.0, rec, rule="exact")
    shared = rocking.required_width(6.0, rec, rule="exact", limit=0.5, overturning=over)
    apart = rocking.required_width(6.0, rec, rule="exact", limit=0.5,
                                   overturning=dataclasses.replace(over, outcomes=None))
    assert apart.shared_runs == 0
    for name in ("width", "search_width", "widest_failing_width", "transitions", "runs",
                 "check_runs", "refine_runs", "failing_share", "overturning_width"):
        assert getattr(shared, name) == getattr(apart, name), name
    assert np.array_equal(shared.check_widths, apart.check_widths)
    assert np.array_equal(shared.check_failed, apart.check_failed)
    scan = DEFAULT_SETTINGS.record_scan - 1 + DEFAULT_SETTINGS.record_tail   # top is never run
    assert scan <= shared.shared_runs < shared.total_runs
    assert shared.solver_runs == shared.total_runs - shared.shared_runs
    # the overturning design's outcomes are its batches: the first is the search's scan, which
    # the same batch run again gives bit for bit (what the sharing relies on), and which
    # independent single runs give to rounding (1e-9 in max|theta|/alpha, as tests/test_lanes.py
    # holds the batch engine to single runs)
    x, toppled, ratio = over.outcomes[0]
    assert x.size == scan and sum(b[0].size for b in over.outcomes) == over.total_runs
    res = rocking.simulate_many([Block.from_dimensions(6.0, b) for b in x], rec)
    assert np.array_equal(res.overturned, toppled) and np.array_equal(res.max_rotation_ratio, ratio)
    for k in (0, x.size // 2, x.size - 1):
        one = rocking.simulate(Block.from_dimensions(6.0, x[k]), rec, history=False)
        assert bool(one.overturned) == toppled[k]
        assert one.max_rotation_ratio == pytest.approx(ratio[k], rel=0, abs=1e-9)


@pytest.mark.slow
def test_level_with_the_vertical_at_least_each_overturning_design():
    """With a vertical (the PEER download's Pacoima Dam 254 and its vertical, 7.5 m), as
    `pipeline run --limit 0.5` computes it (pipeline.batch.record.design_width): the level with
    the vertical is at least the overturning design with it, the horizontal level at least the
    horizontal one (each computed apart); each motion's overturning design, checked above that
    motion's level width, is the one computed apart where it is wider than that width, and the
    reported overturning width is the wider of the two; the design width keeps max|theta|/alpha
    <= 0.5 with and without the vertical (independent runs)."""
    from pipeline.batch.widths import design_width

    if not DOWNLOAD.is_dir():
        pytest.skip(f"the PEER download is absent: {DOWNLOAD}")
    h1, h2, up = pulses.check_triplet(*(pulses.read_record(str(DOWNLOAD / f"RSN77_SFERN_PUL{c}.AT2"))
                                        for c in ("164", "254", "DWN")), "RSN77_SFERN_PULDWN.AT2")
    level = design_width(h2, up, 7.5, 0.0, 0.5, DEFAULT_SETTINGS)
    over_h = rocking.required_width(7.5, h2, rule="exact")
    over = rocking.required_width(7.5, h2, rule="exact", vertical=up, horizontal=over_h)
    # each motion's overturning design, checked above that motion's level width: the independent
    # one where it is wider than that width, at most it otherwise (then the level governs)
    def motions(res):       # (horizontal motion alone, with the vertical)
        return (res, res.other) if res.governed_by == "horizontal" else (res.other, res)

    for mine, ref in zip(motions(level), motions(over)):
        inner = mine.overturning_design
        if inner.width > mine.overturning_above:
            assert inner.width == ref.width
        else:
            assert inner.width <= ref.width <= mine.width
    assert level.overturning_width == max(m.overturning_design.width for m in (level, level.other))
    assert level.horizontal_width >= over.horizontal_width
    assert level.vertical_width >= over.vertical_width
    assert level.width == max(level.horizontal_width, level.vertical_width) >= over.width
    for vertical in (None, up):
        toppled, ratio = _ratio(7.5, level.width, h2, vertical=vertical)
        assert not toppled and ratio <= 0.5
    # inconsistent arguments: one line each
    with pytest.raises(ValueError, match="overturning="):   # a horizontal-only design with vertical=
        rocking.required_width(7.5, h2, rule="exact", limit=0.5, vertical=up, overturning=over_h)
    with pytest.raises(ValueError, match="overturning="):   # a design with the vertical without it
        rocking.required_width(7.5, h2, rule="exact", limit=0.5, overturning=over)
    with pytest.raises(ValueError, match="another record"):
        rocking.required_width(7.5, h1, rule="exact", limit=0.5, overturning=over_h)
    with pytest.raises(ValueError, match="horizontal="):    # a level not given the same design
        rocking.required_width(7.5, h2, rule="exact", limit=0.5, vertical=up, overturning=over,
                               horizontal=rocking.required_width(7.5, h2, rule="exact", limit=0.5))


@pytest.mark.slow
def test_pipeline_design_limit_is_at_least_the_overturning_design():
    """`pipeline.design(..., limit=0.5)` on Kern County, Taft 021 (real, 6 m; a case whose level
    alone fell below its overturning design with another check seed): the design width is at
    least the overturning design width of `rocking.required_width` without a limit (computed
    apart), and keeps max|theta|/alpha <= 0.5 under the record (an independent run at the
    reported width); design.csv and summary.csv carry what the run established of the overturning
    design (its check above the level's width): at most the design width, and here, where the
    level governs, at most the overturning design width too (to the reports' 6 digits)."""
    import pipeline

    path = shared_record("RSN15_KERN_TAF021.AT2")
    run = pipeline.design([str(path)], heights=6.0, limit=0.5, shapes="sine")
    rec = pulses.read_record(path)
    over = rocking.required_width(6.0, rec, rule="exact")
    for table in (run.design, run.summary):
        row = table.iloc[0]
        assert float(row["design_width_m"]) >= over.width
        assert float(row["design_width_m"]) >= float(row["overturning_width_m"])
        if float(row["overturning_width_m"]) < float(row["design_width_m"]):   # the level governs
            assert float(row["overturning_width_m"]) <= over.width * (1 + 1e-6)
    toppled, ratio = _ratio(6.0, float(run.design.iloc[0]["design_width_m"]), rec)
    assert not toppled and ratio <= 0.5
    # without a level (limit=None: the verge alone) the column is blank; the default is the level
    plain = pipeline.design([str(path)], heights=6.0, shapes="sine", limit=None)
    assert plain.design["overturning_width_m"].isna().all()
    default = pipeline.design([str(path)], heights=6.0, shapes="sine")
    assert default.design["design_width_m"].equals(run.design["design_width_m"])
