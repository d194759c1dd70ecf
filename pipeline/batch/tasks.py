"""What one unit of work of ``pipeline run`` is: a :class:`Task` (a record, or a direction of a pair,
with its :class:`Column` s and :class:`Options`), the records' ids, and the input list.

Plain, picklable data: a task runs the same in this process, in a process pool or on a dask worker.
"""
from __future__ import annotations

import fnmatch
import glob
import hashlib
import os
import pathlib
import re
from dataclasses import dataclass, field

from ..reports.outfiles import RESERVED_IDS
from .margin import DEFAULT_LIMIT

@dataclass(frozen=True)
class Column:
    """A column as it stands (``width`` set) or only a height to size (``width`` None)."""

    height: float
    width: float | None = None
    #: the body's shape (rocking.bodies): ``"rectangular"`` or ``"cylinder"`` (``cyl:HxD``)
    body: str = "rectangular"

    @property
    def label(self) -> str:
        size = f"{self.height:g}x{self.width:g}" if self.width is not None else f"{self.height:g}"
        return ("cyl:" if self.body == "cylinder" else "") + size

    @property
    def kind(self) -> str:
        return "block" if self.width is not None else "height"


@dataclass(frozen=True)
class ReadOptions:
    """How a run's records are read: what a file may not say, for :func:`pulses.read_record` (the
    options of :func:`pipeline.args.add_record_options`, checked by :mod:`pipeline.values`)."""

    #: the file format when not detected from the content (``"at2"``, ``"text"``, an obspy format)
    format: str | None = None
    #: the samples' units where the file states none (canonical: ``"cm/s2"``, not ``"gal"``)
    units: str | None = None
    #: the sampling interval, s, of a text file without a time column
    dt: float | None = None
    #: a text file's acceleration column, counted from 1
    column: int | None = None
    #: the trace of a file holding several: an index from 0, a trace id or a channel
    trace: int | str | None = None

    def kwargs(self) -> dict:
        """The keyword arguments of :func:`pulses.read_record` (and :func:`pulses.read_pair`)."""
        return {"format": self.format, "units": self.units, "dt": self.dt, "column": self.column,
                "trace": self.trace}


@dataclass(frozen=True)
class Options:
    shapes: tuple | None = None
    #: the pulse fit's least squares (``pulses.fit_pulse``'s ``weighting``)
    weighting: str = "background"
    #: how the records are read (``--units``, ``--dt``, ``--column``, ``--format``, ``--trace``)
    read: ReadOptions = ReadOptions()
    plots: bool = True
    #: ``--plots all``: a figure for every direction of a pair (default: its governing direction
    #: only, pipeline.batch.passes)
    plots_all: bool = False
    #: a rocking frame's cap beam mass over the columns' (0: lone columns); see pipeline.batch.site
    cap_mass_ratio: float = 0.0
    fragility: bool = False
    up_to: float = 10.0
    #: the performance level (``--limit`` R: max|theta|/alpha <= R; default 0.5, the paper's
    #: dependable design); None (``--limit none``): the verge of overturning alone
    limit: float | None = DEFAULT_LIMIT
    #: the level of ``--fragility``'s critical scales: ``--limit R`` given (R); None: collapse
    #: (overturning), also where the design's level is the default one
    fragility_limit: float | None = None
    #: ``--restitution``: a :class:`rocking.restitution.Restitution` (a factor of Eq. 5, an eta or an
    #: r; one value or a band) every block of the run is made with; None: Eq. 5
    restitution: object = None
    #: ``"auto"``: use a record's known vertical (pipeline.batch.vertical); ``"none"``: horizontal only
    vertical: str = "auto"
    #: ``--thorough``: every direction of a pair gets the check above its search width and
    #: (with plots) its figures, as a lone record does (pipeline.batch.passes)
    thorough: bool = False
    #: ``--hazard`` and its options (pipeline.batch.risk.RiskOptions), used after the batch only: kept
    #: out of the records' resume keys (repr) and comparisons, so a record's work is reused whatever the curve
    risk: object = field(default=None, compare=False, repr=False)
    #: ``--friction MU``: the base's friction coefficient the responses are judged against (None:
    #: the friction demand is reported, not judged; pipeline.batch.validity)
    friction: float | None = None


@dataclass(frozen=True)
class Task:
    index: int
    record_id: str
    path: str
    columns: tuple = ()
    options: Options = field(default_factory=Options)
    #: a direction of a pair (pipeline.batch.site): the second file, the angle (deg) and why it was chosen
    path2: str | None = None
    direction: float | None = None
    direction_kind: str = ""
    pair: str = ""
    scale: float = 1.0
    pair_fields: tuple = ()
    #: a record of a PEER download (pipeline.batch.peer_inputs.PeerSource): where its files are read from
    peer: object = None
    #: the vertical component's file of a pair (pipeline.batch.vertical: --triplet, --pairs auto)
    vertical: str | None = None
    #: run the check above the search width (docs/slivers.md); pipeline.batch.passes decides per
    #: direction of a pair
    check: bool = True
    #: with ``check``: run it for a column only where its top lies above this width (m, one per
    #: column; empty: everywhere), ``rocking.search.SearchSettings.check_above``
    check_above: tuple = ()
    #: draw this task's figures (where ``options.plots``); pipeline.batch.passes decides per direction
    plot: bool = True


# -- record ids ------------------------------------------------------------------------------------
#: longest record id (characters, all ASCII): ``<id>.csv`` and its temporary name stay far below the
#: 255 bytes file systems allow, whatever the input's name
MAX_ID_LENGTH = 96


