"""Safe batches, second round: concurrent runs, full disks, outputs onto inputs, broken folder
entries, scales, pairs of one file, links out of ``--out``, and the smaller wrongs.

Each test reproduces its case first (as the issue ran it on the earlier code) and then checks that
nothing is lost, overwritten or deleted outside the run's own outputs, that the folder is usable by
the next run, and that the status and the message are clear.
"""
from __future__ import annotations

import errno
import os
import re
import signal
import subprocess
import sys
import time

import pytest

from pipeline.reports import files, outfiles

from pipeline.batch import resume
from pipeline.cli import main

from .test_pipeline_run import SAFE_ARGS, read_csv, tree, write_good


def _one_line_error(capsys, command="run"):
    err = capsys.readouterr().err.strip()
    assert err.startswith(f"pipeline {command}: error:") and "\n" not in err, err
    return err


# -- 1. two runs into one --out at once -----------------------------------------------------------
@pytest.fixture(scope="module")
def recs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("safety2-in")
    return [str(write_good(folder, k, duration=6.0)) for k in range(10)]


@pytest.fixture(scope="module")
def alone(recs, tmp_path_factory):
    """The reports of one run alone."""
    out = tmp_path_factory.mktemp("safety2-alone")
    assert main(["run", *recs, *SAFE_ARGS, "--out", str(out)]) == 0
    return tree(out)


@pytest.mark.slow
def test_a_second_run_into_a_busy_out_is_refused_and_nothing_is_lost(recs, alone, tmp_path):
    """Two real processes into one --out: the second is refused at once (exit 2, one line), the
    first finishes as if alone, and the folder is usable by the next run."""
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "pipeline", "run", *recs, *SAFE_ARGS, "--out", str(out)]
    first = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    # the first run holds the folder once it has written its first report
    while time.time() < deadline and not (out / outfiles.MANIFEST).exists() and first.poll() is None:
        time.sleep(0.02)
    # stopped halfway (SIGSTOP), so that the second surely runs while the first is in the folder
    first.send_signal(signal.SIGSTOP)
    try:
        second = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    finally:
        first.send_signal(signal.SIGCONT)
    _, err1 = first.communicate(timeout=300)
    assert first.returncode == 0, err1
    assert second.returncode == 2, second.stderr
    err = second.stderr.strip()
    assert err.startswith("pipeline run: error: --out") and "in use by another pipeline run" in err
    assert "\n" not in err
    assert tree(out) == alone  # nothing lost: the first run's reports are whole
    assert main(["run", *recs, *SAFE_ARGS, "--out", str(out)]) == 0  # the folder is usable
    assert tree(out) == alone


def test_the_lock_goes_with_the_run(recs, tmp_path, capsys):
    """Held: refused; released (the run ended): the next run goes on."""
    from pipeline.batch import outlock

    out = tmp_path / "out"
    out.mkdir()
    with outlock.locked(out):
        assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 2
        assert "in use by another pipeline run" in _one_line_error(capsys)
        assert os.listdir(out) == []  # refused before anything is written
    assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 0


# -- 2. a run started on a full disk ----------------------------------------------------------------
@pytest.mark.parametrize("left", [b"", files._MANIFEST_HEADER.encode()[:17]], ids=["empty", "cut"])
@pytest.mark.parametrize("name", [outfiles.MANIFEST, resume.RESUME])
def test_an_empty_or_cut_journal_does_not_lock_the_folder(name, left, recs, tmp_path):
    """What a full disk leaves (a 0-byte manifest, a header cut short) holds nothing: the next run
    goes on and writes whole journals; a file that is not one of ours is still refused."""
    out = tmp_path / "out"
    out.mkdir()
    header = (files._MANIFEST_HEADER if name == outfiles.MANIFEST else resume._HEADER).encode()
    (out / name).write_bytes(left if name == outfiles.MANIFEST else header[:len(left)])
    assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 0
    text = (out / name).read_bytes()
    assert text.startswith(header) and len(text.splitlines()) >= 2
    assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 0
    (out / name).write_text("my notes\n")  # not ours: left as it is, the folder refused
    assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 2
    assert (out / name).read_text() == "my notes\n"


