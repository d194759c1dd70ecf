"""``pipeline run --hazard`` and ``pipeline.design(..., hazard=)``: the risk files, the width for
the target in design.csv, the printed answer and report.html's first line; a bad curve refused
in one line before any work, an earlier run's reports untouched."""
from __future__ import annotations

import csv
import io
import pathlib
import subprocess
import sys

import pytest

from .conftest import shared_record

DATA = pathlib.Path(__file__).parent / "data" / "hazard"


def _run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "pipeline", "run", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, timeout=900)


def _csv(path):
    return list(csv.DictReader(io.StringIO(path.read_text())))


@pytest.fixture(scope="module")
def risk_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("risk") / "out"
    recs = [shared_record(n) for n in ("RSN77_SFERN_PUL164.AT2", "Rinaldi228.AT2",
                                       "RSN6_IMPVALL.I_I-ELC180.AT2")]
    proc = _run(*recs, "--block", "7.5x1.8", "--hazard", DATA / "plain_pga.csv", "--target-poe", "5%/50",
                "--age", "2500", "--shapes", "sine", "--out", out, "--jobs", "2")
    return out, proc


@pytest.mark.slow
def test_hazard_outputs(risk_run):
    out, proc = risk_run
    assert proc.returncode == 0, proc.stderr[-3000:]
    for name in ("risk.csv", "risk_records.csv", "risk_widths.csv", "risk_disaggregation.csv",
                 "fragility.xml", "plots/risk_widths.png", "plots/risk_disaggregation.png"):
        assert (out / name).is_file(), name
    risk = _csv(out / "risk.csv")
    stands, target = risk
    assert stands["what"] == "as it stands" and target["what"] == "width for target"
    assert float(target["target_rate_per_year"]) == pytest.approx(-__import__("math").log(0.95) / 50, rel=1e-5)
    assert float(target["rate_per_year"]) <= float(target["target_rate_per_year"]) < float(target["narrower_rate_per_year"])
    assert stands["survival_over_age"]
    # the same width in design.csv (every row of the column), the printed answer and report.html
    design = _csv(out / "design.csv")
    assert {d["target_width_m"] for d in design} == {target["width_m"]}
    assert {d["site_rate_per_year"] for d in design} == {stands["rate_per_year"]}
    width = f"{float(target['width_m']):.3f} m"
    assert f"the width for the site's target rate is {width}" in proc.stdout
    html = (out / "report.html").read_text()
    first = html.split('<p class="verdict"><b>')[1].split("</b>")[0]
    assert "design width covering all 3" in first and width in first
    widths = _csv(out / "risk_widths.csv")
    assert len(widths) == int(target["widths_computed"])
    assert "## Columns of `risk.csv`" in (out / "columns.md").read_text()


@pytest.mark.slow
def test_bad_hazard_is_one_line_and_loses_nothing(risk_run, tmp_path):
    out, _ = risk_run
    before = {p: p.read_bytes() for p in out.rglob("*") if p.is_file()}
    bad = tmp_path / "curve.csv"
    bad.write_text("# measure: PGA\n# units: g\niml,rate\n0.1,1e-3\n0.2,2e-3\n")
    rec = shared_record("RSN77_SFERN_PUL164.AT2")
    for args in (["--hazard", bad], ["--hazard", DATA / "plain_unstated.csv"],
                 ["--hazard", DATA / "hazard_curve-mean-SA(1.0)_42.csv"],
                 ["--hazard", DATA / "plain_pga.csv", "--target-poe", "2%"],
                 ["--target-rate", "1e-4"]):
        proc = _run(rec, "--block", "7.5x1.8", *args, "--out", out)
        assert proc.returncode == 2, (args, proc.stderr)
        assert len(proc.stderr.strip().splitlines()) == 1, proc.stderr
    assert {p: p.read_bytes() for p in out.rglob("*") if p.is_file()} == before


@pytest.mark.slow
def test_design_from_python_with_hazard():
    import pipeline
    from pipeline.commands.demo import bundled_records

    with bundled_records() as paths:
        run = pipeline.design(paths[:3], blocks="7.5x1.8", shapes="sine", hazard=DATA / "plain_pga.csv",
                              target_rate=1e-3)
    assert list(run.risk["what"]) == ["as it stands", "width for target"]
    w = run.risk["width_m"].iloc[1]
    assert (run.design["target_width_m"] == w).all()
    assert run.as_dict()["risk"][1]["width_m"] == pytest.approx(w)
    with pytest.raises(ValueError, match="fewer than two positive rates"):
        pipeline.design(paths[:1], blocks="7.5x1.8", hazard=DATA / "hazard_curve-mean-SA(1.0)_42.csv",
                        site_row=3)
