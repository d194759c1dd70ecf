"""The check above the search width (docs/slivers.md): failing slivers above it, found and
reported, against independent dense scans."""
from __future__ import annotations

import math

import numpy as np
import pytest

import pulses
import rocking
from pulses import G, make_pulse
from rocking import Block, binned
from rocking.search import DEFAULT_SETTINGS, SearchSettings
from rocking.widths import _record_seed, check_widths, follow_widths

from .conftest import shared_record


def _verdicts(height, record, widths):
    res = rocking.simulate_many([Block.from_dimensions(height, float(b)) for b in widths], record)
    return np.asarray(res.overturned, dtype=bool)


def _chaotic_record(seed=8, duration=20.0, dt=0.01):
    """A 0.3 g sine pulse in 0.15 g of band-limited noise: under it a 7.5 m column has failing
    widths above its search width (0.878 m): a 3000-width linear scan of (w, 2w] finds three,
    1.0, 1.5 and 2.7 % above it, and 4 % of 1500 log-spaced widths 0.01-1 % above it fail)."""
    from scipy import signal

    rng = np.random.default_rng(seed)
    n = int(round(duration / dt)) + 1
    t = dt * np.arange(n)
    sos = signal.butter(4, (0.3, 10.0), btype="bandpass", fs=1.0 / dt, output="sos")
    noise = signal.sosfiltfilt(sos, rng.standard_normal(n))
    noise *= 0.15 * G / np.std(noise) * np.exp(-((t - 0.35 * duration) / (0.25 * duration)) ** 2)
    return pulses.Record(noise + make_pulse("sine", 0.3 * G, 1.0, 0.3 * duration)(t), dt)


def test_check_widths_layout():
    """First stage jittered: one width per stratum of each part, inside the span, none on the
    search's grid, the same for the same seed and different for another; the later stages put
    its widths where the widths run so far vary most from one to the next, or failed."""
    s = DEFAULT_SETTINGS
    w, top = 1.0, 1.4          # the span ends at the no-uplift width (below check_span w = 1.5)
    x = check_widths(w, top, s, seed=5)
    n_follow = round(s.check_follow * s.check_runs)
    n1 = s.check_runs - n_follow
    assert x.size == n1 and np.all(np.diff(x) > 0)
    assert x[0] > w and x[-1] <= top
    n_near = round(s.check_near * n1)
    n_far = n1 - n_near
    near = w * (1 + s.check_first * ((top / w - 1) / s.check_first) ** (np.arange(n_near + 1) / n_near))
    # every log stratum holds its own width, every linear stratum its own (and the other part's)
    assert np.histogram(x, bins=near)[0].min() >= 1
    assert np.histogram(x, bins=np.linspace(w, top, n_far + 1))[0].min() >= 1
    # not on the search's fixed fine grid top (1 + record_fine)^-k (a width there would repeat a run)
    k = np.log(top / x) / math.log1p(s.record_fine)
    assert np.min(np.abs(k - np.round(k))) > 1e-6
    assert np.array_equal(x, check_widths(w, top, s, seed=5))
    assert not np.array_equal(x, check_widths(w, top, s, seed=6))
    # span: at most check_span times the width
    assert check_widths(1.0, 100.0, s, seed=1)[-1] <= s.check_span
    # nothing to check where the search width is the no-uplift width; 0 runs switch it off
    assert check_widths(1.0, 1.0, s).size == 0
    assert check_widths(1.0, 2.0, s.replace(check_runs=0)).size == 0
    # later stages: two widths in every bin, ratio 0.5 (no spread) except three bins: spread
    # 0.3 (0.2 and 0.8), spread 0.15 (0.35 and 0.65), and one failing width (weight 1 whatever
    # its spread); weights q**power, q the spread over the largest: 1, 0.5**power, 1
    k = s.check_bins
    edges = np.linspace(w, top, k + 1)
    widths = np.repeat(edges[:-1], 2) + np.tile([1 / 3, 2 / 3], k) * (edges[1] - edges[0])
    ratio, failed = np.full(2 * k, 0.5), np.zeros(2 * k, dtype=bool)
    j1, j2, j3 = int(0.6 * k), int(0.75 * k), int(0.9 * k)
    ratio[[2 * j1, 2 * j1 + 1]] = 0.2, 0.8
    ratio[[2 * j2, 2 * j2 + 1]] = 0.35, 0.65
    ratio[2 * j3], failed[2 * j3] = 1.7, True          # a failure's ratio is capped at 1
    n = 200
    y = follow_widths(w, top, widths, ratio, failed, n, s, seed=5)
    assert y.size == n and y[0] > w and y[-1] <= top
    per_bin = np.histogram(y, bins=edges)[0]
    total = 2.0 + 0.5 ** s.check_power
    for j, q in ((j1, 1.0), (j2, 0.5), (j3, 1.0)):
        assert abs(per_bin[j] - n * q ** s.check_power / total) <= 1.0   # largest remainders
    assert per_bin.sum() == per_bin[[j1, j2, j3]].sum()                 # nothing elsewhere
    assert np.array_equal(y, follow_widths(w, top, widths, ratio, failed, n, s, seed=5))
    assert not np.array_equal(y, follow_widths(w, top, widths, ratio, failed, n, s, seed=5, stage=2))
    # no bin varies and none failed: uniform over the bins
    even = np.histogram(follow_widths(w, top, widths, np.full(2 * k, 0.5), np.zeros(2 * k, bool),
                                      2 * k, s, seed=5), bins=edges)[0]
    assert np.all(even == 2)
    with pytest.raises(ValueError):
        SearchSettings(check_near=1.5)
    with pytest.raises(ValueError):
        SearchSettings(check_span=1.0)


