"""PEER NGA-West2 downloads as inputs of ``pipeline run``: ``pipeline run DOWNLOAD.zip --block HxW``
(or the folder it was unpacked into).

The search report ``_SearchResults.csv`` (:mod:`pulses.io.peer`) says which files form a record: each
record with both horizontals in the download is designed as a pair, in every direction
(:mod:`pipeline.batch.pairs`, as ``--pair`` does), with the report's metadata in every row
(:data:`PEER_COLUMNS`, and ``peer_tp_s`` next to the package's ``velocity_tp_s``).  A record whose
listed files are not all in the download fails, with the files it lacks, in ``failures.csv``: the
run goes on and exits with status 1.  Records are designed as recorded unless ``--peer-scales``
applies the search's scale factors; the ``peer_scaled`` column says which.

A zip is read in memory, never unpacked (:class:`pulses.PeerDownload`).  A task of a PEER
record carries a :class:`PeerSource` (plain data): the worker reads its files from the download.
"""
from __future__ import annotations

import functools
import os
from dataclasses import dataclass

from ..reports.columns import Columns, FLAG, TEXT, WHOLE

PEER_COLUMNS = Columns(
    ("peer_rsn", "-", "PEER record sequence number (RSN) of the record, from the download's "
                      "`_SearchResults.csv`; blank for records that do not come from a PEER download.", WHOLE),
    ("peer_event", "-", "Earthquake name as the search report writes it (PEER writes `_` for commas).", TEXT),
    ("peer_year", "-", "Year of the earthquake (search report).", WHOLE),
    ("peer_station", "-", "Station name (search report).", TEXT),
    ("peer_magnitude", "-", "Moment magnitude (search report)."),
    ("peer_mechanism", "-", "Fault mechanism (search report).", TEXT),
    ("peer_rjb_km", "km", "Joyner-Boore distance Rjb (search report)."),
    ("peer_rrup_km", "km", "Rupture distance Rrup (search report)."),
    ("peer_vs30_m_s", "m/s", "Vs30 of the station (search report)."),
    ("peer_lowest_usable_freq_hz", "Hz", "Lowest usable frequency of the record's processing (search "
                                         "report): pulses much longer than its inverse are not in the data."),
    ("peer_scale_factor", "-", "The search's scale factor for the record (`Scale Factor` of the report)."),
    ("peer_scaled", "-", "True when `--peer-scales` applied `peer_scale_factor` (then in `scale`); "
                         "False: the record as recorded, unscaled (the default).", FLAG),
    ("peer_vertical_file", "-", "The record's vertical component as the report lists it (blank: none); "
                                "with `--vertical auto` it is used in the vertical_* columns.", TEXT),
)
#: the report's metadata key behind each column (pulses.io.peer.METADATA)
_KEYS = {"peer_rsn": "rsn", "peer_event": "event", "peer_year": "year", "peer_station": "station",
         "peer_magnitude": "magnitude", "peer_mechanism": "mechanism", "peer_rjb_km": "rjb_km",
         "peer_rrup_km": "rrup_km", "peer_vs30_m_s": "vs30_m_s",
         "peer_lowest_usable_freq_hz": "lowest_usable_freq_hz", "peer_scale_factor": "scale_factor"}
#: the site column holding PEER's pulse period (declared in pipeline.batch.site, next to ours)
PEER_TP = "peer_tp_s"


@dataclass(frozen=True)
class PeerSource:
    """Where a task's ground motion comes from in a PEER download (plain, picklable data).

    ``download`` is the zip or folder as given; ``h1``, ``h2``, ``vertical`` the file names the
    report lists (``vertical`` None when it is not in the download, ``vertical_note`` then says
    so); ``missing`` why the record cannot be read (blank when it can); ``fields`` the
    :data:`PEER_COLUMNS` values and ``tp`` PEER's pulse period.
    """

    download: str
    h1: str | None
    h2: str | None
    vertical: str | None = None
    missing: str = ""
    fields: tuple = ()
    tp: float | None = None
    vertical_note: str = ""

    def inputs(self) -> list[str]:
        """The files whose content the record's results depend on (for :mod:`pipeline.batch.resume`)."""
        if os.path.isdir(self.download):
            return [os.path.join(self.download, n) for n in (self.h1, self.h2, self.vertical) if n]
        return [self.download]


