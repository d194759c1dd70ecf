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
:func:`pulses.triplets.vertical_polarity` reads both and refuses a vertical where neither says
it or they disagree: a polarity is never guessed.
"""
from __future__ import annotations

import csv
import io
import math
import os
import posixpath
import re
import stat
import zipfile
import zlib
from dataclasses import dataclass, field

from ..errors import RecordError
from ..formats import MAX_SAMPLES, at2
from ..record import Record
from .read import record_from_reading, special_kind

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
#: a member unpacking to more than this many times its compressed size (plus :data:`RATIO_SLACK`)
#: is refused, by its stated sizes before it is read and while it is read (a zip's stated size may
#: lie): PEER's AT2 members deflate 2.7 to 3.0 times (measured on the shared download), a member of
#: zeros about 20 times; a "zip bomb" hundreds of times
MAX_RATIO = 100
#: bytes any member may unpack to whatever its ratio (a tiny member, a stored one)
RATIO_SLACK = 1 << 20
#: what reading a damaged zip member raises: a corrupted deflate stream is a ``zlib.error``, a bad
#: checksum ``BadZipFile``, a cut file ``EOFError``, an unknown compression ``NotImplementedError``
ZIP_READ_ERRORS = (OSError, zipfile.BadZipFile, zlib.error, RuntimeError, EOFError, NotImplementedError,
                   ValueError)

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
    ``scaling`` (``Scaling Method``, e.g. ``No Scaling``), ``notes`` (lines such as ``These
    records are UNSCALED, AS RECORDED``) and ``rejected``, ``(line number, reason)`` of the record
    lines that cannot be used."""

    entries: list
    scaling: str = ""
    notes: list = field(default_factory=list)
    source: str = ""
    rejected: list = field(default_factory=list)


def _value(text: str, kind):
    text = text.strip()
    if text.lower() in _ABSENT:
        return None
    if kind is str:
        return _printable(text)
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{_printable(text)[:40]!r} is not a number") from None
    if not math.isfinite(value):
        return None
    if kind is int:
        if value != int(value):
            raise ValueError(f"{text!r} is not a whole number")
        return int(value)
    return value


def _printable(text: str) -> str:
    """``text`` with its control characters written as escapes (``\\x1b``): a station or event
    name of the report reaches terminals, CSV files and pages as text, never as a terminal command."""
    if text.isprintable():
        return text
    return "".join(ch if ch.isprintable() else ch.encode("unicode_escape").decode("ascii") for ch in text)


def _fields(line: str, source: str, lineno: int) -> list[str]:
    """The fields of one line of the report (:class:`RecordError` for a line the csv module refuses:
    a field longer than its limit, a stray quote ...)."""
    try:
        return next(csv.reader([line], skipinitialspace=True), [])
    except csv.Error as exc:
        raise RecordError(f"{source}, line {lineno}: not a line of the table: {exc}") from None


def parse_search_results(text: str, source: str = SEARCH_RESULTS) -> SearchResults:
    """Parse the text of a PEER ``_SearchResults.csv``.

    A record line that cannot be used (the wrong number of fields, a value that is not a number
    where the report has numbers, no record number, a record number listed twice, a file name
    that is not a plain name, a line the csv module refuses) is set aside in
    :attr:`SearchResults.rejected` with its reason; the other records are read.

    Raises
    ------
    RecordError
        Naming ``source`` and the line: no metadata section, a header without the record number or
        the file columns, or no record line that can be used.
    """
    lines = text.splitlines()
    start = next((i for i, ln in enumerate(lines) if ln.strip() == METADATA_SECTION), None)
    if start is None or start + 1 >= len(lines):
        raise RecordError(f"{source}: not a PEER search report: no line {METADATA_SECTION!r}")
    header = [h.strip() for h in _fields(lines[start + 1], source, start + 2)]
    col = {h: i for i, h in enumerate(header) if h}
    needed = [METADATA["rsn"][0], *_FILE_COLUMNS]
    lacking = [h for h in needed if h not in col]
    if lacking:
        raise RecordError(f"{source}, line {start + 2}: the metadata table has no column "
                          f"{', '.join(map(repr, lacking))}")
    entries, rejected, seen = [], [], {}
    n = start + 2
    while n < len(lines) and lines[n].strip():
        n += 1
        try:
            entry = _entry(lines[n - 1], n, header, col, seen, source)
        except RecordError as exc:
            rejected.append((n, str(exc)))
            continue
        seen[entry.rsn] = n
        entries.append(entry)
    if not entries:
        why = f": {rejected[0][1]}" if rejected else ""
        raise RecordError(f"{source}: the metadata table lists no record that can be read{why}")
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
    return SearchResults(entries, scaling, notes, source, rejected)


