"""Report files of ``pipeline run``: per-record CSV, ``summary.csv``, ``failures.csv``, ``columns.md``,
and the manifest of what the run wrote.

Every file is written atomically (to a temporary file created exclusively in the same folder, then
renamed), so an interrupted run never leaves a half-written report, and the content depends only on
the inputs (no time stamps, fixed number formatting, input order), so re-running into the same
folder gives identical files.  Only files the run wrote are ever replaced or removed
(:class:`Outputs`).  The report columns themselves are declared in :mod:`pipeline.batch.record`, next to
the code that computes them (:class:`Columns`).
"""
from __future__ import annotations

import contextlib
import csv
import hashlib
import io
import math
import os
import pathlib
import stat
import tempfile

from pulses.shapes import SHAPES
from rocking.governing import FIT_TOLERANCE  # a shape "fits" a record: rocking.governing_pulse's rule

#: shapes that get their own group of columns, in this order: every shape of ``pulses.SHAPES``, the
#: realisable ones first (the registry's order kept within each group)
SHAPE_NAMES = tuple(sorted(SHAPES, key=lambda shape: not SHAPES[shape].realisable))


def shape_list() -> str:
    """The shapes of :data:`SHAPE_NAMES` in words, for the columns' descriptions:
    ``"`sine` (one-sine, Eq. 9), ... or `rect` (rectangular)"``."""
    words = []
    for name in SHAPE_NAMES:
        cls = SHAPES[name]
        words.append(f"`{name}` ({cls.label}{', ' + cls.equation if cls.equation else ''})")
    return ", ".join(words[:-1]) + " or " + words[-1] if len(words) > 1 else words[0]


GOVERNING_RULE = (
    "Among the shapes that fit the record (score at least "
    f"{FIT_TOLERANCE:g} x the best shape's score, listed in `shapes_fitting`), the governing pulse is "
    "the one whose Eq. 31 fixed-point width at the column's height is largest (the most demanding "
    "design; ties go to the better fit). `eq31_width_m` and `governing_eq31_tan_alpha` use it. "
    "Eq. 31 designs depend on the shape, so this rule is conservative among plausible shapes; the "
    "verification under the full record (`overturns`, `eq31_width_overturns`, `design_width_m`) "
    "does not depend on any shape and is the arbiter."
)


def _shape_key(shape: str) -> str:
    return shape.replace("-", "_")


class Columns:
    """A group of report columns declared together, next to the code that computes them.

    Parameters
    ----------
    *columns : tuple of (str, str, str)
        ``(name, unit, meaning)`` of each column, in report order; ``unit`` is ``-`` for none.
    """

    def __init__(self, *columns):
        self.columns = tuple(columns)
        self.names = tuple(name for name, _, _ in columns)

    def row(self, values: dict) -> dict:
        """``values`` in declaration order; :class:`ReportError` unless it has exactly the declared
        keys (None, NaN or a missing value is written as a blank cell)."""
        if set(values) != set(self.names) or len(values) != len(self.names):
            extra, missing = sorted(set(values) - set(self.names)), sorted(set(self.names) - set(values))
            raise ReportError(f"report values do not match their columns: undeclared {extra}, missing {missing}")
        return {name: values[name] for name in self.names}

    def blank(self) -> dict:
        """The group with every cell blank (the values do not apply)."""
        return dict.fromkeys(self.names)

    def around(self, after: str, *columns) -> tuple:
        """This group's columns with ``columns`` (``(name, unit, meaning)``) put after the column
        ``after``: for a group that reports these columns with some of its own among them."""
        k = self.names.index(after) + 1
        return self.columns[:k] + tuple(columns) + self.columns[k:]


