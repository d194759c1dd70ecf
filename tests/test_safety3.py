"""Safe batches, third round: PEER inputs (damaged zips, scale factors, malformed reports, one file
twice, verticals), special files among inputs and outputs, lift-off as its own verdict, and the
hygiene of inputs.

Each hostile case is built here from small files (zips made with :mod:`zipfile` from records the
test writes); each test failed on the code before its fix.
"""
from __future__ import annotations

import csv
import io
import os
import re
import zipfile

import numpy as np
import pytest

from pipeline.cli import main
from pulses import RecordError, peer

from .test_peer import RUN_ARGS, at2_text, pulse_values


def _row(i, rsn, a, b, v, scale="2.0", event="Test", station="Station"):
    return f"{i + 1}, {rsn}, {scale}, -, \"{event}\", \"{station}\", 6.5, {a}, {b}, {v}\n"


def report(rows, *, raw_rows=()) -> str:
    """A search report: ``rows`` of ``(rsn, h1, h2, vertical[, scale[, event[, station]]])``, then
    ``raw_rows`` as written."""
    head = ("\n -- Summary of Metadata of Selected Records --\nResult ID, Record Sequence Number, Scale Factor, "
            "Tp-Pulse Period (sec), Earthquake Name, Station Name, Magnitude, Horizontal-1 Acc. Filename, "
            "Horizontal-2 Acc. Filename, Vertical Acc. Filename\n")
    body = "".join(_row(i, *r) for i, r in enumerate(rows))
    return head + body + "".join(raw_rows) + "\n"


def make_zip(path, rows, members, *, raw_rows=(), method=zipfile.ZIP_DEFLATED):
    """A PEER-like zip: the report of ``rows`` and ``members`` (name -> text)."""
    with zipfile.ZipFile(path, "w", method) as zf:
        zf.writestr(peer.SEARCH_RESULTS, report(rows, raw_rows=raw_rows))
        for name, text in members.items():
            zf.writestr(name, text)
    return path


def pair_members(stem, vertical=None):
    out = {f"{stem}000.AT2": at2_text(pulse_values(0), "0"), f"{stem}090.AT2": at2_text(pulse_values(90), "90")}
    if vertical is not None:
        out[f"{stem}-UP.AT2"] = vertical
    return out


def read_rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def corrupt_member(path, name, offset=0):
    """Flip one byte of the compressed data of member ``name`` (a zlib.error when unpacked)."""
    raw = bytearray(path.read_bytes())
    with zipfile.ZipFile(io.BytesIO(bytes(raw))) as zf:
        info = zf.getinfo(name)
    start = info.header_offset + 30 + len(info.filename.encode()) + len(info.extra)
    raw[start + offset] ^= 0xFF
    path.write_bytes(bytes(raw))


# -- (4) a corrupted deflate stream ----------------------------------------------------------------
def test_a_corrupted_member_fails_its_record_alone(tmp_path):
    """A flipped byte in one member's deflate stream was a ``zlib.error`` traceback that lost every
    record of the command; now that record fails, naming the member, and the other is designed."""
    path = make_zip(tmp_path / "dl.zip", [(1, "A000.AT2", "A090.AT2", "-----"), (2, "B000.AT2", "B090.AT2", "-----")],
                    {**pair_members("A"), **pair_members("B")})
    corrupt_member(path, "B000.AT2")
    d = peer.PeerDownload(path)
    with pytest.raises(RecordError, match=r"dl\.zip/B000\.AT2: cannot read"):
        d.read_component("B000.AT2")
    out = tmp_path / "out"
    assert main(["run", str(path), *RUN_ARGS, "--out", str(out)]) == 1
    assert {r["peer_rsn"] for r in read_rows(out / "pairs.csv")} == {"1"}
    (fail,) = read_rows(out / "failures.csv")
    assert "B000.AT2: cannot read" in fail["reason"]


