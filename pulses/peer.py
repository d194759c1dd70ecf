"""PEER NGA-West2 downloads: the search report ``_SearchResults.csv`` and the AT2 files it lists,
in a ``.zip`` as PEER delivers it or in the folder it was unpacked into.

The search report is a CSV in sections.  The section that matters starts with the line
``-- Summary of Metadata of Selected Records --``; its next line names the columns and one line
per record follows, up to the first blank line::

    Result ID, Spectral Ordinate, Record Sequence Number, ..., Scale Factor,
    Tp-Pulse Period (sec), ..., Earthquake Name, Year, Station Name, Magnitude, Mechanism,
    Rjb (km), Rrup (km), Vs30 (m/sec), Lowest Useable Frequency (Hz), ...,
    Horizontal-1 Acc. Filename, Horizontal-2 Acc. Filename, Vertical Acc. Filename

Names with commas are quoted; a value PEER does not have is ``-`` (e.g. ``Tp`` of a record that is
not pulse-like) and a file it does not have is ``-----`` (e.g. no vertical).  Everything is read
as the report writes it; numbers are parsed, nothing is inferred from file names.

A zip is read in memory (:mod:`zipfile`): nothing is ever extracted.  Its member names are checked
like any input: a name that is absolute (``/x``, ``C:\\x``, ``\\\\host\\x``) or holds a ``..``
part is never read, and a member larger than :data:`MAX_MEMBER_BYTES` (or a report larger than
:data:`MAX_REPORT_BYTES`) is refused before it is decompressed, and read with that bound.

Verticals: PEER names a vertical's positive direction in its file name and in the second header
line, ``UP`` (positive upwards) or ``DWN`` (positive downwards); see docs/theory.md section 10.
:func:`vertical_polarity` reads both and refuses a vertical where neither says it or they
disagree: a polarity is never guessed.
"""
from __future__ import annotations

import csv
import io
import math
import os
import posixpath
import re
import zipfile
from dataclasses import dataclass, field

from .errors import RecordError
from .formats import MAX_SAMPLES
from .record import Record

#: the search report's file name in a PEER download
SEARCH_RESULTS = "_SearchResults.csv"
#: the line that opens the per-record metadata table
METADATA_SECTION = "-- Summary of Metadata of Selected Records --"
#: an AT2 member larger than this is refused unread: the AT2 reader's own sample limit
#: (:data:`pulses.formats.MAX_SAMPLES`) at 20 characters a sample (PEER writes 15: ``  -.2556093E-02``)
MAX_MEMBER_BYTES = 20 * MAX_SAMPLES + 4096
#: a search report larger than this is refused unread (PEER's report of 100 records with their
#: spectra is under 1 MB)
MAX_REPORT_BYTES = 64 << 20
#: a zip with more members than this is refused (a PEER download of 100 records holds 601)
MAX_MEMBERS = 100_000

#: the report's columns for the grouping: (name in the report, key)
_FILE_COLUMNS = {"Horizontal-1 Acc. Filename": "h1", "Horizontal-2 Acc. Filename": "h2",
                 "Vertical Acc. Filename": "vertical"}
#: the metadata read from the report: key -> (name in the report, type)
METADATA = {
    "rsn": ("Record Sequence Number", int),
    "event": ("Earthquake Name", str),
    "year": ("Year", int),
    "station": ("Station Name", str),
    "magnitude": ("Magnitude", float),
    "mechanism": ("Mechanism", str),
    "rjb_km": ("Rjb (km)", float),
    "rrup_km": ("Rrup (km)", float),
    "vs30_m_s": ("Vs30 (m/sec)", float),
    "lowest_usable_freq_hz": ("Lowest Useable Frequency (Hz)", float),
    "tp_s": ("Tp-Pulse Period (sec)", float),
    "scale_factor": ("Scale Factor", float),
}
#: what the report writes for a value or a file it does not have
_ABSENT = {"", "-", "--", "---", "----", "-----", "n/a", "na", "nan"}


# -- the search report -------------------------------------------------------------------------------
@dataclass(frozen=True)
class PeerEntry:
    """One record of a PEER search: its metadata and its files as the report lists them.

    ``h1``, ``h2``, ``vertical`` are file names (None where the report has none); ``metadata`` maps
    the keys of :data:`METADATA` to values (None where the report has ``-``); ``line`` is the
    report's line number of the record.
    """

    rsn: int
    h1: str | None
    h2: str | None
    vertical: str | None
    metadata: dict = field(default_factory=dict, hash=False, compare=False)
    line: int = 0

    @property
    def files(self) -> list[str]:
        return [f for f in (self.h1, self.h2, self.vertical) if f]