# -- formatting --------------------------------------------------------------------------------
def fmt(value) -> str:
    """One cell: floats with 6 significant digits, booleans as True/False, None/NaN blank."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "True" if value else "False"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return "" if math.isnan(value) else ("inf" if value > 0 else "-inf")
        text = f"{value:.6g}"
        return "0" if text == "-0" else text
    try:  # numpy scalars
        import numpy as np

        if isinstance(value, np.bool_):
            return fmt(bool(value))
        if isinstance(value, np.integer):
            return str(int(value))
        if isinstance(value, np.floating):
            return fmt(float(value))
    except ImportError:  # pragma: no cover
        pass
    return text_cell(value)


#: first characters that make a spreadsheet read a text cell as a formula
FORMULA_STARTS = ("=", "+", "-", "@", "\t", "\r")


def text_cell(value) -> str:
    """A text cell: one line, any bytes of a file name shown (``\\xff``), and never a formula.

    A text starting with ``= + - @``, tab or carriage return is read as a formula by spreadsheets
    (CSV injection): it gets a leading apostrophe, which they show as text.  Numbers are written by
    :func:`fmt` and never pass here.
    """
    text = " ".join(display(value).split())
    return "'" + text if text.startswith(FORMULA_STARTS) else text


def display(value) -> str:
    """``value`` as printable text: bytes of a file name that are not UTF-8 (which Python keeps as
    lone surrogates) written as ``\\xff``."""
    text = str(value)
    try:
        text.encode("utf-8")
        return text
    except UnicodeEncodeError:
        try:
            raw = text.encode("utf-8", "surrogateescape")
        except UnicodeEncodeError:
            raw = text.encode("utf-8", "backslashreplace")
        return raw.decode("utf-8", "backslashreplace")


class ReportError(ValueError):
    """A report row that does not match its declared columns (a programming error)."""


def csv_text(fields, rows) -> str:
    """CSV text of ``rows`` (dicts) under the header ``fields``; every row must have exactly these
    keys (a key not declared, or a declared one never set, is an error, not a blank)."""
    buf = io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(fields)
    declared = set(fields)
    for row in rows:
        if set(row) != declared:
            extra, missing = sorted(set(row) - declared), sorted(declared - set(row))
            raise ReportError(f"report row does not match its columns: undeclared {extra}, missing {missing}")
        writer.writerow([fmt(row[f]) for f in fields])
    return buf.getvalue()


# -- atomic writing ------------------------------------------------------------------------------
def write_atomic(path, data) -> pathlib.Path:
    """Write ``data`` (str or bytes) to ``path`` through a temporary file and a rename.

    The temporary file is created exclusively in ``path``'s folder (:func:`tempfile.mkstemp`: an
    unpredictable name, never opened through an existing symbolic link) and renamed over ``path``
    atomically (a symbolic link at ``path`` is replaced, its target left alone).  On any
    interruption the temporary file is removed and ``path`` keeps its previous content; Ctrl-C
    arriving during the write takes effect when the file is whole.  Unchanged files are not
    rewritten.
    """
    path = pathlib.Path(path)
    raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    if _regular_file_bytes(path) == raw:
        return path
    return _replace(path, raw)


def _replace(path: pathlib.Path, raw: bytes) -> pathlib.Path:
    """:func:`write_atomic` once ``path`` is known not to hold ``raw`` already."""
    from .. import interrupts

    path.parent.mkdir(parents=True, exist_ok=True)
    with interrupts.deferred(), named_errors(path):
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name[:40]}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as fh:
                os.fchmod(fh.fileno(), 0o666 & ~_umask())  # as an ordinary file, not mkstemp's 0600
                fh.write(raw)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    return path


def _regular_file_bytes(path):
    """Content of ``path`` if it is a regular file (not through a symbolic link), else None."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fh.fileno()).st_mode):
            return None
        return fh.read()


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def remove_quietly(path) -> None:
    with contextlib.suppress(FileNotFoundError):
        pathlib.Path(path).unlink()


# -- what the tool wrote ---------------------------------------------------------------------------
#: the manifest in ``--out``: the files ``pipeline run`` wrote there, which alone it replaces or removes
MANIFEST = "pipeline-manifest.txt"
_MANIFEST_HEADER = ("# pipeline run: the files it wrote into this folder (sha256 of the content, path); "
                    "it replaces or removes no other file\n")


#: the resume journal in ``--out`` (:mod:`pipeline.batch.resume`): which records a later run may keep
RESUME = "pipeline-resume.txt"


class NotOurs(OSError):
    """A file in the output folder that ``pipeline run`` did not write (left as it is)."""