# -- (8) (9) FIFOs and devices -----------------------------------------------------------------------
def _pipeline(args, cwd, timeout=120):
    """``pipeline ARGS`` in a process of its own (a hang is a timeout, not a hung test run)."""
    import subprocess
    import sys

    return subprocess.run([sys.executable, "-m", "pipeline", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=timeout)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
def test_fifos_and_devices_among_the_inputs_are_failed_records_not_a_hang(tmp_path):
    """A FIFO, or a link to /dev/zero, among the inputs hung the batch (every input was hashed
    before anything checked it was a regular file); now each is a failed record saying what it is,
    and the other record is designed."""
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "good.AT2").write_text(at2_text(pulse_values(0), "0"))
    os.mkfifo(folder / "pipe.AT2")
    os.symlink("/dev/zero", folder / "zero.AT2")
    out = tmp_path / "out"
    done = _pipeline(["run", str(folder), *RUN_ARGS, "--out", str(out)], tmp_path, timeout=60)
    assert done.returncode == 1, done.stderr
    assert (out / "failures.csv").is_file(), (done.stdout, done.stderr)
    reasons = {os.path.basename(r["file"]): r["reason"] for r in read_rows(out / "failures.csv")}
    assert "a FIFO (named pipe), not a record file" in reasons["pipe.AT2"]
    assert "a character device, not a record file" in reasons["zero.AT2"]
    assert [r["record"] for r in read_rows(out / "design.csv")] == ["good"]


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs on this system")
@pytest.mark.parametrize("command", ["run", "classify"])
def test_a_fifo_as_an_output_is_refused_before_any_work(tmp_path, command):
    """``--log FIFO`` or ``classify --csv FIFO`` hung the pre-check (it opened the file to see
    whether this package wrote it); now refused at once, exit 2, one line."""
    rec = tmp_path / "a.AT2"
    rec.write_text(at2_text(pulse_values(0), "0"))
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    if command == "run":
        args = ["run", str(rec), *RUN_ARGS, "--out", str(tmp_path / "out"), "--log", str(fifo)]
    else:
        args = ["classify", str(rec), "--csv", str(fifo)]
    done = _pipeline(args, tmp_path, timeout=60)
    assert done.returncode == 2, done.stderr
    err = done.stderr.strip()
    assert "is a FIFO (named pipe), not a file" in err and "\n" not in err, err
    assert not (tmp_path / "out" / "design.csv").exists()


# -- (1) (2) (3) (13) (14) the search report ---------------------------------------------------------
@pytest.fixture(scope="module")
def hostile_report(tmp_path_factory):
    """A download whose report holds one good record and every wrong of the issue, run once with
    ``--peer-scales``: ``(out folder, exit status, printed text)``."""
    import contextlib

    tmp = tmp_path_factory.mktemp("hostile-report")
    members = {**pair_members("A"), **pair_members("B"), **pair_members("C")}
    rows = [(1, "A000.AT2", "A090.AT2", "-----", "2.0", "Quake\x1b[2J\x07", "Sta\x1b]0;owned\x07tion"),
            (2, "B000.AT2", "B090.AT2", "-----", "1e6"), (3, "B000.AT2", "B090.AT2", "-----", "nan"),
            (4, "B000.AT2", "B090.AT2", "-----", "-"), (5, "B000.AT2", "B090.AT2", "-----", "0"),
            (6, "C000.AT2", "C000.AT2", "-----"), (7, "C000.AT2", "c000.at2", "-----")]
    raw = ["8, 9, 2.0, -, \"short row\"\n",
           "9, 10, 2.0, -, \"" + "x" * 140_000 + "\", \"S\", 6.5, A000.AT2, A090.AT2, -----\n"]
    path = make_zip(tmp / "dl.zip", rows, members, raw_rows=raw)
    out = tmp / "out"
    buf_out, buf_err = io.StringIO(), io.StringIO()
    loud = [a for a in RUN_ARGS if a != "--quiet"]
    with contextlib.redirect_stdout(buf_out), contextlib.redirect_stderr(buf_err):
        code = main(["run", str(path), *loud, "--out", str(out), "--peer-scales"])
    return out, code, buf_out.getvalue() + buf_err.getvalue()


def _reasons(out):
    return [r["reason"] for r in read_rows(out / "failures.csv")]


def test_peer_scales_obey_the_scale_rule(hostile_report):
    """A search factor of 1e6 designed for ~422,000 g; nan, '-' or 0 became 1 while the row said
    peer_scaled=True.  Now each is a failed record with the reason; the good one is scaled by 2."""
    out, code, _ = hostile_report
    assert code == 1
    (good,) = read_rows(out / "pairs.csv")
    assert good["peer_rsn"] == "1" and float(good["scale"]) == 2.0 and good["peer_scaled"] == "True"
    reasons = _reasons(out)
    for rsn, words in ((2, "must lie between 0.001 and 1000, got 1000000.0"), (3, "is missing"),
                       (4, "is missing"), (5, "must lie between 0.001 and 1000, got 0.0")):
        assert any(r.startswith(f"RSN {rsn}: --peer-scales") and words in r for r in reasons), (rsn, reasons)


