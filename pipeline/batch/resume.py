"""Resuming ``pipeline run``: which records of an earlier run into the same ``--out`` can be kept.

A record's report is kept when it was made from the same file content (sha256 of the bytes; both
files of a pair), the same task (record id, path, columns, options, direction, scale ...) and the
same code: the package's version, a digest of its installed code files and its solver settings
(:func:`code_version`).  These make the record's *key*.  After each record's report is written, a line
``<key>  <sha256 of the report>  <record id>`` is appended to :data:`RESUME` in the output folder;
a later run keeps the record only if that line is there and the report (and its figure, with plots)
still has the content recorded, so a report edited, removed or half-written by a killed run is
computed again.  Records that failed have no line and are always computed again.

The per-record reports hold exactly the rows of ``summary.csv`` (the same header and formatting),
so ``summary.csv`` is rebuilt from the reports' text, and the files computed from the rows
(``suite.csv``, ``pairs.csv``, ``design.csv``, the plots) from the rows read back from that text in
every run, each cell by its column's declared kind (:meth:`pipeline.reports.columns.Columns.read`:
numbers at the reports' 6 digits, flags, whole numbers, text as written, blanks as None; never
guessed from how a cell looks): a resumed run and an uninterrupted one write the same bytes.
"""
from __future__ import annotations

import contextlib
import csv
import functools
import hashlib
import io
import os
import pathlib
import re

from ..reports import cells, columns, files, outfiles

#: the resume journal in ``--out`` (written by ``pipeline run`` alone, like the manifest)
RESUME = outfiles.RESUME
_HEADER = ("# pipeline run: records whose reports may be kept by a later run (key of input, options "
           "and version; sha256 of the report; sha256 of the figure or -; record id)\n")
_LINE = re.compile(r"^([0-9a-f]{64})  ([0-9a-f]{64})  ([0-9a-f]{64}|-)  (\S+)(?:  (\S+))?$")
#: a pair whose passes are all done (pipeline.batch.passes): the digest of its directions' entries
_PAIR_LINE = re.compile(r"^pair  ([0-9a-f]{64})  ([0-9a-f]{64})$")


@functools.lru_cache(maxsize=1)
def package_version() -> str:
    """The installed package's version, or that of the source tree's ``pyproject.toml`` (looked up
    once: 1.6 ms a time, and a batch's passes ask after each result)."""
    try:
        from importlib.metadata import version

        return version("rocking-columns")
    except Exception:
        pass
    path = pathlib.Path(__file__).resolve().parents[1] / "pyproject.toml"
    with contextlib.suppress(OSError):
        m = re.search(r'^version\s*=\s*"([^"]+)"', path.read_text(), re.M)
        if m:
            return m.group(1)
    return "unknown"


#: the files of the package whose content is its code (what a record's result depends on): its
#: sources, the compiled solver and data read at run time; caches and build products are not
CODE_SUFFIXES = (".py", ".pyx", ".pxd", ".pxi", ".h", ".so", ".pyd", ".json", ".csv")
#: the packages whose code computes a record
CODE_PACKAGES = ("pulses", "rocking", "pipeline")


def source_digest(roots) -> str:
    """sha256 of every code file (:data:`CODE_SUFFIXES`) under the folders ``roots``, by path
    relative to its root and content, in sorted order."""
    h = hashlib.sha256()
    for root in map(pathlib.Path, roots):
        files = sorted(p for p in root.rglob("*") if p.suffix in CODE_SUFFIXES
                       and "__pycache__" not in p.parts and p.is_file())
        for p in files:
            h.update(f"{root.name}/{p.relative_to(root).as_posix()}\0".encode("utf-8", "surrogateescape"))
            with contextlib.suppress(OSError):
                h.update(hashlib.sha256(p.read_bytes()).digest())
    return h.hexdigest()


@functools.lru_cache(maxsize=1)
def _code_digest() -> str:
    """:func:`source_digest` of the packages as imported (computed once a process: 10 ms)."""
    import importlib.util

    roots = []
    for name in CODE_PACKAGES:
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.submodule_search_locations:
            roots += list(spec.submodule_search_locations)
    return source_digest(roots)


def code_version() -> str:
    """What a record's result depends on besides its task and files: the package's version, its
    code (:func:`source_digest` of the installed files: an editable install whose code or
    defaults changed keeps no earlier report) and the solver's settings in this process."""
    from rocking.search import DEFAULT_SETTINGS

    settings = hashlib.sha256(repr(DEFAULT_SETTINGS).encode("utf-8")).hexdigest()[:16]
    return f"{package_version()}+{_code_digest()[:32]}+{settings}"


