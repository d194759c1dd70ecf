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

import os
import re

import numpy as np

from .errors import RecordError

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


def read_text_file(path, column: int | None = None):
    """Read columns of numbers from a text or CSV file.

    Parameters
    ----------
    path : str or path-like
        The file.
    column : int, optional
        Which column holds the acceleration, counted from 1.  Needed when the file has several
        acceleration columns; with one column, or a time column and one other, it may be left out.

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
        For a missing or empty file, ragged or non-numeric rows, an ambiguous column, or a time
        column that is not uniformly sampled.
    """
    path = os.fspath(path)
    try:
        with open(path, "r", encoding="utf-8-sig") as fh:
            lines = fh.read().splitlines()
    except FileNotFoundError:
        raise RecordError(f"{path}: no such file") from None
    except UnicodeDecodeError:
        raise RecordError(f"{path}: not a text file (and not a format obspy recognises)") from None
    except OSError as exc:
        raise RecordError(f"{path}: cannot read: {exc.strerror or exc}") from None
    comments, rows, names = [], [], None
    for lineno, line in enumerate(lines, start=1):
        s = line.strip()
        if not s:
            continue
        if s.startswith(_COMMENT):
            comments.append(s.lstrip("%#!/ ").rstrip())
            continue
        tokens = [t for t in _SPLIT.split(s) if t]
        if not all(_is_number(t) for t in tokens):
            if not rows and names is None:
                names = tokens
                continue
            raise RecordError(f"{path}: line {lineno} is not a row of numbers: {s[:60]!r}")
        rows.append((lineno, tokens))
    if not rows:
        raise RecordError(f"{path}: the file holds no samples (empty or only comments)")
    ncols = len(rows[0][1])
    for lineno, tokens in rows:
        if len(tokens) != ncols:
            last = " (truncated last line?)" if lineno == rows[-1][0] else ""
            raise RecordError(f"{path}: line {lineno} has {len(tokens)} value(s), the first data line "
                              f"has {ncols}{last}")
    table = np.array([[float(t) for t in tokens] for _, tokens in rows], dtype=float)

    first = table[:, 0]
    named_time = bool(names) and names[0].lower().startswith(("t", "time", "sec"))
    time_column = ncols >= 2 and table.shape[0] >= 2 and (
        named_time or bool(np.all(np.diff(first) > 0)))
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
    if time_column and column == 1:
        time_column = False  # the user says column 1 is acceleration

    dt_from_time = None
    if time_column:
        steps = np.diff(first)
        dt_mean = (first[-1] - first[0]) / (first.size - 1)
        if not np.all(np.abs(steps - dt_mean) <= UNIFORM_TOLERANCE * dt_mean + 1e-12):
            raise RecordError(f"{path}: non-uniform sampling: time steps range from {steps.min():.6g} "
                              f"to {steps.max():.6g} s; resample to a uniform step first")
        dt_from_time = float(dt_mean)
    info = {"comments": comments, "columns": ncols, "column": column, "time_column": time_column,
            "names": names}
    return table[:, column - 1].copy(), dt_from_time, info


def hint_from_comments(comments) -> str:
    """Comment text that seems to mention units or the time step, quoted for an error message."""
    keys = ("dt", "unit", "cm/", "gal", "m/s", "sec^2", "acc")
    hits = [c for c in comments if any(k in c.lower() for k in keys)]
    if not hits:
        return ""
    text = " ".join(hits)
    return f" (its comments say: {text[:120]!r})"