def test_one_file_named_as_both_horizontals_is_no_pair(hostile_report):
    """The same file as both horizontals (or two names equal but for case) was designed as a pair
    with itself (45 deg: sqrt 2 times the record, 135 deg: zero)."""
    out, _, _ = hostile_report
    reasons = _reasons(out)
    for rsn in (6, 7):
        assert any(r.startswith(f"RSN {rsn}:") and "as both horizontal components" in r for r in reasons), reasons


def test_malformed_and_huge_rows_fail_alone(hostile_report):
    """A field over 131,072 characters was a ``_csv.Error`` traceback losing the command; one short
    row failed the whole download.  Now each such row is a failed record naming its line, and the
    valid records are designed."""
    out, _, printed = hostile_report
    reasons = _reasons(out)
    assert any("line 11: 5 fields, the table's header has 10" in r for r in reasons), reasons
    assert any("line 12: not a line of the table: field larger than field limit" in r for r in reasons), reasons
    assert len(reasons) == 8  # six records and two rows
    assert "Traceback" not in printed


def test_control_characters_of_the_report_never_reach_the_terminal(hostile_report):
    out, _, printed = hostile_report
    assert "\x1b" not in printed and "\x07" not in printed
    assert "Quake\\x1b[2J\\x07" in printed  # shown, as escapes
    (good,) = read_rows(out / "pairs.csv")
    assert good["peer_event"] == "Quake\\x1b[2J\\x07" and good["peer_station"] == "Sta\\x1b]0;owned\\x07tion"
    page = (out / "report.html").read_text()
    assert "\x1b" not in page and "\x07" not in page


# -- (10) two downloads with the same file names --------------------------------------------------
def test_two_downloads_with_the_same_file_names_stay_two_records(tmp_path):
    """Two downloads holding A000.AT2 and A090.AT2 were merged into one design row (one's
    metadata, the other's numbers)."""
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    make_zip(tmp_path / "a" / "dl.zip", [(1, "A000.AT2", "A090.AT2", "-----")], pair_members("A"))
    weaker = pair_members("A")
    weaker["A000.AT2"] = at2_text(0.5 * pulse_values(0), "0")
    make_zip(tmp_path / "b" / "dl.zip", [(2, "A000.AT2", "A090.AT2", "-----")], weaker)
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "a" / "dl.zip"), str(tmp_path / "b" / "dl.zip"), *RUN_ARGS,
                 "--out", str(out)]) == 0
    pairs = {r["peer_rsn"]: r for r in read_rows(out / "pairs.csv")}
    assert set(pairs) == {"1", "2"}
    assert pairs["1"]["file"].startswith(str(tmp_path / "a")) and pairs["2"]["file"].startswith(str(tmp_path / "b"))
    design = read_rows(out / "design.csv")
    assert len(design) == 2 and len({r["record"] for r in design}) == 2


