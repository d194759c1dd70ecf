"""The column in a row of ``pipeline run``: as given (its label, kind and height) and as it stands
under the full record (its response: overturns, max|theta|/alpha, impacts, the model that
answered).
"""
from __future__ import annotations

from ..reports.columns import Columns, FLAG, TEXT, WHOLE


COLUMN_COLUMNS = Columns(
    ("column", "-", "The column as given: `HxW` for `--block`, `H` for `--height`.", TEXT),
    ("column_kind", "-", "`block` (a column as it stands, `--block`) or `height` (only the width a "
                         "column of this height needs, `--height`; the as-it-stands fields are blank).", TEXT),
    ("height_m", "m", "Full height H of the column."),
)


def column_fields(col) -> dict:
    """The :data:`COLUMN_COLUMNS` of a column (:class:`pipeline.batch.tasks.Column`)."""
    return COLUMN_COLUMNS.row({"column": col.label, "column_kind": col.kind, "height_m": col.height})


AS_STANDS_COLUMNS = Columns(
    ("eq31_adequate", "-", "The column as it stands satisfies Eq. 31 for the governing pulse "
                           "(tan_alpha >= governing_eq31_tan_alpha).", FLAG),
    ("overturns", "-", "The column as it stands overturns (|theta| reaches pi/2) under the full record.", FLAG),
    ("exceeds_alpha", "-", "|theta| of the column as it stands passes alpha at some time under the full record.", FLAG),
    ("max_theta_ratio", "-", "max|theta|/alpha of the column as it stands under the full record (at "
                             "least pi/(2 alpha) when it overturns)."),
    ("n_impacts", "-", "Number of impacts of the column as it stands under the full record.", WHOLE),
    ("model", "-", "Solver model that answered for the column as it stands (`rocking.simulate`, model=auto).", TEXT),
)


def as_stands_fields(block, governing: dict, res) -> dict:
    """The :data:`AS_STANDS_COLUMNS` of the column as it stands (``block``; None: a height only):
    ``governing`` its rules' fields, ``res`` its response under the full record."""
    if block is None:
        return AS_STANDS_COLUMNS.blank()
    return AS_STANDS_COLUMNS.row({
        "eq31_adequate": block.tan_alpha >= governing["governing_eq31_tan_alpha"],
        "overturns": bool(res.overturned), "exceeds_alpha": bool(res.exceeded_alpha),
        "max_theta_ratio": float(res.max_rotation_ratio), "n_impacts": int(res.n_impacts),
        "model": str(res.model),
    })
