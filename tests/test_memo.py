"""What a worker keeps between a pair's passes (pipeline/batch/memo.py, rocking/searches.py), and
the passes run on one executor: the kept search, fit and slenderness are the computed ones to the
last bit, never another record's; every pass runs in the workers under ``--jobs 2``, and so does
reading and classifying the pairs, with the same tasks."""
from __future__ import annotations

import json
import os

import numpy as np
import pytest

import pulses
import rocking
from pipeline.batch import memo
from pipeline.cli import main as cli_main
from rocking import searches
from rocking.search import DEFAULT_SETTINGS

from .test_site import H, _pair, _synthetic


@pytest.fixture
def kept():
    """Searches kept for the test only (a test process keeps none otherwise)."""
    searches.keep(8)
    yield
    searches.keep(0)


def _width(record, check_runs):
    return rocking.required_width(H, record, rule="exact",
                                  settings=DEFAULT_SETTINGS.replace(check_runs=check_runs))


def _same(a, b):
    for name in ("width", "search_width", "transitions", "runs", "iterations", "method", "check_runs",
                 "widest_failing_width", "failing_share"):
        assert getattr(a, name) == getattr(b, name), name
    assert np.array_equal(np.asarray(a.check_widths), np.asarray(b.check_widths))


def test_a_kept_search_gives_the_computed_answer_with_and_without_its_check(kept):
    record = _synthetic(0.4, 3)
    fresh_search, fresh_checked = _width(record, 0), _width(record, 300)
    searches.keep(0)
    searches.keep(8)
    first = _width(record, 0)           # computed and kept
    again = _width(record, 300)         # the kept search, then its check
    _same(first, fresh_search)
    _same(again, fresh_checked)
    assert again.check_runs > 0 and first.check_runs == 0
    # a copy: the check run on the kept search did not change what is kept
    _same(_width(record, 0), fresh_search)


def test_a_kept_search_is_never_another_records(kept):
    record = _synthetic(0.4, 3)
    _width(record, 0)
    other = pulses.Record(record.acc * 1.5, record.dt, record.name, record.t_start, record.metadata)
    searches.keep(0)
    fresh = _width(other, 0)
    searches.keep(8)
    _width(record, 0)
    _same(_width(other, 0), fresh)      # not the kept one: its samples differ
    assert _width(other, 0).width != _width(record, 0).width


def test_the_memo_hands_out_copies_of_what_it_computed():
    memo.on()
    try:
        _copies()
    finally:
        memo.off()
    # off: computed every time
    calls = []
    for _ in range(2):
        memo.remembered("fit", "k", lambda: calls.append(1))
    assert len(calls) == 2


def _copies():
    calls = []
    key = ("test", np.random.default_rng(5).random())

    def compute():
        calls.append(1)
        return {"a": [1.0, 2.0]}

    first = memo.remembered("fit", key, compute)
    first["a"].append(3.0)              # the caller's copy only
    assert memo.remembered("fit", key, compute) == {"a": [1.0, 2.0]} and len(calls) == 1


def test_every_pass_runs_in_the_workers_and_logs_its_cpu(tmp_path):
    pair = _pair(tmp_path, "STW", 0.45, 0.3, 1)
    log = tmp_path / "log.jsonl"
    code = cli_main(["run", "--pair", *map(str, pair), "--block", "2.0x0.35", "--directions", "4",
                     "--jobs", "2", "--out", str(tmp_path / "out"), "--quiet", "--log", str(log)])
    assert code == 0
    entries = [json.loads(line) for line in log.read_text().splitlines()]
    assert len(entries) > 6            # 6 directions, some computed again in a later pass
    here = f":{os.getpid()}"
    assert not [e for e in entries if e["worker"].endswith(here)]
    assert all(e["cpu_seconds"] > 0 and e["stages"]["verify:required_width"] > 0 for e in entries)


def test_under_jobs_the_main_process_draws_no_figure_and_never_imports_matplotlib(tmp_path):
    """With workers, the run's own figures (summary, suite) are drawn in a worker too, asked for by
    name: the main process never imports matplotlib (half a second, most of its own CPU)."""
    import subprocess
    import sys

    pair = _pair(tmp_path, "STF", 0.45, 0.3, 1)
    code = ("import sys\nfrom pipeline.cli import main\n"
            f"c = main(['run', '--pair', {str(pair[0])!r}, {str(pair[1])!r}, '--block', '2.0x0.35', "
            f"'--directions', '2', '--jobs', '2', '--quiet', '--out', {str(tmp_path / 'out')!r}])\n"
            "print(c, 'matplotlib' in sys.modules)\n")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert res.stdout.split()[-2:] == ["0", "False"], res.stdout + res.stderr
    for name in ("summary.png", "suite.png"):
        assert (tmp_path / "out" / "plots" / name).read_bytes()[:4] == b"\x89PNG"