@dataclass
class SearchResults:
    """A parsed ``_SearchResults.csv``: ``entries`` in the report's order, the search's
    ``scaling`` (``Scaling Method``, e.g. ``No Scaling``) and ``notes`` (lines such as ``These
    records are UNSCALED, AS RECORDED``)."""

    entries: list
    scaling: str = ""
    notes: list = field(default_factory=list)
    source: str = ""


def _value(text: str, kind):
    text = text.strip()
    if text.lower() in _ABSENT:
        return None
    if kind is str:
        return text
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{text!r} is not a number") from None
    if not math.isfinite(value):
        return None
    if kind is int:
        if value != int(value):
            raise ValueError(f"{text!r} is not a whole number")
        return int(value)
    return value


def parse_search_results(text: str, source: str = SEARCH_RESULTS) -> SearchResults:
    """Parse the text of a PEER ``_SearchResults.csv``.

    Raises
    ------
    RecordError
        Naming ``source`` and the line: no metadata section, a header without the record number or
        the file columns, a record line with the wrong number of fields or a value that is not a
        number where the report has numbers, or a record number listed twice.
    """
    lines = text.splitlines()
    start = next((i for i, ln in enumerate(lines) if ln.strip() == METADATA_SECTION), None)
    if start is None or start + 1 >= len(lines):
        raise RecordError(f"{source}: not a PEER search report: no line {METADATA_SECTION!r}")
    header = [h.strip() for h in next(csv.reader([lines[start + 1]], skipinitialspace=True))]
    col = {h: i for i, h in enumerate(header) if h}
    needed = [METADATA["rsn"][0], *_FILE_COLUMNS]
    lacking = [h for h in needed if h not in col]
    if lacking:
        raise RecordError(f"{source}, line {start + 2}: the metadata table has no column "
                          f"{', '.join(map(repr, lacking))}")
    entries, seen = [], {}
    n = start + 2
    while n < len(lines) and lines[n].strip():
        lineno = n + 1
        row = next(csv.reader([lines[n]], skipinitialspace=True))
        n += 1
        if len(row) < len(header):
            raise RecordError(f"{source}, line {lineno}: {len(row)} fields, the table's header has {len(header)}")
        meta = {}
        for key, (name, kind) in METADATA.items():
            if name not in col:
                meta[key] = None
                continue
            try:
                meta[key] = _value(row[col[name]], kind)
            except ValueError as exc:
                raise RecordError(f"{source}, line {lineno}: {name}: {exc}") from None
        if meta["rsn"] is None:
            raise RecordError(f"{source}, line {lineno}: no record sequence number")
        if meta["rsn"] in seen:
            raise RecordError(f"{source}, line {lineno}: RSN {meta['rsn']} is listed twice "
                              f"(also line {seen[meta['rsn']]})")
        seen[meta["rsn"]] = lineno
        files = {key: _value(row[col[name]], str) for name, key in _FILE_COLUMNS.items()}
        for f in files.values():
            if f is not None and not _safe_name(f):
                raise RecordError(f"{source}, line {lineno}: file name {f!r} is not a plain file name")
        entries.append(PeerEntry(meta["rsn"], files["h1"], files["h2"], files["vertical"], meta, lineno))
    if not entries:
        raise RecordError(f"{source}: the metadata table lists no record")
    scaling = ""
    notes = []
    for ln in lines[:start]:
        name, _, value = ln.partition(",")
        if name.strip().lower() == "scaling method:":
            scaling = value.strip()
    for ln in lines[n:]:
        if ln.strip().startswith("--"):
            break
        if "SCALED" in ln.upper():
            notes.append(ln.strip())
    return SearchResults(entries, scaling, notes, source)


def _safe_name(name: str) -> bool:
    """A file name the report may list: no folder, no drive, no parent."""
    return bool(name) and "/" not in name and "\\" not in name and ":" not in name and name not in (".", "..")


# -- the download ------------------------------------------------------------------------------------
def unsafe_member(name: str) -> str | None:
    """Why a zip member's name must not be read (absolute, a drive, ``..``), or None."""
    if "\x00" in name:
        return "holds a NUL character"
    norm = name.replace("\\", "/")
    if norm.startswith("/") or re.match(r"^[A-Za-z]:", norm):
        return "is an absolute path"
    if ".." in norm.split("/"):
        return "climbs out of the archive ('..')"
    return None


