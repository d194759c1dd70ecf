"""Risk at a site (rocking.risk): hazard curves read and checked, the rate integral against the
closed form of a power law, the fragility in a hazard's measure, NRML, and the width for a target."""
from __future__ import annotations

import json
import math
import os
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from scipy.special import ndtr

import pulses
import rocking
from rocking.risk import HazardCurve, HazardError, read_hazard
from rocking.risk import nrml
from rocking.risk.rate import (discrete_rate, failure_rate, parse_poe, power_law_rate, probability_in,
                               rate_for, survival)

DATA = pathlib.Path(__file__).parent / "data" / "hazard"


# -- the rate integral -------------------------------------------------------------------------------
@pytest.mark.parametrize("per_decade", [20, 25, 30])
@pytest.mark.parametrize("k, median, beta", [(2.5, 0.5, 0.4), (1.8, 0.2, 0.7), (3.2, 1.2, 0.3)])
def test_rate_equals_power_law_closed_form(per_decade, k, median, beta):
    # a power-law curve tabulated as real files are (20-30 points a decade) from 1e-4 to 100 g:
    # the integral (exact per interval for the lognormal; Gauss-Legendre for any fragility) equals
    # k0 theta^-k exp(k^2 beta^2 / 2) to 1e-3; what the curve leaves out above its last level
    # (lambda_N P(x_N), about 1e-5 of the rate here) is the only difference, and is reported
    x = np.geomspace(1e-4, 100.0, 6 * per_decade + 1)
    curve = HazardCurve("SA(1.0)", x, 1e-4 * x ** -k, units="g")
    exact = power_law_rate(1e-4, k, median, beta)
    r = failure_rate(curve, median, beta)
    assert r.rate == pytest.approx(exact, rel=1e-3)
    assert r.rate + r.above_last == pytest.approx(exact, rel=1e-6)
    q = failure_rate(curve, probability=lambda v: ndtr(np.log(v / median) / beta))
    assert q.rate == pytest.approx(exact, rel=1e-3)
    assert q.rate == pytest.approx(r.rate, rel=1e-9)


def test_below_first_share_and_disaggregation():
    # a curve starting at the median: lambda_0 Phi(0) = lambda_0 / 2 comes from below its first level
    x = np.geomspace(0.5, 50.0, 51)
    curve = HazardCurve("PGA", x, 1e-4 * x ** -2.0, units="g")
    r = failure_rate(curve, 0.5, 0.5)
    assert r.below_first == pytest.approx(0.5 * 1e-4 * 0.5 ** -2.0, rel=1e-12)
    assert r.below_first_share == pytest.approx(r.below_first / r.rate)
    shares = r.bands(np.geomspace(0.5, 50.0, 5))
    assert shares.sum() == pytest.approx(1.0, rel=1e-12)
    assert r.contributions.sum() + r.below_first == pytest.approx(r.rate, rel=1e-12)


def test_discrete_rule_differs_on_coarse_curves():
    # OpenQuake's rule (rates of occurrence between midpoints) against the integral: close on a
    # fine curve, a few percent off on a coarse one (the docs say which is used: docs/risk.md, "Theory")
    frag = lambda v: ndtr(np.log(v / 0.5) / 0.4)  # noqa: E731
    fine = np.geomspace(1e-3, 100.0, 151)
    coarse = np.geomspace(1e-3, 100.0, 16)
    exact = power_law_rate(1e-4, 2.5, 0.5, 0.4)
    c_fine = HazardCurve("PGA", fine, 1e-4 * fine ** -2.5, units="g")
    c_coarse = HazardCurve("PGA", coarse, 1e-4 * coarse ** -2.5, units="g")
    assert discrete_rate(c_fine, frag) == pytest.approx(exact, rel=1e-2)
    assert abs(discrete_rate(c_coarse, frag) / exact - 1) > 0.02
    assert failure_rate(c_coarse, 0.5, 0.4).rate == pytest.approx(exact, rel=1e-3)


def test_probabilities_from_rates():
    p, n = parse_poe("2%/50")
    assert (p, n) == (0.02, 50.0)
    assert rate_for(p, n) == pytest.approx(4.04054e-4, rel=1e-5)    # docs/risk.md: 2 % in 50 years
    assert parse_poe("10 % / 50 years") == (0.1, 50.0)
    assert probability_in(rate_for(0.1, 50), 50) == pytest.approx(0.1, rel=1e-12)
    assert survival(1e-4, 2560) == pytest.approx(math.exp(-0.256))
    for bad in ("2%", "150%/50", "2%/-5", "x/50"):
        with pytest.raises(ValueError, match="P%/N|between 0 and 100"):
            parse_poe(bad)