def split_inputs(items, format: str | None = None) -> tuple[list[str], list[str]]:
    """``(PEER downloads, other inputs)``: a zip file, or a folder holding ``_SearchResults.csv``.
    With ``--format`` given, every file is a record of that format (a zip is no download)."""
    from pulses.io.peer import is_peer_download

    downloads, others = [], []
    for item in items:
        plain_file = format is not None and not os.path.isdir(item)
        (downloads if not plain_file and is_peer_download(str(item)) else others).append(str(item))
    return downloads, others


@functools.lru_cache(maxsize=8)
def _open(path: str, stamp):
    from pulses.io.peer import PeerDownload

    return PeerDownload(path)


def open_download(path: str):
    """The :class:`pulses.PeerDownload` at ``path``, parsed once per process (per content)."""
    try:
        st = os.stat(path)
        stamp = (st.st_mtime_ns, st.st_size, st.st_ino)
    except OSError:
        stamp = None
    return _open(path, stamp)


# -- tasks -------------------------------------------------------------------------------------------
def _fields(entry, scaled: bool) -> tuple:
    meta = entry.metadata
    values = {col: meta.get(key) for col, key in _KEYS.items()}
    values.update(peer_scaled=bool(scaled), peer_vertical_file=entry.vertical)
    return tuple(PEER_COLUMNS.row(values).items())


def scale_of(entry) -> float:
    """The search's scale factor of ``entry``, checked by the one rule of every scale
    (:func:`pipeline.values.parse_scale`); :class:`ArgumentError` when it is missing or outside it
    (a factor of 1e6, 0 or nan was applied, or silently taken as 1)."""
    from ..values import ArgumentError, parse_scale

    factor = entry.metadata.get("scale_factor")
    what = f"RSN {entry.rsn}: --peer-scales: the search's scale factor (_SearchResults.csv, line {entry.line})"
    if factor is None:
        raise ArgumentError(f"{what} is missing (blank, '-' or not finite): the record is not "
                            "designed rather than designed unscaled")
    return parse_scale(float(factor), what)


def _why_not(d, e, scaled: bool) -> str:
    """Why the record ``e`` of download ``d`` cannot be designed (blank: it can)."""
    from ..values import ArgumentError

    if e.h1 is None or e.h2 is None:
        return f"RSN {e.rsn}: the search report lists no {'Horizontal-1' if e.h1 is None else 'Horizontal-2'} file"
    lacking = [f for f in (e.h1, e.h2) if d.find(f) is None]
    if lacking:
        reasons = [d.refusal(f) for f in lacking]
        named = ", ".join(f + (f" ({r})" if r else "") for f, r in zip(lacking, reasons))
        return f"RSN {e.rsn}: listed in _SearchResults.csv (line {e.line}) but not in the download: {named}"
    if d.find(e.h1) == d.find(e.h2) or e.h1.casefold() == e.h2.casefold():
        return (f"RSN {e.rsn}: _SearchResults.csv (line {e.line}) names one file, {e.h1}, as both "
                "horizontal components: a pair is two components (it would double the record in one "
                "direction and cancel it in the other)")
    if scaled:
        try:
            scale_of(e)
        except ArgumentError as exc:
            return str(exc)
    return ""


#: the list, in ``--out``, of the records a search report lists that are not in the download
NOT_DOWNLOADED = "peer-not-downloaded.csv"
NOT_DOWNLOADED_FIELDS = ["download", "peer_rsn", "line", "peer_event", "peer_station", "h1", "h2", "vertical"]


def not_downloaded_text(rows) -> str | None:
    """The text of :data:`NOT_DOWNLOADED` (None when no download was given)."""
    from ..reports.columns import csv_text

    return None if rows is None else csv_text(NOT_DOWNLOADED_FIELDS, rows)


def _absent(d, e) -> bool:
    """Not one file of record ``e`` is in download ``d`` (none refused either): a record of the
    search that was not downloaded, the usual case (PEER's zip holds the records ticked)."""
    return bool(e.files) and all(d.find(f) is None and d.refusal(f) is None for f in e.files)