def _entry(line: str, lineno: int, header, col, seen, source) -> PeerEntry:
    """One record line of the metadata table (:class:`RecordError` naming the line otherwise)."""
    row = _fields(line, source, lineno)
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
    files = {key: _value(row[col[name]], str) for name, key in _FILE_COLUMNS.items()}
    for f in files.values():
        if f is not None and not _safe_name(f):
            raise RecordError(f"{source}, line {lineno}: file name {f!r} is not a plain file name")
    return PeerEntry(meta["rsn"], files["h1"], files["h2"], files["vertical"], meta, lineno)


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
        self._packed: dict[str, int] = {}  # zip members' compressed sizes
        self._folded: dict | None = None
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
                self._packed[name] = info.compress_size

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
        if self._folded is None:  # built once: a lookup per listed file must not scan every member
            self._folded = {}
            for n in self._files:
                self._folded.setdefault(n.casefold(), []).append(n)
        folded = self._folded.get(name.casefold(), [])
        return folded[0] if len(folded) == 1 else None

    def missing(self, entry: PeerEntry) -> list[str]:
        """Files the report lists for ``entry`` that the download lacks (or refused)."""
        return [f for f in entry.files if self.find(f) is None]

    def refusal(self, name: str) -> str | None:
        for member, why in self.refused.items():
            if posixpath.basename(member.replace("\\", "/")) == name:
                return why
        return None

    def _bound(self, found: str, limit: int) -> int:
        """The bytes the file ``found`` may unpack to: ``limit``, and for a zip member at most
        :data:`MAX_RATIO` times its compressed size (plus :data:`RATIO_SLACK`); a member whose stated
        size exceeds either is refused unread."""
        size = self._sizes[found]
        if size > limit:
            raise RecordError(f"{self.display(found)}: {size} bytes, larger than the {limit} accepted")
        packed = self._packed.get(found)
        if packed is None:
            return limit
        bound = min(limit, MAX_RATIO * packed + RATIO_SLACK)
        if size > bound:
            raise RecordError(f"{self.display(found)}: unpacks to {size} bytes from {packed}, more than "
                              f"{MAX_RATIO} times its compressed size: refused unread (a damaged or "
                              "hostile zip)")
        return bound

    def _open_member(self, name: str, limit: int):
        """``(name found, a binary stream of the file bounded to what it may hold)``."""
        found = self.find(name)
        if found is None:
            why = self.refusal(name)
            raise RecordError(f"{self.display(name)}: " + (why or f"listed in {SEARCH_RESULTS} but not in the download"))
        bound = self._bound(found, limit)
        try:
            if self.kind == "folder":
                fh = _open_regular(self._files[found])
            else:
                zf = zipfile.ZipFile(self.path)
                try:
                    fh = _Closing(zf.open(self._files[found]), zf)
                except BaseException:
                    zf.close()
                    raise
        except RecordError:
            raise
        except ZIP_READ_ERRORS as exc:
            raise RecordError(f"{self.display(found)}: cannot read: {exc}") from None
        return found, _Bounded(fh, bound, self.display(found))

    def read_bytes(self, name: str, limit: int = MAX_MEMBER_BYTES) -> bytes:
        """The bytes of one file, at most ``limit`` (a larger file is refused unread; a zip member
        also within :data:`MAX_RATIO` of its compressed size, checked as it unpacks)."""
        found, fh = self._open_member(name, limit)
        with fh:
            try:
                return fh.read()
            except RecordError:
                raise
            except ZIP_READ_ERRORS as exc:
                raise RecordError(f"{self.display(found)}: cannot read: {exc}") from None

    def _read_text(self, name: str, limit: int) -> str:
        data = self.read_bytes(name, limit)
        try:
            return data.decode("utf-8-sig")
        except UnicodeDecodeError:
            return data.decode("latin-1")  # PEER writes ASCII; a stray byte must not stop the run

    def read_component(self, name: str, **options) -> Record:
        """One AT2 file of the download as a :class:`pulses.Record` (m/s^2), with every check of
        :func:`pulses.read_record`; ``metadata["source"]`` is :meth:`display`.  The file is
        streamed (a zip member is unpacked as it is parsed, never held whole in memory), and a
        damaged member fails with a message naming it."""
        found, fh = self._open_member(name, MAX_MEMBER_BYTES)
        label = self.display(found)
        with fh:
            text = io.TextIOWrapper(fh, encoding="utf-8-sig", errors="replace")  # as a plain AT2 file
            try:
                values, dt, header = at2.read_at2_stream(text, label)
            except RecordError:
                raise
            except ZIP_READ_ERRORS as exc:
                raise RecordError(f"{label}: cannot read: {exc}") from None
            finally:
                text.detach()
        reading = at2.reading_of(label, values, dt, header)
        return record_from_reading(label, reading, options.get("units"), options.get("dt"), name=found)


