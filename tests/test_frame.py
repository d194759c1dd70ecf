"""Rocking frames (docs/theory.md section 8): columns capped by a free rigid beam.

The theory's ``p_frame`` and ``eta_frame`` are checked against a direct two-body computation that does not
use their lumped forms: the columns and the beam are written out from their coordinates (corners
rotated about the pivots, the beam translated with the column tops), Lagrange's equation is formed
from the bodies' kinetic and potential energies by numerical differentiation, and the impact from
the impulse-momentum balance of every body (each column's angular momentum about its new pivot,
the beam's momentum), solved for the velocity after impact and the impulses together.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

import rocking
from pulses import G, make_pulse
from rocking import Block
from rocking.frame import eta_frame, equivalent_size, frame_p

H, B = 7.5, 1.8                       # column of docs/theory.md section 1 (Temple of Apollo)
#: complex step: d/dx f(x) = Im f(x + i h) / h, exact to rounding (no difference is taken)
CSTEP = 1e-30


def _rot(vx, vy, theta):
    """Rotate ``(vx, vy)`` clockwise by ``theta`` (the block tilting towards +x for theta > 0)."""
    c, s = np.cos(theta), np.sin(theta)
    return vx * c + vy * s, -vx * s + vy * c


class _Frame:
    """``n`` columns ``h x b`` (mass ``m`` each) at ``x0`` (centres), a beam of mass ``m_b``,
    length ``length`` and thickness ``t`` resting on their tops, centred over them."""

    def __init__(self, height, width, gamma, n=3, m=2.0, spacing=5.0, t=0.6):
        self.h, self.b, self.m, self.n = height, width, m, n
        self.x0 = spacing * np.arange(n)
        self.mb = gamma * n * m
        self.t = t
        self.ig = m * (height**2 + width**2) / 12.0           # column about its centre

    def pivot(self, i, s):
        return self.x0[i] + s * self.b / 2.0, 0.0

    def column_centre(self, i, theta, s):
        px, py = self.pivot(i, s)
        dx, dy = _rot(-s * self.b / 2.0, self.h / 2.0, theta)
        return px + dx, py + dy

    def contact(self, i, theta, s):
        """The top corner opposite the pivot, on which the beam rests."""
        px, py = self.pivot(i, s)
        dx, dy = _rot(-s * self.b, self.h, theta)
        return px + dx, py + dy

    def beam_centre(self, theta, s):
        # the beam translates with the contact corners (all columns share theta)
        cx, cy = self.contact(0, theta, s)
        c0x, c0y = self.contact(0, 0.0, s)
        rest = (self.x0.mean(), self.h + self.t / 2.0)
        return rest[0] + cx - c0x, rest[1] + cy - c0y

    def bodies(self, theta, s):
        """``(mass, (x, y))`` of every body's centre."""
        out = [(self.m, self.column_centre(i, theta, s)) for i in range(self.n)]
        return out + [(self.mb, self.beam_centre(theta, s))]

    def _dpos(self, theta, s):
        """d(x, y)/dtheta of every body's centre, by complex step."""
        res = []
        for mass, (x, y) in self.bodies(theta + 1j * CSTEP, s):
            res.append((mass, np.imag(x) / CSTEP, np.imag(y) / CSTEP))
        return res

    def mass_matrix(self, theta, s):
        """Generalised mass: ``T = 1/2 M(theta) theta'^2`` (columns spin at -theta')."""
        total = self.n * self.ig
        for mass, dx, dy in self._dpos(theta, s):
            total += mass * (dx * dx + dy * dy)
        return total

    def potential(self, theta, s, ug):
        """Gravity plus the pseudo-force of the ground acceleration ``ug`` (m/s^2)."""
        return sum(mass * (G * y + ug * x) for mass, (x, y) in self.bodies(theta, s))

    def theta_ddot(self, theta, omega, ug):
        """Lagrange: ``M theta'' + 1/2 M'(theta) theta'^2 + dV/dtheta = 0``."""
        s = 1.0 if theta > 0 else -1.0
        dv = np.imag(self.potential(theta + 1j * CSTEP, s, ug)) / CSTEP
        d = 1e-6
        dm = (self.mass_matrix(theta + d, s) - self.mass_matrix(theta - d, s)) / (2.0 * d)
        return -(dv + 0.5 * dm * omega**2) / self.mass_matrix(theta, s)

    def impact_ratio(self):
        """omega after / omega before at theta = 0, coming back from theta > 0 (pivots +b/2).

        Unknowns: omega after (per unit omega before) and the beam's impulse on every column at
        its new contact corner.  Equations: each column's angular momentum about its new pivot
        changes by the moment of that impulse (the ground's impulse acts at the pivot); the beam's
        momentum changes by minus their sum, and its angular momentum about its centre (it
        translates before and after) by nothing.
        """
        n = self.n
        before = self._dpos(0.0, 1.0)      # velocities per unit omega before (pivots at +b/2)
        after = self._dpos(0.0, -1.0)      # ... and after (pivots at -b/2)
        bx, by = self.beam_centre(0.0, -1.0)
        a = np.zeros((n + 3, 1 + 2 * n))
        rhs = np.zeros(n + 3)
        for i in range(n):
            ox, oy = self.pivot(i, -1.0)
            gx, gy = self.column_centre(i, 0.0, -1.0)
            rx, ry = gx - ox, gy - oy

            def h_about(vx, vy):
                # m r x v + I_G omega_z, omega_z = -theta' (the rotation is clockwise for theta' > 0)
                return self.m * (rx * vy - ry * vx) - self.ig

            a[i, 0] = h_about(after[i][1], after[i][2])
            rhs[i] = h_about(before[i][1], before[i][2])
            cx, cy = self.contact(i, 0.0, -1.0)
            # minus the moment (about the pivot) of the impulse (jx, jy) at the contact
            a[i, 1 + 2 * i] = (cy - oy)
            a[i, 2 + 2 * i] = -(cx - ox)
            # beam: mb (v_after - v_before) + sum J = 0;  sum (c - beam centre) x J = 0
            a[n, 1 + 2 * i] = 1.0
            a[n + 1, 2 + 2 * i] = 1.0
            a[n + 2, 1 + 2 * i] = -(cy - by)
            a[n + 2, 2 + 2 * i] = cx - bx
        a[n, 0], rhs[n] = self.mb * after[-1][1], self.mb * before[-1][1]
        a[n + 1, 0], rhs[n + 1] = self.mb * after[-1][2], self.mb * before[-1][2]
        sol, *_ = np.linalg.lstsq(a, rhs, rcond=None)
        assert np.max(np.abs(a @ sol - rhs)) < 1e-12 * np.max(np.abs(rhs))   # consistent
        return sol[0]


