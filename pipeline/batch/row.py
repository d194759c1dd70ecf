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
from ..reports.report import SHAPE_NAMES

_TO_DESIGN_WIDTH = (fitted.RECORD_COLUMNS.columns + site.SITE_COLUMNS.columns + peer_inputs.PEER_COLUMNS.columns
                    + as_stands.COLUMN_COLUMNS.columns + rules.AS_STANDS_DESIGN_COLUMNS.columns
                    + rules.GOVERNING_COLUMNS.columns
                    + sum((rules.SHAPE_COLUMNS[s].columns for s in SHAPE_NAMES), ())
                    + as_stands.AS_STANDS_COLUMNS.columns + rules.EQ31_DESIGN_COLUMNS.columns
                    + widths.DESIGN_WIDTH_COLUMNS.columns)
_FROM_CHECK = (widths.CHECK_COLUMNS.columns + rules.ENVELOPE_COLUMNS.columns + fragility.FRAGILITY_COLUMNS.columns
               + vertical.VERTICAL_COLUMNS.columns + validity.VALIDITY_COLUMNS.columns)
#: the columns every run's per-record reports and ``summary.csv`` have, in order: (name, unit,
#: meaning); :func:`columns_for` adds those of a run's options
COLUMNS = _TO_DESIGN_WIDTH + _FROM_CHECK
FIELDS = [name for name, _, _ in COLUMNS]


def columns_for(options) -> tuple:
    """The columns of the reports of a run with ``options``: :data:`COLUMNS` with, after the design
    width's, the margin's under a level and the restitution's with ``--restitution``
    (:func:`pipeline.batch.margin.extra_columns`)."""
    return _TO_DESIGN_WIDTH + margin.extra_columns(options) + _FROM_CHECK


def fields_for(options) -> list:
    """The names of :func:`columns_for`."""
    return [name for name, _, _ in columns_for(options)]
