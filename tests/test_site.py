"""``pipeline run`` for a site: pairs in every direction, scales, velocity-pulse columns, suite
results, frames and collapse fragility (pipeline/batch/site.py).

The records are short synthetic pairs (8 s at 100 Hz, a one-sine pulse plus band-limited noise in
each component) written as SAC files by ``pulses.write_sac``, so that each run takes seconds."""
from __future__ import annotations

import csv
import math
import pathlib

import numpy as np
import pytest

import pulses
import rocking
from pipeline.cli import main as cli_main
from pipeline.batch.pairs import directions
from pipeline.reports.pulse_row import NOT_PULSE_WARNING

H, B = 2.0, 0.35  # a small column: the synthetic pulses (0.3-0.5 g) rock it


def _read(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _f(x):
    return float(x) if x not in ("", None) else None


def _pair(folder, name, ap1, ap2, seed):
    """Two orthogonal components (azimuths 0 and 90) of one synthetic station, as SAC files."""
    r1 = _synthetic(ap1, seed)
    r2 = _synthetic(ap2, seed + 1)
    paths = []
    for k, (r, az) in enumerate(((r1, 0.0), (r2, 90.0)), start=1):
        meta = dict(r.metadata or {}, azimuth=az, station=name[:8], event="SYN", component=f"H{k}")
        rec = pulses.Record(r.acc, r.dt, f"{name}_{k}", 0.0, meta)
        path = folder / f"{name}_{k}.sac"
        pulses.write_sac(rec, path)
        paths.append(path)
    return paths


def _synthetic(ap, seed):
    from pulses.fit.synthetic import synthetic_record

    return synthetic_record("sine", ap * pulses.G, 1.0, 2.0, 8.0, dt=0.01, noise=0.3, seed=seed)


@pytest.fixture(scope="module")
def pairs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("pairs")
    return folder, [_pair(folder, "STA", 0.45, 0.3, 1), _pair(folder, "STB", 0.3, 0.4, 7)]


def _run(out, *args):
    code = cli_main(["run", *map(str, args), "--out", str(out), "--quiet", "--no-plots"])
    return code


def test_directions_default_and_even():
    # the two components, the pulse direction and its normal; opposite directions are one
    assert directions(30.0) == [(0.0, "component-1"), (30.0, "pulse"), (90.0, "component-2"),
                                (120.0, "pulse-normal")]
    assert directions(-60.0) == [(0.0, "component-1"), (30.0, "pulse-normal"), (90.0, "component-2"),
                                 (120.0, "pulse")]
    got = directions(45.0, 4)  # 0, 45, 90, 135: each met once, first kind kept
    assert got == [(0.0, "component-1"), (45.0, "pulse"), (90.0, "component-2"), (135.0, "pulse-normal")]
    assert [a for a, _ in directions(10.0, 36)] == sorted({10.0, 100.0, *[5.0 * k for k in range(36)]})


@pytest.fixture(scope="module")
def pair_run(pairs, tmp_path_factory):
    folder, ((a1, a2), (b1, b2)) = pairs
    out = tmp_path_factory.mktemp("out")
    code = _run(out, "--pair", a1, a2, "--pair", b1, b2, "--block", f"{H}x{B}", "--directions", "4")
    assert code == 0
    return out


@pytest.mark.slow
def test_a_failed_direction_is_counted_in_pairs_csv(pairs, pair_run, tmp_path, monkeypatch):
    # one direction of the first pair fails (its worker kills itself): the pair's governing row
    # says so, and is the widest of the other directions; the second pair is untouched
    from pipeline.batch import runner

    rows = _read(pair_run / "summary.csv")
    first = rows[0]["pair"]
    killed = next(r["record"] for r in rows if r["pair"] == first and r["direction_kind"] == "component-2")
    monkeypatch.setenv(runner.TEST_KILL_ENV, killed)
    folder, ((a1, a2), (b1, b2)) = pairs
    out = tmp_path / "out"
    code = _run(out, "--pair", a1, a2, "--pair", b1, b2, "--block", f"{H}x{B}", "--directions", "4",
                "--jobs", "2")
    assert code == 1
    gov = {g["pair"]: g for g in _read(out / "pairs.csv")}
    reference = {g["pair"]: g for g in _read(pair_run / "pairs.csv")}
    others = [r for r in rows if r["pair"] == first and r["record"] != killed]
    assert int(gov[first]["n_directions_failed"]) == 1 and int(gov[first]["n_directions"]) == len(others)
    assert _f(gov[first]["design_width_m"]) == max(_f(r["design_width_m"]) for r in others)
    second = next(p for p in gov if p != first)
    assert int(gov[second]["n_directions_failed"]) == 0 and gov[second] == reference[second]


@pytest.mark.slow
def test_pair_rows_governing_and_suite(pairs, pair_run, tmp_path):
    folder, ((a1, a2), (b1, b2)) = pairs
    rows = _read(pair_run / "summary.csv")
    gov = _read(pair_run / "pairs.csv")
    suite = _read(pair_run / "suite.csv")
    assert len(gov) == 2 and len(suite) == 1
    for g in gov:
        mine = [r for r in rows if r["pair"] == g["pair"]]
        assert int(g["n_directions"]) == len(mine) >= 4
        kinds = {r["direction_kind"] for r in mine}
        assert {"component-1", "component-2"} <= kinds
        assert all(r["file2"] for r in mine)
        # the floor: the governing width is at least each recorded component's design width
        for r in mine:
            assert _f(g["design_width_m"]) >= _f(r["design_width_m"])
        assert _f(g["design_width_m"]) == max(_f(r["design_width_m"]) for r in mine)
    # width_all_m is the largest design width of the suite; all-but-one the second largest governing
    widths = [_f(r["design_width_m"]) for r in rows]
    s = suite[0]
    assert _f(s["width_all_m"]) == max(widths)
    assert _f(s["width_all_but_one_m"]) == sorted(_f(g["design_width_m"]) for g in gov)[0]
    assert int(s["n_records"]) == 2 and int(s["n_rows"]) == len(rows)
    # shares counted by hand from the rows
    survive = [all(r["overturns"] == "False" for r in rows if r["pair"] == g["pair"]) for g in gov]
    assert _f(s["share_column_survives"]) == pytest.approx(sum(survive) / 2, abs=1e-12)

    # each recorded component equals the component file designed alone (an independent path: one
    # file read as it is, no rotation); the pair's direction 0 and 90 rows must give the same widths
    single = tmp_path / "single"
    assert _run(single, a1, a2, "--block", f"{H}x{B}") == 0
    alone = {r["file"]: r for r in _read(single / "summary.csv")}
    pa = [r for r in rows if r["file"] == str(a1)]
    by_kind = {r["direction_kind"]: r for r in pa}
    for kind, path in (("component-1", a1), ("component-2", a2)):
        r, ref = by_kind[kind], alone[str(path)]
        for key in ("design_width_m", "pga_g", "eq31_width_m", "envelope_width_m"):
            # exactly the same samples (cos 0 = 1, sin 0 = 0; cos 90 deg = 6e-17 times the other
            # component: below the last of 6 printed digits)
            assert _f(r[key]) == pytest.approx(_f(ref[key]), rel=1e-5), key
        assert r["overturns"] == ref["overturns"]


def test_direction_equals_rotated_record_file(pairs, pair_run, tmp_path):
    folder, ((a1, a2), _) = pairs
    rows = [r for r in _read(pair_run / "summary.csv") if r["file"] == str(a1)]
    row = next(r for r in rows if abs(_f(r["direction_deg"]) - 45.0) < 1e-9)
    first, second = pulses.read_pair(a1, a2)
    rotated = pulses.component(first, second, 45.0)
    path = tmp_path / "rotated45.sac"
    pulses.write_sac(rotated, path)
    out = tmp_path / "rot"
    assert _run(out, path, "--block", f"{H}x{B}") == 0
    (ref,) = _read(out / "summary.csv")
    # SAC stores float32: samples come back to a relative 6e-8, so the fit and the widths agree to
    # far better than the 1e-4 asked here (the search's own bracket is 1e-3 relative)
    for key in ("pga_g", "pgv_m_s", "design_width_m", "eq31_width_m", "envelope_width_m",
                "max_theta_ratio", "pulse_tp_s"):
        assert _f(row[key]) == pytest.approx(_f(ref[key]), rel=1e-4), key
    assert row["overturns"] == ref["overturns"]
    assert row["direction_kind"] == "even" and row["file2"] == str(a2)


@pytest.mark.slow
def test_jobs_do_not_change_outputs_and_bad_inputs_fail_alone(pairs, tmp_path):
    folder, ((a1, a2), (b1, b2)) = pairs
    missing = folder / "missing.sac"
    short = tmp_path / "short.sac"  # not a pair with b1: 100 samples against 800
    rec = pulses.read_record(b1)
    pulses.write_sac(pulses.Record(rec.acc[:100], rec.dt, "short", 0.0, dict(rec.metadata)), short)
    args = ["--pair", a1, a2, "--pair", b1, short, missing, "--block", f"{H}x{B}", "--fragility",
            "--up-to", "3"]
    out1, out2 = tmp_path / "j1", tmp_path / "j2"
    assert _run(out1, *args) == 1
    assert _run(out2, *args, "--jobs", "2") == 1
    names = sorted(p.name for p in out1.iterdir())
    assert names == sorted(p.name for p in out2.iterdir())
    for name in names:
        assert (out1 / name).read_bytes() == (out2 / name).read_bytes(), name
    failures = _read(out1 / "failures.csv")
    assert {f["stage"] for f in failures} == {"read"} and len(failures) == 2
    assert any("not a pair" in f["reason"] for f in failures)
    rows = _read(out1 / "summary.csv")
    assert {r["pair"] for r in rows} == {"STA_1+2"} and len(rows) >= 4
    assert _read(out1 / "suite.csv")[0]["n_records"] == "1"


@pytest.mark.slow
def test_scale_and_scales(pairs, tmp_path):
    folder, ((a1, a2), _) = pairs
    out1, out2 = tmp_path / "k1", tmp_path / "k2"
    assert _run(out1, a1, "--height", H) == 0
    assert _run(out2, a1, "--height", H, "--scale", "2") == 0
    (r1,), (r2,) = _read(out1 / "summary.csv"), _read(out2 / "summary.csv")
    assert r1["scale"] == "1" and r2["scale"] == "2"
    assert _f(r2["pga_g"]) == pytest.approx(2 * _f(r1["pga_g"]), rel=1e-5)
    # the design width of the scaled record (the default level 0.5), from the library on the record
    # scaled here
    rec = pulses.read_record(a1).scaled(2.0)
    ref = rocking.required_width(H, rec, rule="exact", limit=0.5, overturning=True).width
    assert _f(r2["design_width_m"]) == pytest.approx(ref, rel=1e-5)
    table = tmp_path / "scales.csv"
    table.write_text(f"record,scale\n{pathlib.Path(a1).name},2\n")
    out3 = tmp_path / "k3"
    assert _run(out3, a1, "--height", H, "--scales", table) == 0
    (r3,) = _read(out3 / "summary.csv")
    assert r3["scale"] == "2" and r3["design_width_m"] == r2["design_width_m"]
    # a record the table does not name is an argument error (exit 2), not a guess
    assert _run(tmp_path / "k4", a1, a2, "--height", H, "--scales", table) == 2


@pytest.mark.slow
def test_pulse_columns_and_warning(pairs, tmp_path):
    folder, ((a1, a2), _) = pairs
    out = tmp_path / "cls"
    noise = tmp_path / "noise.sac"
    from pulses.fit.synthetic import band_noise

    acc = band_noise(800, 0.01, 0.5, np.random.default_rng(3))
    pulses.write_sac(pulses.Record(acc, 0.01, "noise", 0.0, {}), noise)
    assert _run(out, a1, noise, "--height", H) == 0
    rows = {pathlib.Path(r["file"]).name: r for r in _read(out / "summary.csv")}
    from pipeline.commands.classify import classify_fields

    for name, path in ((a1.name, a1), ("noise.sac", noise)):
        ref = classify_fields(pulses.read_record(path))
        r = rows[name]
        assert r["pulse_like"] == str(ref["pulse_like"])
        assert _f(r["velocity_tp_s"]) == pytest.approx(ref["velocity_tp_s"], rel=1e-5)
        assert (NOT_PULSE_WARNING in r["warnings"]) == (not ref["pulse_like"])
    assert rows["noise.sac"]["pulse_like"] == "False"  # band-limited noise has no velocity pulse
    text = (out / "columns.md").read_text()
    for name in ("pulse_like", "velocity_pulse_indicator", "direction_deg", "width_all_m", "scale"):
        assert f"`{name}`" in text


def test_frame_reports(pairs, tmp_path):
    folder, ((a1, _), _) = pairs
    out = tmp_path / "frame"
    assert _run(out, a1, "--height", H, "--cap-mass-ratio", "2") == 0
    (r,) = _read(out / "summary.csv")
    assert r["cap_mass_ratio"] == "2"
    # the run's headline: the level 0.5 with its overturning design (pipeline run's default)
    level = dict(rule="exact", limit=0.5, overturning=True)
    ref = rocking.required_width(H, pulses.read_record(a1), cap_mass_ratio=2.0, **level).width
    lone = rocking.required_width(H, pulses.read_record(a1), **level).width
    assert _f(r["design_width_m"]) == pytest.approx(ref, rel=1e-5)
    assert abs(ref - lone) > 1e-3 * lone  # the frame is not the lone column here
    assert _run(tmp_path / "bad", a1, "--height", H, "--cap-mass-ratio", "-1") == 2


@pytest.mark.slow
def test_fragility_outputs(pairs, tmp_path):
    folder, ((a1, a2), (b1, b2)) = pairs
    out = tmp_path / "frag"
    assert _run(out, a1, a2, b1, b2, "--block", f"{H}x{B}", "--fragility", "--up-to", "4") == 0
    rows = _read(out / "summary.csv")
    (summary,) = _read(out / "fragility.csv")
    block = rocking.Block.from_dimensions(H, B)
    crit = []
    for r in rows:
        cs = rocking.critical_scale(block, pulses.read_record(r["file"]), up_to=4.0)
        assert (r["critical_scale"] == "") == (cs.scale is None)
        if cs.scale is not None:
            assert _f(r["critical_scale"]) == pytest.approx(cs.scale, rel=1e-5)
            # just below the critical scale the column stands; at it, it overturns (first failure)
            rec = pulses.read_record(r["file"])
            assert rocking.simulate(block, rec.scaled(cs.scale)).overturned
            assert not rocking.simulate(block, rec.scaled(cs.scale * (1 - 1e-4))).overturned
        crit.append(cs.scale)
    done = [c for c in crit if c is not None]
    if len(done) == len(crit):  # no censoring: the maximum-likelihood fit is the sample's log moments
        logs = np.log(done)
        assert _f(summary["median_scale"]) == pytest.approx(math.exp(logs.mean()), rel=1e-5)
        assert _f(summary["beta_scale"]) == pytest.approx(logs.std(), rel=1e-5)
    assert int(summary["n_records"]) == 4
    curve = _read(out / "fragility_curve.csv")
    p = [_f(c["p_overturn_scale"]) for c in curve]
    assert p == sorted(p) and p[0] < 0.01 and p[-1] > 0.99


@pytest.mark.slow
def test_suite_and_fragility_plots():
    """The suite plot draws the share of records whose design width is at most each width (step curve through the
    sorted governing widths) and marks the column; PNGs are at least 1000 px wide."""
    import io

    from matplotlib.image import imread

    from pipeline.reports.figures.site import fragility_figure_png, suite_figure, suite_figure_png

    rows = [{"column": "2x0.35", "pair": p, "design_width_m": w, "eq31_width_m": e}
            for p, w, e in (("a", 0.30, 0.2), ("a", 0.41, 0.25), ("b", 0.22, 0.3), ("c", 0.50, 0.1))]
    suite = [{"column": "2x0.35", "width_m": 0.35, "width_all_m": 0.50, "n_records": 3, "n_rows": 4}]
    fig = suite_figure(rows, suite)
    (ax,) = fig.axes
    step = ax.lines[0]
    # governing widths: a 0.41, b 0.22, c 0.50 -> shares 1/3, 2/3, 1 at those widths
    np.testing.assert_allclose(step.get_xdata(), [0.0, 0.22, 0.41, 0.50])
    np.testing.assert_allclose(step.get_ydata(), [0.0, 1 / 3, 2 / 3, 1.0])
    assert any(np.allclose(line.get_xdata(), 0.35) for line in ax.lines[1:])  # the column's width
    png = suite_figure_png(rows, suite)
    assert imread(io.BytesIO(png)).shape[1] >= 1000 and b"Software" not in png
    fs = rocking.fragility([1.0, 2.0, 4.0])
    fp = rocking.fragility([0.5, 1.0, 2.0], measure="pga")
    png = fragility_figure_png({"2x0.35": (fs, fp, [])})
    assert imread(io.BytesIO(png)).shape[1] >= 1000


def test_a_pair_whose_classification_fails_is_designed_in_its_components_and_says_why():
    from pipeline.batch.pairs import directions
    from pipeline.reports.pulse_row import classification_fields

    fields, warning = classification_fields(None, pair_fields={"error": "too short"})
    assert set(fields.values()) == {None}  # no pulse columns made up
    assert warning == "velocity-pulse classification of the pair failed: too short"
    assert directions(None) == [(0.0, "component-1"), (90.0, "component-2")]
