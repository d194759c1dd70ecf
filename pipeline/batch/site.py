"""The site's columns of a task's rows in ``pipeline run``: which record of the suite the row belongs
to (a pair's id), its direction, its scale, the frame's cap mass and the velocity pulse.

A *task* of ``pipeline run`` is one ground motion to design for: a single component file, or one
horizontal direction of a pair of components (:mod:`pipeline.batch.pairs` makes them; a direction and its
opposite give the same width: the column is symmetric).  The component at ``theta`` is
``pulses.component(a1, a2, theta)`` (:mod:`pipeline.batch.read`).  After the run, the suite's
tables (``pairs.csv``, ``suite.csv``, the fragility) are made from every task's rows
(:mod:`pipeline.reports.suite`).
"""
from __future__ import annotations

from . import peer_inputs
from .peer_inputs import PEER_TP
from ..reports.pulse_row import RUN_PULSE_COLUMNS, classification_fields
from ..reports.columns import Columns, TEXT


# -- report columns ----------------------------------------------------------------------------------
SITE_COLUMNS = Columns(
    ("pair", "-", "The record this row belongs to in the suite: for a pair of components "
                  "(`--pair`, `--pairs auto`) the pair's id (the first file's id, `+`, what differs "
                  "in the second's), one per direction row; for a single component its record id.", TEXT),
    ("file2", "-", "The second component's path for a pair (the first is `file`); blank for a single "
                   "component.", TEXT),
    ("direction_deg", "deg", "Direction of the ground motion designed for, from the first component "
                             "towards the second (0..180; the component at theta is "
                             "a1 cos(theta) + a2 sin(theta)); blank for a single component."),
    ("direction_kind", "-", "Why this direction: `component-1`, `component-2` (the recorded "
                            "components), `pulse` (the strongest velocity pulse's direction, "
                            "`orientation_deg`), `pulse-normal` (90 deg from it) or `even` "
                            "(`--directions N`); blank for a single component.", TEXT),
    ("direction_azimuth_deg", "deg", "Azimuth of that direction, clockwise from north (0..180), where "
                                     "the files state the components' azimuths; else blank."),
    ("scale", "-", "Factor every sample of the record was multiplied by (`--scale`, `--scales`; 1 "
                   "otherwise). Every other column describes the scaled record."),
    ("cap_mass_ratio", "-", "Mass of the cap beam over the columns' total mass (`--cap-mass-ratio`): "
                            "0 for a lone column, above 0 for a rocking frame of such columns "
                            "(docs/theory.md section 8: the frame's p and restitution are used throughout)."),
    # the velocity-pulse columns (pipeline.reports.pulse_row), PEER's period beside the package's
    *RUN_PULSE_COLUMNS.around(
        "velocity_tp_s",
        (PEER_TP, "s", "PEER's pulse period of the record (`Tp-Pulse Period` of a PEER download's "
                       "`_SearchResults.csv`), to compare with `velocity_tp_s`; blank when PEER gives "
                       "none (`-`: not pulse-like in its search) or the record is not from a PEER download.")),
)

def pair_of(task) -> str:
    """The pair a task's rows belong to (``pair`` in the reports): a single record is its own."""
    return task.pair or task.record_id


def site_fields(task, record, classification=None) -> tuple[dict, str | None]:
    """The :data:`SITE_COLUMNS` group of one task's rows, and the warning to add (or None);
    ``classification``: the record's :class:`pulses.PulseClassification` where already made."""
    cls, warning = classification_fields(record, pair_fields=dict(task.pair_fields) or None,
                                         result=classification)
    az = None
    if task.path2 is not None:
        az = record.metadata.get("azimuth")
        az = None if az is None else float(az) % 180.0
    fields = {"pair": pair_of(task), "file2": task.path2,
              "direction_deg": task.direction, "direction_kind": task.direction_kind or None,
              "direction_azimuth_deg": az, "scale": float(task.scale),
              "cap_mass_ratio": float(task.options.cap_mass_ratio)}
    fields.update(cls)
    fields[PEER_TP] = peer_inputs.tp(task)
    return SITE_COLUMNS.row(fields), warning