def test_pairs_read_and_classified_in_workers_give_the_same_tasks(tmp_path):
    from pipeline.batch.pairs import pair_tasks
    from pipeline.batch.tasks import Column, Options

    pairs = [_pair(tmp_path, "STA", 0.45, 0.3, 1), _pair(tmp_path, "STB", 0.3, 0.4, 7),
             [tmp_path / "missing_1.sac", tmp_path / "missing_2.sac"]]  # unreadable: one failing task

    def tasks(jobs):
        got = pair_tasks([], [tuple(map(str, p)) for p in pairs], "none", [Column(2.0, 0.35)], Options(),
                         n_directions=3, say=lambda msg: None, jobs=jobs)
        return [(t.record_id, t.path, t.path2, t.direction, t.direction_kind, t.pair, t.pair_fields)
                for t in got]

    here = tasks(None)
    assert here == tasks(2)
    # each readable pair in its components, its pulse's direction and normal and 3 more; the
    # pair fields (its classification) carried alike
    assert len(here) > 10 and sum(t[4] == "pulse" for t in here) == 2
    assert all(dict(t[6]).get("pulse_like") is not None for t in here if t[5].startswith("STA"))
    assert sum(1 for t in here if t[5].startswith("missing")) == 1


def test_a_run_in_this_process_keeps_nothing_after_it(tmp_path):
    pair = _pair(tmp_path, "STS", 0.45, 0.3, 1)
    code = cli_main(["run", "--pair", *map(str, pair), "--block", "2.0x0.35", "--directions", "2",
                     "--out", str(tmp_path / "out"), "--quiet", "--no-plots"])
    assert code == 0
    # a later rocking.required_width in this process computes (a test may have changed the solver)
    assert searches._size == 0 and not searches._kept and not memo._kept


@pytest.mark.slow
def test_a_level_and_its_overturning_design_are_both_kept_between_passes(kept, monkeypatch):
    """`pipeline run --limit`'s design of a column (pipeline.batch.record.design_width): a later
    pass (the check on) finds both searches, the overturning design's and the level's, kept from
    the first pass (no search runs again), and answers as a fresh computation."""
    from pipeline.batch.widths import design_width
    from rocking import widths

    record = _synthetic(0.4, 3)
    first_pass, later = DEFAULT_SETTINGS.replace(check_runs=0), DEFAULT_SETTINGS
    searches.keep(0)
    fresh = design_width(record, None, H, 0.0, 0.5, later)
    searches.keep(8)
    calls = []
    real = widths._record_search
    monkeypatch.setattr(widths, "_record_search", lambda *a, **k: calls.append(k.get("criterion")) or real(*a, **k))
    design_width(record, None, H, 0.0, 0.5, first_pass)
    assert len(calls) == 2                       # the overturning design's search and the level's
    again = design_width(record, None, H, 0.0, 0.5, later)
    assert len(calls) == 2                       # both kept
    _same(again, fresh)
    assert again.overturning_width == fresh.overturning_width and again.check_runs > 0


def test_a_pair_is_read_once_per_worker_and_again_once_its_file_changes(tmp_path, monkeypatch):
    """A pair's directions read its two files once (kept by path, size, time and inode); a file
    written since is read again, and the records are the file's as it is then."""
    from types import SimpleNamespace

    from pipeline.batch.read import read_task
    from pipeline.batch.tasks import ReadOptions

    a, b = _pair(tmp_path, "STM", 0.45, 0.3, 3)
    calls = []
    real = pulses.read_pair
    monkeypatch.setattr(pulses, "read_pair", lambda *p, **k: calls.append(p) or real(*p, **k))
    opts = SimpleNamespace(read=ReadOptions(), vertical="auto")
    task = lambda d: SimpleNamespace(peer=None, options=opts, path=a, path2=b, direction=d, scale=1.0,  # noqa: E731
                                     vertical=None)
    memo.on()
    try:
        r0, r30 = read_task(task(0.0))[0], read_task(task(30.0))[0]
        assert len(calls) == 1
        assert np.array_equal(r30.acc, pulses.component(*real(a, b), 30.0).acc)
        rec = pulses.read_record(a)
        pulses.write_sac(pulses.Record(2.0 * rec.acc, rec.dt, rec.name, 0.0, rec.metadata), a)
        os.utime(a, ns=(os.stat(a).st_atime_ns, os.stat(a).st_mtime_ns + 10**9))
        r0_new = read_task(task(0.0))[0]
        assert len(calls) == 2
        # the first component doubled, as written (0 degrees is the first file's azimuth)
        np.testing.assert_allclose(r0_new.acc, 2.0 * r0.acc, rtol=1e-6)
    finally:
        memo.off()


def test_blocks_are_the_blocks_of_their_dimensions_and_run_alike():
    """rocking.Blocks (a search's widths as arrays) holds Block.from_dimensions's numbers to the
    last bit, and simulate_many gives the same results bit for bit."""
    widths = np.geomspace(0.2, 2.0, 17)
    for gamma in (0.0, 0.7):
        many = rocking.Blocks.from_dimensions(7.5, widths, cap_mass_ratio=gamma)
        one = [rocking.Block.from_dimensions(7.5, float(w), cap_mass_ratio=gamma) for w in widths]
        assert list(many) == one
        assert [b.eta for b in many] == [b.eta for b in one]
        rec = _synthetic(0.4, 5)
        x, y = rocking.simulate_many(many, rec), rocking.simulate_many(one, rec)
        assert np.array_equal(x.overturned, y.overturned)
        assert np.array_equal(x.max_rotation, y.max_rotation)
    with pytest.raises(ValueError, match="positive and finite"):
        rocking.Blocks.from_dimensions(7.5, [1.0, -1.0])
