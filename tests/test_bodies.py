"""Bodies other than the rectangular block (rocking.bodies, docs/theory.md "Bodies").

References: the moment of inertia of a solid cylinder about an edge of its base, written out here
from the parallel-axis theorem (not the module's ``4/3 - sin^2(alpha)/12``; docs/theory.md, "Bodies"), with
``p^2 = m g R / I_o`` and Housner's ``eta = 1 - 2 m R^2 sin^2(alpha) / I_o``; the rectangular
block itself for a body given its own ``I_o``, ``R`` and ``alpha``.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import pulses
import rocking
from pulses import G
from rocking.bodies import CYLINDER, RECTANGULAR, Body


def _cylinder(H, D, m=3.7):
    """``(I_o, R, alpha)`` of a solid cylinder rocking on an edge of its base in a plane."""
    radius = D / 2.0
    i_centre = m * (3.0 * radius**2 + H**2) / 12.0       # about a diameter through the centre
    R = math.hypot(H / 2.0, D / 2.0)
    return i_centre + m * R**2, R, math.atan2(D, H), m


@pytest.mark.parametrize("H, D", [(7.5, 1.8), (10.0, 2.2), (3.0, 2.5), (1.0, 0.1)])
def test_cylinder_p_and_eta(H, D):
    I_o, R, alpha, m = _cylinder(H, D)
    drum = rocking.Block.from_dimensions(H, D, body="cylinder")
    assert I_o == pytest.approx(m * (5 * D**2 / 16 + H**2 / 3), rel=1e-14)   # the theory's I_o
    assert drum.p == pytest.approx(math.sqrt(m * G * R / I_o), rel=1e-14)
    assert drum.eta == pytest.approx(1.0 - 2.0 * m * R**2 * math.sin(alpha) ** 2 / I_o, rel=1e-14)
    assert drum.alpha == math.atan2(D, H) and drum.R == pytest.approx(R, rel=1e-14)
    # the same body given by I_o, R and alpha
    given = rocking.Block.from_body(I_o, R, alpha, mass=m)
    assert given.p == pytest.approx(drum.p, rel=1e-14)
    assert given.eta == pytest.approx(drum.eta, rel=1e-14)
    # a cylinder is stiffer in rocking than the rectangle of the same section (I_o smaller)
    block = rocking.Block.from_dimensions(H, D)
    assert drum.p > block.p and drum.eta < block.eta


def test_a_body_given_the_rectangles_own_inertia_is_the_block_bit_for_bit():
    H, B, m = 7.5, 1.8, 2.4
    R, alpha = math.hypot(H / 2, B / 2), math.atan2(B, H)
    block = rocking.Block.from_dimensions(H, B)
    for I_o in (m * (H**2 + B**2) / 3.0, 4.0 / 3.0 * m * R**2, m * R * R * 4 / 3):
        given = rocking.Block.from_body(I_o, R, alpha, mass=m)
        assert (given.p, given.alpha, given.eta) == (block.p, block.alpha, block.eta)
        assert given.body is RECTANGULAR
    rec = pulses.read_record(str(_data("synth_sine_055g_0.9s.sac")))
    a, b = rocking.simulate(block, rec), rocking.simulate(given, rec)
    for name in ("t", "theta", "omega", "impacts"):
        assert np.array_equal(getattr(a, name), getattr(b, name))
    assert a.max_rotation == b.max_rotation and a.n_impacts == b.n_impacts


def _data(name):
    from importlib.resources import files

    return files("pipeline.data") / name


def test_the_rectangles_numbers_do_not_move():
    # the block's formulas, written here: the body= path leaves them exactly as they were
    for H, B in ((7.5, 1.8), (20.0, 3.3), (0.3, 0.07)):
        R = math.hypot(H / 2.0, B / 2.0)
        for body in (None, "rect", RECTANGULAR):
            blk = rocking.Block.from_dimensions(H, B, body=body)
            assert blk.p == math.sqrt(3.0 * G / (4.0 * R))
            assert blk.eta == max(0.0, 1.0 - 1.5 * math.sin(math.atan2(B, H)) ** 2)
            assert blk.R == 3.0 * G / (4.0 * blk.p**2)
        many = rocking.Blocks.from_dimensions(H, [B, 2 * B], body="rect")
        assert many.p[0] == rocking.Block.from_dimensions(H, B).p


def test_cylinder_design_uses_its_own_p_and_impact_rule():
    pulse = pulses.OneSine(0.5 * G, 1.0)
    w = rocking.required_width(7.5, pulse, rule="eq31", body="cylinder")
    drum = rocking.Block.from_dimensions(7.5, w.width, body="cylinder")
    # Eq. 31 holds at the fixed point with the cylinder's p
    assert w.tan_alpha == pytest.approx(rocking.eq31(pulse.ap, pulse.tp, drum.p), rel=1e-12)
    assert w.block.body is not RECTANGULAR and w.block.p == drum.p
    ex = rocking.required_width(7.5, pulse, rule="exact", body="cylinder")
    assert ex.body.kind == "cylinder"
    # at the design width the cylinder survives; a little narrower (below the refinement) fails
    at = rocking.Block.from_dimensions(7.5, ex.width, body="cylinder")
    assert not rocking.simulate(at, pulse).overturned
    under = rocking.Block.from_dimensions(7.5, ex.width * (1 - 3e-3), body="cylinder")
    assert rocking.simulate(under, pulse).overturned
    # the exact minimum slenderness at the cylinder's p uses its impact rule at each slenderness
    ms = rocking.min_slenderness(pulse, drum.p, body="cylinder")
    probe = rocking.Block.from_tan_alpha(drum.p, ms.tan_alpha * (1 + 1e-3), body="cylinder")
    assert probe.eta == pytest.approx(CYLINDER.eta_housner(probe.alpha), rel=1e-15)
    assert not rocking.simulate(probe, pulse).overturned


def test_frames_and_custom_bodies_are_refused_where_not_modelled():
    with pytest.raises(ValueError, match="rectangular columns only"):
        rocking.Block.from_dimensions(7.5, 1.8, cap_mass_ratio=0.3, body="cylinder")
    with pytest.raises(ValueError, match="rectangular columns only"):
        rocking.required_width(7.5, pulses.OneSine(3.0, 1.0), cap_mass_ratio=0.3, body="cyl")
    custom = Body("custom", 1.2)
    with pytest.raises(ValueError, match="no width"):
        rocking.required_width(7.5, pulses.OneSine(3.0, 1.0), body=custom)
    with pytest.raises(ValueError, match="at least 1"):
        Body("custom", 0.9)
    with pytest.raises(ValueError, match="below m R"):
        rocking.Block.from_body(0.5, 1.0, 0.2)
    with pytest.raises(ValueError, match="unknown shape"):
        Body.parse("hexagon")
    # the restitution as a factor of the body's own rule
    from rocking.restitution import Restitution

    drum = rocking.Block.from_dimensions(7.5, 1.8, Restitution(0.95), body="cylinder")
    assert drum.eta == pytest.approx(0.95 * CYLINDER.eta_housner(drum.alpha), rel=1e-15)