# -- bad curves: one line each --------------------------------------------------------------------
@pytest.mark.parametrize("imls, rates, words", [
    ([0.1], [1e-3], "at least two levels"),
    ([0.1, 0.2, 0.4], [1e-3, 2e-3, 1e-4], "rates rise with the level"),
    ([0.1, 0.2], [1e-3, -1e-4], "negative"),
    ([0.1, 0.2], [1e-3, float("nan")], "not a number"),
    ([0.2, 0.1], [1e-3, 1e-4], "levels must rise"),
    ([0.1, 0.2], [0.0, 0.0], "fewer than two positive"),
])
def test_bad_curves_refused_in_one_line(imls, rates, words):
    with pytest.raises(HazardError, match=words) as exc:
        HazardCurve("PGA", imls, rates, units="g")
    assert "\n" not in str(exc.value)


def test_probabilities_at_or_above_one_refused(tmp_path):
    f = tmp_path / "hazard_curve-mean-PGA_1.csv"
    f.write_text("#,,,,\"generated_by='OpenQuake engine 3.18.0', kind='mean', investigation_time=50.0, "
                 "imt='PGA'\"\nlon,lat,depth,poe-0.1000000,poe-0.2000000\n0.0,0.0,0.0,1.000000E+00,5.0E-01\n")
    with pytest.raises(HazardError, match=r"must lie in \[0, 1\)") as exc:
        read_hazard(f)
    assert "\n" not in str(exc.value)


def test_measure_and_units_never_guessed(tmp_path):
    with pytest.raises(HazardError, match="intensity measure is not stated"):
        read_hazard(DATA / "plain_unstated.csv")
    with pytest.raises(HazardError, match="units of the levels .* not stated"):
        read_hazard(DATA / "plain_unstated.csv", imt="PGA")
    c = read_hazard(DATA / "plain_unstated.csv", imt="PGA", units="m/s2")
    assert c.imls[0] == pytest.approx(0.02 / 9.80665)           # kept in g
    with pytest.raises(HazardError, match="states the measure 'PGA', not 'PGV'"):
        read_hazard(DATA / "plain_pga.csv", imt="PGV")
    with pytest.raises(HazardError, match="do not fit PGV"):
        read_hazard(DATA / "plain_unstated.csv", imt="PGV", units="g")


# -- every format, from files laid out as their programs write them -------------------------------------
def _poe_rates(path, row):
    lines = path.read_text().splitlines()
    cells = lines[1 + row].split(",")
    return -np.log1p(-np.array([float(c) for c in cells[3:]]))


def test_openquake_current_header_several_sites():
    path = DATA / "hazard_curve-mean-SA(1.0)_42.csv"
    with pytest.raises(HazardError, match="4 sites"):
        read_hazard(path)
    c = read_hazard(path, site=(-118.25, 34.05))
    assert c.measure == "SA(1.0)" and c.units == "g" and c.investigation_time == 50.0
    assert c.imls[0] == 0.005 and c.imls[-1] == 7.38
    np.testing.assert_allclose(c.rates, _poe_rates(path, 2) / 50.0, rtol=1e-12)
    assert read_hazard(path, site_row=2).rates.tolist() == c.rates.tolist()
    # the site of zeros is refused, and no other site is lost by it
    with pytest.raises(HazardError, match="fewer than two positive rates"):
        read_hazard(path, site_row=3)
    assert read_hazard(path, site_row=4).site == (23.7, 37.97)
    with pytest.raises(HazardError, match="no site at 10,10"):
        read_hazard(path, site=(10, 10))


def test_openquake_older_header():
    c = read_hazard(DATA / "hazard_curve-PGA.csv")
    assert c.measure == "PGA" and c.imls.tolist() == [0.1, 0.4, 0.6]
    np.testing.assert_allclose(c.rates, _poe_rates(DATA / "hazard_curve-PGA.csv", 1), rtol=1e-12)