class _Closing(io.RawIOBase):
    """A zip member's stream that closes its archive with it."""

    def __init__(self, member, archive):
        self._member, self._archive = member, archive

    def readable(self):
        return True

    def readinto(self, buf):
        data = self._member.read(len(buf))
        buf[:len(data)] = data
        return len(data)

    def close(self):
        if not self.closed:
            self._member.close()
            self._archive.close()
        super().close()


class _Bounded(io.RawIOBase):
    """A binary stream that raises :class:`RecordError` once more than ``limit`` bytes came out of
    it: a file (or a zip member whose stated size lies) is never read beyond what it may hold."""

    def __init__(self, raw, limit: int, label: str):
        self._raw, self._left, self._limit, self._label = raw, limit, limit, label

    def readable(self):
        return True

    def readinto(self, buf):
        n = self._raw.readinto(memoryview(buf)[:min(len(buf), self._left + 1)])
        self._left -= n
        if self._left < 0:
            raise RecordError(f"{self._label}: unpacks to more than the {self._limit} bytes accepted "
                              f"(at most {MAX_RATIO} times a zip member's compressed size)")
        return n

    def close(self):
        if not self.closed:
            self._raw.close()
        super().close()


def _open_regular(path):
    """``path`` opened for reading if it is a regular file; a FIFO, a device or a socket (which
    would block or never end) is refused before anything opens it."""
    st = os.stat(path)
    if not stat.S_ISREG(st.st_mode):
        raise RecordError(f"{path}: {special_kind(st.st_mode)}, not a record file: not opened")
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    st = os.fstat(fd)
    if not stat.S_ISREG(st.st_mode):  # replaced between the two looks
        os.close(fd)
        raise RecordError(f"{path}: {special_kind(st.st_mode)}, not a record file: not opened")
    return io.FileIO(fd, "r")


#: how a zip archive starts: a local file header (or the end record of an empty archive)
_ZIP_STARTS = (b"PK\x03\x04", b"PK\x05\x06")


def is_peer_zip(path) -> bool:
    """A regular file that is a zip archive (its content says so, not its name): it starts as a
    zip starts, and :func:`zipfile.is_zipfile` finds its end record.  The end record alone is not
    enough: a SAC or text record whose last bytes happen to hold a zip signature is a record."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        return False
    try:
        with open(path, "rb") as fh:
            head = fh.read(4)
    except OSError:
        return False
    return head in _ZIP_STARTS and zipfile.is_zipfile(path)


def is_peer_download(path) -> bool:
    """A zip file, or a folder holding ``_SearchResults.csv``."""
    path = os.fspath(path)
    if os.path.isdir(path):
        return os.path.isfile(os.path.join(path, SEARCH_RESULTS))
    return is_peer_zip(path)
