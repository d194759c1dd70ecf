"""OpenQuake engine hazard-curve CSV exports (``hazard_curve-mean-PGA_<id>.csv``).

Two header styles, as the engine has written them:

current (3.x)::

    #,,,,,"generated_by='OpenQuake engine 3.18.0', ..., kind='mean', investigation_time=1.0, imt='PGA'"
    lon,lat,depth,poe-0.1000000,poe-0.4000000,poe-0.6000000

older::

    # source_model_tree_path=('b1',), gsim_tree_path=('b1',), investigation_time=1.0,imt="PGA"
    lon,lat,depth,poe-0.1,poe-0.4,poe-0.6

One row per site; the values are probabilities of exceedance in ``investigation_time`` years
(turned into annual rates by :func:`rocking.risk.curve.rates_from_poes`).  PGA and SA are in g,
PGV in cm/s (the engine's units).
"""
from __future__ import annotations

import csv
import io
import re

from pulses.intensity import UNITS, parse_measure

from . import HazardFormat, Row, Table, numbers, register
from ..curve import HazardError

_TIME = re.compile(r"investigation_time\s*=\s*([0-9.eE+-]+)")
_IMT = re.compile(r"imt\s*=\s*['\"]([^'\"]+)['\"]")


def sniff(path, head) -> bool:
    lines = head.splitlines()
    return (len(lines) >= 2 and lines[0].startswith("#") and "investigation_time" in lines[0]
            and lines[1].replace(" ", "").lower().startswith("lon,lat"))


def read(path, text) -> Table:
    lines = text.splitlines()
    header = lines[0]
    m = _TIME.search(header)
    if m is None:
        raise HazardError(f"hazard file {path} (openquake): no investigation_time in its first line")
    time = float(m.group(1))
    m = _IMT.search(header)
    measure = m.group(1) if m else None
    units = UNITS[parse_measure(measure)[0]] if measure else None
    reader = csv.reader(io.StringIO("\n".join(lines[1:])))
    names = [c.strip() for c in next(reader)]
    cols = [i for i, c in enumerate(names) if c.lower().startswith("poe-")]
    if not cols:
        raise HazardError(f"hazard file {path} (openquake): no poe-<level> columns")
    imls = numbers([names[i][4:] for i in cols], f"hazard file {path}: a level")
    lon_at, lat_at = names.index("lon"), names.index("lat")
    rows = []
    for n, cells in enumerate(reader, start=1):
        if not cells or not "".join(cells).strip():
            continue
        lon, lat = float(cells[lon_at]), float(cells[lat_at])
        rows.append(Row(f"{n} ({lon:g},{lat:g})", lon, lat,
                        numbers([cells[i] for i in cols], f"hazard file {path}, row {n}")))
    return Table(measure, units, imls, rows, "poe", time, "OpenQuake")


register(HazardFormat("openquake", "OpenQuake hazard_curve CSV (poe-<level> columns)", sniff, read))
