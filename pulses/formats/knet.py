"""K-NET and KiK-net ASCII records (read through obspy).

obspy keeps the samples in counts and puts the header's scale factor, converted from gal to m/s^2,
into ``stats.calib``; the samples are multiplied by it and the mean is removed (the K-NET
convention), so the file states its units (m/s^2) and a user's units are not applied.
"""
from __future__ import annotations

from ..orientation import orientation
from .obspy import read as read_by_obspy
from .obspy import trace_metadata
from .registry import UNITS_STATED, Reading, ReadOptions, RecordFormat, register

#: K-NET ``Dir.`` (obspy's channel, KiK-net's 1-6 mapped to NS1 ... UD2) -> orientation
_DIRECTIONS = {"NS": orientation(azimuth=0.0), "EW": orientation(azimuth=90.0),
               "UD": orientation(vertical=True)}


def knet_orientation(channel) -> dict:
    """``azimuth`` and ``vertical`` from a K-NET or KiK-net direction (``N-S`` 0, ``E-W`` 90, ``U-D``)."""
    return dict(_DIRECTIONS.get(str(channel or "").strip().upper()[:2], {}))


def from_trace(tr, path: str, options: ReadOptions) -> Reading:
    """Interpret a K-NET trace obspy read: counts times the scale factor, mean removed, in m/s^2."""
    st = tr.stats
    values = tr.data.astype(float)
    values -= values.mean()
    values *= float(st.calib)
    meta = trace_metadata(tr)
    knet = st.get("knet", {})
    meta["event"] = f"M{knet.get('mag', '')} {knet.get('evot', '')}".strip()
    meta["knet_accmax_gal"] = knet.get("accmax")
    meta.update(knet_orientation(st.channel))
    meta["notes"] = ["K-NET: samples times the header scale factor, mean removed"]
    return Reading(values, float(st.delta), meta, units="m/s2", units_rule=UNITS_STATED)


FORMAT = register(RecordFormat(
    name="knet", obspy_name="KNET", from_trace=from_trace,
    read=lambda path, options: read_by_obspy(path, options, "KNET")))
