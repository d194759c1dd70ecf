"""Plain text and CSV accelerograms: one or more columns of numbers.

Accepted layouts (comment lines start with ``%`` or ``#``; fields are separated by blanks, tabs,
commas or semicolons; a byte-order mark is ignored; one header row of column names is allowed):

- one column of accelerations;
- a time column and an acceleration column (``time,acc``): the time column gives ``dt`` and is
  checked for uniform sampling;
- several acceleration columns (``rinaldi.txt`` holds the 228 and 318 components): the user
  picks one with ``column`` (counted from 1, as spreadsheets and the records manifest count).

Such files state their units and ``dt`` nowhere a program can rely on, so the user gives them;
comments that seem to mention them are quoted back in the error message, never used silently.
"""
from __future__ import annotations

import io
import os
import re

import numpy as np

from ..errors import RecordError
from .registry import (
    MAX_SAMPLES,
    UNITS_NONE,
    Reading,
    ReadOptions,
    RecordFormat,
    join_blocks,
    register,
    too_long,
)

_SPLIT = re.compile(r"[\s,;]+")
_COMMENT = ("%", "#", "!", "//")
#: relative spread of the time steps above which sampling counts as non-uniform
UNIFORM_TOLERANCE = 1e-3


def _is_number(token: str) -> bool:
    try:
        float(token)
    except ValueError:
        return False
    return True


def sniff_text(path, max_lines: int = 40) -> bool:
    """True if the file looks like columns of numbers (after comments and one header row)."""
    try:
        with open(path, "r", encoding="utf-8-sig") as fh:
            lines = [fh.readline() for _ in range(max_lines)]
    except (UnicodeDecodeError, OSError):
        return False
    rows = [ln.strip() for ln in lines if ln.strip() and not ln.strip().startswith(_COMMENT)]
    if not rows:
        return False
    numeric = [all(_is_number(t) for t in _SPLIT.split(r) if t) for r in rows]
    if not numeric[0]:
        numeric = numeric[1:]  # one header row of column names
    return bool(numeric) and all(numeric)


def read_text_file(path, column: int | None = None, max_samples: int = MAX_SAMPLES):
    """Read columns of numbers from a text or CSV file.

    The file is read in blocks of lines, each parsed by numpy, so memory stays proportional to
    the samples kept (the first column and the chosen one, 8 bytes each a row).

    Parameters
    ----------
    path : str or path-like
        The file.
    column : int, optional
        Which column holds the acceleration, counted from 1.  Needed when the file has several
        acceleration columns; with one column, or a time column and one other, it may be left out.
    max_samples : int, optional
        More rows than this are refused (:data:`pulses.formats.MAX_SAMPLES` by default).

    Returns
    -------
    values : ndarray
        The chosen column, in the file's units.
    dt_from_time : float or None
        Sampling interval from a time column (s), if the file has one.
    info : dict
        ``comments`` (list of str), ``columns`` (count), ``column`` (chosen, from 1),
        ``time_column`` (bool), ``names`` (header row or ``None``).

    Raises
    ------
    RecordError
        For a missing or empty file, ragged or non-numeric rows, an ambiguous column, a time
        column that is not uniformly sampled, or more than ``max_samples`` rows.
    """
    path = os.fspath(path)
    parsed = _parse(path, column, max_samples)
    ncols = parsed.ncols
    first = join_blocks(parsed.first)
    kept = join_blocks(parsed.kept) if parsed.kept_index else first
    names = parsed.names
    named_time = bool(names) and names[0].lower().startswith(("t", "time", "sec"))
    time_column = ncols >= 2 and first.size >= 2 and (named_time or _increasing(first))
    column = _chosen_column(path, column, ncols, time_column)
    if time_column and column == 1:
        time_column = False  # the user says column 1 is acceleration
    dt_from_time = _time_step(path, first) if time_column else None
    info = {"comments": parsed.comments, "columns": ncols, "column": column, "time_column": time_column,
            "names": names}
    # the chosen column was kept while reading: the first, or the one named (or the second)
    return (first if column == 1 else kept), dt_from_time, info


