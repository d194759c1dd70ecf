"""The batch from Python: :func:`design` runs what ``pipeline run`` runs (the command line is a thin
layer over it: same tasks, same rules, same numbers) and returns a :class:`DesignRun` whose tables
are pandas DataFrames built from the rows the CSV reports are written from.
"""
from __future__ import annotations

import contextlib
import dataclasses
import os
import pathlib
import shutil
import sys
import tempfile
from dataclasses import dataclass, field

from .args import ArgumentError, jobs_count

#: most worker processes: each holds the solver and a record (a few hundred MB)

_COLUMN_FORMS = ("a rocking.Block, a 'HxW' string in m (e.g. '7.5x1.8') or a (height, width) pair "
                 "of numbers in m")
_RECORD_FORMS = "a path (str or os.PathLike) or a list of paths (files, folders, PEER downloads)"
_PAIR_FORMS = ("'auto', 'none', or a list of (A, B) pairs or (A, B, V) triplets of paths "
               "(V: the vertical component)")


# -- what the caller gives, checked -----------------------------------------------------------------
def _is_number(x) -> bool:
    import numbers

    return isinstance(x, numbers.Real) and not isinstance(x, bool)


def _is_path(x) -> bool:
    return isinstance(x, (str, os.PathLike))


def _records(records) -> list[str]:
    if _is_path(records):
        return [os.fspath(records)]
    if isinstance(records, (bytes, dict)) or not hasattr(records, "__iter__"):
        raise TypeError(f"records: expected {_RECORD_FORMS}, got {type(records).__name__}")
    out = []
    for r in records:
        if not _is_path(r):
            raise TypeError(f"records: expected {_RECORD_FORMS}; an item is a {type(r).__name__}")
        out.append(os.fspath(r))
    return out


def _many(value, *, pair_is_one: bool = False):
    """A single item or an iterable of them, as a list: a string is one item, and with
    ``pair_is_one`` so is a tuple of two numbers (a block's ``(height, width)``)."""
    if value is None:
        return []
    if isinstance(value, (str, bytes)) or not hasattr(value, "__iter__"):
        return [value]
    if pair_is_one and isinstance(value, tuple) and len(value) == 2 and all(map(_is_number, value)):
        return [value]
    return list(value)


def _column(block):
    """A :class:`pipeline.batch.tasks.Column` (height, width) from one of the accepted forms."""
    from .args import parse_block
    from .batch.tasks import Column

    if isinstance(block, Column):  # the command line's own, already checked
        return block
    if isinstance(block, str):
        return Column(*parse_block(block))
    if isinstance(block, tuple) and len(block) == 2 and all(map(_is_number, block)):
        return Column(*parse_block(f"{float(block[0])!r}x{float(block[1])!r}"))
    from rocking import Block

    if isinstance(block, Block):
        if block.height is None or block.width is None:
            raise ValueError("blocks: a rocking.Block with its full height and width (made by "
                             "Block.from_dimensions), not only p and alpha")
        return Column(*parse_block(f"{float(block.height)!r}x{float(block.width)!r}"))
    raise TypeError(f"blocks: expected {_COLUMN_FORMS}; got {type(block).__name__} {block!r:.60}")


def _height(h):
    from .args import parse_length
    from .batch.tasks import Column

    if not _is_number(h):
        raise TypeError(f"heights: expected numbers (the column's full height in m), got "
                        f"{type(h).__name__} {h!r:.60}")
    return Column(parse_length(repr(float(h)), "heights (m)"))


def columns_from(blocks, heights) -> tuple:
    """The columns of a run, in order, each once: ``blocks`` (as they stand) then ``heights``."""
    columns = [_column(b) for b in _many(blocks, pair_is_one=True)]
    columns += [_height(h) for h in _many(heights)]
    if not columns:
        raise ValueError("give at least one column: blocks= (e.g. '7.5x1.8', a rocking.Block) or "
                         "heights= (m)")
    return tuple(dict.fromkeys(columns))


def _pairs(pairs) -> tuple[str, list, dict]:
    """``(pairs mode, explicit pairs [[A, B]], triplets {(A, B): V})``."""
    if pairs is None or pairs in ("none", "auto"):
        return pairs or "none", [], {}
    if isinstance(pairs, str) or not hasattr(pairs, "__iter__"):
        raise (ValueError if isinstance(pairs, str) else TypeError)(
            f"pairs: expected {_PAIR_FORMS}, got {pairs!r:.60}")
    explicit, triplets = [], {}
    for p in pairs:
        if not isinstance(p, (tuple, list)) or len(p) not in (2, 3) or not all(map(_is_path, p)):
            raise TypeError(f"pairs: expected {_PAIR_FORMS}; an item is {p!r:.60}")
        a, b = os.fspath(p[0]), os.fspath(p[1])
        explicit.append([a, b])
        if len(p) == 3:
            triplets[(a, b)] = os.fspath(p[2])
    return "none", explicit, triplets


