"""``pipeline run`` resumed: a batch killed halfway and run again computes only what is missing."""
from __future__ import annotations

import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import time

import pytest

from pipeline.reports import columns, outfiles

from pipeline.batch import resume
from pipeline.cli import main

from .test_pipeline_run import BATCH_ARGS, tree, write_bad, write_good


def _counts(text):
    """(processed, records, reused, computed) from the final line of ``pipeline run``."""
    m = re.search(r"(\d+) of (\d+) records processed \((\d+) reused from an earlier run, (\d+) computed\)", text)
    assert m, text
    return tuple(int(g) for g in m.groups())


@pytest.fixture(scope="module")
def batch(tmp_path_factory):
    folder = tmp_path_factory.mktemp("resume-in")
    return [str(write_good(folder, k, duration=4.0)) for k in range(20)]


@pytest.fixture(scope="module")
def whole(batch, tmp_path_factory):
    """An uninterrupted run of the batch."""
    out = tmp_path_factory.mktemp("whole")
    assert main(["run", *batch, *BATCH_ARGS, "--out", str(out)]) == 0
    return out


@pytest.mark.slow
def test_killed_batch_resumes_with_only_the_missing_records_and_same_bytes(batch, whole, tmp_path, capsys):
    out = tmp_path / "out"
    args = [a for a in BATCH_ARGS if a != "--quiet"]
    proc = subprocess.Popen([sys.executable, "-m", "pipeline", "run", *batch, *args, "--out", str(out)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 300
    while time.time() < deadline and len(list(out.glob("good*.csv"))) < 8 and proc.poll() is None:
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    kept = resume.Journal(out).entries  # the records whose reports were whole when it died
    assert 8 <= len(kept) < 20
    assert main(["run", *batch, *args, "--out", str(out)]) == 0
    processed, n, reused, computed = _counts(capsys.readouterr().out)
    assert (processed, n, reused, computed) == (20, 20, len(kept), 20 - len(kept))
    assert tree(out) == tree(whole)
    # and once more: everything kept, nothing changes
    assert main(["run", *batch, *args, "--out", str(out)]) == 0
    assert _counts(capsys.readouterr().out) == (20, 20, 20, 0)
    assert tree(out) == tree(whole)


@pytest.mark.slow
def test_stale_reports_failures_and_force_are_computed_again(batch, whole, tmp_path, capsys):
    """A removed report, a changed input, a changed option and a failed record are computed again;
    --force computes all; the summary always holds every record, in input order."""
    folder = tmp_path / "in"
    folder.mkdir()
    recs = [write_good(folder, k, duration=4.0) for k in range(4)]
    bad = write_bad(folder)[1]  # an empty file: fails at reading
    paths = [str(p) for p in recs] + [str(bad)]
    out = tmp_path / "out"
    args = ["--block", "7.5x1.8", "--shapes", "sine", "--no-plots", "--out", str(out)]
    assert main(["run", *paths, *args]) == 1
    assert _counts(capsys.readouterr().out) == (4, 5, 0, 5)
    first = tree(out)
    # the report of record 0 removed, record 1's file changed (same name)
    (out / "good00.csv").unlink()
    write_good(folder, 11).replace(recs[1])
    log = tmp_path / "log.jsonl"
    assert main(["run", *paths, *args, "--log", str(log)]) == 1
    # 2 and 3 kept; 0 (removed), 1 (new content) and the empty file (failed) computed
    assert _counts(capsys.readouterr().out) == (4, 5, 2, 3)
    entries = {e["record"]: e for e in map(json.loads, log.read_text().splitlines())}
    assert {k: e["status"] for k, e in entries.items()} == {
        "good00": "ok", "good01": "ok", "good02": "reused", "good03": "reused", "empty": "failed"}
    assert entries["empty"]["stage"] == "read"
    for k in ("good00", "good01"):  # computed here, in this process, with its fitted shape
        assert entries[k]["worker"].endswith(f":{os.getpid()}") and entries[k]["seconds"] > 0
        assert entries[k]["model"] == "sine"  # the only shape fitted (--shapes sine)
    again = tree(out)
    assert again["good00.csv"] == first["good00.csv"]
    assert again["good01.csv"] != first["good01.csv"]
    summary = again["summary.csv"].decode()
    from pipeline.batch.tasks import Options

    fields = resume._fields(Options())   # the columns of the run's options (the default level's)
    assert summary == columns.csv_text(fields, []) + "".join(
        resume.report_rows_text(again[f"good{k:02d}.csv"], fields) for k in range(4))
    # another column height: a different option, so nothing is kept
    assert main(["run", *paths, *args, "--block", "6x1.2"]) == 1
    assert _counts(capsys.readouterr().out) == (4, 5, 0, 5)
    assert main(["run", *paths, *args, "--block", "6x1.2"]) == 1
    assert _counts(capsys.readouterr().out) == (4, 5, 4, 1)
    assert main(["run", *paths, *args, "--block", "6x1.2", "--force"]) == 1
    assert _counts(capsys.readouterr().out) == (4, 5, 0, 5)


def test_leftover_temporary_files_of_a_killed_run_are_removed(tmp_path):
    (tmp_path / "plots").mkdir()
    left = [tmp_path / ".summary.csv.ab12cd_9.tmp", tmp_path / "plots" / ".rec.png.x1y2z3w4.tmp"]
    other = [tmp_path / ".notes.txt.ab12cd_9.tmp", tmp_path / ".summary.csv.tmp"]
    for p in left + other:
        p.write_text("x")
    assert resume.remove_stale_temporaries(tmp_path, ["summary.csv", "plots/rec.png"]) == 2
    assert not any(p.exists() for p in left) and all(p.exists() for p in other)


def test_a_resume_journal_not_written_by_the_tool_is_an_argument_error(batch, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / resume.RESUME).write_text("my notes\n")
    assert main(["run", batch[0], *BATCH_ARGS, "--out", str(out)]) == 2
    assert "was not written by pipeline run" in capsys.readouterr().err
    assert (out / resume.RESUME).read_text() == "my notes\n"


def _earlier_header(head):
    """A header line of 0.6's reports: the design width's columns under their names of then."""
    for new, old in (("vertical_design_width_m", "vertical_verified_width_m"), ("design_width_m", "verified_width_m"),
                     ("design_tan_alpha", "verified_tan_alpha"), ("design_adequate", "verified_adequate")):
        head = re.sub(rf"(^|,){new}(,|$)", rf"\g<1>{old}\g<2>", head)
    return head


@pytest.mark.slow
def test_a_report_with_the_column_names_of_an_earlier_version_is_computed_again(batch, tmp_path, capsys):
    """0.7 renamed ``verified_width_m`` and its siblings (``design_width_m`` ...).  A report written
    with the earlier header, even under a journal line that matches it, is not read back (its
    columns would be misplaced): the record is computed again and the folder is as a fresh run's."""
    out = tmp_path / "out"
    assert main(["run", batch[0], *BATCH_ARGS, "--out", str(out)]) == 0
    first = tree(out)
    name = outfiles.record_csv_name("good00")
    manifest = out / outfiles.MANIFEST
    for rel in (name, "summary.csv"):  # as the earlier run wrote them, and listed in its manifest
        head, _, rows = first[rel].decode("utf-8").partition("\n")
        assert "design_width_m" in head.split(",") and "verified_width_m" not in head.split(",")
        raw = (_earlier_header(head) + "\n" + rows).encode("utf-8")
        assert "verified_width_m" in raw.decode("utf-8").split("\n")[0].split(",")
        (out / rel).write_bytes(raw)
        manifest.write_text(manifest.read_text().replace(
            f"{hashlib.sha256(first[rel]).hexdigest()}  {rel}\n", f"{hashlib.sha256(raw).hexdigest()}  {rel}\n"))
    journal = resume.Journal(out)  # the journal vouches for the report
    journal.add("good00", journal.entries["good00"][0], (out / name).read_bytes(), None)
    assert main(["run", batch[0], *[a for a in BATCH_ARGS if a != "--quiet"], "--out", str(out)]) == 0
    assert _counts(capsys.readouterr().out) == (1, 1, 0, 1)
    assert tree(out) == first
