"""The USGS hazard web service's JSON response (the ``Total`` component of each measure).

The service (nshmp-haz-ws ``/hazard``) answers with one entry per measure::

    {"status": "success", ..., "response": [
        {"metadata": {"latitude": 34.0, "longitude": -118.0, "imt": {"value": "PGA", ...},
                      "xlabel": "Ground Motion (g)", "ylabel": "Annual Frequency of Exceedence",
                      "xvalues": [0.0025, ...]},
         "data": [{"component": "Total", "yvalues": [...]}, {"component": "Fault", ...}]}]}

and its newer form (``hazardCurves``) with ``{"imt": {...}, "data": [{"component": "Total",
"values": {"xs": [...], "ys": [...]}}]}``.  Annual rates; the units are those of ``xlabel`` (the
older form) or of the measure (g; cm/s for PGV).
"""
from __future__ import annotations

import json
import re

from pulses.intensity import UNITS, parse_measure

from . import HazardFormat, Row, Table, numbers, register
from ..curve import HazardError

_UNITS = re.compile(r"\(([^)]+)\)\s*$")


def sniff(path, head) -> bool:
    h = head.lstrip()
    return h.startswith("{") and ('"response"' in head or '"hazardCurves"' in head)


def _imt(meta):
    imt = meta.get("imt")
    return imt.get("value") if isinstance(imt, dict) else imt


def _total(data, path, measure):
    for d in data:
        if str(d.get("component", "")).lower() == "total":
            return d
    raise HazardError(f"hazard file {path} (usgs-json): no Total component for {measure}")


def _table(measure, units, xs, ys, lon, lat, path):
    label = f"{lon:g},{lat:g}" if lon is not None else "1"
    xs = numbers([str(v) for v in xs], f"hazard file {path}: a level")
    ys = numbers([str(v) for v in ys], f"hazard file {path}: a rate")
    return Table(measure, units, xs, [Row(label, lon, lat, ys)], "rate", None, "USGS web service")


def read(path, text) -> Table:
    doc = json.loads(text)
    tables = []
    for entry in doc.get("response") or []:
        meta = entry["metadata"]
        measure = _imt(meta)
        m = _UNITS.search(str(meta.get("xlabel", "")))
        units = m.group(1).strip() if m else None
        d = _total(entry["data"], path, measure)
        tables.append((measure, _table(measure, units, meta["xvalues"], d["yvalues"],
                                       meta.get("longitude"), meta.get("latitude"), path)))
    for entry in doc.get("hazardCurves") or []:
        measure = _imt(entry)
        units = UNITS[parse_measure(measure)[0]]
        d = _total(entry["data"], path, measure)
        site = (doc.get("request") or {}).get("site") or {}
        tables.append((measure, _table(measure, units, d["values"]["xs"], d["values"]["ys"],
                                       site.get("longitude"), site.get("latitude"), path)))
    if not tables:
        raise HazardError(f"hazard file {path} (usgs-json): no hazard curve in the response"
                          + (f" (status {doc.get('status')!r})" if doc.get("status") else ""))
    first = tables[0][1]
    return Table(None, None, first.imls, first.rows, "rate", None, "USGS web service", measures=tables)


register(HazardFormat("usgs-json", "USGS hazard web service JSON (component Total)", sniff, read))
