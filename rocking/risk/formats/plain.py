"""A plain two-column CSV: level, annual rate of exceedance (or probability in a stated time).

::

    # measure: SA(1.0)
    # units: g
    iml,rate
    0.05,2.1e-2
    0.1,8.4e-3

The measure and units are given by ``#`` lines (``measure``, ``imt``, ``units``, and for
probabilities ``investigation_time``; ``key: value`` or ``key=value``) or by a column heading
such as ``SA(1.0) [g]`` / ``PGV (cm/s)``; where the file states neither, the user must (``imt=``,
``units=``).  A second column headed ``poe`` holds probabilities in ``investigation_time`` years.
"""
from __future__ import annotations

import csv
import io
import re

from . import HazardFormat, Row, Table, numbers, register
from ..curve import HazardError

_KEY = re.compile(r"^#\s*([A-Za-z_ ]+?)\s*[:=]\s*(.+?)\s*$")
_HEADING = re.compile(r"^\s*([^\[\(]+?)\s*[\[\(]\s*([^\]\)]+)\s*[\]\)]\s*$")
_RATE_WORDS = ("rate", "annual_rate", "afe", "lambda", "annual_rate_of_exceedance", "frequency")


def sniff(path, head) -> bool:
    for line in head.splitlines():
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        cells = [c for c in re.split(r"[,;\s]+", s) if c]
        if len(cells) != 2:
            return False
        try:
            [float(c) for c in cells]
            return True
        except ValueError:
            continue  # the heading
    return False


def _keys(lines):
    keys = {}
    for line in lines:
        m = _KEY.match(line.strip())
        if m:
            keys[m.group(1).strip().lower().replace(" ", "_")] = m.group(2).strip()
    return keys


def read(path, text) -> Table:
    lines = text.splitlines()
    keys = _keys(l for l in lines if l.strip().startswith("#"))
    measure = keys.get("measure") or keys.get("imt") or keys.get("intensity_measure")
    units = keys.get("units")
    body = [l for l in lines if l.strip() and not l.strip().startswith("#")]
    delimiter = "," if "," in body[0] else None
    split = (lambda l: next(csv.reader(io.StringIO(l)))) if delimiter else str.split
    values = "rate"
    first = [c.strip() for c in split(body[0])]
    try:
        numbers(first, "")
        data = body
    except HazardError:
        data = body[1:]
        m = _HEADING.match(first[0])
        if m:
            measure = measure or (m.group(1) if m.group(1).lower() not in ("iml", "level") else None)
            units = units or m.group(2)
        elif first[0].lower() not in ("iml", "level", "x"):
            measure = measure or first[0]
        if first[1].lower().startswith("poe"):
            values = "poe"
        elif first[1].lower() not in _RATE_WORDS:
            raise HazardError(f"hazard file {path} (plain): second column {first[1]!r}: expected an "
                              f"annual rate ({', '.join(_RATE_WORDS)}) or poe")
    xs, ys = [], []
    for n, line in enumerate(data, start=1):
        cells = [c for c in split(line) if c.strip()]
        if len(cells) != 2:
            raise HazardError(f"hazard file {path} (plain): line {n} of the data has {len(cells)} "
                              "values; expected two (level, rate)")
        x, y = numbers(cells, f"hazard file {path}, line {n}")
        xs.append(x)
        ys.append(y)
    time = keys.get("investigation_time")
    if values == "poe" and time is None:
        raise HazardError(f"hazard file {path} (plain): probabilities (poe) without "
                          "'# investigation_time: YEARS'")
    return Table(measure, units, xs, [Row("1", None, None, ys)], values,
                 None if time is None else float(time), "plain CSV")


register(HazardFormat("plain", "two columns: level, annual rate (measure and units in '#' lines "
                               "or the heading, or given)", sniff, read))