def file_digest(path) -> str | None:
    """sha256 of a file's bytes, or None when it cannot be read or is no regular file.  A file is
    hashed once per process while it stays the same (device, inode, size, modification and change
    times; the change time cannot be set back by hand): the
    tasks of a PEER download's records all depend on the one zip (205 tasks on a 50 MB zip hashed it
    205 times)."""
    import stat

    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    if not stat.S_ISREG(st.st_mode):  # a FIFO or /dev/zero: never opened (it would hang)
        return None
    stamp = (os.path.abspath(path), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)
    if stamp not in _DIGESTS:
        if len(_DIGESTS) >= _MAX_DIGESTS:
            _DIGESTS.clear()
        h = hashlib.sha256()
        try:
            with open(path, "rb") as fh:
                for chunk in iter(lambda: fh.read(1 << 20), b""):
                    h.update(chunk)
        except (OSError, ValueError):
            return None
        _DIGESTS[stamp] = h.hexdigest()
    return _DIGESTS[stamp]


#: digests of the files hashed in this process, by what identifies their content
_DIGESTS: dict = {}
_MAX_DIGESTS = 100_000


def task_key(task, version: str) -> str | None:
    """The key of ``task`` (see the module's docstring): every field of the task but its place in
    the batch, the content of its file(s) and ``version``; None when a file cannot be read."""
    import dataclasses

    peer = getattr(task, "peer", None)  # a record of a PEER download: its download's files
    inputs = peer.inputs() if peer is not None else (task.path, getattr(task, "path2", None),
                                                     getattr(task, "vertical", None))
    contents = [file_digest(p) for p in inputs if p is not None]
    if None in contents:
        return None
    text = repr((version, contents, dataclasses.replace(task, index=0)))
    return hashlib.sha256(text.encode("utf-8", "surrogateescape")).hexdigest()


def _digest(raw: bytes) -> str:
    return hashlib.sha256(raw).hexdigest()


def report_rows_text(raw: bytes, fields=None) -> str | None:
    """The rows of a per-record report (its text after the header line), or None if the header is
    not the present one."""
    text = raw.decode("utf-8", "surrogateescape")
    head, sep, rest = text.partition("\n")
    if not sep or head + "\n" != columns.csv_text(fields or _fields(), []):
        return None
    return rest


def _fields(options=None):
    """The columns of the reports of a run with ``options`` (None: ``--limit none``'s, the
    columns every run has)."""
    from .row import FIELDS, fields_for

    return FIELDS if options is None else fields_for(options)


def form_text(task) -> str:
    """The switches :mod:`pipeline.batch.passes` sets on a task (``check``, ``plot``,
    ``check_above``) as one word of the journal: ``10:`` or ``11:1.25,0.8`` (floats by repr, so
    that the task made from it again has the same key)."""
    above = ",".join(repr(float(x)) for x in task.check_above)
    return f"{int(bool(task.check))}{int(bool(task.plot))}:{above}"


def with_form(task, text: str | None):
    """``task`` with the switches of :func:`form_text`'s ``text``, or None where it is none."""
    import dataclasses

    if not text or len(text) < 3 or text[2] != ":" or any(c not in "01" for c in text[:2]):
        return None
    try:
        above = tuple(float(x) for x in text[3:].split(",") if x)
    except ValueError:
        return None
    return dataclasses.replace(task, check=text[0] == "1", plot=text[1] == "1", check_above=above)


