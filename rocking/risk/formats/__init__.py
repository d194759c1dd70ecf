"""The registry of hazard-curve formats that :func:`read_hazard` reads.

A format is one module and one registration, as the record formats of :mod:`pulses.formats` are:
the module builds one :class:`HazardFormat` (how to recognise the file from its name and first
lines, how to read it) and passes it to :func:`register`.  A reader returns a :class:`Table`: the
measure and units the file states (None where it states none), the levels, and one row of values
per site, as probabilities in the file's investigation time or as annual rates.
:func:`read_hazard` then only dispatches: it picks the site, applies what the user states (never
in place of what the file states: a conflict is an error) and makes the
:class:`rocking.risk.HazardCurve`, which checks the curve.

To add a format: a module here with ``sniff(path, head) -> bool`` and ``read(path, text) ->
Table``, registered once at its end, and its name in :data:`MODULES`.
"""
from __future__ import annotations

import dataclasses
import importlib
import math
import os
from typing import Callable

from ..curve import HazardCurve, HazardError, rates_from_poes

#: the format modules, in the order they are asked whether a file is theirs (the plain CSV last)
MODULES = ("openquake", "usgs_json", "nshmp", "plain")


@dataclasses.dataclass
class Row:
    """One site's values: ``label`` (a name or ``lon,lat``), where it is, and its values."""

    label: str
    lon: float | None
    lat: float | None
    values: list


@dataclasses.dataclass
class Table:
    """What a format's reader found in a file.

    Attributes
    ----------
    measure, units : str or None
        As the file states them (None: it does not).
    imls : list of float
        The levels, in ``units``.
    rows : list of Row
        One per site (per measure, for a file of several: ``Row.label`` then names the measure).
    values : {"poe", "rate"}
        Probabilities of exceedance in ``investigation_time`` years, or annual rates.
    investigation_time : float or None
    fmt : str
        The format's name.
    measures : list of (str, Table) or None
        A file holding curves of several measures (USGS's web service): each measure's table;
        the caller picks one with ``imt``.
    """

    measure: str | None
    units: str | None
    imls: list
    rows: list
    values: str = "rate"
    investigation_time: float | None = None
    fmt: str = ""
    measures: list | None = None


@dataclasses.dataclass(frozen=True)
class HazardFormat:
    name: str
    description: str
    sniff: Callable
    read: Callable


_REGISTRY: dict[str, HazardFormat] = {}


def register(fmt: HazardFormat) -> HazardFormat:
    if fmt.name in _REGISTRY:
        raise ValueError(f"hazard format {fmt.name!r} is registered twice")
    _REGISTRY[fmt.name] = fmt
    return fmt


def formats() -> dict[str, HazardFormat]:
    """``{name: HazardFormat}`` of every registered format, in the order files are tried."""
    for name in MODULES:
        importlib.import_module(f"{__name__}.{name}")
    return dict(_REGISTRY)


#: bytes of a file looked at to recognise its format
HEAD = 4096
#: largest hazard file read (a national grid of curves is larger; cut the site out first)
MAX_BYTES = 200_000_000


def read_hazard(path, *, format=None, site=None, site_row=None, imt=None, units=None) -> HazardCurve:
    """The hazard curve of one site from a file of any registered format.

    Parameters
    ----------
    path : str or path
        An OpenQuake ``hazard_curve-*.csv`` export, an nshmp-haz ``curves/<IMT>/total.csv``, a
        JSON response of the USGS hazard web service, or a two-column CSV (level, annual rate).
    format : str, optional
        The format's name (:func:`formats`); default: recognised from the file.
    site : (float, float), optional
        Longitude and latitude of the site, for a file of several sites (the nearest within
        0.005 deg).
    site_row : int, optional
        Or the site's row among the file's sites, from 1.
    imt : str, optional
        The measure (``PGA``, ``PGV``, ``SA(1.0)``) where the file does not state it, or the one to
        pick from a file of several.
    units : str, optional
        The levels' units where the file does not state them.

    Raises
    ------
    rocking.risk.HazardError
        One line saying what is wrong: a file that cannot be read, a format not recognised, a
        site not found, a measure or units not stated, a bad curve.

    Examples
    --------
    >>> import os, tempfile
    >>> from rocking.risk import read_hazard
    >>> path = os.path.join(tempfile.mkdtemp(), "site.csv")
    >>> with open(path, "w") as fh:
    ...     _ = fh.write("# measure: SA(1.0)\\n# units: g\\niml,rate\\n0.1,1e-2\\n0.2,3e-3\\n0.4,5e-4\\n")
    >>> curve = read_hazard(path)
    >>> curve.measure, curve.n, round(curve.rate_at(0.3), 6)
    ('SA(1.0)', 3, 0.001052)
    >>> read_hazard(path, imt="PGA")
    Traceback (most recent call last):
    ...
    rocking.risk.curve.HazardError: hazard file ...site.csv: the file states the measure 'SA(1.0)', not 'PGA'
    """
    shown = os.fspath(path)
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        raise HazardError(f"hazard file {shown}: {exc.strerror or exc}") from None
    if len(raw) > MAX_BYTES:
        raise HazardError(f"hazard file {shown}: larger than {MAX_BYTES // 1_000_000} MB; "
                          "cut the site's curve out first")
    text = raw.decode("utf-8-sig", errors="replace")
    fmt = _format_of(shown, text[:HEAD], format)
    try:
        table = fmt.read(shown, text)
    except HazardError:
        raise
    except (ValueError, KeyError, IndexError, TypeError) as exc:
        raise HazardError(f"hazard file {shown} ({fmt.name}): {exc}") from None
    table = _pick_measure(table, imt, shown)
    return _curve(table, shown, site, site_row, imt, units)