@pytest.mark.slow
def test_check_against_dense_scans_synthetic():
    """A synthetic chaotic record: the check changes nothing else, is repeatable, reports only
    widths that overturn, and its share just above the search width agrees with a dense
    independent scan of the same stretch."""
    height = 7.5
    rec = _chaotic_record()
    res = rocking.required_width(height, rec, rule="exact")
    off = rocking.required_width(height, rec, rule="exact", settings=SearchSettings(check_runs=0))
    # the search is that of the search without the check; the design width lies above it and
    # above every failing width found (here the check finds slivers up to ~3 % above the search's)
    w = res.search_width
    assert w == off.search_width and res.runs == off.runs and res.transitions == off.transitions
    assert off.failing_share is None and off.widest_failing_width is None and off.check_runs == 0
    assert res.width > res.widest_failing_width > w
    assert not res.check_failed[res.check_widths > res.width].any()
    again = rocking.required_width(height, rec, rule="exact")
    assert np.array_equal(again.check_widths, res.check_widths) and again.width == res.width
    assert again.failing_share == res.failing_share
    top = height * rec.pga / G
    # the binned check's runs: its first stage, and at most what its bins allow
    assert res.check_runs == res.check_widths.size
    hi = binned.span_top(w, top, DEFAULT_SETTINGS)
    first = binned.first_widths(w, hi, DEFAULT_SETTINGS, _record_seed(rec, height, "overturn", None, 0.0))
    assert first.size < res.check_runs <= binned.most_runs(w, hi, DEFAULT_SETTINGS)
    assert res.check_top == pytest.approx(hi, rel=1e-15)
    assert res.failing_share == pytest.approx(res.check_failed.mean(), abs=0)
    # the widest failing width overturns in the reference model too (an independent integrator)
    ref = rocking.simulate(Block.from_dimensions(height, res.widest_failing_width), rec,
                           model="reference", history=False)
    assert ref.overturned
    # the first stage's log-spaced widths in d = B/w - 1 in [1e-4, 1e-2] (the
    # later stages place theirs by what it found, so only the first stage is an unbiased sample)
    # against 1500 log-spaced widths of the same stretch (an independent deterministic grid): the
    # check's count of failures there is binomial with the grid's share p; 4 standard deviations
    # plus 2 for the grid's own sampling error (a 1500-point estimate of p) bound it (a chance of
    # ~1e-4 to fail by luck)
    assert np.isin(first, res.check_widths).all()
    d = res.check_widths / w - 1.0
    sel = (d >= 1e-4) & (d <= 1e-2) & np.isin(res.check_widths, first)
    m, k = int(sel.sum()), int(res.check_failed[sel].sum())
    grid = w * (1.0 + np.geomspace(1e-4, 1e-2, 1500))
    p = _verdicts(height, rec, grid).mean()
    assert m > 25 and 0.0 < p < 1.0
    sigma = math.sqrt(m * p * (1 - p)) + math.sqrt(m * m * p * (1 - p) / grid.size)
    assert abs(k - m * p) <= 4.0 * sigma + 2.0, (k, m, p)


