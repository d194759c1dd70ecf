"""The row of ``<record>.csv`` and ``summary.csv``: its groups of columns, in report order.

Each group (:class:`pipeline.reports.columns.Columns`) is declared in the module that computes it,
next to the function that fills it; this module only puts them in order.  A row is one record (or
one direction of a pair) and one column; :func:`columns_for` gives the columns of a run's options
(a performance level adds the margin's, ``--restitution`` the restitution's).

Adding a report column
----------------------
1. Declare it in the group of the module that computes it, ``(name, unit, meaning)``: the name in
   snake case ending in its unit (``_m``, ``_s``, ``_g``, ``_deg``; none for a ratio), the unit as
   ``columns.md`` shows it (``-`` for none), the meaning in one or two sentences a user reads in
   ``columns.md``.  A column that is not a number says its kind (``TEXT``, ``FLAG``, ``COUNT``,
   :mod:`pipeline.reports.columns`): a resumed run reads the reports' text back by these kinds.
2. Set it where the group's row is made (``GROUP.row({...})`` refuses a row whose keys differ
   from the declaration; ``GROUP.blank()`` where it does not apply): a number as a Python
   number, a flag as a bool, blank as None.  The CSV writer formats it (6 significant digits).
3. A new group: add it to :data:`_TO_DESIGN_WIDTH` or :data:`_FROM_CHECK` below where it belongs
   in the report, and fill it in :func:`pipeline.batch.record.column_row`.  A group that only some
   runs have goes to :func:`columns_for` (as :func:`pipeline.batch.margin.extra_columns`).
4. A column ``design.csv`` should show too: add it to
   :data:`pipeline.reports.design_table.DESIGN_COLUMNS` and to
   :func:`pipeline.reports.design_table.design_rows`, which makes a record's (a pair's) design row
   from its rows.
5. Test it against an independent number (tests/test_pipeline_run.py has a small batch), and see
   that ``columns.md`` of a run lists it; a resumed run's files must stay byte-identical
   (tests/test_resume.py).
"""
from __future__ import annotations

from . import as_stands, fitted, fragility, margin, peer_inputs, rules, site, validity, vertical, widths
from ..reports.columns import Columns
from ..reports.shapes import SHAPE_NAMES

_TO_DESIGN_WIDTH = Columns.joined(fitted.RECORD_COLUMNS, site.SITE_COLUMNS, peer_inputs.PEER_COLUMNS,
                                  as_stands.COLUMN_COLUMNS, rules.AS_STANDS_DESIGN_COLUMNS, rules.GOVERNING_COLUMNS,
                                  *(rules.SHAPE_COLUMNS[s] for s in SHAPE_NAMES), as_stands.AS_STANDS_COLUMNS,
                                  rules.EQ31_DESIGN_COLUMNS, widths.DESIGN_WIDTH_COLUMNS)
_FROM_CHECK = Columns.joined(widths.CHECK_COLUMNS, rules.ENVELOPE_COLUMNS, fragility.FRAGILITY_COLUMNS,
                             vertical.VERTICAL_COLUMNS, validity.VALIDITY_COLUMNS)
#: the columns every run's per-record reports and ``summary.csv`` have, in order;
#: :func:`columns_for` adds those of a run's options
COLUMNS = _TO_DESIGN_WIDTH + _FROM_CHECK
FIELDS = list(COLUMNS.names)


def columns_for(options) -> Columns:
    """The columns of the reports of a run with ``options``: :data:`COLUMNS` with, after the design
    width's, the margin's under a level and the restitution's with ``--restitution``
    (:func:`pipeline.batch.margin.extra_columns`)."""
    return Columns.joined(_TO_DESIGN_WIDTH, *margin.extra_columns(options), _FROM_CHECK)


def fields_for(options) -> list:
    """The names of :func:`columns_for`."""
    return list(columns_for(options).names)


def rows_of(text: str, options) -> list[dict]:
    """The rows of the reports' ``text`` (no header) of a run with ``options``, each value read by
    its column's kind (:meth:`pipeline.reports.columns.Columns.read`)."""
    return columns_for(options).read(text)
