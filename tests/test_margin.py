"""A margin by default and the restitution as a design input (docs/design.md, "Choosing the width"
and "Choosing the restitution").

- By default ``pipeline run`` quotes the width of the level 0.5 first (max theta/alpha <= 0.5,
  checked by a run of its own at that width), at least the overturning design width; the verge
  (the overturning design, no margin) stands beside it, and the table says where a quoted width
  lets the column pass its slenderness angle.
- ``--limit none`` (and no ``--restitution``) writes every report as the version before the margin
  did: the files main wrote are kept in tests/golden/limit_none (the demo, and the 15 records of
  ``../shared/records/raw/*.AT2`` for a 7.5 x 1.8 m column) and compared column by column.
- A restitution band's design width is at least each of its values' design width (computed
  apart, one value at a time).
"""
from __future__ import annotations

import csv
import math
import pathlib

import numpy as np
import pytest

import pulses
import rocking
from pipeline.cli import main
from pipeline.commands.demo import bundled_records
from rocking.band import BAND_VALUES
from rocking.restitution import Restitution

from .conftest import SHARED_RECORDS, shared_record

GOLDEN = pathlib.Path(__file__).resolve().parent / "golden" / "limit_none"
#: max|theta|/alpha at the level's design width, run alone, against the level: the design ran
#: that width in a batch whose lanes share their Taylor order, and a run of its own agrees with
#: it to rounding (peaks to 1e-9 relative, tests/test_golden.py), so 1e-8 of slack and no more
LEVEL_SLACK = 1e-8
#: the reports print 6 significant digits: two machines that round the solver's last bit
#: differently can print the last digit one apart (tests/test_golden.py: the demo's summary at
#: 2e-5 relative); text cells (verdicts, names, models) must be equal
REPORT_RTOL = 2e-5


