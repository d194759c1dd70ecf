"""``pipeline run`` / ``simulate`` / ``design`` say which model answered and whether it holds:
the body, the restitution, the friction each response needs (``--friction MU`` judges it) and
lift-off with the vertical; circular columns (``cyl:``) everywhere a column is given.  Each
number of the rows is checked against the library called here directly."""
from __future__ import annotations

import csv
import json
import math
from importlib.resources import files

import pytest

import pulses
import rocking
from pipeline.cli import main as cli_main

RECORD = str(files("pipeline.data") / "synth_sine_055g_0.9s.sac")


def _rows(out, name="summary.csv"):
    with open(out / name, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def judged(tmp_path_factory):
    out = tmp_path_factory.mktemp("judged")
    code = cli_main(["run", RECORD, "--block", "7.5x1.8", "--block", "cyl:7.5x1.8", "--height", "7.5",
                     "--friction", "0.3", "--out", str(out), "--quiet"])
    assert code == 0
    return out


def test_rows_name_the_body_and_the_restitution(judged):
    rows = {r["column"]: r for r in _rows(judged)}
    assert set(rows) == {"7.5x1.8", "cyl:7.5x1.8", "7.5"}
    assert rows["7.5x1.8"]["body"] == "rectangular" and rows["7.5x1.8"]["impact_rule"] == "Eq. 5"
    cyl = rows["cyl:7.5x1.8"]
    assert cyl["body"] == "cylinder (planar rocking)"
    drum = rocking.Block.from_dimensions(7.5, 1.8, body="cylinder")
    assert float(cyl["eta"]) == pytest.approx(drum.eta, rel=1e-5)      # 6 digits printed
    assert float(cyl["p_rad_s"]) == pytest.approx(drum.p, rel=1e-5)
    # the cylinder's design width is the library's, with its own p and impact rule (at the run's
    # default level, max|theta|/alpha <= 0.5, at least the verge)
    rec = pulses.read_record(RECORD)
    w = rocking.required_width(7.5, rec, rule="exact", body="cylinder", limit=0.5, overturning=True).width
    assert float(cyl["design_width_m"]) == pytest.approx(w, rel=1e-5)
    assert float(cyl["design_width_m"]) != float(rows["7.5x1.8"]["design_width_m"])


def test_friction_columns_are_the_librarys_and_judged(judged):
    rec = pulses.read_record(RECORD)
    for r in _rows(judged):
        body = "cylinder" if r["column"].startswith("cyl:") else None
        dw = float(r["design_width_m"])
        at = rocking.Block.from_dimensions(7.5, dw, body=body)
        need = rocking.friction_demand(rocking.simulate(at, rec), rec)
        assert float(r["design_friction_demand"]) == pytest.approx(need.max_demand, rel=1e-5)
        assert (r["design_slides"] == "True") == (need.max_demand > 0.3)
        if r["column_kind"] == "block":
            blk = rocking.Block.from_dimensions(7.5, 1.8, body=body)
            mine = rocking.friction_demand(rocking.simulate(blk, rec), rec)
            assert float(r["friction_demand"]) == pytest.approx(mine.max_demand, rel=1e-5)
            assert float(r["impulse_ratio"]) == pytest.approx(mine.impulse_ratio, rel=1e-5)
            assert (r["slides"] == "True") == mine.judge(0.3).slides
            if mine.judge(0.3).slides:
                assert float(r["t_slide_s"]) == pytest.approx(mine.judge(0.3).t_slide, abs=1e-4)
        assert r["friction_mu"] == "0.3"
        # the demand grows with the width to PGA/g (0.634) at rest: no width holds at mu 0.3
        if r["design_slides"] == "True":
            assert r["friction_width_m"] == "" and "no width holds" in r["validity"]
            assert "friction: FAILED (mu 0.3)" in r["validity"]
        assert "lift-off: no vertical" in r["validity"]


def test_design_csv_and_report_say_where_the_model_holds(judged):
    design = {r["column"]: r for r in _rows(judged, "design.csv")}
    assert design["cyl:7.5x1.8"]["body"] == "cylinder (planar rocking)"
    assert design["7.5x1.8"]["slides"] == "True"
    html = (judged / "report.html").read_text(encoding="utf-8")
    assert "Where the rocking model holds" in html
    assert 'src="plots/friction/synth_sine_055g_0.9s.png"' in html
    assert (judged / "plots" / "friction" / "synth_sine_055g_0.9s.png").stat().st_size > 10_000
    manifest = (judged / "pipeline-manifest.txt").read_text(encoding="utf-8")
    assert "plots/friction/synth_sine_055g_0.9s.png" in manifest


def test_without_friction_the_demand_is_reported_not_judged(tmp_path):
    assert cli_main(["run", RECORD, "--block", "7.5x1.8", "--out", str(tmp_path), "--quiet",
                     "--no-plots"]) == 0
    r = _rows(tmp_path)[0]
    assert r["friction_mu"] == "" and r["slides"] == "" and r["design_slides"] == ""
    assert float(r["friction_demand"]) > 0 and "not judged" in r["validity"]
    assert not (tmp_path / "plots").exists()


def test_a_generous_coefficient_passes(tmp_path):
    assert cli_main(["run", RECORD, "--block", "7.5x1.8", "--friction", "0.7", "--out",
                     str(tmp_path), "--quiet", "--no-plots"]) == 0
    r = _rows(tmp_path)[0]
    assert r["slides"] == "False" and r["design_slides"] == "False"
    assert "friction: passed" in r["validity"]


@pytest.mark.parametrize("args, says", [
    (["--block", "hex:7.5x1.8"], "unknown body"),
    (["--block", "7.5x1.8", "--friction", "-0.2"], "--friction"),
    (["--block", "7.5x1.8", "--friction", "40"], "friction coefficient"),
    (["--block", "cyl:7.5x1.8", "--cap-mass-ratio", "0.5"], "rectangular columns only"),
])
def test_argument_errors_are_one_line(tmp_path, capsys, args, says):
    assert cli_main(["run", RECORD, *args, "--out", str(tmp_path), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert says in err and "\n" not in err


def test_simulate_reports_and_judges_the_friction(capsys):
    assert cli_main(["simulate", "--block", "7.5x1.8", "--pulse", "rect", "--ap", "0.5g", "--tp",
                     "1", "--friction", "0.3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    f = out["friction"]
    alpha = math.atan(0.24)
    q = 0.75 * (0.5 * math.cos(alpha) - math.sin(alpha))
    shenton = (0.5 - q * math.cos(alpha)) / (1 + q * math.sin(alpha))
    assert f["uplift_demand"] == pytest.approx(shenton, rel=1e-12)
    assert f["slides"] is True and f["t_slide_s"] == 0.0 and f["mu"] == 0.3
    assert cli_main(["simulate", "--block", "cyl:7.5x1.8", "--pulse", "sine", "--ap", "0.4g",
                     "--tp", "1", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    drum = rocking.Block.from_dimensions(7.5, 1.8, body="cylinder")
    assert out["block"]["body"] == "cylinder (planar rocking)"
    assert out["block"]["p_rad_s"] == pytest.approx(drum.p, rel=1e-15)
    assert "slides" not in out["friction"]


def test_design_command_with_a_cylinder_and_friction(capsys):
    assert cli_main(["design", "--height", "cyl:7.5", "--pulse", "sine", "--ap", "0.5g", "--tp",
                     "1", "--friction", "0.25", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["body"] == "cylinder (planar rocking)"
    w = rocking.required_width(7.5, pulses.OneSine(0.5 * pulses.G, 1.0), rule="exact", body="cyl")
    assert out["rules"]["exact"]["required_width_m"] == pytest.approx(w.width, rel=1e-12)
    f = out["friction"]["exact_width"]
    assert f["slides"] is True and "valid_width_m" in f


def test_python_api_takes_friction_and_cylinders():
    import pipeline

    run = pipeline.design(RECORD, blocks=["cyl:7.5x1.8", rocking.Block.from_dimensions(
        7.5, 1.8, body="cylinder")], friction=0.5, shapes="sine")
    assert list(run.design["column"]) == ["cyl:7.5x1.8"]        # the same column once
    assert run.design["body"].iloc[0] == "cylinder (planar rocking)"
    assert run.summary["friction_mu"].iloc[0] == 0.5
    with pytest.raises(TypeError, match="friction"):
        pipeline.design(RECORD, blocks="7.5x1.8", friction="a lot")