@pytest.mark.slow
def test_check_against_dense_scan_real_record():
    """Landers, Lucerne 345 (real, 7.5 m): an independent linear scan of 4000 widths of (w, 2w]
    finds failing widths more than 1 % above the search width; the check reports a widest
    failing width at least that far up (not None), which overturns in the reference model."""
    height = 7.5
    rec = pulses.read_record(shared_record("RSN879_LANDERS_LCN345.AT2"))
    res = rocking.required_width(height, rec, rule="exact")
    w = res.search_width
    assert w == pytest.approx(0.593261, rel=1e-5)      # the search's first transition
    x = np.linspace(w, min(2.0 * w, height * rec.pga / G), 4001)[1:]
    f = _verdicts(height, rec, x)
    assert f.any() and x[f].max() > 1.01 * w
    assert res.widest_failing_width is not None and res.widest_failing_width >= 1.01 * w
    assert res.width > res.widest_failing_width          # the design width lies above it
    assert 0.0 < res.failing_share < 0.2
    ref = rocking.simulate(Block.from_dimensions(height, res.widest_failing_width), rec,
                           model="reference", history=False)
    assert ref.overturned


@pytest.mark.slow
def test_pipeline_reports_the_check(tmp_path):
    """`pipeline run`: the check's columns in the record's report equal `required_width`'s, the
    suite's checked share follows from them, and the barcode figure is written where the check
    found failing widths (the synthetic record above: it does)."""
    import csv

    from pipeline.cli import main

    rec = _chaotic_record()
    path = tmp_path / "chaotic.sac"
    pulses.write_sac(pulses.Record(rec.acc, rec.dt, name="chaotic"), path)
    out = tmp_path / "out"
    # a column at the search's width (rounded up to 1 mm): above the search's first transition,
    # yet the check found wider failing widths (0.878 m, failing widths up to ~0.91 m), so it is
    # below the design width: not design-adequate
    ver = rocking.required_width(7.5, pulses.read_record(path), rule="exact")
    width = math.ceil(ver.search_width * 1000) / 1000
    assert ver.search_width <= width < ver.widest_failing_width < ver.width
    # --limit none: the check of the overturning design, the verge, which these columns describe
    assert main(["run", str(path), "--block", f"7.5x{width}", "--out", str(out), "-q", "--limit", "none"]) == 0
    row = next(csv.DictReader(open(out / "chaotic.csv")))
    assert float(row["design_width_m"]) == pytest.approx(ver.width, rel=1e-5)  # 6 digits
    assert float(row["search_width_m"]) == pytest.approx(ver.search_width, rel=1e-5)
    assert float(row["failing_share"]) == pytest.approx(ver.failing_share, rel=1e-5)
    assert float(row["widest_failing_width_m"]) == pytest.approx(ver.widest_failing_width, rel=1e-5)
    assert int(float(row["check_runs"])) == ver.check_runs
    assert row["design_adequate"] == "False"
    suite = next(csv.DictReader(open(out / "suite.csv")))
    assert suite["share_column_adequate"] == "0" and suite["share_column_checked"] == "0"
    assert (out / "plots" / "widths" / "chaotic.png").stat().st_size > 10_000
    text = (out / "columns.md").read_text()
    assert "`widest_failing_width_m`" in text and "docs/slivers.md" in text
    assert "plots/widths/<record>.png" in text