def _parse(path: str, column, max_samples) -> "_Rows":
    """The rows of the file, read block by block; refused if missing, not text, empty or ragged."""
    try:
        with open(path, "r", encoding="utf-8-sig") as fh:
            parsed = _Rows(path, column, max_samples)
            while True:
                lines = fh.readlines(_BLOCK_CHARS)
                if not lines:
                    break
                parsed.add(lines)
    except FileNotFoundError:
        raise RecordError(f"{path}: no such file") from None
    except UnicodeDecodeError:
        raise RecordError(f"{path}: not a text file (and not a format obspy recognises)") from None
    except OSError as exc:
        raise RecordError(f"{path}: cannot read: {exc.strerror or exc}") from None
    if not parsed.nrows:
        raise RecordError(f"{path}: the file holds no samples (empty or only comments)")
    if parsed.ragged is not None:
        lineno, count = parsed.ragged
        last = " (truncated last line?)" if lineno == parsed.last_row else ""
        raise RecordError(f"{path}: line {lineno} has {count} value(s), the first data line "
                          f"has {parsed.ncols}{last}")
    return parsed


def _chosen_column(path: str, column, ncols: int, time_column: bool) -> int:
    """The acceleration column (from 1): the one asked for, or the only one there can be."""
    if column is None:
        if ncols == 1:
            column = 1
        elif ncols == 2 and time_column:
            column = 2
        else:
            kind = "a time column and " if time_column else ""
            raise RecordError(f"{path}: {ncols} columns ({kind}several acceleration columns); choose one "
                              f"with column=N (--column N), counted from 1")
    column = int(column)
    if not 1 <= column <= ncols:
        raise RecordError(f"{path}: column {column} asked for, the file has {ncols} column(s) (counted from 1)")
    return column


def _time_step(path: str, first: np.ndarray) -> float:
    """The time step (s) of the time column ``first``; refused unless uniform."""
    steps = np.diff(first)
    dt_mean = (first[-1] - first[0]) / (first.size - 1)
    shortest, longest = steps.min(), steps.max()
    steps -= dt_mean  # in place: no more arrays the record's length
    if not np.all(np.abs(steps, out=steps) <= UNIFORM_TOLERANCE * dt_mean + 1e-12):
        raise RecordError(f"{path}: non-uniform sampling: time steps range from {shortest:.6g} "
                          f"to {longest:.6g} s; resample to a uniform step first")
    return float(dt_mean)


def _increasing(values: np.ndarray) -> bool:
    """Every value above the one before (without an array of differences)."""
    block = 1 << 20
    for i in range(0, values.size - 1, block):
        part = values[i:i + block + 1]
        if not np.all(part[1:] > part[:-1]):
            return False
    return True


#: a character that numpy is not given directly (only numbers and separators are)
_NOT_FAST = re.compile(r"[^0-9.+\-eE \t\n,;]")
_TO_BLANKS = str.maketrans(",;", "  ")
#: characters read per block of lines
_BLOCK_CHARS = 1 << 22


