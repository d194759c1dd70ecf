"""Safe batches, second round: concurrent runs, full disks, outputs onto inputs, broken folder
entries, scales, pairs of one file, links out of ``--out``, and the smaller wrongs.

Each test reproduces its case first (as the issue ran it on the earlier code) and then checks that
nothing is lost, overwritten or deleted outside the run's own outputs, that the folder is usable by
the next run, and that the status and the message are clear.
"""
from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time

import pytest

from pipeline import report, resume
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


def test_a_second_run_into_a_busy_out_is_refused_and_nothing_is_lost(recs, alone, tmp_path):
    """Two real processes into one --out: the second is refused at once (exit 2, one line), the
    first finishes as if alone, and the folder is usable by the next run."""
    out = tmp_path / "out"
    cmd = [sys.executable, "-m", "pipeline", "run", *recs, *SAFE_ARGS, "--out", str(out)]
    first = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 120
    # the first run holds the folder once it has written its first report
    while time.time() < deadline and not (out / report.MANIFEST).exists() and first.poll() is None:
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
    from pipeline import outlock

    out = tmp_path / "out"
    out.mkdir()
    with outlock.locked(out):
        assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 2
        assert "in use by another pipeline run" in _one_line_error(capsys)
        assert os.listdir(out) == []  # refused before anything is written
    assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 0


# -- 2. a run started on a full disk ----------------------------------------------------------------
@pytest.mark.parametrize("left", [b"", report._MANIFEST_HEADER.encode()[:17]], ids=["empty", "cut"])
@pytest.mark.parametrize("name", [report.MANIFEST, resume.RESUME])
def test_an_empty_or_cut_journal_does_not_lock_the_folder(name, left, recs, tmp_path):
    """What a full disk leaves (a 0-byte manifest, a header cut short) holds nothing: the next run
    goes on and writes whole journals; a file that is not one of ours is still refused."""
    out = tmp_path / "out"
    out.mkdir()
    header = (report._MANIFEST_HEADER if name == report.MANIFEST else resume._HEADER).encode()
    (out / name).write_bytes(left if name == report.MANIFEST else header[:len(left)])
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
    report.append_line(path, "# header\n", "a line\n")
    assert path.read_text() == "# header\na line\n"
    report.append_line(path, "# header\n", "b\n")
    assert path.read_text() == "# header\na line\nb\n"


def test_a_full_disk_error_names_the_file(recs, tmp_path, monkeypatch, capsys):
    """ENOSPC from a write says no file name; the message does."""
    def full(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(report.os, "replace", full)
    with pytest.raises(OSError, match="No space left on device: .*summary.csv"):
        report.write_atomic(tmp_path / "summary.csv", "x\n")
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

    monkeypatch.setattr(report.os, "fdopen", lambda *a, **k: Full(real_fdopen(*a, **k)))
    out = tmp_path / "out"
    code = main(["run", recs[0], *SAFE_ARGS, "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1 and "No space left on device" in err and report.MANIFEST in err, err
    monkeypatch.undo()
    assert main(["run", recs[0], *SAFE_ARGS, "--out", str(out)]) == 0  # space freed: usable