def record_units(download, scaled: bool, say, absent: list | None = None) -> list[tuple]:
    """``(entry, PeerSource)`` for every record the report lists, in its order; a record line the
    report's parser set aside is ``(None, PeerSource)`` failing with its reason.  A vertical
    that is not in the download is no reason to fail the record: it is not used (the row says why).
    With ``absent`` (a list), the records none of whose files is in the download are appended to
    it as rows of :data:`NOT_DOWNLOADED` instead of being failures."""
    from pulses import RecordError

    try:
        d = open_download(download)
    except RecordError as exc:
        return [(None, PeerSource(download, None, None, missing=str(exc)))]
    entries = d.search.entries
    units = [(None, PeerSource(download, None, None, missing=why)) for _, why in d.search.rejected]
    n_missing = len(units)
    n_absent = 0
    for e in entries:
        if absent is not None and _absent(d, e):
            n_absent += 1
            absent.append({"download": d.path, "peer_rsn": e.rsn, "line": e.line, "h1": e.h1, "h2": e.h2,
                           "vertical": e.vertical, "peer_event": e.metadata.get("event"),
                           "peer_station": e.metadata.get("station")})
            continue
        why = _why_not(d, e, scaled)
        n_missing += bool(why)
        vertical = d.find(e.vertical) if e.vertical else None
        units.append((e, PeerSource(download, d.find(e.h1) or e.h1 if e.h1 else None,
                                    d.find(e.h2) or e.h2 if e.h2 else None, vertical,
                                    missing=why, fields=_fields(e, scaled), tp=e.metadata.get("tp_s"),
                                    vertical_note=_vertical_note(d, e, vertical))))
    scaling = "scaled by the search's factors (--peer-scales)" if scaled else \
        "as recorded, unscaled (--peer-scales applies the search's factors)"
    for member, why in d.refused.items():
        say(f"pipeline run: note: {d.path}: {why}")
    listed = len(entries) + len(d.search.rejected)
    not_here = f", {n_absent} not in the download (listed in {NOT_DOWNLOADED})" if n_absent else ""
    say(f"pipeline run: PEER download {d.path}: {listed} records listed, "
        f"{listed - n_missing - n_absent} complete{not_here}, {n_missing} incomplete (failures); "
        f"designed {scaling}")
    return units


def _vertical_note(d, e, found) -> str:
    """Why the vertical ``e`` lists is not used although listed (blank: used, or none listed)."""
    if not e.vertical or found is not None:
        return ""
    why = d.refusal(e.vertical) or "listed in _SearchResults.csv but not in the download"
    return f"vertical not used: {d.display(e.vertical)}: {why}"


# -- in the worker -----------------------------------------------------------------------------------
def read_components(task):
    """``(first, second, the vertical's name or None)`` of a PEER task, as read (unscaled, not yet
    checked as a pair); a record with files missing raises :class:`pulses.RecordError`."""
    from pulses import RecordError

    src = task.peer
    if src.missing:
        raise RecordError(src.missing)
    d = open_download(src.download)
    first, second = d.read_component(src.h1), d.read_component(src.h2)
    return first, second, (d.display(src.vertical) if src.vertical else None)


def read_vertical(task):
    """``(the vertical of a PEER task as read, or None; why it is not used, or "")``: a vertical
    that is absent or cannot be read (a damaged member, a constant, NaN samples ...) is not used,
    and the horizontals are designed as they are through ``--triplet``."""
    from pulses import RecordError

    src = task.peer
    if not src.vertical:
        return None, src.vertical_note
    try:
        return open_download(src.download).read_component(src.vertical), ""
    except RecordError as exc:
        return None, f"vertical not used: {exc}"


def fields(task) -> dict:
    """The :data:`PEER_COLUMNS` of a task's rows (blank for a task that is not a PEER record)."""
    src = getattr(task, "peer", None)
    if src is None or not src.fields:
        return PEER_COLUMNS.blank()
    return PEER_COLUMNS.row(dict(src.fields))


def tp(task):
    """PEER's pulse period of a task's record (None: not a PEER record, or not pulse-like in PEER's search)."""
    src = getattr(task, "peer", None)
    return None if src is None else src.tp