class _Rows:
    """Rows of numbers gathered block by block: comments, header, column count, kept columns.

    A block of plain numeric rows is parsed by :func:`numpy.loadtxt`; any other block (comments,
    the header row, a bad or ragged row, ``nan``) is read line by line with the same rules, so
    the messages name the exact line.
    """

    def __init__(self, path, column, max_samples):
        self.path, self.column, self.max_samples = path, column, max_samples
        self.comments, self.names, self.ncols = [], None, None
        self.first, self.kept, self.kept_index = [], [], None
        self.nrows, self.lineno, self.last_row, self.ragged = 0, 0, None, None

    def add(self, lines):
        if self.ncols is None:  # comments and the header row, line by line up to the first row
            for i, line in enumerate(lines):
                table = self._slow([line])
                if table is not None and table.shape[0]:
                    self._keep(table)
                if self.ncols is not None:
                    lines = lines[i + 1:]
                    break
            else:
                return
        table = self._fast(lines) if self.ragged is None else None
        if table is None:
            table = self._slow(lines)
        else:
            self.lineno += len(lines)
            for back, line in enumerate(reversed(lines)):
                if line.strip():
                    self.last_row = self.lineno - back
                    break
        if table is not None and table.shape[0]:
            self._keep(table)

    def _fast(self, lines):
        block = "".join(lines)
        if _NOT_FAST.search(block):
            return None
        if not block.strip():
            return np.empty((0, self.ncols))
        try:
            table = np.loadtxt(io.StringIO(block.translate(_TO_BLANKS)), ndmin=2, comments=None)
        except ValueError:
            return None
        if table.shape[0] and table.shape[1] != self.ncols:
            return None
        return table

    def _slow(self, lines):
        rows = []
        for line in lines:
            self.lineno += 1
            s = line.strip()
            if not s:
                continue
            if s.startswith(_COMMENT):
                self.comments.append(s.lstrip("%#!/ ").rstrip())
                continue
            tokens = [t for t in _SPLIT.split(s) if t]
            if not all(_is_number(t) for t in tokens):
                if self.ncols is None and self.names is None:
                    self.names = tokens
                    continue
                raise RecordError(f"{self.path}: line {self.lineno} is not a row of numbers: {s[:60]!r}")
            if self.ncols is None:
                self.ncols = len(tokens)
            self.last_row = self.lineno
            if len(tokens) != self.ncols and self.ragged is None:
                self.ragged = (self.lineno, len(tokens))
            if self.ragged is None:
                rows.append([float(t) for t in tokens])
            else:
                self._count(1)
        if self.ragged is not None:
            if rows:
                self._keep(np.array(rows, dtype=float))
            return None
        return np.array(rows, dtype=float).reshape(len(rows), self.ncols or 0)

    def _count(self, n):
        self.nrows += n
        if self.nrows > self.max_samples:
            raise RecordError(too_long(self.path, self.max_samples))

    def _keep(self, table):
        self._count(table.shape[0])
        if self.kept_index is None and self.ncols >= 2:
            # the first column may be time; keep it and the acceleration column the caller
            # named (or the second, the one a time column goes with)
            wanted = int(self.column) - 1 if self.column is not None else 1
            self.kept_index = wanted if 1 <= wanted < self.ncols else None
        self.first.append(table[:, 0].copy())
        if self.kept_index is not None:
            self.kept.append(table[:, self.kept_index].copy())


def hint_from_comments(comments) -> str:
    """Comment text that seems to mention units or the time step, quoted for an error message."""
    keys = ("dt", "unit", "cm/", "gal", "m/s", "sec^2", "acc")
    hits = [c for c in comments if any(k in c.lower() for k in keys)]
    if not hits:
        return ""
    text = " ".join(hits)
    return f" (its comments say: {text[:120]!r})"


def read(path: str, options: ReadOptions) -> Reading:
    """The text format's reader: the chosen column; units and ``dt`` come from the user."""
    values, dt_time, info = read_text_file(path, column=options.column, max_samples=options.max_samples)
    meta = {"format": "text", "comments": info["comments"], "columns": info["columns"],
            "column": info["column"], "time_column": info["time_column"],
            "component": f"column {info['column']}" if info["columns"] > 1 else ""}
    hint = hint_from_comments(info["comments"])
    return Reading(values, dt_time, meta, units_rule=UNITS_NONE, hint=hint,
                   no_units=f"the file does not state its units{hint}")


FORMAT = register(RecordFormat(
    name="text", aliases=("txt", "csv", "ascii"), detect=sniff_text, read=read, sniff_order=20))
