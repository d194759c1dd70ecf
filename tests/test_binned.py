"""The binned check above the search width (rocking/binned.py) is separable in a threshold: run
above ``T`` (``SearchSettings.check_above``), it runs exactly the full check's widths above ``T``
with the same verdicts, and its design width is the full check's wherever that lies above ``T``
(what pipeline/batch/passes.py relies on for a pair's design width)."""
from __future__ import annotations

import numpy as np
import pytest

import pulses
import rocking
from rocking import binned
from rocking.search import DEFAULT_SETTINGS
from rocking.widths import digits_up

from .conftest import shared_record

BINS = DEFAULT_SETTINGS.replace(check_layout="bins")


def _above(full, part, T):
    """The part's widths and verdicts above ``T`` are the full check's, exactly; its design width
    is the full one's where that lies above ``T``, and never more."""
    sel = full.check_widths > T
    x = part.check_widths[part.check_widths > T]
    np.testing.assert_array_equal(x, full.check_widths[sel])          # bit for bit: same draws
    np.testing.assert_array_equal(part.check_failed[part.check_widths > T], full.check_failed[sel])
    assert part.search_width == full.search_width
    if full.width > T:
        assert (part.width, part.widest_failing_width) == (full.width, full.widest_failing_width)
    else:
        assert part.width <= full.width
    # consistent rows: nothing reported failing above the reported width
    assert part.widest_failing_width is None or part.widest_failing_width < part.width
    assert part.check_runs == part.check_widths.size <= full.check_runs
    if T > part.search_width * (1.0 + 2.0 * BINS.check_bin_width):   # a bin or more left out
        assert part.check_runs < full.check_runs


def _thresholds(full):
    """Thresholds across the span: above the search width, at and around the widest failing
    width and the design width, near the top."""
    w, W = full.search_width, full.width
    ts = [w * 1.003, w * 1.05, w * 1.2, W * (1 - 1e-6), W * (1 + 1e-6), full.check_top * 0.99]
    if full.widest_failing_width:
        f = full.widest_failing_width
        ts += [f * (1 - 1e-7), f * (1 + 1e-7)]
    return ts


@pytest.mark.slow
@pytest.mark.parametrize("name,height", [("RSN879_LANDERS_LCN345.AT2", 7.5), ("RSN879_LANDERS_LCN345.AT2", 6.0)])
def test_the_check_above_a_threshold_is_the_full_check_above_it_on_a_real_record(name, height):
    record = pulses.read_record(str(shared_record(name)))
    full = rocking.required_width(height, record, rule="exact", settings=BINS)
    # Landers Lucerne 345: failing widths above the search width at both heights (docs/slivers.md)
    assert full.widest_failing_width is not None and full.width > full.search_width
    for T in _thresholds(full):
        part = rocking.required_width(height, record, rule="exact", settings=BINS.replace(check_above=T))
        _above(full, part, T)


def test_the_check_above_a_threshold_is_the_full_check_above_it():
    import importlib.resources

    record = pulses.read_record(str(importlib.resources.files("pipeline.data") / "synth_sine_055g_0.9s.sac"))
    full = rocking.required_width(7.5, record, rule="exact", settings=BINS)
    for T in _thresholds(full):
        part = rocking.required_width(7.5, record, rule="exact", settings=BINS.replace(check_above=T))
        _above(full, part, T)
    # above the span's top and the search's next width: nothing to run
    none = rocking.required_width(7.5, record, rule="exact",
                                  settings=BINS.replace(check_above=full.check_top * 1.2))
    assert (none.check_runs, none.search_width) == (0, full.search_width)
    assert none.width == digits_up(full.search_width, BINS.design_digits)   # run there: survived


def test_a_bins_widths_depend_on_its_own_runs_only():
    # two made-up spans of runs that differ outside bin 3 only: bin 3 gets the same widths
    s = BINS
    e = binned.edges(1.0, 1.5, s)
    x = np.linspace(1.0005, 1.4995, 400)
    r = 0.5 + 0.3 * np.sin(x * 3e3)
    r2 = np.where(binned.bin_of(e, x) == 3, r, 0.2)
    f = np.zeros(x.size, dtype=bool)
    on = np.zeros(e.size - 1, dtype=bool)
    on[3] = True
    for stage in (1, 2):
        a = binned.follow_widths(e, on, x, r, f, s, 7, stage)
        b = binned.follow_widths(e, on, x, r2, f, s, 7, stage)
        np.testing.assert_array_equal(a, b)
        assert a.size and np.all((a > e[3]) & (a <= e[4]))
    np.testing.assert_array_equal(binned.zoom_widths(e, on, x, r, f, s, 7),
                                  binned.zoom_widths(e, on, x, r2, f, s, 7))
