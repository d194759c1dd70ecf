"""``pipeline simulate`` against the library called directly, and its bad-argument handling."""
from __future__ import annotations

import json

import pytest

import pulses
import rocking
from pipeline.cli import main


def test_simulate_json_matches_library(capsys):
    assert main(["simulate", "--block", "7.5x1.8", "--pulse", "sine", "--ap", "0.71g", "--tp",
                 "0.8", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    direct = rocking.simulate(rocking.Block.from_dimensions(7.5, 1.8),
                              pulses.OneSine(0.71 * pulses.G, 0.8))
    assert out["overturned"] is False and out["model"] == direct.model
    # same call, same numbers (printed with full precision by json)
    assert out["max_rotation_ratio"] == pytest.approx(direct.max_rotation_ratio, rel=1e-15)
    assert out["block"]["p_rad_s"] == pytest.approx(1.381, abs=5e-4)


@pytest.mark.slow
def test_simulate_history_csv_and_plot(tmp_path, capsys):
    csv, png = tmp_path / "h.csv", tmp_path / "h.png"
    assert main(["simulate", "--block", "2x3", "--pulse", "ricker-sym", "--ap=-2.0g", "--tp",
                 "0.5", "--duration", "4", "--csv", str(csv), "--plot", str(png)]) == 0
    assert "column" in capsys.readouterr().out  # a block wider than tall is valid
    lines = csv.read_text().splitlines()
    assert lines[0] == "t_s,theta_rad,omega_rad_s" and len(lines) > 100
    assert png.stat().st_size > 10_000


@pytest.mark.parametrize("argv", [
    ["simulate", "--block", "0x1", "--pulse", "sine", "--ap", "0.5g", "--tp", "1"],
    ["simulate", "--block", "7.5x1.8", "--pulse", "sine", "--ap", "nan", "--tp", "1"],
    ["simulate", "--block", "7.5x1.8", "--pulse", "sine", "--ap", "0.5", "--tp", "1"],
    ["simulate", "--block", "7.5x1.8", "--pulse", "sine", "--ap", "0.5g", "--tp", "-1"],
    ["simulate", "--block", "7.5x1.8", "--record", "/nonexistent/record.AT2"],
    ["simulate", "--block", "7.5x1.8", "--pulse", "sine"],
])
def test_simulate_bad_arguments_exit_2_with_one_line(argv, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "error" in err and "Traceback" not in err
