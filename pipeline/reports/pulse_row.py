"""The velocity-pulse row: Shahi & Baker's (2014) classification (:func:`pulses.classify_pulse`) of a
record or pair as ``pipeline classify`` reports it, and the subset ``pipeline run`` adds to its rows.
"""
from __future__ import annotations

from .columns import Columns, FLAG, TEXT

#: columns of one row, in order (units in the names)
COLUMNS = ["file", "file2", "pulse_like", "velocity_pulse_indicator", "velocity_tp_s", "pgv_m_s",
           "orientation_deg", "azimuth_deg", "arrival_s", "late", "pgv_ratio", "energy_ratio",
           "pulse_like_reason"]
#: the subset ``pipeline run`` reports, with their units and meanings (its reports' columns)
RUN_PULSE_COLUMNS = Columns(
    ("pulse_like", "-", "The record (for a pair: the pair) is pulse-like by Shahi & Baker's (2014) "
                        "velocity-pulse classification (`pulses.classify_pulse`). When it is not, "
                        "`warnings` notes that Eq. 31 assumes a pulse.", FLAG),
    ("velocity_pulse_indicator", "-", "Shahi & Baker's pulse indicator PI (pulse-like when above 0, "
                                      "with an early enough arrival)."),
    ("velocity_tp_s", "s", "Pseudo-period Tp of the extracted velocity pulse."),
    ("orientation_deg", "deg", "Direction of the strongest velocity pulse, from the first component "
                               "towards the second (0 for a single component)."),
    ("azimuth_deg", "deg", "Azimuth of the strongest velocity pulse, clockwise from north (0..180), "
                           "where the files state the azimuths; else blank."),
    ("pulse_like_reason", "-", "Why the record is or is not pulse-like: the test of Shahi & Baker's "
                               "that decided (the indicator PI with the residual's shares, or a late "
                               "arrival), and a note where the velocity is one-sided, which their "
                               "two-sided wavelets fit poorly (`PulseClassification.reason`).", TEXT),
)
#: their names
RUN_COLUMNS = list(RUN_PULSE_COLUMNS.names)

def result_row(result, file="", file2="") -> dict:
    """One report row of a :class:`pulses.PulseClassification` (see :data:`COLUMNS`)."""
    return {"file": str(file), "file2": str(file2) if file2 else "", "pulse_like": bool(result.is_pulse),
            "velocity_pulse_indicator": float(result.indicator), "velocity_tp_s": float(result.tp),
            "pgv_m_s": float(result.pgv), "orientation_deg": float(result.orientation),
            "azimuth_deg": None if result.azimuth is None else float(result.azimuth),
            "arrival_s": float(result.arrival), "late": bool(result.late),
            "pgv_ratio": float(result.pgv_ratio), "energy_ratio": float(result.energy_ratio),
            "pulse_like_reason": result.reason}


def classify_fields(record, other=None) -> dict:
    """The velocity-pulse columns of ``pipeline run`` for one record or pair.

    Returns ``pulse_like`` (bool), ``velocity_pulse_indicator`` (Shahi & Baker's PI),
    ``velocity_tp_s`` (s), ``orientation_deg`` (from the first component towards the second; 0
    for one component) and ``azimuth_deg`` (clockwise from north, 0..180, or None).  Raises
    :class:`pulses.RecordError` for a pair that cannot be used.
    """
    from pulses import classify_pulse

    row = result_row(classify_pulse(record, other))
    return {k: row[k] for k in RUN_COLUMNS}


NOT_PULSE_WARNING = "Eq. 31 assumes a pulse; the design width does not"


def classification_fields(record, other=None, pair_fields=None, result=None) -> tuple[dict, str | None]:
    """The velocity-pulse columns of a row, and a warning (or None).

    ``pair_fields`` (already computed for the pair, in the main process) are used as they are;
    so is ``result``, the record's :class:`pulses.PulseClassification` where already made.
    """
    blank = RUN_PULSE_COLUMNS.blank()
    if pair_fields and "error" in pair_fields:  # the pair's classification failed: no direction
        return blank, f"velocity-pulse classification of the pair failed: {pair_fields['error']}"
    if pair_fields:
        fields = dict(pair_fields)
    elif result is not None:
        row = result_row(result)
        fields = {k: row[k] for k in RUN_COLUMNS}
    else:
        try:
            fields = classify_fields(record, other)
        except Exception as exc:  # an unusual record: designed all the same, and said so
            return blank, f"velocity-pulse classification failed: {' '.join(str(exc).split())}"
    return fields, (None if fields.get("pulse_like") else NOT_PULSE_WARNING)


def pair_classification(first, second) -> dict:
    """The pair's velocity-pulse fields; where the classification fails, ``{"error": reason}``:
    the pair is then designed in its recorded components and every row says why."""
    try:
        return classify_fields(first, second)
    except Exception as exc:
        return {"error": " ".join(str(exc).split()) or type(exc).__name__}