def test_nshmp_csv_measure_from_its_folder_and_trailing_zeros():
    assert read_hazard(DATA / "nshmp" / "curves" / "SA1P0" / "total.csv", site_row=1).measure == "SA(1.0)"
    c = read_hazard(DATA / "nshmp" / "curves" / "PGA" / "total.csv", site=(-121.9, 37.35))
    assert c.measure == "PGA" and c.units == "g"
    assert c.rates[-1] == 0.0 and c.rates[c.rates > 0].size < c.n      # the curve stops there
    row = (DATA / "nshmp" / "curves" / "PGA" / "total.csv").read_text().splitlines()[3].split(",")
    np.testing.assert_allclose(c.rates, [float(v) for v in row[3:]], rtol=0)
    assert c.rate_at(c.imls[-1] * 1.01) == 0.0


def test_usgs_web_service_json_total_component():
    doc = json.loads((DATA / "usgs_hazard.json").read_text())
    with pytest.raises(HazardError, match="2 measures"):
        read_hazard(DATA / "usgs_hazard.json")
    c = read_hazard(DATA / "usgs_hazard.json", imt="SA(1.0)")
    total = next(d for d in doc["response"][1]["data"] if d["component"] == "Total")["yvalues"]
    assert c.measure == "SA(1.0)" and c.site == (-118.25, 34.05)
    np.testing.assert_allclose(c.rates, total, rtol=0)
    assert read_hazard(DATA / "usgs_hazard.json", imt="PGA").imls.tolist() == doc["response"][0]["metadata"]["xvalues"]


def test_plain_csv_and_unknown_file(tmp_path):
    c = read_hazard(DATA / "plain_pga.csv")
    assert c.measure == "PGA" and c.n == 25
    f = tmp_path / "notes.txt"
    f.write_text("not a curve\n")
    with pytest.raises(HazardError, match="not a hazard curve"):
        read_hazard(f)
    with pytest.raises(HazardError, match="No such file"):
        read_hazard(tmp_path / "absent.csv")


# -- fragility in the hazard's measure, and NRML --------------------------------------------------------
def test_fragility_in_a_hazard_measure():
    f = rocking.fragility([1.2, 1.5, 2.0, None], up_to=3.0, measure="SA(1.0)",
                          intensities=[0.5, 0.4, 0.2, 0.3])
    assert f.measure == "SA(1.0)"
    np.testing.assert_allclose(f.values[:3], [0.6, 0.6, 0.4])
    assert f.censored_at.tolist() == pytest.approx([0.9])
    g = f.goodness_of_fit(50)
    assert 0 <= g.ks <= 1 and 0 < g.p_value <= 1
    with pytest.raises(ValueError, match="needs intensities"):
        rocking.fragility([1.2, 1.5], measure="PGV")


def test_nrml_round_trip():
    ff = nrml.FragilityFunction("7.5x1.8", "SA(1.0)", [("exceeds_0_5", 0.3, 0.35), ("overturns", 0.5, 0.4)],
                                0.05, 4.0)
    back = nrml.read_nrml_text(nrml.nrml_text([ff]))[0]
    assert back.id == "column_7_5x1_8" and back.measure == "SA(1.0)"
    for (_, t0, b0), (_, t1, b1) in zip(ff.limit_states, back.limit_states):
        assert t1 == pytest.approx(t0, rel=1e-10) and b1 == pytest.approx(b0, rel=1e-10)


def _openquake_python():
    """A Python that imports openquake: this one, or ROCKING_OPENQUAKE_PYTHON's."""
    try:
        import openquake.risklib  # noqa: F401

        return sys.executable
    except ImportError:
        other = os.environ.get("ROCKING_OPENQUAKE_PYTHON")
        if other:
            return other
    pytest.skip("OpenQuake is not importable here (pip install openquake.engine, or point "
                "ROCKING_OPENQUAKE_PYTHON at a Python that has it)")