def _choice(value, what, choices):
    if not isinstance(value, str):
        raise TypeError(f"{what}: expected one of {', '.join(map(repr, choices))}, got {type(value).__name__}")
    if value not in choices:
        raise ValueError(f"{what}: expected one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def _jobs(jobs) -> int:
    if not isinstance(jobs, int) or isinstance(jobs, bool):
        raise TypeError(f"jobs: expected a whole number of processes (0: one per CPU), got {type(jobs).__name__}")
    return jobs_count(jobs, "jobs")


def _shapes(shapes):
    from .args import parse_shapes

    if shapes is None:
        return None
    if not all(isinstance(s, str) for s in _many(shapes)):
        raise TypeError("shapes: expected a shape name or a list of them (pulses.SHAPES, or 'all')")
    return parse_shapes(_many(shapes))


def _number_option(value, what, *, default=None):
    if value is None:
        return default
    if not _is_number(value):
        raise TypeError(f"{what}: expected a number, got {type(value).__name__} {value!r:.60}")
    return float(value)


# -- the run ---------------------------------------------------------------------------------------
@dataclass
class DesignRun:
    """What :func:`design` returns: the run's tables as row dicts and as pandas DataFrames.

    Attributes
    ----------
    design_rows : list of dict
        ``design.csv``: one row per record (a pair once, by its governing direction) and column.
    summary_rows : list of dict
        ``summary.csv``: one row per record direction and column, every quantity.
    failure_rows : list of dict
        ``failures.csv``: one row per record (or direction) that failed, with the stage and reason.
    suite_rows : list of dict
        ``suite.csv``: one row per column over the whole suite.
    n_records, n_failed : int
        Tasks run (a pair's directions count one each) and tasks that failed.
    out : pathlib.Path or None
        The folder the reports were written to (None: nothing was written).

    Examples
    --------
    >>> import pipeline
    >>> from pipeline.commands.demo import bundled_records
    >>> with bundled_records() as paths:
    ...     run = pipeline.design(paths[3:4], heights=7.5, shapes="sine")
    >>> run.exit_code, list(run.design["governing_shape"]), run.out is None
    (0, ['sine'], True)
    """

    design_rows: list = field(default_factory=list)
    summary_rows: list = field(default_factory=list)
    failure_rows: list = field(default_factory=list)
    suite_rows: list = field(default_factory=list)
    n_records: int = 0
    n_failed: int = 0
    out: pathlib.Path | None = None

    @property
    def exit_code(self) -> int:
        """``pipeline run``'s exit status: 0 when every record was processed, 1 when some failed."""
        return 0 if self.n_failed == 0 else 1

    @property
    def design(self):
        """``design.csv`` as a DataFrame (columns in the file's order)."""
        from .reports.design_table import design_fields

        return _frame(self.design_rows, design_fields(self.summary_rows))

    @property
    def summary(self):
        """``summary.csv`` as a DataFrame."""
        from .batch.record import FIELDS

        # the columns of the run's options (a level's margin, a restitution), as summary.csv's
        return _frame(self.summary_rows, list(self.summary_rows[0]) if self.summary_rows else FIELDS)

    @property
    def failures(self):
        """``failures.csv`` as a DataFrame: ``record``, ``file``, ``stage``, ``reason`` ..."""
        from .batch.record import FAILURE_FIELDS

        return _frame(self.failure_rows, FAILURE_FIELDS)

    @property
    def suite(self):
        """``suite.csv`` as a DataFrame."""
        from .batch.site import SUITE_COLUMNS

        return _frame(self.suite_rows, list(SUITE_COLUMNS.names))

    def as_dict(self) -> dict:
        """The tables as lists of plain rows (JSON-safe: NaN and infinities as None)."""
        from pulses.export import plain

        return plain({"design": self.design_rows, "summary": self.summary_rows,
                      "failures": self.failure_rows, "suite": self.suite_rows,
                      "n_records": self.n_records, "n_failed": self.n_failed,
                      "out": None if self.out is None else str(self.out)})


#: columns of names: the reports' rows read back from their text type a height's label ("12") or a
#: record named "1063" as a number; the tables give them as the text the reports hold
_NAMES = ("record", "column", "pair", "file")


def _frame(rows, columns):
    import pandas as pd

    from .reports.report import fmt

    def cell(row, c):
        v = row.get(c)
        return fmt(v) if c in _NAMES and v is not None and not isinstance(v, str) else v

    return pd.DataFrame([[cell(r, c) for c in columns] for r in rows], columns=list(columns))


def design(records, *, blocks=None, heights=None, pairs=None, directions: int = 0, vertical: str = "auto",
           limit=0.5, restitution=None, jobs: int = 1, out=None, shapes=None, weighting: str = "background", units=None,
           dt=None, scale=None, plots=None, force: bool = False, quiet: bool = True, **more) -> DesignRun:
    """Design columns for a batch of records, as ``pipeline run`` does, and return the tables.

    Parameters
    ----------
    records : path or list of paths
        Record files (any format :func:`pulses.read_record` reads), folders of them, or PEER
        NGA-West2 downloads (a ``.zip``, or a folder holding ``_SearchResults.csv``).  A file that
        is missing or cannot be read is a row of :attr:`DesignRun.failures`, not an exception.
    blocks : Block, str, (float, float) or a list of them
        Columns as they stand: a :class:`rocking.Block`, ``"HxW"`` (full height x full width, m,
        e.g. ``"7.5x1.8"``) or ``(height, width)`` in m.  ``pipeline run --block``.
    heights : float or list of float
        Heights (m) of columns whose width is only to be sized.  ``--height``.
    pairs : {"none", "auto"} or list of (A, B) or (A, B, V)
        Horizontal components designed as pairs in every direction (``--pair``, ``--triplet`` with
        a vertical ``V``, ``--pairs auto``).  Default: every file alone.
    directions : int
        Evenly spaced directions added for a pair (``--directions``).
    vertical : {"auto", "none"}
        Use a pair's known vertical component (``--vertical``).
    limit : float or None
        The performance level R, ``0 < R <= 1`` (``--limit``) of the design width, the width the
        run quotes first: max|theta|/alpha <= R, at least the overturning design width; default
        0.5, the paper's dependable design (peaks at or below alpha/2).  The overturning design
        width, the verge (no margin), is reported beside it (``overturning_width_m``).  None (or
        ``"none"``): the verge alone, as the design width.
    restitution : str, float or rocking.restitution.Restitution, optional
        The restitution at impact every block of the run is made with (``--restitution``): a
        factor of Eq. 5 (``0.97``), ``"eta=0.9"`` (the velocity ratio), ``"r=0.81"`` (the energy
        ratio), or a band ``"0.95:1.05"`` whose design covers it; default Eq. 5.
    jobs : int
        Worker processes (0: one per CPU); the tables do not depend on it.
    out : path, optional
        Folder to write every report into, as ``pipeline run --out``; None (default): nothing is
        written (the run uses a private temporary folder, removed at the end).
    shapes : str or list of str, optional
        Pulse shapes to fit (``--shapes``); default the fitter's set.
    weighting : {"background", "plain"}
        The pulse fit's least squares (``--weighting``).
    units, dt : optional
        What a file does not say (``--units``, ``--dt``).
    scale : float, optional
        A factor on every record (``--scale``).
    plots : bool, optional
        Draw the figures (default: when ``out`` is given).
    force : bool
        Compute every record again instead of keeping an earlier run's reports in ``out``.
    quiet : bool
        No messages and no table on stderr/stdout (default); False prints what ``pipeline run`` prints.
    **more
        The other options of ``pipeline run`` by their names: ``column``, ``format``, ``trace``,
        ``scales``, ``peer_scales``, ``cap_mass_ratio``, ``fragility``, ``up_to``, ``dask``, ``log``,
        ``glob``; and ``fragility_limit``, the level R of ``fragility``'s critical scales (None,
        the default: collapse; ``pipeline run --fragility --limit R`` sets both to R).

    Returns
    -------
    DesignRun
        ``.design``, ``.summary``, ``.failures`` and ``.suite`` (DataFrames).

    Raises
    ------
    TypeError
        An argument of a type not accepted (the message names the accepted forms).
    ValueError
        A value out of range (a negative height, an unknown shape ...).

    Examples
    --------
    >>> import pipeline
    >>> from pipeline.commands.demo import bundled_records
    >>> with bundled_records() as paths:
    ...     run = pipeline.design(paths[1:2], blocks="7.5x1.8", shapes="sine")
    >>> run.design[["record", "column", "design_width_m"]].shape
    (1, 3)
    >>> pipeline.design(paths, blocks=7.5)
    Traceback (most recent call last):
    ...
    TypeError: blocks: expected a rocking.Block, a 'HxW' string in m (e.g. '7.5x1.8') or a (height, width) pair of numbers in m; got float 7.5
    """
    plan = _plan(records, blocks=blocks, heights=heights, pairs=pairs, directions=directions,
                 vertical=vertical, limit=limit, restitution=restitution, jobs=jobs, out=out, shapes=shapes, weighting=weighting,
                 units=units, dt=dt, scale=scale, plots=plots, force=force, quiet=quiet, **more)
    return run_plan(plan)


_MORE = {"column": None, "format": None, "trace": None, "scales": None, "peer_scales": False,
         "cap_mass_ratio": 0.0, "fragility": False, "fragility_limit": None, "up_to": 10.0, "dask": None,
         "log": None, "glob": None}


def _plan(records, *, blocks, heights, pairs, directions, vertical, limit, restitution, jobs, out, shapes, weighting,
          units, dt, scale, plots, force, quiet, **more) -> Plan:
    """Every argument of :func:`design` checked and in the forms the runner takes."""
    from .args import parse_units
    from .batch.tasks import Options

    unknown = sorted(set(more) - set(_MORE))
    if unknown:
        raise TypeError(f"design() got unexpected keyword arguments {unknown}; accepted besides the "
                        f"named ones: {', '.join(_MORE)}")
    more = {**_MORE, **more}
    mode, explicit, triplets = _pairs(pairs)
    if not isinstance(directions, int) or isinstance(directions, bool):
        raise TypeError(f"directions: expected a whole number, got {type(directions).__name__}")
    if out is not None and not _is_path(out):
        raise TypeError(f"out: expected a folder path (str or os.PathLike) or None, got {type(out).__name__}")
    if units is not None and not isinstance(units, str):
        raise TypeError(f"units: expected a unit name (e.g. 'g', 'm/s2', 'cm/s2'), got {type(units).__name__}")
    opts = {"format": more["format"], "units": parse_units(units),
            "dt": _number_option(dt, "dt"), "column": more["column"], "trace": more["trace"]}
    kw = dict(plots=(out is not None) if plots is None else bool(plots), shapes=_shapes(shapes),
              weighting=_choice(weighting, "weighting", ("background", "plain")),
              vertical=_choice(vertical, "vertical", ("auto", "none")),
              cap_mass_ratio=_number_option(more["cap_mass_ratio"], "cap_mass_ratio"),
              fragility=bool(more["fragility"]), up_to=_number_option(more["up_to"], "up_to"),
              fragility_limit=_limit(more["fragility_limit"]), **opts)
    kw["limit"] = _limit(limit)
    kw["restitution"] = _restitution(restitution)
    return Plan(
        records=_records(records), columns=columns_from(blocks, heights), options=Options(**kw),
        record_opts=opts, pairs=mode, pair=explicit, triplets=triplets, directions=str(directions),
        scale=None if scale is None else repr(_number_option(scale, "scale")), scales=more["scales"],
        peer_scales=bool(more["peer_scales"]), jobs=_jobs(jobs), out=out, force=bool(force),
        quiet=bool(quiet), dask=more["dask"], log=more["log"], glob=more["glob"])


def _limit(limit):
    """``limit=``: None or "none" (the verge alone), else a number in (0, 1]."""
    if limit is None or (isinstance(limit, str) and limit.strip().lower() == "none"):
        return None
    value = _number_option(limit, "limit")
    if not 0.0 < value <= 1.0:
        raise ValueError(f"limit (max|theta|/alpha) must lie in (0, 1], or be None, got {limit!r}")
    return value


def _restitution(restitution):
    """``restitution=``: None (Eq. 5), or a :class:`rocking.restitution.Restitution` from one, a
    number (a factor of Eq. 5) or the text ``--restitution`` takes."""
    from rocking.restitution import Restitution

    if restitution is None:
        return None
    if isinstance(restitution, bool) or not isinstance(restitution, (str, int, float, Restitution)):
        raise TypeError("restitution: expected a factor of Eq. 5, 'eta=V', 'r=V', 'LOW:HIGH' or a "
                        f"rocking.restitution.Restitution; got {type(restitution).__name__}")
    return Restitution.parse(restitution)


@dataclass
class Plan:
    """A run, checked: what :func:`design` and ``pipeline run`` hand to :func:`run_plan`.  The
    settings of pairs and scales keep the command line's names and text forms (``directions``,
    ``scale`` as text), which :func:`pipeline.batch.pairs.tasks_from_args` reads."""

    records: list
    columns: tuple
    options: object
    record_opts: dict
    pairs: str = "none"
    pair: list = field(default_factory=list)
    triplets: dict = field(default_factory=dict)
    directions: str = "0"
    scale: str | None = None
    scales: str | None = None
    peer_scales: bool = False
    jobs: int = 1
    out: object = None
    force: bool = False
    quiet: bool = True
    dask: str | None = None
    log: object = None
    #: ``--glob``: the files of the folders given that are read
    glob: str | None = None


def _paths(plan, say):
    """``(downloads, record paths)`` of a run's inputs; the files of its folders that are plainly
    not records are skipped with a note."""
    from .batch import peer_inputs
    from .reports.report import display
    from .batch.tasks import expand_inputs, skipped_note

    if not plan.records and not plan.pair:
        raise ArgumentError("no records given: pipeline run RECORD... --block HxW")
    downloads, others = peer_inputs.split_inputs(plan.records, plan.record_opts.get("format"))
    skipped = []
    paths = [p for p in expand_inputs(others, skipped, plan.glob) if p not in set(plan.triplets.values())]
    if skipped:
        say(f"pipeline run: note: {skipped_note(skipped)}")
    if not paths and not plan.pair and not downloads:
        raise ArgumentError(f"no record files in {', '.join(map(display, plan.records))} "
                            "(a folder gives the files directly in it)")
    if paths and not downloads and not plan.pair and not any(os.path.lexists(p) for p in paths):
        shown = ", ".join(map(display, paths[:3])) + (f" and {len(paths) - 3} more" if len(paths) > 3 else "")
        raise ArgumentError(f"none of the inputs exists ({shown}): nothing to do, nothing written")
    return downloads, paths


def _tasks(plan, say):
    """``(paths, tasks or None, absent)`` of a run, as ``pipeline run`` makes them (``absent``: the
    PEER search's records not in the download, listed, not failed)."""
    from .batch import pairs, vertical

    # a triplet's horizontals are a pair
    plan = dataclasses.replace(plan, pair=list(plan.pair) + [[a, b] for a, b in plan.triplets])
    downloads, paths = _paths(plan, say)
    absent = [] if downloads else None
    tasks = pairs.tasks_from_args(plan, downloads, paths, plan.columns, plan.options, absent)
    if tasks is not None and plan.options.vertical == "auto":
        found = {}
        if plan.pairs == "auto":
            rest = [p for p in paths if p not in {q for ab in plan.pair for q in ab}]
            found = vertical.auto_verticals(rest, plan.record_opts, say)
        tasks = vertical.attach(tasks, {**found, **plan.triplets})
    return paths, tasks, absent


def run_plan(plan) -> DesignRun:
    """Run a checked plan (:func:`design`; ``pipeline run`` builds its plan from its arguments)."""
    from .batch.runner import run

    say = (lambda msg: None) if plan.quiet else (lambda msg: print(msg, file=sys.stderr))
    from .batch.peer_inputs import NOT_DOWNLOADED, not_downloaded_text

    paths, tasks, absent = _tasks(plan, say)
    # with no folder of the caller's, the runner's messages would name the private one: the table
    # is printed here instead
    quiet = plan.quiet or plan.out is None
    with _folder(plan.out) as out:
        summary = run(paths, plan.columns, out, options=plan.options, jobs=plan.jobs, dask=plan.dask,
                      quiet=quiet, tasks=tasks, force=plan.force, log=plan.log,
                      lists={NOT_DOWNLOADED: not_downloaded_text(absent)})
    t = summary.tables
    if not plan.quiet and plan.out is None:
        from .reports.design_table import table_text

        print(table_text(t["design"], t["failures"], t["summary"]), end="")
    return DesignRun(t["design"], t["summary"], t["failures"], t["suite"], summary.n_records,
                     summary.n_failed, None if plan.out is None else summary.out)


@contextlib.contextmanager
def _folder(out):
    """``out``, or a private temporary folder removed afterwards (the runner keeps its journal and
    lock in a folder; with no ``out`` nothing of the run is left on disk)."""
    if out is not None:
        yield out
        return
    tmp = tempfile.mkdtemp(prefix="pipeline-design.")
    try:
        yield tmp
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
