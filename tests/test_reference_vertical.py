"""The reference integrator with vertical ground motion (rocking.reference_vertical) against the
horizontal-only reference (rocking.reference), an independent implementation: zero vertical, the
exact similarity of a constant vertical, free flight, and the shared PEER records."""
from __future__ import annotations

import math

import numpy as np
import pytest

import pulses
import rocking
from pulses import G
from rocking.reference import simulate_reference
from rocking.reference_vertical import check_axes, simulate_vertical_reference

from .vertical_cases import BLOCKS, DOWNLOAD, record

#: both integrators run DOP853 at rtol 1e-12 and locate their events to ~1e-15 s: their peak
#: rotations agree far better than 1e-6 of alpha, the floor asked of the solvers
TOL_ALPHA = 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("block", BLOCKS, ids=["overturns", "rocks", "stands-tall"])
def test_zero_vertical_equals_the_horizontal_reference(block):
    rec = record()
    ref = simulate_reference(block, rec)
    for vertical in (None, pulses.Record(np.zeros(rec.npts), rec.dt)):
        res = simulate_vertical_reference(block, rec, vertical)
        assert res.overturned == ref.overturned
        assert abs(res.max_rotation - ref.max_rotation) <= TOL_ALPHA * block.alpha
        assert not res.lifts_off and math.isnan(res.t_lift_off)
        if not ref.overturned:
            # impacts during the record are the same; the vertical reference also integrates the
            # free rocking after it, to its first peak
            n = int(np.sum(ref.impacts <= rec.support[1]))
            np.testing.assert_allclose(res.impacts[:n], ref.impacts[:n], atol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("c_g", [0.3, -0.3, 0.6, -0.5])
@pytest.mark.parametrize("block", BLOCKS[:2], ids=["slender", "stocky"])
def test_constant_vertical_is_the_similar_block(block, c_g):
    """docs/theory.md section 10: a constant uv'' = c is the block with p sqrt(1 + c/g) under
    ag g / (g + c): same alpha, eta and response."""
    rec = record(seed=1, ap_g=0.3)
    c = c_g * G
    res = simulate_vertical_reference(block, rec, pulses.Record(np.full(rec.npts, c), rec.dt))
    similar = rocking.Block(block.p * math.sqrt(1 + c / G), block.alpha, block.eta)
    ref = simulate_reference(similar, rec.scaled(G / (G + c)))
    assert res.overturned == ref.overturned
    assert res.uplifted == ref.uplifted
    assert abs(res.max_rotation - ref.max_rotation) <= TOL_ALPHA * block.alpha
    assert res.min_effective_gravity == pytest.approx(1 + c_g)


def test_uplift_threshold_uses_the_effective_gravity():
    """A constant ag just below g tan(alpha) does not uplift the block; with a downward vertical
    of 0.2 g it does: |ag| > (g + av) tan(alpha)."""
    block = rocking.Block.from_dimensions(3.0, 0.6)
    dt, n = 0.01, 200
    ag = pulses.Record(np.full(n, 0.95 * G * block.tan_alpha), dt)
    assert not simulate_vertical_reference(block, ag).uplifted
    down = pulses.Record(np.full(n, -0.2 * G), dt)
    res = simulate_vertical_reference(block, ag, down)
    assert res.uplifted and res.max_rotation > 0


def test_free_flight_is_detected_not_integrated():
    block = rocking.Block.from_dimensions(3.0, 0.9)
    rec = record()
    t = rec.time
    # the ground falls at 1.5 g from t = 2.0 s on (reached by linear interpolation from 2.0 to 2.01 s)
    v = np.where(t > 2.005, -1.5 * G, 0.0)
    res = simulate_vertical_reference(block, rec, pulses.Record(v, rec.dt))
    assert res.lifts_off and res.verdict_by == "lifts off"
    # 1 + v/g = 0 where the ramp from 0 to -1.5 reaches -1: two thirds into the step
    assert res.t_lift_off == pytest.approx(2.0 + 0.01 * 2 / 3, abs=1e-12)
    assert res.t[-1] <= res.t_lift_off + 1e-12  # nothing integrated past it
    # at rest too: a block that never uplifts (no horizontal motion) still leaves the ground
    quiet = pulses.Record(np.zeros(rec.npts), rec.dt)
    res = simulate_vertical_reference(block, quiet, pulses.Record(v, rec.dt))
    assert res.lifts_off and not res.uplifted


def test_axes_must_agree():
    rec = record()
    with pytest.raises(ValueError, match="time step"):
        check_axes(rec, pulses.Record(np.zeros(rec.npts), 0.02))
    with pytest.raises(ValueError, match="fewer"):
        check_axes(rec, pulses.Record(np.zeros(rec.npts - 1), rec.dt))
    assert check_axes(rec, pulses.Record(np.zeros(rec.npts + 5), rec.dt)).npts == rec.npts


@pytest.mark.parametrize("rsn, h1, h2, v, polarity", [
    (77, "RSN77_SFERN_PUL164.AT2", "RSN77_SFERN_PUL254.AT2", "RSN77_SFERN_PULDWN.AT2", -1),
    (15, "RSN15_KERN_TAF021.AT2", "RSN15_KERN_TAF111.AT2", "RSN15_KERN_TAF-UP.AT2", 1),
])
@pytest.mark.slow
def test_real_three_component_records(rsn, h1, h2, v, polarity):
    """On the shared PEER records (a DWN and an UP vertical): the vertical read with its polarity;
    the zero-vertical run equals the horizontal reference; the vertical's effect is measured."""
    if not DOWNLOAD.is_dir():
        pytest.skip(f"the shared PEER download is not available: {DOWNLOAD} is absent")
    d = pulses.peer.PeerDownload(DOWNLOAD)
    first, second, up = pulses.check_triplet(d.read_component(h1), d.read_component(h2), d.read_component(v))
    raw = d.read_component(v)
    n = up.npts
    assert first.npts == second.npts == n == min(first.npts, raw.npts)  # cut to the shortest
    np.testing.assert_array_equal(up.acc, polarity * raw.acc[:n])
    raw = pulses.Record(raw.acc[:n], raw.dt)
    hor = first if rsn == 77 else second
    block = rocking.Block.from_dimensions(3.0, 0.45)  # slender: it rocks under both records
    window = 8.0  # the strong motion; the reference is slow by design
    ref = simulate_reference(block, hor, duration=window)
    zero = simulate_vertical_reference(block, hor, pulses.Record(np.zeros(hor.npts), hor.dt), duration=window)
    assert zero.uplifted and ref.uplifted
    assert zero.overturned == ref.overturned
    assert abs(zero.max_rotation - ref.max_rotation) <= TOL_ALPHA * block.alpha
    with_v = simulate_vertical_reference(block, hor, up, duration=window)
    assert not with_v.lifts_off  # the verticals stay well below 1 g here
    assert with_v.min_effective_gravity > 0.0
    flipped = simulate_vertical_reference(block, hor, raw if polarity < 0 else up.scaled(-1), duration=window)
    # the polarity matters: the wrong sign gives another response
    assert (with_v.max_rotation, with_v.t_overturn) != (flipped.max_rotation, flipped.t_overturn)


@pytest.mark.slow
def test_simulate_with_a_vertical_says_which_model_answered():
    block = rocking.Block.from_dimensions(3.0, 0.9)
    rec = record()
    up = pulses.Record(0.2 * G * np.sin(3 * rec.time), rec.dt)
    res = rocking.simulate(block, rec, vertical=up, model="reference")
    ref = simulate_vertical_reference(block, rec, up)
    assert res.model == "reference-vertical" and res.max_rotation == ref.max_rotation
    # by default the compiled engine answers (tests/test_vertical_core.py measures it)
    assert rocking.simulate(block, rec, vertical=up).model == "fast-vertical"
    with pytest.raises(rocking.errors.RockingInputError):
        rocking.simulate(block, pulses.make_pulse("sine", 3.0, 1.0), vertical=up)