class PeerDownload:
    """A PEER download: a ``.zip`` (read in memory, never extracted) or a folder.

    Parameters
    ----------
    path : str or path-like
        The zip file or the folder holding ``_SearchResults.csv``.

    Attributes
    ----------
    search : SearchResults
        The parsed report.
    refused : dict
        Zip members that are never read, ``name -> reason`` (unsafe names, oversized members).

    Examples
    --------
    >>> import tempfile
    >>> import pulses
    >>> try:
    ...     pulses.PeerDownload(tempfile.mkdtemp())
    ... except pulses.RecordError as err:
    ...     print("_SearchResults.csv" in str(err))
    True
    """

    def __init__(self, path):
        self.path = os.fspath(path)
        self.refused: dict[str, str] = {}
        self._files: dict[str, str] = {}  # file name -> member name (zip) or path (folder)
        self._sizes: dict[str, int] = {}
        if os.path.isdir(self.path):
            self.kind = "folder"
            self._scan_folder()
        elif is_peer_zip(self.path):
            self.kind = "zip"
            self._scan_zip()
        else:
            raise RecordError(f"{self.path}: not a PEER download (a .zip or a folder holding {SEARCH_RESULTS})")
        self.search = parse_search_results(self._read_text(SEARCH_RESULTS, MAX_REPORT_BYTES),
                                           self.display(SEARCH_RESULTS))

    # -- listing ---------------------------------------------------------------------------------
    def _scan_folder(self):
        names = sorted(n for n in os.listdir(self.path) if os.path.isfile(os.path.join(self.path, n)))
        if SEARCH_RESULTS not in names:
            raise RecordError(f"{self.path}: no {SEARCH_RESULTS} in the folder: not a PEER download")
        for n in names:
            full = os.path.join(self.path, n)
            self._files[n] = full
            self._sizes[n] = os.path.getsize(full)

    def _scan_zip(self):
        try:
            with zipfile.ZipFile(self.path) as zf:
                infos = zf.infolist()
        except (zipfile.BadZipFile, OSError, RuntimeError) as exc:
            raise RecordError(f"{self.path}: cannot read the zip: {exc}") from None
        if len(infos) > MAX_MEMBERS:
            raise RecordError(f"{self.path}: {len(infos)} members, more than {MAX_MEMBERS} accepted")
        safe = []
        for info in infos:
            if info.is_dir():
                continue
            why = unsafe_member(info.filename)
            if why:
                self.refused[info.filename] = f"member name {info.filename!r} {why}: not read"
                continue
            safe.append(info)
        reports = [i for i in safe if posixpath.basename(i.filename) == SEARCH_RESULTS]
        if not reports:
            raise RecordError(f"{self.path}: no {SEARCH_RESULTS} in the zip: not a PEER download")
        if len(reports) > 1:
            raise RecordError(f"{self.path}: {len(reports)} files named {SEARCH_RESULTS} in the zip "
                              f"({', '.join(i.filename for i in reports)}): give one download at a time")
        folder = posixpath.dirname(reports[0].filename)
        for info in safe:
            if posixpath.dirname(info.filename) == folder:  # the report's files sit next to it
                name = posixpath.basename(info.filename)
                self._files[name] = info.filename
                self._sizes[name] = info.file_size

    # -- reading ---------------------------------------------------------------------------------
    def display(self, name: str) -> str:
        """How a file of the download is named in reports: ``folder/name`` or ``download.zip/name``."""
        if self.kind == "folder":
            return os.path.join(self.path, name)
        return f"{self.path}/{self._files.get(name, name)}"

    def find(self, name: str) -> str | None:
        """The download's file of that name: exactly, else the only one equal but for case."""
        if name in self._files:
            return name
        folded = [n for n in self._files if n.casefold() == name.casefold()]
        return folded[0] if len(folded) == 1 else None

    def missing(self, entry: PeerEntry) -> list[str]:
        """Files the report lists for ``entry`` that the download lacks (or refused)."""
        return [f for f in entry.files if self.find(f) is None]

    def refusal(self, name: str) -> str | None:
        for member, why in self.refused.items():
            if posixpath.basename(member.replace("\\", "/")) == name:
                return why
        return None

    def read_bytes(self, name: str, limit: int = MAX_MEMBER_BYTES) -> bytes:
        """The bytes of one file, at most ``limit`` (a larger file is refused unread)."""
        found = self.find(name)
        if found is None:
            why = self.refusal(name)
            raise RecordError(f"{self.display(name)}: " + (why or f"listed in {SEARCH_RESULTS} but not in the download"))
        size = self._sizes[found]
        if size > limit:
            raise RecordError(f"{self.display(found)}: {size} bytes, larger than the {limit} accepted")
        try:
            if self.kind == "folder":
                with open(self._files[found], "rb") as fh:
                    data = fh.read(limit + 1)
            else:
                with zipfile.ZipFile(self.path) as zf, zf.open(self._files[found]) as fh:
                    data = fh.read(limit + 1)  # bounded even if the zip's stated size lies
        except (OSError, zipfile.BadZipFile, RuntimeError, EOFError) as exc:
            raise RecordError(f"{self.display(found)}: cannot read: {exc}") from None
        if len(data) > limit:
            raise RecordError(f"{self.display(found)}: larger than the {limit} bytes accepted")
        return data

    def _read_text(self, name: str, limit: int) -> str:
        data = self.read_bytes(name, limit)
        try:
            return data.decode("utf-8-sig")
        except UnicodeDecodeError:
            return data.decode("latin-1")  # PEER writes ASCII; a stray byte must not stop the run

    def read_component(self, name: str, **options) -> Record:
        """One AT2 file of the download as a :class:`pulses.Record` (m/s^2), with every check of
        :func:`pulses.read_record`; ``metadata["source"]`` is :meth:`display`."""
        from . import at2
        from .io import record_from_reading

        found = self.find(name)
        label = self.display(found or name)
        text = self._read_text(name, MAX_MEMBER_BYTES)
        values, dt, header = at2.read_at2_stream(io.StringIO(text), label)
        reading = at2.reading_of(label, values, dt, header)
        return record_from_reading(label, reading, options.get("units"), options.get("dt"),
                                   name=found or name)