def _rows(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def _header(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return next(csv.reader(fh))


def _same_cells(got_path, want_path, skip=("file",)):
    """Every cell of the stored report equal in the new one: numbers to REPORT_RTOL, text exactly
    (``skip``: the columns of paths, which name the machine's folders; compared by file name).
    The stored columns come in the same order; columns added since (which model answered, risk at
    a site: blank or new facts, never a changed number) may follow them."""
    got_header, want_header = _header(got_path), _header(want_path)
    assert [c for c in got_header if c in want_header] == want_header
    got, want = _rows(got_path), _rows(want_path)
    assert len(got) == len(want)
    for g, w in zip(got, want):
        for k in w:
            a, b = g[k], w[k]
            if k in skip:
                assert pathlib.PurePath(a).name == pathlib.PurePath(b).name, k
                continue
            try:
                x, y = float(a), float(b)
            except ValueError:
                assert a == b, (w.get("record"), k, a, b)
                continue
            assert math.isclose(x, y, rel_tol=REPORT_RTOL, abs_tol=1e-12), (w.get("record"), k, a, b)


def _demo(out, *extra):
    assert main(["demo", "--jobs", "1", "--no-plots", "--quiet", "--out", str(out), *extra]) == 0


@pytest.fixture(scope="module")
def demo_runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("margin")
    _demo(root / "default")
    _demo(root / "none", "--limit", "none")
    return root / "default", root / "none"


def test_limit_none_writes_the_reports_of_the_verge_as_before(demo_runs):
    _, none = demo_runs
    for name in ("summary.csv", "design.csv"):
        _same_cells(none / name, GOLDEN / f"demo_{name.replace('.csv', '')}.csv")
    for row in _rows(none / "summary.csv"):   # each record's own report: the rows of summary.csv
        assert _header(none / f"{row['record']}.csv") == _header(none / "summary.csv")


def test_the_default_quotes_the_level_half_first_and_holds_it(demo_runs):
    default, none = demo_runs
    verge = {r["record"]: float(r["design_width_m"]) for r in _rows(none / "summary.csv")}
    with bundled_records() as paths:
        records = {pathlib.Path(p).stem: pulses.read_record(p) for p in paths}
    rows = _rows(default / "summary.csv")
    assert len(rows) == 5
    for r in rows:
        w = float(r["design_width_m"])
        assert r["design_limit"] == "0.5"
        # at least the verge in full (--limit none's design width) and the verge beside it
        assert w >= verge[r["record"]] >= float(r["overturning_width_m"])
        res = rocking.simulate(rocking.Block.from_dimensions(7.5, w), records[r["record"]])
        assert not res.overturned and res.max_rotation_ratio <= 0.5 * (1 + LEVEL_SLACK)
        assert float(r["design_max_theta_ratio"]) == pytest.approx(res.max_rotation_ratio, rel=REPORT_RTOL)
        over = rocking.simulate(rocking.Block.from_dimensions(7.5, float(r["overturning_width_m"])),
                                records[r["record"]])
        assert float(r["overturning_max_theta_ratio"]) == pytest.approx(over.max_rotation_ratio, rel=REPORT_RTOL)


def test_the_table_shows_the_verge_and_where_a_width_passes_alpha(demo_runs, capsys):
    default, none = demo_runs
    main(["demo", "--jobs", "1", "--no-plots", "--out", str(default)])   # reused: prints the table
    text = capsys.readouterr().out
    head = text.splitlines()[0]
    assert head.index("design width") < head.index("verge (no margin)") < head.index("search width")
    rows = {r["record"]: r for r in _rows(default / "design.csv")}
    lines = {line.split()[0]: line for line in text.splitlines()[2:7]}
    passing = [k for k, r in rows.items() if float(r["overturning_max_theta_ratio"]) >= 1.0]
    assert passing   # the demo's verges: 4 of 5 pass alpha (max theta/alpha 1.0004-1.009)
    for k, r in rows.items():
        cell = f"{float(r['overturning_width_m']):.3f} m, passes alpha"
        assert (cell in lines[k]) == (k in passing), k
    assert "Verge (no margin)" in text and "for max theta/alpha <= 0.5" in text
    main(["demo", "--jobs", "1", "--no-plots", "--limit", "none", "--out", str(none)])
    text = capsys.readouterr().out
    assert "verge (no margin)" not in text.splitlines()[0]
    assert "Margin: none, the design width is the verge of overturning (--limit none)" in text
    page = (default / "report.html").read_text(encoding="utf-8")
    assert "verge, no margin (m)" in page and "passes alpha" in page


@pytest.mark.slow
def test_on_real_records_limit_none_is_as_before_and_the_default_holds_the_level(tmp_path):
    if not SHARED_RECORDS.is_dir():
        pytest.skip(f"real records not available: {SHARED_RECORDS} is absent")
    paths = sorted(str(p) for p in SHARED_RECORDS.glob("*.AT2"))
    none, default = tmp_path / "none", tmp_path / "default"
    for out, extra in ((none, ["--limit", "none"]), (default, [])):
        assert main(["run", *paths, "--block", "7.5x1.8", "--no-plots", "--quiet", "--out", str(out), *extra]) == 0
    for name in ("summary", "design"):
        _same_cells(none / f"{name}.csv", GOLDEN / f"raw_{name}.csv")
    verge = {r["record"]: float(r["design_width_m"]) for r in _rows(none / "summary.csv")}
    for r in _rows(default / "summary.csv"):
        w = float(r["design_width_m"])
        assert w >= verge[r["record"]]
        res = rocking.simulate(rocking.Block.from_dimensions(7.5, w), pulses.read_record(r["file"]))
        assert not res.overturned and res.max_rotation_ratio <= 0.5 * (1 + LEVEL_SLACK), r["record"]


# -- the restitution ---------------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("name", ["Rinaldi228.AT2", "RSN77_SFERN_PUL164.AT2"])
@pytest.mark.parametrize("limit", [0.5, None])
def test_a_bands_design_width_covers_each_of_its_values(name, limit):
    rec = pulses.read_record(shared_record(name))
    band = Restitution.parse("0.95:1.05")
    kw = dict(rule="exact", limit=limit, overturning=None if limit is None else True)
    res = rocking.required_width(7.5, rec, eta=band, **kw)
    values = band.values(BAND_VALUES)
    assert res.restitution_values == tuple(values) and len(values) == BAND_VALUES
    alone = [rocking.required_width(7.5, rec, eta=v, **kw).width for v in values]
    assert list(res.restitution_widths) == alone              # each value as designed alone
    assert all(res.width >= w for w in alone) and res.width == max(alone)
    assert res.restitution_governing == values[int(np.argmax(alone))]
    assert res.eta == band and res.block.eta == pytest.approx(
        min(1.0, res.restitution_governing.low * rocking.eta_housner(res.alpha)), rel=1e-15)


def test_a_band_covers_its_values_in_slenderness_and_spectra():
    band = Restitution.parse("0.9:1.05")
    ptp, apg = [1.0, 2.0, 4.0], [0.5, 0.3, 0.5]
    covering = rocking.min_slenderness_batch("sine", ptp, apg, eta=band)
    each = [rocking.min_slenderness_batch("sine", ptp, apg, eta=v) for v in band.values(BAND_VALUES)]
    for i, c in enumerate(covering):
        assert c.tan_alpha == max(e[i].tan_alpha for e in each) and c.band_runs == BAND_VALUES
    spec = rocking.overturning_spectrum(0.2, "sine", [2.0, 4.0, 8.0], [1.0, 2.0, 3.0], eta=band)
    specs = [rocking.overturning_spectrum(0.2, "sine", [2.0, 4.0, 8.0], [1.0, 2.0, 3.0], eta=v)
             for v in band.values(BAND_VALUES)]
    assert (spec.overturned == np.logical_or.reduce([s.overturned for s in specs])).all()
    assert (spec.max_rotation_ratio == np.maximum.reduce([s.max_rotation_ratio for s in specs])).all()


def test_eq5_itself_and_an_eta_give_the_runs_of_the_plain_number():
    pulse = pulses.OneSine(0.5 * pulses.G, 1.0)
    assert (rocking.required_width(7.5, pulse, rule="exact", eta=Restitution(1.0)).width
            == rocking.required_width(7.5, pulse, rule="exact").width)
    assert (rocking.required_width(7.5, pulse, rule="exact", eta=Restitution.parse("r=0.81")).width
            == rocking.required_width(7.5, pulse, rule="exact", eta=0.9).width)
    # less restitution, more energy lost at each impact: a narrower column under this pulse
    assert (rocking.required_width(7.5, pulse, rule="exact", eta=Restitution(0.67)).width
            < rocking.required_width(7.5, pulse, rule="exact").width)


def test_a_run_with_a_restitution_names_it_and_its_eta_and_r(tmp_path):
    with bundled_records() as paths:
        out = tmp_path / "r"
        assert main(["run", paths[3], "--height", "7.5", "--shapes", "sine", "--no-plots", "--quiet",
                     "--restitution", "0.97", "--out", str(out)]) == 0
    (row,) = _rows(out / "summary.csv")
    w = float(row["design_width_m"])
    assert row["restitution"] == "0.97" and row["restitution_values_run"] == "1"
    assert row["restitution_governing"] == "0.97"
    eta = 0.97 * rocking.eta_housner(math.atan2(w, 7.5))     # a factor of Eq. 5 at the design width
    assert float(row["design_eta"]) == pytest.approx(eta, rel=REPORT_RTOL)
    assert float(row["design_r"]) == pytest.approx(eta * eta, rel=REPORT_RTOL)
    rec = pulses.read_record(paths[3])
    want = rocking.required_width(7.5, rec, rule="exact", eta=Restitution(0.97), limit=0.5, overturning=True)
    assert w == pytest.approx(want.width, rel=REPORT_RTOL)
    assert set(_header(out / "design.csv")) >= {"restitution", "restitution_governing", "design_eta", "design_r"}
    assert "`design_eta`" in (out / "columns.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("args, words", [
    (["--limit", "1.5"], "--limit"), (["--limit", "zero"], "--limit"),
    (["--restitution", "eta=1.2"], "--restitution"), (["--restitution", "0.9:0.8"], "--restitution")])
def test_bad_margin_options_are_one_line_and_exit_2(args, words, tmp_path, capsys):
    with bundled_records() as paths:
        code = main(["run", paths[0], "--height", "7.5", "--out", str(tmp_path / "x"), *args])
    err = capsys.readouterr().err.strip()
    assert code == 2 and words in err and len(err.splitlines()) == 1
    assert not (tmp_path / "x" / "summary.csv").exists()


def test_the_options_hold_a_restitution_object():
    from pipeline.cli import build_parser
    from pipeline.commands.run import options_from

    args = build_parser().parse_args(["run", "x.AT2", "--height", "7.5", "--restitution", "r=0.7:0.85",
                                      "--limit", "none"])
    opts = options_from(args)
    assert opts.restitution == Restitution(0.7, 0.85, "r") and opts.limit is None
    args = build_parser().parse_args(["run", "x.AT2", "--height", "7.5"])
    assert options_from(args).limit == 0.5 and options_from(args).restitution is None


def test_the_printed_cells_of_the_margin():
    from pipeline.reports.answer import table_text
    from pipeline.reports.design_table import design_rows

    row = {"record": "a", "pair": "a", "column": "7.5x1.8", "column_kind": "block", "direction_deg": None,
           "design_width_m": 2.0, "widest_failing_width_m": None, "overturns": False,
           "vertical_overturns": None, "width_m": 1.8, "design_adequate": False, "max_theta_ratio": 1.02,
           "search_width_m": 2.0, "check_runs": 300, "design_limit": 0.5, "overturning_width_m": 1.7,
           "design_max_theta_ratio": 0.5, "overturning_max_theta_ratio": 1.03}
    d, = design_rows([row])
    assert d["overturning_max_theta_ratio"] == 1.03 and d["verdict"] == "NO: exceeds level"
    text = table_text([d])
    line = text.splitlines()[2]
    assert "1.700 m, passes alpha" in line and line.rstrip().endswith("NO: passes alpha")
    assert "the column passes its slenderness angle on 1 of 1 row(s)" in text
    calm, = design_rows([dict(row, overturning_max_theta_ratio=0.97, max_theta_ratio=0.7)])
    assert "passes alpha" not in table_text([calm]).splitlines()[2]


def test_the_fragility_stays_collapse_unless_a_level_is_named(tmp_path):
    """The margin is the design width's: ``--fragility`` without ``--limit`` is the collapse
    fragility as before (critical scales of overturning); ``--limit R`` named asks for R's."""
    with bundled_records() as paths:
        path = paths[3]
        for name, extra in (("collapse", []), ("level", ["--limit", "0.5"])):
            assert main(["run", path, "--block", "7.5x1.8", "--shapes", "sine", "--no-plots", "--quiet",
                         "--fragility", "--up-to", "3", "--out", str(tmp_path / name), *extra]) == 0
    rec, block = pulses.read_record(path), rocking.Block.from_dimensions(7.5, 1.8)
    for name, limit in (("collapse", None), ("level", 0.5)):
        (row,) = _rows(tmp_path / name / "summary.csv")
        assert row["design_limit"] == "0.5"           # the design width is the level's either way
        want = rocking.critical_scale(block, rec, up_to=3.0, limit=limit).scale
        assert float(row["critical_scale"]) == pytest.approx(want, rel=REPORT_RTOL), name


def test_the_help_states_the_number_of_band_values():
    from pipeline.args import RESTITUTION_HELP

    # the help is written without importing rocking (the command line starts fast): said once here
    assert f"every one of {BAND_VALUES} values" in RESTITUTION_HELP
