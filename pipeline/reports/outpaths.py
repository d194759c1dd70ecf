"""Output files named on the command line (``--csv``, ``--plot``, ``--log``, ``--out``), checked
against the inputs and the run's own outputs before any work, the same way by every command.

A command writes a file it is given by name only where nothing is lost:

- never onto one of its inputs (the same file by whatever path or link), nor onto a file the same
  run writes itself (``--log out/summary.csv``);
- never over an existing file it did not write: a file is replaced (``--csv``, ``--plot``) or
  appended to (``--log``) only when it is empty or carries the mark of its kind that this package
  writes (:data:`KINDS`): a CSV table whose first line is column names, a PNG with this package's
  ``Software`` text chunk, a ``--log`` of JSON lines with ``record`` and ``status``.

Everything else is refused with a one-line reason (:class:`ArgumentError`, exit status 2), before
the command reads a record, or, for a file whose name is known only later (``classify --plot
DIR``: one PNG per record), by :func:`write_output`, which fails that file only.
"""
from __future__ import annotations

import json
import os
import pathlib
import re
import struct
import zlib

from ..values import ArgumentError
from .cells import display
from .files import NotOurs, write_atomic

#: the ``Software`` text chunk of the PNG files this package writes (no version: the bytes of a
#: figure do not change with it)
PNG_SOFTWARE = b"rocking-columns pipeline"
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PNG_MARK_CHUNK = b"tEXt" + b"Software\x00" + PNG_SOFTWARE
_CSV_HEADER = re.compile(rb"[A-Za-z_][A-Za-z0-9_.]*(,[A-Za-z_][A-Za-z0-9_.]*)+\r?")

#: how much of a file is read to recognise it
_HEAD = 1 << 16


def _csv_ours(head: bytes) -> bool:
    return _CSV_HEADER.fullmatch(head.split(b"\n", 1)[0]) is not None


def _png_ours(head: bytes) -> bool:
    return head.startswith(_PNG_SIGNATURE) and _PNG_MARK_CHUNK in head


def _log_ours(head: bytes) -> bool:
    try:
        entry = json.loads(head.split(b"\n", 1)[0])
    except ValueError:
        return False
    return isinstance(entry, dict) and {"record", "status"} <= set(entry)


#: kinds of output file: how a file this package wrote is recognised (None: any file may be
#: replaced that is no input, e.g. ``convert``'s records, whose formats carry no mark)
KINDS = {"csv": _csv_ours, "png": _png_ours, "log": _log_ours, "record": None}


def _identity(path):
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return st.st_dev, st.st_ino


def _same(path, others) -> str | None:
    """The first of ``others`` that is the file at ``path`` (the same inode, or the same absolute
    path for a file not there yet)."""
    mine = _identity(path)
    real = os.path.realpath(path)
    for other in others:
        if other is None:
            continue
        if (mine is not None and _identity(other) == mine) or os.path.realpath(other) == real:
            return str(other)
    return None


def special_file(path) -> str | None:
    """What ``path`` is when it is a FIFO, a device or a socket (by :func:`os.stat`, following
    links, without opening it: opening a FIFO blocks until a writer comes), else None."""
    import stat

    from pulses.io import special_kind

    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):
        return None
    return None if stat.S_ISREG(mode) or stat.S_ISDIR(mode) else special_kind(mode)


def is_ours(path, kind: str) -> bool:
    """Whether the existing file at ``path`` may be replaced (appended to, for a log) by an output
    of ``kind``: empty, or marked as this package writes that kind."""
    if special_file(path):
        return False
    test = KINDS[kind]
    if test is None:
        return True
    try:
        with open(path, "rb") as fh:
            head = fh.read(_HEAD)
    except OSError:
        return False
    return not head or test(head)


def check_output_file(path, what: str, kind: str, *, inputs=(), reserved=(), command: str = "") -> pathlib.Path:
    """Check the output file ``path`` of option ``what`` before any work (see the module's
    description); :class:`ArgumentError` with a one-line reason otherwise.  ``inputs``: the
    command's input files; ``reserved``: files the same run writes itself.  The folder is
    created if needed."""
    from ..values import output_folder

    text = str(path) if path is not None else ""
    if not text.strip():
        raise ArgumentError(f"{what}: an empty file name; name a file")
    path = pathlib.Path(text)
    if path.is_dir():
        raise ArgumentError(f"{what} {display(path)} is a folder; name a file")
    special = special_file(path)
    if special:
        raise ArgumentError(f"{what} {display(path)} is {special}, not a file: name a regular file")
    same = _same(path, inputs)
    if same is not None:
        raise ArgumentError(f"{what} {display(path)} is one of the input records ({display(same)}); "
                            "name another file")
    same = _same(path, reserved)
    if same is not None:
        raise ArgumentError(f"{what} {display(path)} is one of this run's own outputs; name another file")
    if os.path.lexists(path) and not is_ours(path, kind):
        who = f"pipeline {command}" if command else "this package"
        raise ArgumentError(f"{what} {display(path)} exists and was not written by {who} "
                            f"(not a {kind} it writes): left as it is; name another file or move it away")
    output_folder(path.parent if str(path.parent) else ".", f"{what}: the folder of")
    return path


def check_file_options(args, command: str, inputs=()) -> None:
    """:func:`check_output_file` of ``--csv`` (a CSV) and ``--plot`` (a PNG file), where the
    command has them and they are given."""
    for option, kind in (("csv", "csv"), ("plot", "png")):
        value = getattr(args, option, None)
        if value is not None:
            check_output_file(value, f"--{option}", kind, inputs=inputs, command=command)


def check_output_dir(path, what: str, *, inputs=()) -> pathlib.Path:
    """An output folder (created if needed, writable) that is none of the inputs."""
    from ..values import output_folder

    if path is not None and str(path).strip() and _same(path, [p for p in inputs if p is not None]):
        raise ArgumentError(f"{what} {display(path)} is one of the inputs; name another folder")
    return output_folder(path, what)


def mark_png(raw: bytes) -> bytes:
    """``raw`` (a PNG) with this package's ``Software`` text chunk after its header chunk."""
    if not raw.startswith(_PNG_SIGNATURE) or _PNG_MARK_CHUNK in raw[:_HEAD]:
        return raw
    end = len(_PNG_SIGNATURE) + 8 + struct.unpack(">I", raw[8:12])[0] + 4  # after IHDR
    body = _PNG_MARK_CHUNK
    chunk = struct.pack(">I", len(body) - 4) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    return raw[:end] + chunk + raw[end:]


def write_output(path, data, kind: str, *, what: str = "output", inputs=()) -> pathlib.Path:
    """Write an output file atomically, unless a file this package did not write is there (or
    it is an input): :class:`pipeline.reports.files.NotOurs` (an :class:`OSError`) naming it, the file
    left as it is.  PNG data gets this package's mark."""
    path = pathlib.Path(path)
    same = _same(path, inputs)
    if same is not None:
        raise NotOurs(f"{display(path)} is one of the input records ({display(same)}): not written")
    if os.path.lexists(path) and (not path.is_file() or not is_ours(path, kind)):
        raise NotOurs(f"{display(path)} exists and was not written by this package: left as it is")
    if kind == "png":
        data = mark_png(bytes(data))
    return write_atomic(path, data)


def figure_png(draw) -> bytes:
    """The PNG bytes ``draw(buffer)`` saves (a plotting function given a file object)."""
    import io

    buf = io.BytesIO()
    draw(buf)
    return buf.getvalue()