class Journal:
    """The resume journal of one output folder (see the module's docstring).

    Besides a line per record, a pair computed in passes gets a line once its passes are done
    (:meth:`settle`): the digest of its directions' lines.  A later run keeps such a pair whole, in
    the forms its passes left it in, and only such a pair: a pair left half done is computed
    again pass by pass, keeping a direction's report only where a pass asks for it in the very
    form it was made in, so that every direction's rows are those of a run never stopped."""

    def __init__(self, folder):
        self.folder = pathlib.Path(folder)
        self.path = self.folder / RESUME
        self.entries: dict[str, tuple[str, str, str]] = {}  # record id -> (key, report, figure)
        self.forms: dict[str, str] = {}  # record id -> form_text of the task its report is of
        self.pairs: dict[str, str] = {}  # sha256 of a pair's name -> digest of its entries
        text = files.read_journal(self.path, _HEADER)
        if text is not None:
            for line in text.splitlines()[1:]:  # a line cut by a killed run does not match
                m = _LINE.match(line)
                if m:
                    self.entries[m.group(4)] = m.group(1, 2, 3)
                    self.forms.pop(m.group(4), None)
                    if m.group(5):
                        self.forms[m.group(4)] = m.group(5)
                    continue
                m = _PAIR_LINE.match(line)
                if m:
                    self.pairs[m.group(1)] = m.group(2)

    def reusable(self, task, key: str | None, plots: bool) -> str | None:
        """The rows text of ``task``'s report if it can be kept, else None."""
        entry = self.entries.get(task.record_id)
        if key is None or entry is None or entry[0] != key:
            return None
        raw = files._regular_file_bytes(self.folder / outfiles.record_csv_name(task.record_id))
        if raw is None or _digest(raw) != entry[1]:
            return None
        if plots:
            fig = files._regular_file_bytes(self.folder / outfiles.record_plot_name(task.record_id))
            if fig is None or entry[2] == "-" or _digest(fig) != entry[2]:
                return None
        return report_rows_text(raw, _fields(task.options))

    def add(self, record_id: str, key: str, report_raw: bytes, figure_raw: bytes | None,
            form: str | None = None) -> None:
        """Note that ``record_id``'s report (and figure) were written from ``key`` (by the task of
        :func:`form_text` ``form``, for a pair's direction)."""
        entry = (key, _digest(report_raw), _digest(figure_raw) if figure_raw is not None else "-")
        self.entries[record_id] = entry
        self.forms.pop(record_id, None)
        if form:
            self.forms[record_id] = form
        files.append_line(self.path, _HEADER, self._line(record_id))

    def _line(self, record_id: str) -> str:
        e, form = self.entries[record_id], self.forms.get(record_id)
        return f"{e[0]}  {e[1]}  {e[2]}  {record_id}" + (f"  {form}" if form else "") + "\n"

    def drop(self, record_id: str) -> None:
        self.entries.pop(record_id, None)
        self.forms.pop(record_id, None)

    def pair_digest(self, record_ids) -> str | None:
        """The digest of the entries of a pair's directions ``record_ids`` (in order), or None
        where one has none (failed, not computed)."""
        parts = []
        for rid in record_ids:
            e = self.entries.get(rid)
            if e is None or rid not in self.forms:
                return None
            parts.append(f"{rid} {e[0]} {e[1]} {e[2]} {self.forms[rid]}")
        return _digest("\n".join(parts).encode("utf-8", "surrogateescape"))

    def settle(self, pair: str, record_ids) -> None:
        """Note that the passes of ``pair`` (its directions ``record_ids``) are done, where each
        has its entry."""
        digest = self.pair_digest(record_ids)
        name = _pair_name(pair)
        if digest is None or self.pairs.get(name) == digest:
            return
        self.pairs[name] = digest
        files.append_line(self.path, _HEADER, f"pair  {name}  {digest}\n")

    def settled(self, pair: str) -> str | None:
        """The digest noted when ``pair``'s passes were done (:meth:`settle`), or None."""
        return self.pairs.get(_pair_name(pair))

    def finish(self, record_ids, pairs=()) -> None:
        """Rewrite the journal with the entries of ``record_ids`` only, in that order, and the
        settled ``pairs`` (``{pair: its directions' record ids}``) whose entries are still those
        noted."""
        lines = [self._line(rid) for rid in record_ids if rid in self.entries]
        for pair, rids in pairs.items():
            digest = self.pair_digest(rids)
            if digest is not None and self.settled(pair) == digest:
                lines.append(f"pair  {_pair_name(pair)}  {digest}\n")
        if lines or os.path.lexists(self.path):
            files.write_atomic(self.path, _HEADER + "".join(lines))


def _pair_name(pair: str) -> str:
    """A pair's name in the journal (names may hold any character: a PEER download's paths)."""
    return _digest(pair.encode("utf-8", "surrogateescape"))


def remove_stale_temporaries(folder, names) -> int:
    """Remove temporary files a killed run left in ``folder`` while writing one of ``names``
    (paths relative to ``folder``): ``.<name>.XXXXXXXX.tmp``, as :func:`files.write_atomic` makes
    them.  Returns how many were removed."""
    folder = pathlib.Path(folder)
    prefixes: dict[pathlib.Path, set[str]] = {}
    for rel in names:
        p = folder / rel
        prefixes.setdefault(p.parent, set()).add(f".{p.name[:40]}.")
    removed = 0
    for parent, starts in prefixes.items():
        if not files._real_folder(parent, folder):  # a link out of the folder: not ours to clean
            continue
        try:
            listing = os.listdir(parent)
        except OSError:
            continue
        for name in listing:
            if name.startswith(".") and name.endswith(".tmp"):
                body = name[:-4]
                if any(body.startswith(s) and re.fullmatch(r"[a-z0-9_]{8}", body[len(s):]) for s in starts):
                    with contextlib.suppress(OSError):
                        os.unlink(parent / name)
                        removed += 1
    return removed