class Outputs:
    """The report files of one output folder, and the manifest that says which the tool wrote.

    A file is replaced or removed only when its present content is one the tool wrote there
    (recorded in :data:`MANIFEST` before the file is written, so that an interrupted run still
    knows its files); any other file in the way is left as it is (:class:`NotOurs`).
    """

    def __init__(self, folder):
        self.folder = pathlib.Path(folder)
        self.path = self.folder / MANIFEST
        self._written: dict[str, set[str]] = {}
        text = read_journal(self.path, _MANIFEST_HEADER)
        if text is not None:
            for line in text.splitlines()[1:]:
                digest, _, rel = line.partition("  ")
                if len(digest) == 64 and rel:
                    self._written.setdefault(rel, set()).add(digest)

    def _target(self, rel: str) -> pathlib.Path:
        return self.folder / rel

    def owned(self, rel: str) -> bool:
        """Whether the file at ``rel`` (a path relative to the folder) may be replaced: it does not
        exist, or its content is one the tool wrote there."""
        path = self._target(rel)
        if not os.path.lexists(path):
            return True
        raw = _regular_file_bytes(path)
        return raw is not None and _digest(raw) in self._written.get(rel, ())

    def check(self, rel: str) -> None:
        """Raise :class:`NotOurs` if the file at ``rel`` exists and was not written by the tool."""
        path = self._target(rel)
        if not self.owned(rel):
            raise NotOurs(f"{display(path)} exists and was not written by pipeline run "
                          f"(not in {MANIFEST}): left as it is")
        if not _real_folder(path.parent, self.folder):
            raise NotOurs(f"{display(path.parent)} is not a folder of its own (a symbolic link?): "
                          f"{path.name} not written")

    def write(self, rel: str, data) -> pathlib.Path:
        """Write ``data`` to ``rel`` atomically, unless a file the tool did not write is there."""
        raw = data.encode("utf-8") if isinstance(data, str) else bytes(data)
        path = self._target(rel)
        if _regular_file_bytes(path) == raw:
            return path  # already so (whoever wrote it, nothing changes)
        self.check(rel)
        digest = _digest(raw)
        if digest not in self._written.get(rel, ()):
            self._journal(f"{digest}  {rel}\n")
            self._written.setdefault(rel, set()).add(digest)
        return _replace(path, raw)

    def remove(self, rel: str) -> bool:
        """Remove the tool's file at ``rel``; True if removed, False if absent; :class:`NotOurs`
        for a file the tool did not write."""
        path = self._target(rel)
        if not os.path.lexists(path):
            return False
        self.check(rel)
        remove_quietly(path)
        return True

    def _journal(self, line: str) -> None:
        append_line(self.path, _MANIFEST_HEADER, line)

    def finish(self) -> None:
        """Rewrite the manifest compactly: for each file still there, the content the tool wrote
        (sorted, so that the same run gives the same manifest)."""
        lines = []
        for rel in sorted(self._written):
            path = self._target(rel)
            if not os.path.lexists(path):
                continue
            raw = _regular_file_bytes(path)
            digests = self._written[rel]
            if raw is not None and _digest(raw) in digests:
                digests = {_digest(raw)}
            lines += [f"{d}  {rel}\n" for d in sorted(digests)]
        if lines or os.path.lexists(self.path):
            write_atomic(self.path, _MANIFEST_HEADER + "".join(lines))


def read_journal(path, header: str) -> str | None:
    """The text of a journal this package keeps in an output folder (the manifest, the resume
    journal), or None when there is none yet.

    A file that is empty or holds only the start of ``header`` is what a run stopped by a full disk
    (or killed) while starting the journal leaves: it holds nothing, and counts as no journal.  Any
    other file that does not start with ``header`` was not written by ``pipeline run``:
    :class:`NotOurs`."""
    raw = _regular_file_bytes(path)
    if raw is None:
        if os.path.lexists(path):
            raise NotOurs(f"{display(path)} is not a file pipeline run wrote")
        return None
    text = raw.decode("utf-8", "replace")
    if header.startswith(text):  # empty, or the header cut short
        return None
    if not text.startswith(header):
        raise NotOurs(f"{display(path)} was not written by pipeline run")
    return text


def append_line(path, header: str, line: str) -> None:
    """Append ``line`` (ending in a newline) to the journal at ``path``, starting it with ``header``.

    A last line cut by a killed run is ended first, so that it spoils no other line; a journal
    holding only part of its header (see :func:`read_journal`) is started again.  Ctrl-C waits
    until the line is written.  A failure (a full disk ...) raises an :class:`OSError` naming the
    file."""
    from .. import interrupts

    head = header.encode("utf-8")
    with interrupts.deferred(), named_errors(path):
        flags = os.O_RDWR | os.O_APPEND | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0)
        fd = os.open(path, flags, 0o666)
        with os.fdopen(fd, "a+b") as fh:
            end = fh.seek(0, os.SEEK_END)
            if end < len(head):
                fh.seek(0)
                if head.startswith(fh.read()):  # nothing yet, or the header cut short
                    fh.truncate(0)
                    end = 0
            if end == 0:
                fh.write(head)
            else:
                fh.seek(end - 1)
                if fh.read(1) != b"\n":
                    fh.write(b"\n")
            fh.write(line.encode("utf-8"))


@contextlib.contextmanager
def named_errors(path):
    """Give an :class:`OSError` raised in the block the file's name where it has none (``No space
    left on device`` from a write says not which file)."""
    try:
        yield
    except OSError as exc:
        if exc.filename is not None or isinstance(exc, NotOurs):
            raise
        raise type(exc)(exc.errno, f"{exc.strerror or exc}", display(path)) from exc


def _digest(raw: bytes) -> str:
    return hashlib.sha256(raw).hexdigest()


def _real_folder(folder, top) -> bool:
    """Whether ``folder`` is ``top`` or inside it with no symbolic link or file on the way (folders
    not there yet are created as real ones)."""
    folder, top = pathlib.Path(folder), pathlib.Path(top)
    while folder != top:
        if folder.is_symlink() or (os.path.lexists(folder) and not folder.is_dir()):
            return False
        folder = folder.parent
    return True