def is_peer_zip(path) -> bool:
    """A regular file that is a zip archive (its content says so, not its name)."""
    path = os.fspath(path)
    return os.path.isfile(path) and zipfile.is_zipfile(path)


def is_peer_download(path) -> bool:
    """A zip file, or a folder holding ``_SearchResults.csv``."""
    path = os.fspath(path)
    if os.path.isdir(path):
        return os.path.isfile(os.path.join(path, SEARCH_RESULTS))
    return is_peer_zip(path)


# -- verticals ---------------------------------------------------------------------------------------
#: PEER writes the polarity at the end of a vertical's name: ``TAF-UP``, ``ORRDWN``
_NAME_POLARITY = re.compile(r"(UP|DWN)$", re.IGNORECASE)


def vertical_polarity(record: Record, file_name: str | None = None) -> int:
    """+1 for a vertical whose samples are positive upwards (``UP``), -1 for positive downwards
    (``DWN``), from the file name and the header's component (docs/theory.md section 10).

    Raises
    ------
    RecordError
        When neither says ``UP`` or ``DWN``, or they disagree: a polarity is never guessed.
    """
    name = file_name or str(record.metadata.get("source") or record.name)
    stem = os.path.splitext(os.path.basename(name))[0]
    said = {}
    m = _NAME_POLARITY.search(stem)
    if m:
        said["file name"] = m.group(1).upper()
    comp = str(record.metadata.get("component") or "").strip().upper()
    m = _NAME_POLARITY.search(comp)
    if m:
        said["header"] = m.group(1)
    if not said:
        raise RecordError(f"{name}: the polarity of this vertical is not stated (neither its name nor "
                          f"its header component {comp!r} says UP or DWN); it is not used")
    if len(set(said.values())) > 1:
        raise RecordError(f"{name}: the file name says {said['file name']} but the header says "
                          f"{said['header']}: polarity unknown, not used")
    return 1 if next(iter(said.values())) == "UP" else -1


def upward(record: Record, file_name: str | None = None) -> Record:
    """The vertical as upward ground acceleration ``uv''`` (m/s^2): multiplied by -1 for ``DWN``."""
    sign = vertical_polarity(record, file_name)
    meta = dict(record.metadata, polarity="UP" if sign > 0 else "DWN", vertical=True)
    return Record(record.acc * sign, record.dt, record.name, record.t_start, meta)