GAMMAS = [0.0, 0.25, 1.0, 2.0, 10.0]


@pytest.mark.parametrize("gamma", GAMMAS)
@pytest.mark.parametrize("width", [0.3, 1.8, 4.0, 6.0])
def test_equation_of_motion_matches_two_body_lagrangian(gamma, width):
    frame = _Frame(H, width, gamma)
    block = Block.from_dimensions(H, width, cap_mass_ratio=gamma)
    alpha = block.alpha
    for theta, omega, ug in [(0.3 * alpha, 0.1, 2.0), (-0.7 * alpha, -0.4, -3.0),
                             (1.4 * alpha, 0.2, 0.5), (-0.05, 0.3, 9.0)]:
        s = math.copysign(1.0, theta)
        spec = -block.p**2 * (math.sin(s * alpha - theta) + ug / G * math.cos(s * alpha - theta))
        # complex-step derivatives are exact to rounding; the central difference of M (constant
        # here) adds ~1e-10 of M times omega^2: 1e-9 relative is well clear of both
        assert frame.theta_ddot(theta, omega, ug) == pytest.approx(spec, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("gamma", GAMMAS)
@pytest.mark.parametrize("width", [0.3, 1.8, 4.0, 6.0])
def test_impact_matches_two_body_momentum_balance(gamma, width):
    # a 7.5 x 6 m column: alpha = 38.7 deg; the formula's value stays positive (no clipping)
    block = Block.from_dimensions(H, width, cap_mass_ratio=gamma)
    ratio = _Frame(H, width, gamma).impact_ratio()
    assert ratio > 0
    # a linear solve of a 6 x 7 system of O(1) entries: rounding ~1e-15
    assert block.eta == pytest.approx(ratio, rel=1e-9, abs=1e-12)
    assert eta_frame(block.alpha, gamma) == block.eta


def test_impact_does_not_depend_on_beam_thickness_or_layout():
    # the impulses redistribute among the columns; the velocity after impact does not change
    ref = _Frame(H, B, 1.5).impact_ratio()
    for n, t, spacing in [(2, 0.0, 3.0), (4, 1.5, 7.0)]:
        assert _Frame(H, B, 1.5, n=n, t=t, spacing=spacing).impact_ratio() == pytest.approx(ref, rel=1e-12)


def test_limits():
    alpha = 0.3
    assert eta_frame(alpha, 0.0) == rocking.eta_housner(alpha)
    assert eta_frame(alpha, 1e12) == pytest.approx(math.cos(2 * alpha), rel=1e-10)
    assert frame_p(1.3, 0.0) == 1.3
    assert frame_p(1.3, 1e12) == pytest.approx(1.3 * math.sqrt(2.0 / 3.0), rel=1e-10)


def test_cap_mass_ratio_zero_is_the_column_bit_for_bit(shared_records):
    import pulses

    col = Block.from_dimensions(H, B)
    frm = Block.from_dimensions(H, B, cap_mass_ratio=0)
    assert frm == col and hash(frm) == hash(col)
    assert (frm.p, frm.alpha, frm.eta, frm.R) == (col.p, col.alpha, col.eta, col.R)
    assert frm.cap_mass_ratio == 0.0 and repr(frm) == repr(col)
    rec = pulses.read_record(shared_records / "Rinaldi228.AT2")
    a, b = rocking.simulate(col, rec), rocking.simulate(frm, rec)
    assert np.array_equal(a.theta, b.theta) and a.max_rotation == b.max_rotation
    pulse = make_pulse("sine", 0.71 * G, 0.8)
    assert (rocking.required_width(H, pulse, cap_mass_ratio=0).width
            == rocking.required_width(H, pulse).width)


def test_frame_simulates_as_the_equivalent_column(shared_records):
    import pulses

    gamma = 2.0
    frame = Block.from_dimensions(H, B, cap_mass_ratio=gamma)
    k = equivalent_size(1.0, gamma)                 # (1 + 3 gamma) / (1 + 2 gamma)
    lone = Block.from_dimensions(H * k, B * k, eta=eta_frame(frame.alpha, gamma))
    assert lone.p == pytest.approx(frame.p, rel=1e-15)
    assert frame.R == pytest.approx(equivalent_size(math.hypot(H, B) / 2, gamma), rel=1e-14)
    assert frame.uplift_acceleration == pytest.approx(G * B / H, rel=1e-15)
    rec = pulses.read_record(shared_records / "Rinaldi228.AT2")
    for exc in (rec.scaled(2.0), make_pulse("sine", 0.9 * G, 1.2)):
        a, b = rocking.simulate(frame, exc), rocking.simulate(lone, exc)
        assert a.overturned == b.overturned
        # p agrees to one rounding; the compiled engine's answer is that close (1e-12 at most on
        # records, README "Solver accuracy"), so 1e-9 has ample room
        assert a.max_rotation == pytest.approx(b.max_rotation, rel=1e-9)
    # the heavier the beam, the more stable the frame: it rocks less than the lone column
    col = rocking.simulate(Block.from_dimensions(H, B), make_pulse("sine", 0.5 * G, 1.0))
    frm = rocking.simulate(frame, make_pulse("sine", 0.5 * G, 1.0))
    assert frm.max_rotation < col.max_rotation


def test_required_width_of_a_frame():
    pulse = make_pulse("sine", 0.71 * G, 0.8)
    gamma = 1.5
    res = rocking.required_width(H, pulse, rule="eq31", cap_mass_ratio=gamma)
    assert res.cap_mass_ratio == gamma and res.block.cap_mass_ratio == gamma
    # the fixed point of Eq. 31 with the frame's p
    p = Block.from_dimensions(H, res.width, cap_mass_ratio=gamma).p
    assert res.width == pytest.approx(H * rocking.eq31(pulse.ap, pulse.tp, p), rel=1e-12)
    assert res.width < rocking.required_width(H, pulse, rule="eq31").width
    exact = rocking.required_width(H, pulse, rule="exact", cap_mass_ratio=gamma)
    top = exact.block
    assert top.cap_mass_ratio == gamma and top.eta == eta_frame(top.alpha, gamma)
    # the answer survives; the bracket's failing end (rtol 1e-9 below) overturns
    assert not rocking.simulate(top, pulse).overturned
    below = Block.from_dimensions(H, exact.width * (1 - 2e-9), cap_mass_ratio=gamma)
    assert rocking.simulate(below, pulse).overturned


def test_bad_cap_mass_ratio():
    for bad in (-0.1, math.nan, math.inf, "x"):
        with pytest.raises(ValueError, match="cap_mass_ratio"):
            Block.from_dimensions(H, B, cap_mass_ratio=bad)


def test_from_tan_alpha_keeps_a_frame():
    import math

    import rocking
    from rocking.frame import eta_frame

    frame = rocking.Block.from_tan_alpha(1.2, 0.2, cap_mass_ratio=2.0)
    # the frame's restitution (docs/theory.md section 8), not the lone column's Eq. 5
    assert frame.eta == eta_frame(math.atan(0.2), 2.0) < rocking.eta_housner(math.atan(0.2))
    assert rocking.Block.from_tan_alpha(1.2, 0.2) == rocking.Block(1.2, math.atan(0.2))