# -- the files -------------------------------------------------------------------------------------
SUMMARY, FAILURES, COLUMNS_MD = "summary.csv", "failures.csv", "columns.md"
SUMMARY_PLOT = "plots/summary.png"
#: the site part's tables and figures (pipeline.batch.site: pairs, suite, fragility)
PAIRS_CSV, SUITE_CSV, FRAGILITY_CSV, FRAGILITY_CURVE_CSV = ("pairs.csv", "suite.csv", "fragility.csv",
                                                           "fragility_curve.csv")
SUITE_PLOT, FRAGILITY_PLOT = "plots/suite.png", "plots/fragility.png"


def record_csv_name(record_id: str) -> str:
    """Path of a record's report, relative to the output folder."""
    return f"{record_id}.csv"


def record_plot_name(record_id: str) -> str:
    """Path of a record's figure, relative to the output folder."""
    return f"plots/{record_id}.png"


def record_widths_plot_name(record_id: str) -> str:
    """Path of a record's barcode of the widths checked above its search width (a folder of
    its own: ``plots/<record>_widths.png`` could be another record's figure)."""
    return f"plots/widths/{record_id}.png"


def record_friction_plot_name(record_id: str) -> str:
    """Path of a record's figure of the friction its responses need (a folder of its own)."""
    return f"plots/friction/{record_id}.png"


def columns_markdown(columns, failure_columns) -> str:
    """``columns.md``: the files of the output folder and every column of the reports.

    ``columns`` and ``failure_columns`` are ``(name, unit, meaning)`` tuples, in report order.
    """
    lines = [
        "# Reports of `pipeline run`",
        "",
        "Files in this folder:",
        "",
        "- `<record>.csv`: one per record, one row per column (`--block`) or height (`--height`).",
        "- `summary.csv`: the rows of every record's report, in input order (one row per record and column).",
        "- `failures.csv`: records that could not be processed, with the reason (header only when none failed).",
        "- `design.csv`: the answer, one row per record (a pair once) and column (below); printed at the end of the run.",
        "- `report.html`: the batch to review in a browser, opened from this folder (no server, no network).",
        "- `plots/<record>.png`: the record with its fitted pulses (paper's Fig. 4), its velocity with the "
        "extracted velocity pulse, and the rotation histories of each column as it stands, of its Eq. 31 "
        "design and at its design width under the full record (Figs. 9, 11); `plots/summary.png`: "
        "required against actual tan(alpha) across records.",
        "- `plots/widths/<record>.png` (only where the check above a search width found failing "
        "widths): the verdict against the width above the search width, a barcode of the widths "
        "that fail, with the design width (`failing_share`, `widest_failing_width_m`; docs/slivers.md).",
        "- `columns.md`: this file.",
        f"- `{MANIFEST}`: the files `pipeline run` wrote here (with a hash of their content). A later "
        "run into this folder replaces or removes only those, and only while their content is still "
        "what it wrote; any other file in its way is left as it is, and the run says so.",
        f"- `{RESUME}`: for each record computed, a key of its file content, options and "
        "the package's code (version, installed files, solver settings) and a hash of its report: a later run into this folder with the same "
        "command keeps those records and computes only the others (`--force`: all).",
        "",
        "Accelerations are in g (g = 9.81 m/s^2, the value of the paper the design rules come from, "
        "in every conversion; standard gravity is 9.80665 m/s^2), lengths in m, times in s. Numbers carry 6 significant "
        "digits; a blank cell means the value does not apply (or, in `<shape>_*` columns, that the shape "
        "does not fit or was not tried). Booleans are `True`/`False`.",
        "",
        "Text cells (file names, and what the records' headers say: `station`, `component`, `event`, "
        "...) that start with `=`, `+`, `-`, `@`, a tab or a carriage return get a leading apostrophe "
        "(`'`), so that a spreadsheet opening the file shows them as text and never evaluates them as "
        "a formula; numbers are written as they are.",
        "",
        "## Governing pulse",
        "",
        GOVERNING_RULE,
        "",
        "## Columns of `<record>.csv` and `summary.csv`",
        "",
        "| column | unit | meaning |",
        "|---|---|---|",
    ]
    cell = lambda text: text.replace("|", "\\|")  # a bare | would end the table cell
    lines += [f"| `{n}` | {u} | {cell(d)} |" for n, u, d in columns]
    lines += ["", "## Columns of `failures.csv`", "", "| column | unit | meaning |", "|---|---|---|"]
    lines += [f"| `{n}` | {u} | {cell(d)} |" for n, u, d in failure_columns]
    return "\n".join(lines) + "\n"
