"""The friction a rocking response needs (rocking.friction, docs/theory.md "Friction").

References, each independent of the module's formulas:
- Shenton's (1996) closed form at uplift, written out here, and the examples of its statement
  (tan(alpha) = 0.25 at 0.4 g: 0.2865; the 7.5 x 1.8 m column at 0.5 g: 0.3022; tan(alpha) = 0.5
  at 0.8 g: 0.5688);
- the impulse ratio at impact from the momentum balance of the body's centre of mass, its
  velocity before and after taken from the positions of the two pivots;
- over a whole record: the base forces from finite differences of the centre of mass's position,
  computed from the response to the same record resampled 20 and 80 times finer (linear
  interpolation: the same forcing), extrapolated in the step (the second difference across a
  sample's kink of the forcing errs by O(h)).
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import pulses
import rocking
from pulses import G
from rocking.friction import friction_demand, impulse_ratio, uplift_demand
from rocking.sliding import sliding_width

from .conftest import shared_record


def _shenton(tan_alpha, a):
    alpha = math.atan(tan_alpha)
    q = 0.75 * (a * math.cos(alpha) - math.sin(alpha))
    return (a - q * math.cos(alpha)) / (1.0 + q * math.sin(alpha))


@pytest.mark.parametrize("tan_alpha, a, spec", [(0.25, 0.4, 0.2865), (0.24, 0.5, 0.3022),
                                                (0.5, 0.8, 0.5688), (0.1, 0.3, None),
                                                (0.7, 0.71, None), (0.05, 1.5, None)])
def test_uplift_equals_shentons_closed_form(tan_alpha, a, spec):
    block = rocking.Block.from_dimensions(7.5, 7.5 * tan_alpha)
    pulse = pulses.Rectangular(a * G, 1.0)
    need = friction_demand(rocking.simulate(block, pulse), pulse)
    # the floor: 1e-6; the same algebra in another order agrees to rounding (1e-14)
    assert need.uplift_demand == pytest.approx(_shenton(tan_alpha, a), rel=1e-12, abs=1e-14)
    assert need.t_uplift == 0.0
    assert uplift_demand(block, a) == pytest.approx(_shenton(tan_alpha, a), rel=1e-12)
    if spec is not None:
        assert round(need.uplift_demand, 4) == spec
    assert uplift_demand(block, 0.5 * tan_alpha) == pytest.approx(0.5 * tan_alpha)  # at rest


def _impulse_ratio_from_momentum(alpha, eta, omega=-0.3):
    """|P_x| / |P_z| from the centre of mass's velocity about the old pivot (right corner, theta
    > 0 falling back) and the new one (left corner), the pivots' positions written out."""
    R = 2.0
    b, h = R * math.sin(alpha), R * math.cos(alpha)
    # centre of mass at theta = 0 relative to each pivot; velocity = omega x r (clockwise theta)
    r_old, r_new = np.array([-b, h]), np.array([b, h])
    v_before = omega * np.array([r_old[1], -r_old[0]])
    v_after = eta * omega * np.array([r_new[1], -r_new[0]])
    dp = v_after - v_before
    return abs(dp[0]) / abs(dp[1])


@pytest.mark.parametrize("body", ["rect", "cylinder"])
def test_impulse_ratio_at_impact(body):
    block = rocking.Block.from_dimensions(7.5, 1.8, body=body)
    ref = _impulse_ratio_from_momentum(block.alpha, block.eta)
    assert impulse_ratio(block.eta, block.alpha) == pytest.approx(ref, rel=1e-12)   # floor 1e-9
    rec = pulses.read_record(str(_data("synth_sine_055g_0.9s.sac")))
    need = friction_demand(rocking.simulate(block, rec), rec)
    assert need.impacts.size > 0 and need.impulse_ratio == pytest.approx(ref, rel=1e-12)
    if body == "rect":
        # 0.1775, as the statement of the issue gives it, is the ratio at eta rounded to 0.9183
        # (with Eq. 5 exactly: 0.177445, docs/theory.md "Friction")
        assert round(impulse_ratio(round(block.eta, 4), block.alpha), 4) == 0.1775
        assert need.impulse_ratio == pytest.approx(0.1774448, abs=1e-7)


