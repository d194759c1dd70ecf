"""``pipeline.design``: the batch from Python gives ``pipeline run``'s tables (same rows, same
numbers as its CSV files, cell by cell), refuses wrong argument types naming the accepted forms, and
lists a missing or unreadable file as a failure."""
from __future__ import annotations

import csv
import pathlib

import pytest

import pipeline
import rocking
from pipeline.reports import cells
from pipeline.batch.margin import DEFAULT_LIMIT
from pipeline.batch.row import FIELDS, fields_for
from pipeline.batch.tasks import Options
from pipeline.cli import main
from pipeline.commands.demo import bundled_records
from pipeline.plan import _limit, _restitution, plan_from
from pipeline.reports.design_table import DESIGN_FIELDS, design_columns

from .vertical_cases import DOWNLOAD

#: the cheap batch of these tests: one shape (the rules are the same for every set of shapes)
CHEAP = ["--shapes", "sine", "--no-plots", "--quiet"]


def _cells(path) -> list[list[str]]:
    with open(path, newline="", encoding="utf-8") as fh:
        return list(csv.reader(fh))


def _frame_cells(df, fields) -> list[list[str]]:
    """A DataFrame's cells as the CSV writer formats them (cells.fmt), under the header."""
    import math

    def cell(v):
        return "" if v is None or (isinstance(v, float) and math.isnan(v)) else cells.fmt(v)

    assert list(df.columns) == list(fields)
    return [list(fields)] + [[cell(v) for v in row] for row in df.itertuples(index=False)]


def _same_as_cli(tmp_path, inputs, cli_args, **kw):
    """Run ``pipeline run`` and :func:`pipeline.design` on the same inputs; compare design.csv and
    summary.csv with the DataFrames, every cell as text (the CSV's 6 significant digits are the
    numbers both are made from: equal text is equal to the last digit)."""
    out = tmp_path / "cli"
    code = main(["run", *map(str, inputs), *cli_args, "--out", str(out)])
    run = pipeline.design(inputs, **kw)
    assert run.exit_code == code
    # the columns of the run's options: a level's margin (the default), a restitution's
    opts = Options(limit=_limit(kw.get("limit", DEFAULT_LIMIT)),
                   restitution=_restitution(kw.get("restitution")))
    design_fields = [n for n, _, _ in design_columns(opts.limit is not None, opts.restitution is not None)]
    assert _frame_cells(run.design, design_fields) == _cells(out / "design.csv")
    assert _frame_cells(run.summary, fields_for(opts)) == _cells(out / "summary.csv")
    assert len(run.failures) == len(_cells(out / "failures.csv")) - 1
    return run


def test_the_demo_records_give_pipeline_runs_design_csv(tmp_path):
    with bundled_records() as paths:
        run = _same_as_cli(tmp_path, paths, ["--block", "7.5x1.8", "--height", "12", *CHEAP],
                           blocks="7.5x1.8", heights=12.0, shapes="sine")
    assert len(run.design) == 10 and run.failures.empty  # 5 records x 2 columns
    assert set(run.suite["column"]) == {"7.5x1.8", "12"}


def test_a_performance_level_flows_through(tmp_path):
    with bundled_records() as paths:
        run = _same_as_cli(tmp_path, paths[2:4], ["--height", "7.5", "--limit", "0.5", *CHEAP],
                           heights=7.5, limit=0.5, shapes="sine")
    assert list(run.design["design_limit"]) == [0.5, 0.5]


def test_the_verge_alone_has_the_columns_of_every_run(tmp_path):
    with bundled_records() as paths:
        run = _same_as_cli(tmp_path, paths[2:4], ["--height", "7.5", "--limit", "none", *CHEAP],
                           heights=7.5, limit=None, shapes="sine")
    assert list(run.summary.columns) == FIELDS and list(run.design.columns) == DESIGN_FIELDS
    assert run.design["design_limit"].isna().all() and run.design["overturning_width_m"].isna().all()