def test_check_uses_the_search_widths():
    """The later stages measure the spread over the search's widths above the search width too
    (at no cost): a model response with no spread anywhere but in the search's widths of one bin
    sends the later stages there; without them the stages spread evenly."""
    from rocking.widths import _add_check

    s = DEFAULT_SETTINGS.replace(check_runs=500, check_zoom=0.0)   # the later stages alone
    w, top = 1.0, 3.0                                 # the span is (1, check_span]

    def flat(x):                                      # every width survives, ratio 0.5
        return np.zeros(np.size(x), dtype=bool), np.full(np.size(x), 0.5)

    k = s.check_bins
    edges = np.linspace(w, s.check_span * w, k + 1)
    j = int(0.4 * k)
    seen_x = np.concatenate([[0.5, 2.5], edges[j] + np.array([0.2, 0.4, 0.6, 0.8]) * (edges[1] - edges[0])])
    seen = (seen_x, np.zeros(seen_x.size, dtype=bool), np.array([0.9, 0.1, 0.2, 0.8, 0.3, 0.7]))
    n_later = s.check_runs - (s.check_runs - round(s.check_follow * s.check_runs))
    first = check_widths(w, top, s, seed=3)
    for known, expect in ((seen, n_later), (None, n_later / k)):
        res = rocking.RequiredWidth(w, 7.5, "exact", 0, "test")
        x, f, _ = _add_check(res, top, flat, s, 3, known)
        later = x[~np.isin(x, first)]
        assert later.size == n_later and x.size == s.check_runs
        in_bin = int(np.sum((later > edges[j]) & (later <= edges[j + 1])))
        # all later widths in that bin (the widths below w and above the span are left out);
        # without the search's widths, the even share of one bin (within one: largest remainders)
        assert abs(in_bin - expect) <= 1.0, (known is None, in_bin, expect)
    assert not f.any()


def test_zoom_widths_go_around_the_widths_nearest_to_failing():
    """The last stage: check_zoom_points jittered widths within check_zoom_width (relative) of
    each surviving width that rocked hardest, peaks closer than two zoom widths once, failed
    widths and widths outside the span left out; the same for the same seed."""
    from rocking.widths import zoom_widths

    s = DEFAULT_SETTINGS.replace(check_zoom_points=4, check_zoom_width=1e-3)
    w, top = 1.0, 3.0
    widths = np.array([0.9, 1.1, 1.1005, 1.2, 1.3, 1.4, 1.6])
    ratio = np.array([0.99, 0.9, 0.89, 0.3, 0.95, 0.97, 0.99])
    failed = np.array([False, False, False, False, False, True, False])
    y = zoom_widths(w, top, widths, ratio, failed, 8, s, seed=2)
    # 0.9 is below w, 1.6 above the span (1.5), 1.4 failed: the peaks are 1.3 and 1.1 (1.1005 is
    # within two zoom widths of 1.1), four widths around each
    assert y.size == 8 and np.all(np.diff(y) > 0)
    near = lambda b: np.sum(np.abs(y / b - 1.0) <= s.check_zoom_width)
    assert near(1.3) == 4 and near(1.1) == 4
    assert np.array_equal(y, zoom_widths(w, top, widths, ratio, failed, 8, s, seed=2))
    assert not np.array_equal(y, zoom_widths(w, top, widths, ratio, failed, 8, s, seed=3))
    assert zoom_widths(w, top, widths, ratio, failed, 0, s).size == 0


def _printed_width_is_safe(height, record, limit=None, overturning=None):
    """The design width has the reports' 6 significant digits, survives as printed, and lies above
    every failing width found (the widest one included, to the printed digits)."""
    w = rocking.required_width(height, record, rule="exact", limit=limit, overturning=overturning)
    printed = float(f"{w.width:.6g}")
    assert printed == w.width
    if w.widest_failing_width is not None:
        assert float(f"{w.widest_failing_width:.6g}") <= printed and w.widest_failing_width < printed
    res = rocking.simulate(Block.from_dimensions(height, printed), record)
    assert not res.overturned
    if limit is not None:
        assert res.max_rotation_ratio <= limit
    return w


def test_the_printed_design_width_is_a_width_that_survived():
    """Raised to 6 significant digits (SearchSettings.design_digits) and run there: a width just
    1e-6 above a failing one, printed with 6 digits, could otherwise print below it."""
    w = _printed_width_is_safe(7.5, _chaotic_record())
    assert w.width >= w.search_width


@pytest.mark.slow
def test_the_printed_level_width_keeps_the_level_on_a_real_record():
    """Kern Taft 021 at 6 m, level 0.5 given the overturning design, and with it computed where it
    can change the level's (``overturning=True``, pipeline run --limit's path): bisected to 1e-6
    alone, the design width lay 0.36 um above a failing width (0.5557753720 against 0.5557750122
    m), and its 6-digit print, 0.555775 m, reached max theta/alpha 0.715; now 0.555776 m (0.30)."""
    record = pulses.read_record(shared_record("RSN15_KERN_TAF021.AT2"))
    over = _printed_width_is_safe(6.0, record)
    for overturning in (over, True):
        w = _printed_width_is_safe(6.0, record, limit=0.5, overturning=overturning)
        assert w.width >= over.width