def _data(name):
    from importlib.resources import files

    return files("pipeline.data") / name


def _fd_demand(block, rec, n, vertical=None, gamma=0.0):
    """Demand from finite differences of the centre of mass's position, on ``rec`` resampled
    ``n`` times finer: ``(t, demand)`` where three consecutive instants rock on one side and no
    impact lies within 1.5 steps (a second difference across an impact is its impulse)."""
    t = rec.time
    tf = np.linspace(t[0], t[-1], (t.size - 1) * n + 1)
    fine = pulses.Record(np.interp(tf, t, rec.acc), rec.dt / n)
    up = None if vertical is None else pulses.Record(np.interp(tf, t, vertical.acc), rec.dt / n)
    res = rocking.simulate(block, fine, vertical=up)
    th = res.theta
    s = np.sign(th)
    R = block.R * ((1 + 2 * gamma) / (1 + 3 * gamma))        # one column's size in a frame
    phi = block.alpha - np.abs(th)
    x, z = -s * R * np.sin(phi), R * np.cos(phi)
    hh = fine.dt
    xdd = (x[2:] - 2 * x[1:-1] + x[:-2]) / hh**2
    zdd = (z[2:] - 2 * z[1:-1] + z[:-2]) / hh**2
    tt = res.t[1:-1]
    ug = fine.acc[1:tt.size + 1]
    gv = G + (0.0 if up is None else up.acc[1:tt.size + 1])
    # columns (mass 1 each) and the beam (gamma) moving with the column tops: twice x and z
    fx = (1 + gamma) * ug + xdd + 2 * gamma * xdd
    fz = (1 + gamma) * gv + zdd + 2 * gamma * zdd
    ok = (s[:-2] == s[1:-1]) & (s[1:-1] == s[2:])
    for ti in res.impacts:
        ok &= np.abs(tt - ti) > 1.5 * hh
    return tt[ok], np.abs(fx[ok]) / fz[ok]


def _extrapolated_max(block, rec, **kw):
    m20 = _fd_demand(block, rec, 20, **kw)[1].max()
    m80 = _fd_demand(block, rec, 80, **kw)[1].max()
    return (4.0 * m80 - m20) / 3.0, m80


CASES = [("Rinaldi228.AT2", 1.8, "rect"), ("RSN77_SFERN_PUL164.AT2", 1.8, "rect"),
         ("RSN77_SFERN_PUL164.AT2", 2.5, "rect"), ("RSN77_SFERN_PUL164.AT2", 1.8, "cylinder")]


@pytest.mark.parametrize("name, width, body", CASES)
def test_whole_record_against_finite_differences(name, width, body):
    rec = pulses.read_record(str(shared_record(name)))
    block = rocking.Block.from_dimensions(7.5, width, body=body)
    need = friction_demand(rocking.simulate(block, rec), rec)
    ref, m80 = _extrapolated_max(block, rec)
    # floor 1e-3 relative.  Measured 6e-5 (Rinaldi: its peak is just after an impact, which
    # finite differences cannot reach), 5e-7 and 6e-4 (RSN77 2.5 m: the finer grids' peaks sit
    # at neighbouring samples, which the extrapolation mixes)
    assert need.max_demand == pytest.approx(ref, rel=1e-3)
    assert need.max_demand == pytest.approx(m80, rel=3e-3)   # the 80x grid alone: O(h) off
    # the normal force stays well above zero on these records (horizontal motion only)
    assert 0.5 < need.min_normal < 1.0


def test_synthetic_record_cylinder_and_frame_against_finite_differences():
    rec = pulses.read_record(str(_data("synth_sine_055g_0.9s.sac")))
    for block, gamma in ((rocking.Block.from_dimensions(7.5, 1.8, body="cylinder"), 0.0),
                         (rocking.Block.from_dimensions(7.5, 1.8, cap_mass_ratio=0.5), 0.5),
                         (rocking.Block.from_dimensions(20.0, 5.0), 0.0)):
        res = rocking.simulate(block, rec)
        assert res.n_impacts > 0
        need = friction_demand(res, rec)
        ref, _ = _extrapolated_max(block, rec, gamma=gamma)
        assert need.max_demand == pytest.approx(ref, rel=1e-3)