def test_a_restitution_band_flows_through(tmp_path):
    from rocking.band import BAND_VALUES
    from rocking.restitution import Restitution

    with bundled_records() as paths:
        run = _same_as_cli(tmp_path, paths[3:4], ["--height", "7.5", "--restitution", "0.95:1.05", *CHEAP],
                           heights=7.5, restitution="0.95:1.05", shapes="sine")
    row = run.summary_rows[0]
    assert row["restitution"] == "0.95:1.05" and row["restitution_values_run"] == BAND_VALUES
    widths = [float(p.split("=")[1]) for p in row["restitution_design_widths_m"].split("; ")]
    assert len(widths) == BAND_VALUES and row["design_width_m"] == max(widths)
    assert plan_from([], blocks=None, heights=7.5, pairs=None, directions=0, vertical="auto", limit=0.5,
                     restitution="eta=0.9", jobs=1, out=None, shapes=None, weighting="background",
                     units=None, dt=None, scale=None, plots=None, force=False, thorough=False,
                     quiet=True).options.restitution == Restitution(0.9, kind="eta")


@pytest.mark.slow
def test_the_demo_with_every_shape_and_two_jobs(tmp_path):
    with bundled_records() as paths:
        block = rocking.Block.from_dimensions(7.5, 1.8)
        _same_as_cli(tmp_path, paths, ["--block", "7.5x1.8", "--no-plots", "--quiet"], blocks=block, jobs=2)


@pytest.mark.slow
def test_a_peer_download_gives_pipeline_runs_design_csv(tmp_path):
    if not DOWNLOAD.is_dir():
        pytest.skip(f"the PEER download is absent: {DOWNLOAD}")
    run = _same_as_cli(tmp_path, [DOWNLOAD], ["--block", "6x1.5", *CHEAP], blocks=[(6, 1.5)], shapes=["sine"])
    assert len(run.design) >= 3 and run.design["n_directions"].min() >= 4  # pairs in every direction


def test_the_forms_of_a_column():
    from pipeline.plan import columns_from
    from pipeline.batch.tasks import Column

    block = rocking.Block.from_dimensions(7.5, 1.8)
    want = (Column(7.5, 1.8),)
    for blocks in ("7.5x1.8", (7.5, 1.8), [(7.5, 1.8)], block, [block, "7.5x1.8"], ("7.5x1.8",)):
        assert columns_from(blocks, None) == want, blocks
    assert columns_from(("7.5x1.8", (6, 1.2)), (12, 4.5)) == (want[0], Column(6.0, 1.2), Column(12.0), Column(4.5))
    assert columns_from(None, 12) == columns_from(None, [12.0]) == (Column(12.0),)