# -- (7) a vertical that lifts the block off ---------------------------------------------------------
def test_lift_off_is_its_own_verdict_never_survives(tmp_path, capsys):
    """A vertical below -1 g (free flight) was reported "survives with the vertical" in design.csv,
    the printed table and report.html, though the response stopped at lift-off."""
    n = 400
    v = 0.05 * np.sin(0.02 * np.arange(n))
    v[150:160] = -1.5  # 1.5 g downwards at 1.5 s: the ground falls away faster than gravity
    files = []
    for name, values, comp in (("S000.AT2", pulse_values(0), "0"), ("S090.AT2", pulse_values(90), "90"),
                               ("S-UP.AT2", v, "UP")):
        (tmp_path / name).write_text(at2_text(values, comp))
        files.append(str(tmp_path / name))
    out = tmp_path / "out"
    loud = [a for a in RUN_ARGS if a != "--quiet"]
    assert main(["run", "--triplet", *files, *loud, "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    summary = read_rows(out / "summary.csv")
    # g + av crosses zero between the samples at 1.49 s and 1.50 s (interpolated: 1.4967 s)
    assert all(r["vertical_lifts_off"] == "True" and 1.49 < float(r["vertical_t_lift_off_s"]) <= 1.5
               for r in summary)
    (row,) = read_rows(out / "design.csv")
    assert row["survives_vertical"] == "False" and 1.49 < float(row["vertical_lift_off_s"]) <= 1.5
    line = [ln for ln in printed.splitlines() if ln.startswith("S000+90")][0]
    assert line.rstrip().endswith("lifts off at 1.50 s"), line
    page = (out / "report.html").read_text()
    assert "lifts off at 1.50 s" in page
    assert "with the vertical (" in page and "with the vertical (fast-vertical): survives" not in page


# -- (12) anchors --------------------------------------------------------------------------------------
def test_record_ids_get_distinct_anchors():
    """Record ids ``a+b`` and ``a_2Bb`` had one anchor in report.html."""
    from pipeline.reports.html_report import _anchor

    ids = ["a+b", "a_2Bb", "a_b", "a%b", "a_25b", "RSN77_SFERN_PUL164"]
    anchors = [_anchor(i) for i in ids]
    assert len(set(anchors)) == len(ids)
    assert all(re.fullmatch(r"r-[A-Za-z0-9_.~-]+", a) for a in anchors)  # valid in a URL fragment


# -- (5) (6) verticals that cannot be used -----------------------------------------------------------
@pytest.mark.parametrize("vertical, reason", [
    ("zero", "every sample is zero"), ("constant", "constant"), ("nan", "is not a list of numbers"), ("absent", "not in the download"), ("corrupt", "cannot read")])
def test_an_unusable_peer_vertical_is_not_used_and_the_record_designed(tmp_path, vertical, reason):
    """A PEER vertical that was constant, zero, NaN or inf (or a damaged member) failed the record
    in every direction; now the horizontals are designed, as through --triplet, and every row
    says why the vertical was not used, naming the member."""
    values = {"zero": np.zeros(400), "constant": np.full(400, 0.1), "nan": np.r_[pulse_values(0)[:-1], np.nan]}.get(vertical, pulse_values(0))
    members = pair_members("A", vertical=at2_text(values, "UP"))
    if vertical == "absent":
        del members["A-UP.AT2"]
    path = make_zip(tmp_path / "dl.zip", [(1, "A000.AT2", "A090.AT2", "A-UP.AT2")], members)
    if vertical == "corrupt":
        corrupt_member(path, "A-UP.AT2")
    out = tmp_path / "out"
    assert main(["run", str(path), *RUN_ARGS, "--out", str(out)]) == 0
    rows = read_rows(out / "summary.csv")
    assert rows and all(r["vertical_file"] == "" for r in rows)
    for r in rows:
        assert "vertical not used" in r["warnings"] and "A-UP.AT2" in r["warnings"], r["warnings"]
        assert reason.lower() in r["warnings"].lower(), r["warnings"]


def test_vertical_none_needs_no_vertical(tmp_path):
    """``--vertical none`` still failed a PEER record whose unneeded vertical was absent."""
    path = make_zip(tmp_path / "dl.zip", [(1, "A000.AT2", "A090.AT2", "A-UP.AT2")], pair_members("A"))
    out = tmp_path / "out"
    assert main(["run", str(path), *RUN_ARGS, "--out", str(out), "--vertical", "none"]) == 0
    rows = read_rows(out / "summary.csv")
    assert rows and all(r["vertical_file"] == "" and "vertical" not in r["warnings"] for r in rows)


# -- (11) a record whose last bytes hold a zip signature ------------------------------------------
def test_a_sac_record_ending_in_a_zip_signature_is_a_record(tmp_path):
    """A SAC file whose last 22 bytes (its last samples) hold a zip's end record was taken as a PEER
    download, even with ``--format sac``."""
    import importlib.resources

    import pulses

    raw = bytearray((importlib.resources.files("pipeline.data") / "synth_sine_055g_0.9s.sac").read_bytes())
    buf = io.BytesIO()
    zipfile.ZipFile(buf, "w").close()  # an empty zip: its 22-byte end record
    raw[-22:] = buf.getvalue()
    path = tmp_path / "tail.sac"
    path.write_bytes(bytes(raw))
    assert zipfile.is_zipfile(path)  # the case: the end record alone says "zip"
    assert not peer.is_peer_zip(path)
    assert pulses.read_record(path).npts == len(raw[632:]) // 4
    for fmt in ([], ["--format", "sac"]):
        out = tmp_path / f"out{len(fmt)}"
        assert main(["run", str(path), *RUN_ARGS, *fmt, "--out", str(out)]) == 0
        assert [r["record"] for r in read_rows(out / "design.csv")] == ["tail"]


# -- resources -----------------------------------------------------------------------------------------
def test_a_download_is_hashed_once_per_run(tmp_path, monkeypatch):
    """Every task of a PEER download hashed the whole zip again (205 tasks on a 50 MB zip: +7.3 s);
    now a file is hashed once while it stays the same, and again once it changes."""
    from pipeline.batch import resume

    path = make_zip(tmp_path / "dl.zip", [(1, "A000.AT2", "A090.AT2", "-----")], pair_members("A"))
    opened = []

    def counting(p, *a, **k):
        opened.append(p)
        return open(p, *a, **k)

    monkeypatch.setattr(resume, "open", counting, raising=False)
    first = resume.file_digest(path)
    assert [resume.file_digest(path) for _ in range(5)] == [first] * 5 and len(opened) == 1
    import hashlib

    assert first == hashlib.sha256(path.read_bytes()).hexdigest()
    make_zip(path, [(2, "A000.AT2", "A090.AT2", "-----")], pair_members("A"))  # same size, new content
    assert resume.file_digest(path) == hashlib.sha256(path.read_bytes()).hexdigest() != first


def test_finding_the_files_of_a_long_report_is_linear(tmp_path, monkeypatch):
    """The case-insensitive lookup scanned every member for every listed file (4,000 rows x 4,000
    members: 8.7 s); now one index, built once."""
    d = object.__new__(peer.PeerDownload)
    d._files = {f"RSN{k}_X{c}.AT2": "" for k in range(4000) for c in ("000", "090")}
    d._folded = None
    scans = []
    real = peer.PeerDownload.find

    class Counting(dict):
        def __iter__(self):
            scans.append(1)
            return super().__iter__()

    d._files = Counting(d._files)
    assert real(d, "rsn17_x090.at2") == "RSN17_X090.AT2"
    for k in range(4000):
        assert real(d, f"rsn{k}_x000.AT2") == f"RSN{k}_X000.AT2"
    assert len(scans) == 1  # the members were listed once, for the index


def test_a_member_that_unpacks_far_beyond_its_size_is_refused_unread(tmp_path):
    """A 650 kB zip whose member unpacked to 190 MB took 1.0 GB of memory; a member unpacking to
    more than MAX_RATIO times its compressed size is now refused by its stated sizes, before it is
    read, and its record fails alone."""
    bomb = at2_text(pulse_values(0), "0") + " " * (8 << 20)  # 8 MB of blanks deflate ~1000 times
    members = {**pair_members("A"), **pair_members("B")}
    members["B000.AT2"] = bomb
    path = make_zip(tmp_path / "dl.zip", [(1, "A000.AT2", "A090.AT2", "-----"), (2, "B000.AT2", "B090.AT2", "-----")],
                    members)
    with zipfile.ZipFile(path) as zf:
        info = zf.getinfo("B000.AT2")
    assert info.file_size > peer.MAX_RATIO * info.compress_size + peer.RATIO_SLACK
    d = peer.PeerDownload(path)
    with pytest.raises(RecordError, match=r"B000\.AT2: unpacks to \d+ bytes from \d+, more than 100 times"):
        d.read_component("B000.AT2")
    assert d.read_component("A000.AT2").npts == 400
    out = tmp_path / "out"
    assert main(["run", str(path), *RUN_ARGS, "--out", str(out)]) == 1
    assert {r["peer_rsn"] for r in read_rows(out / "pairs.csv")} == {"1"}


def test_a_member_whose_stated_size_lies_is_bounded_as_it_unpacks(tmp_path, monkeypatch):
    """The bound holds while a member is read, not only on what the zip states: the reader stops
    past it (here with the bound lowered below the member's true size)."""
    path = make_zip(tmp_path / "dl.zip", [(1, "A000.AT2", "A090.AT2", "-----")], pair_members("A"))
    d = peer.PeerDownload(path)
    size = d._sizes["A000.AT2"]
    d._sizes["A000.AT2"] = 10  # what a lying header would state
    monkeypatch.setattr(peer, "RATIO_SLACK", 0)
    monkeypatch.setattr(peer, "MAX_RATIO", 1)  # bound: the compressed size, below the true size
    assert size > d._packed["A000.AT2"]
    with pytest.raises(RecordError, match="unpacks to more than"):
        d.read_component("A000.AT2")


# -- new users ----------------------------------------------------------------------------------------
def test_width_over_height_warns_with_the_swap(capsys):
    from pipeline.values import parse_block

    assert parse_block("1.8x7.5") == (1.8, 7.5)  # allowed: a squat block exists
    assert "did you mean 7.5x1.8?" in capsys.readouterr().err
    assert parse_block("7.5x1.8") == (7.5, 1.8)
    assert capsys.readouterr().err == ""


def test_every_input_missing_is_an_argument_error_and_nothing_is_written(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "a.AT2"), str(tmp_path / "b*.AT2"), *RUN_ARGS, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("pipeline run: error: none of the inputs exists") and "\n" not in err
    assert not out.exists()


@pytest.mark.parametrize("argv, hint", [
    (["rn", "x"], "did you mean 'run'?"), (["clasify", "x"], "did you mean 'classify'?"),
    (["run", "x.AT2", "--blok", "7.5x1.8"], "did you mean --block for --blok?"),
    (["run", "x.AT2", "--block", "7.5x1.8", "--vertcal", "none"], "did you mean --vertical for --vertcal?"),
])
def test_mistyped_commands_and_options_get_a_suggestion(argv, hint, capsys):
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith(hint) and "\n" not in err, err


def test_files_of_a_folder_that_are_plainly_not_records_are_skipped_with_one_line(tmp_path, capsys):
    """A README.txt or notes.md in a records folder was a failed record; now skipped, named in one
    line; a record that fails to read is still a failure, and a file named directly is read."""
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "good.AT2").write_text(at2_text(pulse_values(0), "0"))
    (folder / "README.txt").write_text("Records of the 1994 event\n")
    (folder / "notes.md").write_text("# notes\n")
    (folder / "words.txt").write_text("no numbers here\n")
    (folder / "photo.png").write_bytes(b"\x89PNG\r\n\x1a\n")
    (folder / "broken.AT2").write_text("not a record\n")
    out = tmp_path / "out"
    assert main(["run", str(folder), *[a for a in RUN_ARGS if a != "--quiet"], "--out", str(out)]) == 1
    err = capsys.readouterr().err
    (line,) = [ln for ln in err.splitlines() if "plainly not records" in ln]
    assert "4 file(s)" in line and all(n in line for n in ("README.txt", "notes.md", "words.txt", "photo.png"))
    assert [f["record"] for f in read_rows(out / "failures.csv")] == ["broken"]
    assert [r["record"] for r in read_rows(out / "design.csv")] == ["good"]


def test_classify_names_the_files_of_a_folder_it_skips(tmp_path, capsys):
    """classify skipped a folder's README without a word (run printed one line): now the same
    line, without run's --glob hint, which classify does not have."""
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "good.AT2").write_text(at2_text(pulse_values(0), "0"))
    (folder / "README.txt").write_text("Records of the 1994 event\n")
    assert main(["classify", str(folder), "--pairs", "none"]) == 0
    err = capsys.readouterr().err
    (line,) = [ln for ln in err.splitlines() if "plainly not records" in ln]
    assert line.startswith("pipeline classify: note: 1 file(s)") and "README.txt" in line
    assert "--glob" not in line