def _format_of(shown, head, name) -> HazardFormat:
    known = formats()
    if name is not None:
        if name not in known:
            raise HazardError(f"hazard format {name!r}: expected one of {', '.join(known)}")
        return known[name]
    for fmt in known.values():
        if fmt.sniff(shown, head):
            return fmt
    raise HazardError(f"hazard file {shown}: not a hazard curve this package reads (formats: "
                      + "; ".join(f"{f.name}: {f.description}" for f in known.values()) + ")")


def _pick_measure(table, imt, shown) -> Table:
    if not table.measures:
        return table
    from pulses.intensity import measure_name, parse_measure

    names = [m for m, _ in table.measures]
    if imt is None:
        if len(names) == 1:
            return table.measures[0][1]
        raise HazardError(f"hazard file {shown}: curves of {len(names)} measures ({', '.join(names)}); "
                          "pick one with imt (--imt)")
    want = measure_name(*parse_measure(imt))
    for m, t in table.measures:
        if measure_name(*parse_measure(m)) == want:
            return t
    raise HazardError(f"hazard file {shown}: no curve of {want} (it has {', '.join(names)})")


def _stated(what, in_file, given, shown, same):
    """What the file states, or the user's value where it states none; a conflict is an error."""
    if in_file is not None and given is not None and not same(in_file, given):
        raise HazardError(f"hazard file {shown}: the file states {what} {in_file!r}, not {given!r}")
    return in_file if in_file is not None else given


def _same_measure(a, b):
    from pulses.intensity import measure_name, parse_measure

    try:
        return measure_name(*parse_measure(a)) == measure_name(*parse_measure(b))
    except ValueError:
        return False


def _curve(table, shown, site, site_row, imt, units) -> HazardCurve:
    measure = _stated("the measure", table.measure, imt, shown, _same_measure)
    unit = _stated("the units", table.units, units, shown, lambda a, b: a.lower() == b.lower())
    row = pick_site(table.rows, site, site_row, shown)
    who = f"{shown}" + (f", site {row.label}" if len(table.rows) > 1 else "")
    values = row.values
    if table.values == "poe":
        values = rates_from_poes(values, table.investigation_time, f"hazard curve {who}")
    where = None if row.lon is None else (row.lon, row.lat)
    source = f"{os.path.basename(shown)}, {table.fmt}" + (f", site {row.label}" if len(table.rows) > 1 else "")
    if measure is None:
        raise HazardError(f"hazard file {shown}: the intensity measure is not stated; give it "
                          "(imt, --imt: PGA, PGV or SA(T))")
    if unit is None:
        raise HazardError(f"hazard file {shown}: the units of the levels ({measure}) are not stated; "
                          "give them (units, --units: g, m/s2, cm/s2; cm/s, m/s for PGV)")
    return HazardCurve(measure, table.imls, values, units=unit, source=source, site=where,
                       investigation_time=table.investigation_time if table.values == "poe" else None)


def pick_site(rows, site, site_row, shown) -> Row:
    """The row of the site asked for (the only one where the file has one)."""
    if not rows:
        raise HazardError(f"hazard file {shown}: no curve in it")
    if site_row is not None:
        n = int(site_row)
        if not 1 <= n <= len(rows):
            raise HazardError(f"hazard file {shown}: site row {site_row} asked for; it has "
                              f"{len(rows)} site(s) (rows 1-{len(rows)})")
        return rows[n - 1]
    if site is not None:
        lon, lat = (float(v) for v in site)
        located = [r for r in rows if r.lon is not None]
        if not located:
            raise HazardError(f"hazard file {shown}: its curves give no location; pick by row")
        near = min(located, key=lambda r: math.hypot(r.lon - lon, r.lat - lat))
        if math.hypot(near.lon - lon, near.lat - lat) > 0.005:
            raise HazardError(f"hazard file {shown}: no site at {lon:g},{lat:g} (nearest: "
                              f"{near.lon:g},{near.lat:g}, {near.label})")
        return near
    if len(rows) > 1:
        first = ", ".join(r.label for r in rows[:3]) + (" ..." if len(rows) > 3 else "")
        raise HazardError(f"hazard file {shown}: {len(rows)} sites ({first}); pick one with "
                          "site=(lon, lat) or site_row=N (--site LON,LAT or --site-row N)")
    return rows[0]


def numbers(cells, what) -> list:
    """Floats of ``cells`` (blank cells are an error naming ``what``)."""
    out = []
    for c in cells:
        try:
            out.append(float(c))
        except ValueError:
            raise HazardError(f"{what}: {c.strip()!r} is not a number") from None
    return out