def test_out_none_writes_nothing_and_out_writes_the_reports(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with bundled_records() as paths:
        run = pipeline.design(paths[1:2], blocks="7.5x1.8", shapes="sine")
        assert run.out is None and list(tmp_path.iterdir()) == []
        run2 = pipeline.design(paths[1:2], blocks="7.5x1.8", shapes="sine", out=tmp_path / "o", plots=False)
    assert (tmp_path / "o" / "design.csv").is_file() and run2.out == tmp_path / "o"
    assert run.design.equals(run2.design)
    import json

    d = json.loads(json.dumps(run.as_dict(), allow_nan=False))  # plain data, no NaN
    assert d["design"][0]["design_width_m"] == run.design_rows[0]["design_width_m"] and d["out"] is None


def test_not_quiet_prints_pipeline_runs_table_and_names_no_private_folder(tmp_path, capsys):
    with bundled_records() as paths:
        pipeline.design(paths[3:4], heights=7.5, shapes="sine", quiet=False)
        api_out = capsys.readouterr().out
        main(["run", paths[3], "--height", "7.5", "--shapes", "sine", "--no-plots", "--out", str(tmp_path)])
        cli_out = capsys.readouterr().out
    assert "synth_sine_055g_0.9s" in api_out and "pipeline-design." not in api_out
    assert cli_out.startswith(api_out)  # the command line's table, then its line about the run


def test_a_missing_or_unreadable_file_is_a_failures_row(tmp_path):
    bad = tmp_path / "garbage.at2"
    bad.write_text("not a record\n")
    with bundled_records() as paths:
        run = pipeline.design([paths[1], tmp_path / "missing.sac", bad], blocks="7.5x1.8", shapes="sine")
    assert run.exit_code == 1 and len(run.design) == 1
    assert sorted(run.failures["record"]) == ["garbage", "missing"]
    assert set(run.failures["stage"]) == {"read"} and run.failures["reason"].str.len().min() > 10


@pytest.mark.parametrize("kw, error, words", [
    (dict(records=3.5, blocks="7.5x1.8"), TypeError, "path (str or os.PathLike)"),
    (dict(records=[b"a.sac"], blocks="7.5x1.8"), TypeError, "path (str or os.PathLike)"),
    (dict(blocks=7.5), TypeError, "rocking.Block, a 'HxW' string"),
    (dict(blocks=["7.5x1.8", {"h": 7.5}]), TypeError, "(height, width) pair"),
    (dict(blocks=(7.5, "1.8")), TypeError, "rocking.Block"),
    (dict(heights="7.5"), TypeError, "numbers (the column's full height in m)"),
    (dict(heights=[True]), TypeError, "numbers"),
    (dict(blocks="7.5x1.8", pairs=[("a.sac",)]), TypeError, "(A, B) pairs or (A, B, V) triplets"),
    (dict(blocks="7.5x1.8", pairs="both"), ValueError, "'auto', 'none'"),
    (dict(blocks="7.5x1.8", jobs=1.5), TypeError, "whole number of processes"),
    (dict(blocks="7.5x1.8", jobs=-1), ValueError, "0 (one per CPU)"),
    (dict(blocks="7.5x1.8", vertical=True), TypeError, "'auto', 'none'"),
    (dict(blocks="7.5x1.8", out=5), TypeError, "folder path"),
    (dict(blocks="7.5x1.8", shapes=[1]), TypeError, "shape name"),
    (dict(blocks="7.5x1.8", shapes="square"), ValueError, "choose from"),
    (dict(blocks="7.5x-1.8"), ValueError, "width"),
    (dict(), ValueError, "give at least one column"),
    (dict(blocks="7.5x1.8", colour="red"), TypeError, "accepted besides"),
    (dict(blocks="7.5x1.8", limit="0.5"), TypeError, "expected a number"),
    (dict(blocks="7.5x1.8", limit=1.5), ValueError, "(0, 1]"),
    (dict(blocks=rocking.Block(p=2.0, alpha=0.2)), ValueError, "Block.from_dimensions"),
])
def test_wrong_inputs_name_the_accepted_forms(kw, error, words, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    kw.setdefault("records", [tmp_path / "none.sac"])
    with pytest.raises(error) as info:
        pipeline.design(**kw)
    assert words in str(info.value)
    assert list(tmp_path.iterdir()) == []  # refused before any work


def test_import_pipeline_stays_light():
    import subprocess
    import sys

    code = "import sys, pipeline; pipeline.design; print('numpy' in sys.modules, 'pandas' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"]


def test_a_loop_with_the_governing_pulse_gives_pipeline_runs_eq31_widths():
    """rocking.governing_pulse is the command line's rule: a loop over fit_pulse gives design.csv's
    governing shape, ap, Tp and Eq. 31 width (as the CSV prints them: 6 significant digits)."""
    import pulses

    with bundled_records() as paths:
        run = pipeline.design(paths, heights=7.5)
        rows = []
        for path in paths:
            gov = rocking.governing_pulse(pulses.fit_pulse(pulses.read_record(path)), 7.5)
            rows.append([gov.candidate.shape, cells.fmt(gov.candidate.ap_g), cells.fmt(gov.candidate.tp),
                         cells.fmt(gov.width)])
        # the best fit alone is not the rule: on the demo it gives another shape on some record
        best = [pulses.fit_pulse(pulses.read_record(p)).best.shape for p in paths]
    table = run.design[["governing_shape", "governing_ap_g", "governing_tp_s", "eq31_width_m"]]
    assert [[r[0]] + [cells.fmt(x) for x in r[1:]] for r in table.itertuples(index=False)] == rows
    assert best != [r[0] for r in rows]


def test_the_runner_refuses_columns_that_are_not_columns(tmp_path):
    """The issue's first finding: runner.run(paths, ["9"], out) wrote a header-only design.csv and
    an internal AttributeError per record; now a TypeError pointing to pipeline.design."""
    from pipeline.batch.runner import run

    with pytest.raises(TypeError, match=r"pipeline.design\(records, blocks="):
        run([tmp_path / "a.sac"], ["9"], tmp_path / "out")
    assert not (tmp_path / "out").exists()