def test_demand_with_a_vertical_record():
    rec = pulses.read_record(str(_data("synth_sine_055g_0.9s.sac")))
    t = rec.time
    up = pulses.Record(0.4 * G * np.sin(2 * math.pi * 1.7 * t), rec.dt)
    block = rocking.Block.from_dimensions(7.5, 2.5)
    need = friction_demand(rocking.simulate(block, rec, vertical=up), rec, vertical=up)
    ref, _ = _extrapolated_max(block, rec, vertical=up)
    assert need.max_demand == pytest.approx(ref, rel=1e-3)
    # at rest the demand is |ug''| / (g + uv''): a column too wide to uplift
    wide = rocking.Block.from_dimensions(7.5, 7.0)
    rest = friction_demand(rocking.simulate(wide, rec, vertical=up), rec, vertical=up)
    assert rest.max_demand == pytest.approx(np.max(np.abs(rec.acc) / (G + up.acc)), rel=1e-12)


def test_at_rest_the_demand_is_the_ground_acceleration():
    rec = pulses.read_record(str(_data("synth_sine_055g_0.9s.sac")))
    wide = rocking.Block.from_dimensions(7.5, 7.0)          # tan(alpha) 0.93 > PGA/g
    res = rocking.simulate(wide, rec)
    assert res.model == "rest"
    need = friction_demand(res, rec)
    assert need.max_demand == pytest.approx(rec.pga / G, rel=1e-12)
    assert need.min_normal == 1.0 and math.isnan(need.uplift_demand)


def test_verdict_and_the_narrowest_width_that_holds():
    rec = pulses.read_record(str(_data("synth_sine_055g_0.9s.sac")))
    block = rocking.Block.from_dimensions(7.5, 2.0)
    need = friction_demand(rocking.simulate(block, rec), rec)
    low = need.judge(0.9 * need.max_demand)
    assert low.slides and low.t_slide <= need.t_max and "slides at" in low.describe()
    assert not need.judge(1.01 * need.max_demand).slides
    with pytest.raises(ValueError, match="mu"):
        need.judge(-1)
    # below the demand and below PGA/g: every wider column slides too (at rest, if not rocking)
    mu = 0.95 * need.max_demand
    assert mu < rec.pga / G
    none = sliding_width(7.5, rec, 2.0, mu)
    assert none.given_slides and none.width is None and "no width" in none.reason
    for w in (2.2, 3.0, 5.0):          # checked independently at a few wider widths
        wider = rocking.Block.from_dimensions(7.5, w)
        assert friction_demand(rocking.simulate(wider, rec), rec).judge(mu).slides
    held = sliding_width(7.5, rec, 2.0, 1.01 * need.max_demand)
    assert not held.given_slides and held.width == 2.0 and held.runs == 1


def test_the_narrowest_width_that_holds_is_refined():
    # a soft restitution (eta 0.5): every impact asks (1 - eta)/((1 + eta) tan(alpha)) > 0.7 of
    # the base, so every column that rocks slides; only those too wide to uplift hold (mu > PGA/g)
    rec = pulses.read_record(str(_data("synth_sine_055g_0.9s.sac")))
    mu = 0.7
    sw = sliding_width(7.5, rec, 2.0, mu, eta=0.5)
    top = 7.5 * rec.pga / G
    assert sw.given_slides and sw.width is not None and 2.0 < sw.width <= top * (1 + 1e-8)
    assert sw.demand <= mu
    at = rocking.Block.from_dimensions(7.5, sw.width, 0.5)
    assert not friction_demand(rocking.simulate(at, rec), rec).judge(mu).slides
    below = rocking.Block.from_dimensions(7.5, sw.width * (1 - 2e-3), 0.5)   # refined to 1e-3
    check = friction_demand(rocking.simulate(below, rec), rec).judge(mu)
    assert check.slides and check.how == "at an impact"
