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