def test_records_not_downloaded_are_listed_not_failed(tmp_path, capsys):
    """A partial PEER download printed one "failed" line per record not downloaded, counted them as
    failures in report.html and exited 1 for the usual case; now one line and a list in --out, and
    exit 0 when every downloaded record was designed.  A record half there is still a failure."""
    rows = [(1, "A000.AT2", "A090.AT2", "-----"), (2, "N000.AT2", "N090.AT2", "N-UP.AT2"),
            (3, "M000.AT2", "M090.AT2", "-----")]
    path = make_zip(tmp_path / "dl.zip", rows, pair_members("A"))
    out = tmp_path / "out"
    assert main(["run", str(path), *[a for a in RUN_ARGS if a != "--quiet"], "--out", str(out)]) == 0
    captured = capsys.readouterr()
    assert "1 complete, 2 not in the download (listed in peer-not-downloaded.csv), 0 incomplete" in captured.err
    assert "failed" not in captured.out + captured.err
    assert read_rows(out / "failures.csv") == []
    listed = read_rows(out / "peer-not-downloaded.csv")
    assert [(r["peer_rsn"], r["h1"], r["vertical"]) for r in listed] == [("2", "N000.AT2", "N-UP.AT2"), ("3", "M000.AT2", "")]
    # half there: a failure naming what it lacks
    members = {**pair_members("A"), "M000.AT2": at2_text(pulse_values(0), "0")}
    path = make_zip(tmp_path / "dl.zip", rows, members)
    assert main(["run", str(path), *RUN_ARGS, "--out", str(out)]) == 1
    (fail,) = read_rows(out / "failures.csv")
    assert fail["reason"].startswith("RSN 3:") and fail["reason"].endswith("not in the download: M090.AT2")
    assert [r["peer_rsn"] for r in read_rows(out / "peer-not-downloaded.csv")] == ["2"]
    # the list is one of the run's own files: --log may not name it, even before it exists (the
    # log and the list would write over each other)
    fresh = tmp_path / "fresh"
    capsys.readouterr()
    assert main(["run", str(path), *RUN_ARGS, "--out", str(fresh), "--log", str(fresh / "peer-not-downloaded.csv")]) == 2
    err = capsys.readouterr().err.strip()
    assert "one of this run's own outputs" in err and "\n" not in err
    assert not (fresh / "peer-not-downloaded.csv").exists()


