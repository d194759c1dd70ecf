"""USGS nshmp-haz hazard-curve CSV (``curves/<IMT>/total.csv``, one folder per measure).

::

    name,lon,lat,0.005,0.007,0.0098,...,2.2,3.3
    Concord CA,-122.00000,37.95000,2.85280770e-03,...,1.11793842e-05,0.0,0.0

Annual rates of exceedance; trailing zeros are real (the curve stops there).  The measure is the
folder's name as nshmp-haz writes it (``PGA``, ``SA0P2``, ``SA1P0``, ``PGV``), else the user's;
nshmp-haz gives PGA and SA in g and PGV in cm/s.
"""
from __future__ import annotations

import csv
import io
import os

from pulses.intensity import UNITS, parse_measure

from . import HazardFormat, Row, Table, numbers, register


def sniff(path, head) -> bool:
    first = head.splitlines()[0] if head else ""
    cells = [c.strip().lower() for c in first.split(",")]
    if cells[:3] != ["name", "lon", "lat"] or len(cells) < 5:
        return False
    try:
        [float(c) for c in cells[3:]]
    except ValueError:
        return False
    return True


def _folder_measure(path):
    folder = os.path.basename(os.path.dirname(os.path.abspath(path)))
    try:
        parse_measure(folder)
    except ValueError:
        return None
    return folder


def read(path, text) -> Table:
    reader = csv.reader(io.StringIO(text))
    names = next(reader)
    imls = numbers(names[3:], f"hazard file {path}: a level")
    rows = []
    for n, cells in enumerate(reader, start=1):
        if not cells or not "".join(cells).strip():
            continue
        lon, lat = float(cells[1]), float(cells[2])
        rows.append(Row(cells[0].strip() or f"{n}", lon, lat,
                        numbers(cells[3:], f"hazard file {path}, row {n}")))
    measure = _folder_measure(path)
    units = UNITS[parse_measure(measure)[0]] if measure else None
    return Table(measure, units, imls, rows, "rate", None, "nshmp-haz")


register(HazardFormat("nshmp", "USGS nshmp-haz curves CSV (name,lon,lat,<levels>; annual rates)",
                      sniff, read))