def test_append_to_a_cut_journal_starts_it_again(tmp_path):
    path = tmp_path / "j.txt"
    path.write_bytes(b"# head")
    files.append_line(path, "# header\n", "a line\n")
    assert path.read_text() == "# header\na line\n"
    files.append_line(path, "# header\n", "b\n")
    assert path.read_text() == "# header\na line\nb\n"


def test_a_full_disk_error_names_the_file(recs, tmp_path, monkeypatch, capsys):
    """ENOSPC from a write says no file name; the message does."""
    def full(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files.os, "replace", full)
    with pytest.raises(OSError, match="No space left on device: .*summary.csv"):
        files.write_atomic(tmp_path / "summary.csv", "x\n")
    assert os.listdir(tmp_path) == []  # no temporary file left
    monkeypatch.undo()

    real_fdopen = os.fdopen

    class Full:
        def __init__(self, fh):
            self.fh = fh

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            self.fh.close()

        def __getattr__(self, name):
            return getattr(self.fh, name)

        def write(self, data):
            raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(files.os, "fdopen", lambda *a, **k: Full(real_fdopen(*a, **k)))
    out = tmp_path / "out"
    code = main(["run", recs[0], *SAFE_ARGS, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1 and "No space left on device" in err and outfiles.MANIFEST in err, err
    monkeypatch.undo()
    assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 0  # space freed: usable


# -- 3. outputs checked against inputs, the run's own files and users' files ---------------------------
def test_classify_csv_never_replaces_a_record(tmp_path, capsys):
    """``classify --csv a.sac b.sac`` (a forgotten file name) replaced the record a.sac with a CSV."""
    a, b = write_good(tmp_path, 1), write_good(tmp_path, 2)
    before = a.read_bytes()
    assert main(["classify", "--csv", str(a), str(b)]) == 2
    assert "exists and was not written by pipeline classify" in _one_line_error(capsys, "classify")
    assert a.read_bytes() == before
    link = tmp_path / "link.csv"  # the input by another name
    link.symlink_to(b)
    assert main(["classify", str(b), "--csv", str(link)]) == 2
    assert "is one of the input records" in _one_line_error(capsys, "classify")
    # its own CSV is replaced by the next run, as before
    table = tmp_path / "table.csv"
    assert main(["classify", str(a), str(b), "--pairs", "none", "--csv", str(table)]) == 0
    first = table.read_text()
    assert main(["classify", str(a), "--csv", str(table)]) == 0
    assert table.read_text() != first and len(read_csv(table)) == 1


def test_run_log_never_onto_an_input_or_the_runs_own_files(tmp_path, capsys):
    a, b = write_good(tmp_path, 1), write_good(tmp_path, 2)
    before = a.read_bytes()
    out = tmp_path / "out"
    assert main(["run", str(b), *SAFE_ARGS, "--log", str(a), "--out", str(out)]) == 2
    assert "exists and was not written by pipeline run" in _one_line_error(capsys)
    assert main(["run", str(a), str(b), *SAFE_ARGS, "--log", str(a), "--out", str(out)]) == 2
    assert "is one of the input records" in _one_line_error(capsys)
    assert a.read_bytes() == before
    for own in (outfiles.SUMMARY, "good02.csv", outfiles.MANIFEST):
        assert main(["run", str(b), *SAFE_ARGS, "--log", str(out / own), "--out", str(out)]) == 2
        assert "one of this run's own outputs" in _one_line_error(capsys)
    assert not out.exists() or not any(out.iterdir())  # refused before anything was written
    log = out / "run.log"  # a log of its own beside the reports is fine, and appended to
    for _ in range(2):
        assert main(["run", str(b), *SAFE_ARGS, "--log", str(log), "--out", str(out)]) == 0
    assert [line.count('"record"') for line in log.read_text().splitlines()] == [1, 1]
    assert main(["run", str(b), *SAFE_ARGS, "--out", str(out)]) == 0  # the folder is usable


@pytest.mark.slow
def test_classify_plot_never_replaces_a_users_png(tmp_path, capsys):
    """``classify --plot DIR`` replaced a user's PNG of the same name; now only its own PNGs."""
    a = write_good(tmp_path, 1)
    plots = tmp_path / "plots"
    plots.mkdir()
    mine = plots / "good01.png"
    mine.write_bytes(b"\x89PNG\r\n\x1a\nmy own picture")
    assert main(["classify", str(a), "--plot", str(plots)]) == 1
    err = capsys.readouterr().err
    assert "good01.png exists and was not written by this package" in err
    assert mine.read_bytes() == b"\x89PNG\r\n\x1a\nmy own picture"
    mine.unlink()
    assert main(["classify", str(a), "--plot", str(plots)]) == 0
    drawn = mine.read_bytes()
    from pipeline.reports.outpaths import is_ours

    assert is_ours(mine, "png") and drawn.startswith(b"\x89PNG")
    assert main(["classify", str(a), "--plot", str(plots)]) == 0  # its own: replaced
    assert mine.read_bytes() == drawn


def test_every_command_checks_its_file_outputs_the_same_way(tmp_path, capsys, monkeypatch):
    """fit, simulate, spectrum, chart: --csv and --plot over a file they did not write, or onto
    their input, are refused in one line; ``--out ""`` (it wrote into the current folder) too;
    convert never writes onto an input."""
    monkeypatch.chdir(tmp_path)  # where --out "" wrote
    a = write_good(tmp_path, 1)
    before = a.read_bytes()
    notes = tmp_path / "notes.txt"
    notes.write_text("my notes\n")
    cases = [
        ("fit", ["fit", str(a), "--shapes", "sine", "--csv", str(a)]),
        ("fit", ["fit", str(a), "--shapes", "sine", "--csv", str(notes)]),
        ("simulate", ["simulate", "--block", "7.5x1.8", "--record", str(a), "--csv", str(a)]),
        ("simulate", ["simulate", "--block", "7.5x1.8", "--record", str(a), "--plot", str(notes)]),
        ("spectrum", ["spectrum", "--alpha", "14deg", "--grid", "3x3", "--csv", str(notes)]),
        ("chart", ["chart", "--pulse", "sine", "--ptp", "2", "--apg", "1", "--plot", str(notes)]),
        ("run", ["run", str(a), *SAFE_ARGS, "--out", ""]),
    ]
    for command, argv in cases:
        assert main(argv) == 2, argv
        _one_line_error(capsys, command)
    assert a.read_bytes() == before and notes.read_text() == "my notes\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["good01.sac", "notes.txt"]
    assert main(["convert", str(a), "--to", "sac", "--out", str(tmp_path)]) == 1  # good01.sac is a
    assert "is one of the input records" in capsys.readouterr().err
    assert a.read_bytes() == before


# -- 4. folder inputs: broken entries are failed records, never skipped -----------------------------
@pytest.mark.slow
def test_broken_entries_of_a_folder_are_failed_records(tmp_path, capsys):
    """A dangling link and a link loop in a folder were skipped (exit 0); given by a glob they failed.
    Now both ways give the same failed records, with the reason."""
    recs = tmp_path / "recs"
    recs.mkdir()
    write_good(recs, 1)
    (recs / "gone.sac").symlink_to(tmp_path / "nowhere.sac")
    (recs / "loop1.sac").symlink_to(recs / "loop2.sac")
    (recs / "loop2.sac").symlink_to(recs / "loop1.sac")
    (recs / "sub").mkdir()  # a folder inside: not a record (folders give the files directly in them)
    out = tmp_path / "out"
    assert main(["run", str(recs), *SAFE_ARGS, "--out", str(out)]) == 1
    fails = {f["record"]: f for f in read_csv(out / "failures.csv")}
    assert sorted(fails) == ["gone", "loop1", "loop2"]
    assert all(f["stage"] == "read" for f in fails.values())
    assert "symbolic link to a file that does not exist" in fails["gone"]["reason"]
    assert "loop of symbolic links" in fails["loop1"]["reason"]
    assert [r["record"] for r in read_csv(out / "summary.csv")] == ["good01"]
    by_glob = tmp_path / "out2"
    assert main(["run", *sorted(str(p) for p in recs.glob("*.sac")), *SAFE_ARGS, "--out", str(by_glob)]) == 1
    assert read_csv(by_glob / "failures.csv") == read_csv(out / "failures.csv")


def test_a_folder_that_cannot_be_listed_fails_alone(tmp_path, monkeypatch):
    """An unreadable folder stopped the whole batch with no failures.csv; now it is one failed
    record and the others are processed."""
    import pipeline.batch.runner as runner_module

    good = tmp_path / "good"
    good.mkdir()
    write_good(good, 1)
    shut = tmp_path / "shut"
    shut.mkdir()
    real = os.listdir

    def listdir(path="."):
        if os.path.abspath(path) == str(shut):
            raise PermissionError(errno.EACCES, "Permission denied", str(path))
        return real(path)

    monkeypatch.setattr(os, "listdir", listdir)
    assert runner_module.expand_inputs([str(shut), str(good)]) == [str(shut), str(good / "good01.sac")]
    out = tmp_path / "out"
    assert main(["run", str(shut), str(good), *SAFE_ARGS, "--out", str(out)]) == 1
    fails = read_csv(out / "failures.csv")
    assert [(f["record"], f["stage"]) for f in fails] == [("shut", "read")]
    assert "cannot be listed: Permission denied" in fails[0]["reason"]
    assert [r["record"] for r in read_csv(out / "summary.csv")] == ["good01"]


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0,
                    reason="permissions do not apply to root: the monkeypatched test above covers it")
def test_files_of_a_folder_without_search_permission_are_failed_records(tmp_path):
    recs = tmp_path / "recs"
    recs.mkdir()
    write_good(recs, 1)
    recs.chmod(0o600)  # names can be listed, files not looked at
    try:
        out = tmp_path / "out"
        assert main(["run", str(recs), *SAFE_ARGS, "--out", str(out)]) == 1
        fails = read_csv(out / "failures.csv")
        assert [(f["record"], f["stage"]) for f in fails] == [("good01", "read")]
        assert "Permission denied" in fails[0]["reason"]
    finally:
        recs.chmod(0o700)


# -- 5. one range rule for every way a scale reaches a record -----------------------------------------
@pytest.mark.parametrize("table", ["record,scale\ngood01,1e6\n", "record,scale\ngood01,1e-9\n",
                                   "record,scale\ngood01,nan\n", "record,scale\ngood01,-2\n",
                                   "record,scale\ngood01,2\ngood01,3\n",
                                   "record,scale\ngood01,2\ngood01.sac,3\n"],
                         ids=["huge", "tiny", "nan", "negative", "twice", "two-names"])
def test_scales_obey_the_scale_rule(table, tmp_path, capsys, monkeypatch):
    """--scales 1e6 ran to the end at 874,060 g (exit 0), 1e-9 failed deep inside after 18 s; rows
    for one record were resolved silently.  Now each is refused at once, in one line."""
    from pipeline.batch import worker

    def no_work(task):
        raise AssertionError("a record was processed")

    monkeypatch.setattr(worker, "process_record", no_work)
    a = write_good(tmp_path, 1)
    scales = tmp_path / "scales.csv"
    scales.write_text(table)
    out = tmp_path / "out"
    assert main(["run", str(a), *SAFE_ARGS, "--scales", str(scales), "--out", str(out)]) == 2
    err = _one_line_error(capsys)
    assert "must lie between 0.001 and 1000" in err or "two rows for good01" in err or "several scales" in err
    assert not out.exists()


def test_scale_options_share_the_rule(tmp_path, capsys):
    a = write_good(tmp_path, 1)
    for argv in (["run", str(a), *SAFE_ARGS, "--scale", "1e6"], ["run", str(a), *SAFE_ARGS, "--scale", "1e-9"],
                 ["run", str(a), *SAFE_ARGS, "--fragility", "--up-to", "1e6"],
                 ["simulate", "--block", "7.5x1.8", "--record", str(a), "--scale", "1e6"],
                 ["simulate", "--block", "7.5x1.8", "--record", str(a), "--scale=-1e-9"]):
        assert main([*argv, "--out", str(tmp_path / "o")] if argv[0] == "run" else argv) == 2, argv
        assert "must lie" in _one_line_error(capsys, argv[0])


# -- 6. --pair A A ------------------------------------------------------------------------------------
def test_a_pair_of_one_file_is_refused(tmp_path, capsys):
    """``--pair A A`` was designed as a pair (45 deg: the file times sqrt 2; 135 deg: zeros)."""
    a = write_good(tmp_path, 1)
    link = tmp_path / "again.sac"
    link.symlink_to(a)
    sub = tmp_path / "sub"
    sub.mkdir()
    other_path = str(sub / ".." / a.name)
    out = tmp_path / "out"
    for second in (str(a), str(link), other_path):
        assert main(["run", "--pair", str(a), second, *SAFE_ARGS, "--out", str(out)]) == 2
        assert "both name one file" in _one_line_error(capsys)
        assert main(["classify", "--pair", str(a), second]) == 2
        assert "both name one file" in _one_line_error(capsys, "classify")
    assert not out.exists()


# -- 8. no clean-up through a link out of --out ----------------------------------------------------------
def test_stale_temporaries_are_not_removed_through_a_link(tmp_path):
    """With --no-plots and OUT/plots a link to another folder, the clean-up of stale temporary
    files followed the link and deleted matching names there."""
    a = write_good(tmp_path, 1)
    victim = tmp_path / "elsewhere"
    victim.mkdir()
    names = [".good01.png.abcd1234.tmp", ".summary.png.x1y2z3w4.tmp"]
    for name in names:
        (victim / name).write_text("someone else's")
    out = tmp_path / "out"
    out.mkdir()
    (out / "plots").symlink_to(victim)
    (out / ".summary.csv.ab12cd_9.tmp").write_text("left by a killed run")  # its own: removed
    assert main(["run", str(a), *SAFE_ARGS, "--out", str(out)]) == 0
    assert sorted(p.name for p in victim.iterdir()) == sorted(names)
    assert not (out / ".summary.csv.ab12cd_9.tmp").exists()
    assert resume.remove_stale_temporaries(out, ["plots/good01.png", "plots/summary.png"]) == 0
    assert sorted(p.name for p in victim.iterdir()) == sorted(names)


# -- the smaller wrongs ---------------------------------------------------------------------------------
def test_a_constant_offset_is_reported_and_a_constant_refused(tmp_path):
    """A record with a 1 g offset was designed as if the offset were ground motion, silently (the
    design width went from 1.84 to 8.30 m).  Now every report of it says so; a record that is
    one constant throughout has no motion and is refused."""
    import numpy as np

    import pulses

    a = write_good(tmp_path, 1)
    rec = pulses.read_record(a)
    assert not [w for w in rec.metadata["warnings"] if "from zero" in w]
    shifted = tmp_path / "shifted.sac"
    pulses.write_sac(pulses.Record(rec.acc + pulses.G, rec.dt, name="shifted"), shifted)
    warned = pulses.read_record(shifted).metadata["warnings"]
    assert any(re.search(r"sit \+(0\.99|1\.0)\d* g from zero \(median\)", w) and "constant offset" in w
               for w in warned), warned
    out = tmp_path / "out"
    assert main(["run", str(shifted), *SAFE_ARGS, "--out", str(out)]) == 0
    (row,) = read_csv(out / "summary.csv")
    assert "constant offset" in row["warnings"]
    flat = tmp_path / "flat.sac"
    pulses.write_sac(pulses.Record(np.full(500, 0.3 * pulses.G), 0.01, name="flat"), flat)
    with pytest.raises(pulses.RecordError, match="a constant, no ground motion"):
        pulses.read_record(flat)


@pytest.mark.parametrize("iftype", ["irlim", "iamph", "ixy"])
def test_a_sac_file_that_is_no_time_series_is_refused(iftype, tmp_path):
    """A SAC file whose iftype says spectrum or x-y data was read as a time series."""
    import numpy as np
    from obspy.io.sac import SACTrace

    import pulses

    path = tmp_path / "spectrum.sac"
    trace = SACTrace(data=(np.sin(np.arange(800) / 20.0) * 1e9).astype(np.float32), delta=0.01)
    trace.idep, trace.iftype = "iacc", iftype
    trace.write(str(path))
    with pytest.raises(pulses.RecordError, match="iftype says this file is not a time series"):
        pulses.read_record(path)
    trace.iftype = "itime"
    trace.write(str(path))
    assert pulses.read_record(path).acc.size == 800


# -- 7. memory in proportion to the record ---------------------------------------------------------------
def test_byte_bounded_cache_keeps_within_its_budget():
    import numpy as np

    from pulses.bytecache import byte_lru

    calls = []

    @byte_lru(10 * 8000)
    def block(k):
        calls.append(k)
        return np.zeros(1000)  # 8000 bytes

    for k in range(25):
        block(k)
    assert block.cache_bytes() == 10 * 8000  # the last ten kept, the others dropped
    block(24)
    block(0)
    assert calls.count(24) == 1 and calls.count(0) == 2
    big = byte_lru(100)(lambda n: np.zeros(n))
    assert big(1000).size == 1000 and big.cache_bytes() == 0  # larger than the budget: not kept


def test_the_strongest_map_gives_what_the_whole_map_gives():
    """The classification keeps per time the strongest coefficient over the scales instead of the
    (51, n) maps: the candidates it picks (with numpy.argmax's first index on ties, and after
    clearing) are those of the whole map, value for value."""
    import math

    import numpy as np

    from pulses.velocity import _StrongestMap

    rng = np.random.default_rng(24)
    for pair in (False, True):
        n, rows = 400, 7
        coefs = np.round(rng.standard_normal((2 if pair else 1, rows, n)), 1)  # many exact ties
        coefs[:, :, 50:60] = 0.0  # columns of zeros
        power = (coefs ** 2).sum(axis=0)
        strongest = _StrongestMap(n, rows, pair)
        for i in rng.permutation(rows):  # rows come in the order of their FFT sizes
            strongest.add(int(i), coefs[:, i] if pair else coefs[0, i])
        peak = power.max(axis=0)
        for _ in range(60):  # until everything is cleared, and beyond
            row, col, a, b = strongest.strongest()
            cols = np.flatnonzero(peak == peak.max())
            if cols.size == 1:
                ref = int(np.argmax(power[:, cols[0]])), int(cols[0])
            else:
                ref = tuple(int(v) for v in np.unravel_index(int(np.argmax(power)), power.shape))
            assert (row, col) == ref
            assert (a, b) == (coefs[0, row, col], coefs[1, row, col] if pair else 0.0)
            cleared = slice(max(0, math.floor(col - 4.5) + 1), max(0, math.ceil(col + 4.5)))
            power[:, cleared] = 0.0
            peak[cleared] = 0.0
            strongest.clear(cleared)


@pytest.mark.slow
def test_classification_caches_stay_within_their_bytes():
    """A 10 kHz record: the filters' caches hold at most their budgets (they held 10.9 GB after a
    2e6-sample record)."""
    import numpy as np

    import pulses
    from pulses import db4

    dt = 1e-4
    t = np.arange(60_000) * dt
    acc = np.where((t > 2.0) & (t < 2.5), np.sin(2 * np.pi * (t - 2.0) / 0.5), 0.0) * 3.0
    acc += 0.05 * np.sin(2 * np.pi * 7.0 * t)
    res = pulses.classify_pulse(pulses.Record(acc, dt, name="fine"))
    assert res.tp > 0
    for cache in (db4.difference_filter, db4._point_filter, db4.unit_wavelet, db4._filter_spectrum):
        assert 0 < cache.cache_bytes() <= cache.max_bytes