def test_nrml_read_by_openquake_gives_our_probabilities(tmp_path):
    python = _openquake_python()
    ff = nrml.FragilityFunction("7.5x1.8", "SA(1.0)", [("exceeds_0_5", 0.31, 0.35), ("overturns", 0.52, 0.47)],
                                0.02, 5.0)
    path = tmp_path / "fragility.xml"
    nrml.write_nrml(path, [ff])
    x = np.geomspace(0.02, 5.0, 40)
    script = ("import json, sys, numpy\nfrom openquake.hazardlib import nrml\nfrom openquake.risklib import read_nrml\n"
              f"fm = nrml.to_python({str(path)!r})\nx = numpy.array({x.tolist()!r})\n"
              "out = {}\nfor key, ffl in fm.items():\n"
              "    out[key[1]] = [list(map(float, f(x))) for f in ffl.build(fm.limitStates)]\n"
              "print(json.dumps(out))\n")
    proc = subprocess.run([python, "-c", script], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    theirs = json.loads(proc.stdout.strip().splitlines()[-1])["column_7_5x1_8"]
    for state, probs in enumerate(theirs):
        np.testing.assert_allclose(probs, ff.probability(x, state), rtol=0, atol=1e-6)
        # and those of the package's own lognormal
        _, t, b = ff.limit_states[state]
        np.testing.assert_allclose(probs, ndtr(np.log(x / t) / b), rtol=0, atol=1e-6)


# -- the width for a target ---------------------------------------------------------------------------
def _suite():
    t = np.arange(0.0, 8.0, 0.01)
    shapes = [(0.35, 1.0), (0.3, 1.4), (0.45, 0.8), (0.25, 1.9), (0.4, 1.2), (0.3, 0.9)]
    return [pulses.Record(pulses.make_pulse("sine", a * pulses.G, tp, 1.0)(t), 0.01, name=f"p{i}")
            for i, (a, tp) in enumerate(shapes)]


def test_width_for_target_meets_it_and_narrower_does_not():
    x = np.geomspace(0.01, 10.0, 76)
    curve = HazardCurve("PGA", x, 2e-4 * x ** -2.3, units="g")
    recs = _suite()
    res = rocking.risk(recs, curve, height=6.0, target_rate=3e-4, restitution="0.9:1.1", seed=3, n_boot=10)
    t = res.target
    assert t.width is not None and t.narrower_width < t.width
    assert t.width / t.narrower_width - 1 <= 0.005 + 1e-12
    # recomputed from scratch at both widths (the same seed draws the same restitutions)
    at = rocking.risk(recs, curve, height=6.0, width=t.width, restitution="0.9:1.1", seed=3, n_boot=10)
    below = rocking.risk(recs, curve, height=6.0, width=t.narrower_width, restitution="0.9:1.1", seed=3,
                         n_boot=10)
    assert at.rate <= 3e-4 < below.rate
    assert at.rate == pytest.approx(t.rate, rel=1e-12)
    # every scanned width above the answer meets the target
    assert all(w.rate <= 3e-4 for w in t.widths if w.width >= t.width)
    # the restitution's band widens the fragility
    m = at.modes[0]
    assert m.fragility.beta > 0 and m.fragility_eq5.beta > 0
    frame = res.to_frame()
    assert list(frame["what"]) == ["width for target"]
    assert res.as_dict()["widths"]


def test_risk_rows_of_a_column_as_it_stands():
    x = np.geomspace(0.01, 10.0, 76)
    curve = HazardCurve("PGA", x, 2e-4 * x ** -2.3, units="g")
    res = rocking.risk(_suite(), curve, height=6.0, width=1.2, limit=0.5, age=2500, n_boot=20)
    rows = res.rows()
    assert [r["mode"] for r in rows] == ["overturning", "max theta/alpha > 0.5"]
    over, level = rows
    assert level["rate_per_year"] >= over["rate_per_year"] > 0
    f = res.modes[0].fragility
    assert over["rate_per_year"] == pytest.approx(failure_rate(curve, f.median, f.beta).rate)
    assert over["survival_over_age"] == pytest.approx(math.exp(-2500 * over["rate_per_year"]))
    assert over["rate_p5_per_year"] <= over["rate_per_year"] * 1.5 and over["rate_p95_per_year"] > 0
    assert len(res.record_rows()) == 2 * 6
    ff = nrml.functions_of(res)
    assert [s[0] for s in ff.limit_states] == ["exceeds_0_5", "overturns"]


def test_a_circular_columns_risk_uses_its_own_body():
    # the critical scales are the cylinder's own (its p and impact rule), not the rectangle's
    x = np.geomspace(0.01, 10.0, 76)
    curve = HazardCurve("PGA", x, 2e-4 * x ** -2.3, units="g")
    recs = _suite()
    drum = rocking.risk(recs, curve, height=6.0, width=1.2, body="cylinder", n_boot=5)
    block = rocking.Block.from_dimensions(6.0, 1.2, body="cylinder")
    for rec, entry in zip(recs, drum.modes[0].critical.entries):
        own = rocking.critical_scale(block, rec, up_to=entry.up_to)
        assert entry.scale == own.scale
    box = rocking.risk(recs, curve, height=6.0, width=1.2, n_boot=5)
    assert drum.rate != box.rate
