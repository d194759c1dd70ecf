"""Report columns: a group of them declared together (:class:`Columns`: name, unit, meaning and
kind), the CSV writer (:func:`csv_text`, the one place where a row's values become text) and the
typed read of a report's rows (:meth:`Columns.read`, the one place where text becomes values).

A row is made of values (numbers, booleans, text, None for blank) where they are computed; the CSV
writer formats them (:func:`pipeline.reports.cells.fmt`: 6 significant digits).  A resumed run
keeps a record's report as text (its journal vouches for it, :mod:`pipeline.batch.resume`), and the
run's tables are made from the rows as the reports hold them, so that a resumed run and one never
stopped write the same bytes: each cell is read back by its column's declared *kind*, never
guessed.  A column is a :data:`NUMBER` (a float: every column with a unit, and by default one
without) unless declared otherwise: :data:`WHOLE` (an int: counts, an RSN), :data:`FLAG`
(``True``/``False``) or :data:`TEXT` (as written, whatever it looks like: a record named ``1063``
or a height's label ``12`` stay text).  Blank is None in every kind.
"""
from __future__ import annotations

import csv
import io

from .cells import fmt

#: the kinds of a column's values, as a report's text is read back (:meth:`Columns.read`)
NUMBER, WHOLE, FLAG, TEXT = "number", "whole", "flag", "text"
KINDS = (NUMBER, WHOLE, FLAG, TEXT)


class ReportError(ValueError):
    """A report row that does not match its declared columns, or a cell not of its column's kind
    (a programming error, never a user's)."""


class Columns:
    """A group of report columns declared together, next to the code that computes them.

    Parameters
    ----------
    *columns : tuple of (str, str, str) or (str, str, str, str)
        ``(name, unit, meaning)`` of each column, in report order; ``unit`` is ``-`` for none;
        a fourth item is the column's kind (:data:`KINDS`; default :data:`NUMBER`).

    Attributes
    ----------
    columns : tuple of (name, unit, meaning)
        As ``columns.md`` lists them.
    names : tuple of str
    kinds : dict
        ``{name: kind}``.
    """

    def __init__(self, *columns):
        declared = []
        for c in columns:
            name, unit, meaning, kind = (*c, NUMBER) if len(c) == 3 else c
            if kind not in KINDS:
                raise ReportError(f"column {name}: kind {kind!r} is none of {KINDS}")
            declared.append((name, unit, meaning, kind))
        self.declared = tuple(declared)
        self.columns = tuple(c[:3] for c in declared)
        self.names = tuple(c[0] for c in declared)
        self.kinds = {c[0]: c[3] for c in declared}
        if len(self.kinds) != len(self.names):
            raise ReportError(f"columns declared twice: {sorted(n for n in self.names if self.names.count(n) > 1)}")

    def __add__(self, other: Columns) -> Columns:
        """The columns of both groups, in order (a report's row of several groups)."""
        return Columns(*self.declared, *other.declared)

    @classmethod
    def joined(cls, *groups: Columns) -> Columns:
        """The columns of ``groups``, in order."""
        return cls(*(c for g in groups for c in g.declared))

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
        """This group's columns (as declared, kinds with them) with ``columns`` put after the column
        ``after``: for a group that reports these columns with some of its own among them."""
        k = self.names.index(after) + 1
        return self.declared[:k] + tuple(columns) + self.declared[k:]

    def read(self, text: str) -> list[dict]:
        """The rows of CSV ``text`` written under these columns (no header), each cell read by its
        column's kind: the values the rows were written from, as the report holds them (numbers
        at its 6 digits)."""
        kinds = [self.kinds[n] for n in self.names]
        out = []
        for cells in csv.reader(io.StringIO(text)):
            if len(cells) != len(kinds):
                raise ReportError(f"a report row of {len(cells)} cells under {len(kinds)} columns")
            out.append({n: _value(c, k, n) for n, c, k in zip(self.names, cells, kinds)})
        return out

    def as_written(self, rows) -> list[dict]:
        """``rows`` as their CSV file holds them (6 significant digits), read back."""
        return self.read(csv_text(self.names, rows).partition("\n")[2])


def _value(cell: str, kind: str, name: str):
    """A cell as the value of its column's ``kind`` (blank: None)."""
    if cell == "":
        return None
    try:
        if kind == NUMBER:
            return float(cell)
        if kind == WHOLE:
            return int(cell)
        if kind == FLAG:
            return {"True": True, "False": False}[cell]
    except (KeyError, ValueError):
        raise ReportError(f"column {name} ({kind}): cannot read {cell!r}") from None
    return cell


def csv_text(fields, rows) -> str:
    """CSV text of ``rows`` (dicts) under the header ``fields``; every row must have exactly these
    keys (a key not declared, or a declared one never set, is an error, not a blank).  The one
    place where a report's values become text (:func:`pipeline.reports.cells.fmt`)."""
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