def record_ids(paths) -> list[str]:
    """Unique, file-system-safe ids from the file names, in input order.

    Characters other than ASCII letters, digits and ``._+-`` become ``_`` (a name's bytes need not
    be UTF-8); an id never starts with ``.``, ``+`` or ``-``; a name longer than
    :data:`MAX_ID_LENGTH` is cut and ends in a short hash of the whole name.
    """
    ids, seen = [], {}
    for path in paths:
        name = pathlib.PurePath(str(path)).name
        stem = name.rsplit(".", 1)[0] if "." in name.lstrip(".") else name
        stem = re.sub(r"[^A-Za-z0-9._+-]+", "_", stem)
        stem = re.sub(r"^[._+-]+|[._]+$", "", stem) or "record"
        if len(stem) > MAX_ID_LENGTH:
            digest = hashlib.sha1(os.fsencode(name)).hexdigest()[:8]
            stem = stem[:MAX_ID_LENGTH - 9].rstrip("._") + "-" + digest
        if stem.lower() in RESERVED_IDS:
            stem += "-record"
        base, k = stem, 1
        while stem.lower() in seen:
            k += 1
            stem = f"{base}-{k}"
        seen[stem.lower()] = True
        ids.append(stem)
    return ids


def make_tasks(paths, columns, options: Options) -> list[Task]:
    """One task per file (no pairs): the tasks of a plain ``pipeline run``."""
    ids = record_ids(paths)
    return [Task(i, rid, str(path), tuple(columns), options) for i, (rid, path) in enumerate(zip(ids, paths))]


# -- inputs ----------------------------------------------------------------------------------------
#: extensions of files that are plainly no record (documents, images, web pages, spreadsheets)
NOT_RECORDS = frozenset({".md", ".rst", ".pdf", ".doc", ".docx", ".odt", ".xls", ".xlsx", ".ods",
                         ".png", ".jpg", ".jpeg", ".gif", ".svg", ".bmp", ".tif", ".tiff", ".webp",
                         ".html", ".htm", ".json", ".yaml", ".yml", ".py", ".ipynb"})
_README = re.compile(r"^(readme|license|licence|changelog)(\.(txt|md|rst))?$", re.IGNORECASE)


def plainly_not_a_record(path) -> bool:
    """A file of a folder that is plainly no record: a document, an image or a page by its
    extension (:data:`NOT_RECORDS`), a README, LICENSE or CHANGELOG, or a ``.txt`` file without a digit in
    its first 64 kB.  Only regular files are looked into; anything else is left to the reader."""
    import stat

    name = os.path.basename(path)
    ext = os.path.splitext(name)[1].lower()
    if ext in NOT_RECORDS or _README.match(name):
        return True
    if ext != ".txt":
        return False
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            return False
        with open(path, "rb") as fh:
            head = fh.read(1 << 16)
    except OSError:
        return False  # fails as a record, with the reason
    return bool(head.strip()) and re.search(rb"[0-9]", head) is None


def skipped_note(skipped, glob_option=True) -> str:
    """The note that ``run`` and ``classify`` print for the files of folders left out by
    :func:`expand_inputs` (the first five named; ``glob_option``: the command has ``--glob``)."""
    from ..reports.cells import display

    shown = ", ".join(display(os.path.basename(p)) for p in skipped[:5]) + (" ..." if len(skipped) > 5 else "")
    return (f"{len(skipped)} file(s) of the folders skipped, plainly not records ({shown}); name a "
            "file to read it as a record" + (", or choose files with --glob" if glob_option else ""))


def expand_inputs(items, skipped: list | None = None, pattern: str | None = None) -> list[str]:
    """File arguments as given; folders give their entries (sorted; not hidden ones, not folders,
    not files that are plainly no record, :func:`plainly_not_a_record`, which are appended to
    ``skipped`` when given; with ``pattern``, a shell pattern such as ``*.AT2``, exactly the
    entries whose names match it); unexpanded wildcards are globbed.

    A path that does not exist stays in the list: it is reported as a failed record, not an argument
    error, so one missing file does not stop a batch.  So are a folder's entries that cannot be
    read (a symbolic link to nothing, a loop of links, files of a folder without search
    permission), and a folder that cannot be listed: each fails at reading, with the reason.
    """
    paths: list[str] = []
    seen = set()

    def add(p):
        key = os.path.abspath(p)
        if key not in seen:
            seen.add(key)
            paths.append(p)

    for item in items:
        item = str(item)
        if os.path.isdir(item):
            try:
                names = sorted(os.listdir(item))
            except OSError:  # a folder that cannot be read: a failed record, with the reason
                add(item)
                continue
            for name in names:
                full = os.path.join(item, name)
                # every entry but hidden ones and folders: a broken link, a link loop or a file
                # that cannot be looked at is a failed record with the reason, never skipped
                if name.startswith(".") or os.path.isdir(full):
                    continue
                if pattern is not None:  # chosen by name: nothing else is looked at
                    if fnmatch.fnmatchcase(name, pattern):
                        add(full)
                    continue
                if plainly_not_a_record(full):
                    if skipped is not None:
                        skipped.append(full)
                    continue
                add(full)
        elif not os.path.exists(item) and glob.has_magic(item):
            matches = sorted(glob.glob(item))
            if not matches:
                add(item)  # reported as not found
            for m in matches:
                add(m)
        else:
            add(item)
    return paths