def test_all_of_a_files_missing_settings_in_one_message(tmp_path):
    """A text file stating neither units nor time step said only the first; after --units, the
    next run said the second."""
    import pulses

    path = tmp_path / "plain.txt"
    path.write_text("".join(f"{v:.3f}\n" for v in pulse_values(0, n=50)))
    with pytest.raises(RecordError) as err:
        pulses.read_record(path)
    text = str(err.value)
    assert "does not state its units" in text and "does not state its time step" in text
    assert text.count(str(path)) == 1 and "\n" not in text
    assert pulses.read_record(path, units="g", dt=0.01).npts == 50


def test_glob_chooses_the_files_of_a_folder(tmp_path):
    """``--glob PATTERN`` takes exactly the folder's files whose names match (a README.txt with
    numbers in it, which the default would read as a record, is left out)."""
    folder = tmp_path / "in"
    folder.mkdir()
    (folder / "good.AT2").write_text(at2_text(pulse_values(0), "0"))
    (folder / "other.AT2").write_text(at2_text(pulse_values(90), "90"))
    (folder / "list.txt").write_text("stations 1 2 3\n")
    out = tmp_path / "out"
    assert main(["run", str(folder), "--glob", "g*.AT2", *RUN_ARGS, "--out", str(out)]) == 0
    assert [r["record"] for r in read_rows(out / "design.csv")] == ["good"]
    assert read_rows(out / "failures.csv") == []


def test_random_byte_flips_of_a_download_never_escape_as_anything_but_a_record_error(tmp_path):
    """46 % of random byte flips of a download were a traceback losing every record; now every flip
    (of 300, seeded) is at worst a RecordError, for the download or for the member it hit."""
    path = make_zip(tmp_path / "dl.zip", [(1, "A000.AT2", "A090.AT2", "A-UP.AT2"), (2, "B000.AT2", "B090.AT2", "-----")],
                    {**pair_members("A", vertical=at2_text(pulse_values(0), "UP")), **pair_members("B")})
    raw = path.read_bytes()
    rng = np.random.default_rng(37)
    outcomes = {"download": 0, "member": 0, "clean": 0}
    for k in range(300):
        hit = bytearray(raw)
        hit[int(rng.integers(len(raw)))] ^= int(rng.integers(1, 256))
        flipped = tmp_path / f"flip{k}.zip"
        flipped.write_bytes(bytes(hit))
        try:
            d = peer.PeerDownload(flipped)
        except RecordError:
            outcomes["download"] += 1
            continue
        failed = False
        for e in d.search.entries:
            for name in e.files:
                try:
                    d.read_component(name)
                except RecordError:
                    failed = True
        outcomes["member" if failed else "clean"] += 1
        flipped.unlink()
    assert sum(outcomes.values()) == 300 and outcomes["member"] > 0, outcomes
