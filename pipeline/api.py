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
    from .args import parse_block, parse_column_block
    from .batch.tasks import Column

    if isinstance(block, Column):  # the command line's own, already checked
        return block
    if isinstance(block, str):
        return Column(*parse_column_block(block))
    if isinstance(block, tuple) and len(block) == 2 and all(map(_is_number, block)):
        return Column(*parse_block(f"{float(block[0])!r}x{float(block[1])!r}"))
    from rocking import Block

    if isinstance(block, Block):
        if block.height is None or block.width is None:
            raise ValueError("blocks: a rocking.Block with its full height and width (made by "
                             "Block.from_dimensions), not only p and alpha")
        return Column(*parse_block(f"{float(block.height)!r}x{float(block.width)!r}"),
                      block.body.kind)
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


def _is_whole(x) -> bool:
    """A whole number, numpy's included, not a boolean."""
    import numbers

    return isinstance(x, numbers.Integral) and not _is_flag(x)


def _is_flag(x) -> bool:
    """``True``/``False``, numpy's included."""
    return isinstance(x, bool) or (type(x).__module__ == "numpy" and type(x).__name__ in ("bool", "bool_"))


def _jobs(jobs) -> int:
    if not _is_whole(jobs):
        raise TypeError(f"jobs: expected a whole number of processes (0: one per CPU), got {type(jobs).__name__}")
    return jobs_count(int(jobs), "jobs")


def _flag(value, what) -> bool:
    """A boolean argument: True or False only (``"no"`` is not False)."""
    if not _is_flag(value):
        raise TypeError(f"{what}: expected True or False, got {type(value).__name__} {value!r:.60}")
    return bool(value)


#: what ``plots`` takes, as ``pipeline run``'s ``--plots [governing|all]`` and ``--no-plots``
_PLOTS = ("governing", "all", "none")


def _plots(plots, out) -> dict:
    """``plots`` and ``plots_all`` of the options from ``plots`` (None: figures when ``out``)."""
    if plots is None:
        plots = out is not None
    if not _is_flag(plots) and not isinstance(plots, str):
        raise TypeError(f"plots: expected True, False, None or one of {', '.join(map(repr, _PLOTS))}, "
                        f"got {type(plots).__name__}")
    scope = ("governing" if plots else "none") if _is_flag(plots) else _choice(plots, "plots", _PLOTS)
    return {"plots": scope != "none", "plots_all": scope == "all"}


def _text_option(value, what, *, whole=False):
    """A text argument (or None); ``whole``: a whole number is taken as its text too."""
    if value is None or isinstance(value, str) or (whole and _is_whole(value)):
        return None if value is None else str(value)
    raise TypeError(f"{what}: expected {'a whole number or ' if whole else ''}text, got "
                    f"{type(value).__name__} {value!r:.60}")


def _path_option(value, what):
    if value is not None and not _is_path(value):
        raise TypeError(f"{what}: expected a file path (str or os.PathLike) or None, got {type(value).__name__}")
    return value


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
    n_unwritten : int
        The run's own figures that could not be written (a full disk): left out, the tables and
        ``report.html`` written all the same.

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
    #: the run's own figures that could not be written (a full disk ...), left out
    n_unwritten: int = 0
    #: ``risk.csv`` (``hazard=``): each column's rate at the site and the width for the target
    risk_rows: list = field(default_factory=list)

    @property
    def exit_code(self) -> int:
        """``pipeline run``'s exit status: 0 when every record was processed, 1 when some failed
        (or a figure of the run's could not be written)."""
        return 0 if self.n_failed == 0 and not self.n_unwritten else 1

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

    @property
    def risk(self):
        """``risk.csv`` as a DataFrame (``hazard=``; empty without)."""
        from rocking.risk.rows import RISK_COLUMNS

        return _frame(self.risk_rows, list(RISK_COLUMNS.names))

    def as_dict(self) -> dict:
        """The tables as lists of plain rows (JSON-safe: NaN and infinities as None)."""
        from pulses.export import plain

        return plain({"design": self.design_rows, "summary": self.summary_rows,
                      "failures": self.failure_rows, "suite": self.suite_rows, "risk": self.risk_rows,
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
           limit=0.5, restitution=None, jobs: int = 1, out=None, shapes=None, weighting: str = "background",
           units=None, dt=None, scale=None, plots=None, force: bool = False, quiet: bool = True,
           thorough: bool = False, **more) -> DesignRun:
    """Design columns for a batch of records, as ``pipeline run`` does, and return the tables.

    Parameters
    ----------
    records : path or list of paths
        Record files (any format :func:`pulses.read_record` reads), folders of them, or PEER
        NGA-West2 downloads (a ``.zip``, or a folder holding ``_SearchResults.csv``).  A file that
        is missing or cannot be read is a row of :attr:`DesignRun.failures`, not an exception.
    blocks : Block, str, (float, float) or a list of them
        Columns as they stand: a :class:`rocking.Block`, ``"HxW"`` (full height x full width, m,
        e.g. ``"7.5x1.8"``; ``"cyl:HxD"`` a circular column of diameter D) or ``(height, width)``
        in m.  ``pipeline run --block``.
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
        The level R of the design width (``--limit``): max|theta|/alpha <= R, at least the verge
        (no margin, ``overturning_width_m``); default 0.5, the paper's dependable design.  None
        (or ``"none"``): the verge alone.
    restitution : str, float or rocking.restitution.Restitution, optional
        ``--restitution``: a factor of Eq. 5 (``0.97``), ``"eta=0.9"``, ``"r=0.81"`` or a band
        ``"0.95:1.05"`` whose design covers it; default Eq. 5.
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
    plots : bool or {"governing", "all", "none"}, optional
        Draw the figures (default: when ``out`` is given): True or ``"governing"`` (for a pair in
        several directions, its governing direction's), ``"all"`` (every direction's), False or
        ``"none"``.  ``--plots [all]``, ``--no-plots``.
    force : bool
        Compute every record again instead of keeping an earlier run's reports in ``out``.
    quiet : bool
        No messages, no warnings and no table on stderr/stdout (default); False prints what
        ``pipeline run`` prints.
    thorough : bool
        For pairs: the check above the search width (and the figures) in every direction
        (``--thorough``); the same pair design width.
    **more
        The other options of ``pipeline run`` by their names: ``column``, ``format``, ``trace``,
        ``scales``, ``peer_scales``, ``cap_mass_ratio``, ``fragility``, ``up_to``, ``dask``, ``log``,
        ``glob``, ``friction`` (docs/validity.md), ``fragility_limit`` (the level R of ``fragility``'s
        critical scales; None, the default: collapse); risk at a site (docs/risk.md): ``hazard`` (a file
        or a :class:`rocking.risk.HazardCurve`), ``site`` ((lon, lat)), ``site_row``, ``imt``,
        ``hazard_units``, ``years``, ``age``, ``target_rate``, ``target_poe`` (``"2%/50"``), ``risk_seed``.

    Returns
    -------
    DesignRun
        ``.design``, ``.summary``, ``.failures`` and ``.suite`` (DataFrames).

    Raises
    ------
    TypeError
        An argument of a type not accepted (the message names the accepted forms).
    ValueError
        A value out of range (a negative height, an unknown shape ...), refused with the words
        ``pipeline run`` uses for it.
    RuntimeError
        ``jobs > 1`` (or ``dask="local"``) at the top level of a script without the ``if __name__
        == "__main__":`` guard: the workers import the script again (docs/notebook.md; a notebook
        needs nothing).

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
                 vertical=vertical, limit=limit, restitution=restitution, jobs=jobs, out=out, shapes=shapes,
                 weighting=weighting, units=units, dt=dt, scale=scale, plots=plots, force=force, quiet=quiet,
                 thorough=thorough, **more)
    return run_plan(plan)


_MORE = {"column": None, "format": None, "trace": None, "scales": None, "peer_scales": False,
         "cap_mass_ratio": 0.0, "fragility": False, "fragility_limit": None, "up_to": 10.0, "dask": None,
         "log": None, "glob": None,
         "hazard": None, "site": None, "site_row": None, "imt": None, "hazard_units": None, "years": 50,
         "age": None, "target_rate": None, "target_poe": None, "risk_seed": 0, "friction": None}


def _plan(records, *, blocks, heights, pairs, directions, vertical, limit, restitution, jobs, out, shapes,
          weighting, units, dt, scale, plots, force, quiet, thorough, **more) -> Plan:
    """Every argument of :func:`design` checked and in the forms the runner takes: each value by
    the rule ``pipeline run`` applies to its option (:mod:`pipeline.args`), named as here."""
    from .args import (parse_cap_mass_ratio, parse_column, parse_directions, parse_dt, parse_scale,
                       parse_units, parse_up_to)
    from .batch.tasks import Options

    unknown = sorted(set(more) - set(_MORE))
    if unknown:
        raise TypeError(f"design() got unexpected keyword arguments {unknown}; accepted besides the "
                        f"named ones: {', '.join(_MORE)}")
    more = {**_MORE, **more}
    mode, explicit, triplets = _pairs(pairs)
    if not _is_whole(directions):
        raise TypeError(f"directions: expected a whole number, got {type(directions).__name__}")
    if out is not None and not _is_path(out):
        raise TypeError(f"out: expected a folder path (str or os.PathLike) or None, got {type(out).__name__}")
    if units is not None and not isinstance(units, str):
        raise TypeError(f"units: expected a unit name (e.g. 'g', 'm/s2', 'cm/s2'), got {type(units).__name__}")
    number = _number_option
    column = more["column"]
    if column is not None and not (_is_whole(column) or isinstance(column, str)):
        raise TypeError(f"column: expected a whole number (counted from 1), got {type(column).__name__}")
    opts = {"format": _text_option(more["format"], "format"), "units": parse_units(units, "units"),
            "dt": None if dt is None else parse_dt(number(dt, "dt"), "dt"),
            "column": parse_column(column, "column"), "trace": _text_option(more["trace"], "trace", whole=True)}
    kw = dict(**_plots(plots, out), thorough=_flag(thorough, "thorough"), shapes=_shapes(shapes),
              weighting=_choice(weighting, "weighting", ("background", "plain")),
              vertical=_choice(vertical, "vertical", ("auto", "none")),
              cap_mass_ratio=parse_cap_mass_ratio(number(more["cap_mass_ratio"], "cap_mass_ratio"), "cap_mass_ratio"),
              fragility=_flag(more["fragility"], "fragility"),
              up_to=parse_up_to(number(more["up_to"], "up_to"), "up_to"),
              fragility_limit=_limit(more["fragility_limit"], "fragility_limit"),
              limit=_limit(limit), restitution=_restitution(restitution),
              friction=_friction(more["friction"]), **opts)
    kw["risk"] = _risk(more, kw["restitution"])
    if more["dask"] is not None and not isinstance(more["dask"], str):
        raise TypeError(f"dask: expected 'local' or a scheduler address such as 'tcp://HOST:8786', "
                        f"got {type(more['dask']).__name__}")
    return Plan(
        records=_records(records), columns=columns_from(blocks, heights), options=Options(**kw),
        record_opts=opts, pairs=mode, pair=explicit, triplets=triplets,
        directions=str(parse_directions(int(directions), "directions")),
        scale=None if scale is None else repr(parse_scale(number(scale, "scale"), "scale")),
        scales=_path_option(more["scales"], "scales"), peer_scales=_flag(more["peer_scales"], "peer_scales"),
        jobs=_jobs(jobs), out=out, force=_flag(force, "force"), quiet=_flag(quiet, "quiet"),
        dask=more["dask"], log=_path_option(more["log"], "log"), glob=_text_option(more["glob"], "glob"))


def _risk(more, restitution=None):
    """``hazard=`` and its options, checked (pipeline.batch.risk.RiskOptions), or None."""
    from .batch import risk

    if more["hazard"] is None:
        given = [k for k in ("site", "site_row", "imt", "hazard_units", "age", "target_rate", "target_poe")
                 if more[k] is not None]
        if given:
            raise ValueError(f"{given[0]} needs hazard= (the site's hazard curve)")
        return None
    try:
        return risk.risk_options(more["hazard"], site=more["site"], site_row=more["site_row"],
                                 imt=more["imt"], units=more["hazard_units"], years=more["years"],
                                 age=more["age"], target_rate=more["target_rate"],
                                 target_poe=more["target_poe"], seed=more["risk_seed"],
                                 restitution=restitution)
    except ArgumentError as exc:
        raise ValueError(str(exc)) from None


def _limit(limit, name="limit"):
    """``limit=``: None or "none" (the verge alone), else a level by ``--limit``'s rule."""
    from .args import parse_limit

    if limit is None or (isinstance(limit, str) and limit.strip().lower() == "none"):
        return None
    return parse_limit(_number_option(limit, name), name)


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
    """Run a checked plan (:func:`design`; ``pipeline run`` builds its plan from its arguments);
    with ``quiet``, no warning is printed meanwhile, here or in the workers."""
    from .batch.quiet import quieted

    with quieted(plan.quiet):
        return _run_plan(plan)


def _run_plan(plan) -> DesignRun:
    from .batch.runner import run

    _check_bodies(plan.columns, plan.options)
    say = (lambda msg: None) if plan.quiet else (lambda msg: print(msg, file=sys.stderr))
    from .batch.peer_inputs import NOT_DOWNLOADED, not_downloaded_text

    if plan.dask:
        _check_dask(plan.dask)
    if (plan.jobs or 1) > 1 or plan.dask == "local":  # worker processes, which import the script again
        from .batch import mainguard

        mainguard.check("dask='local'" if plan.dask == "local" else f"jobs={plan.jobs}")
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
                     summary.n_failed, None if plan.out is None else summary.out, summary.n_unwritten,
                     t.get("risk", []))


def _check_dask(address) -> None:
    """``--dask``: dask.distributed installed and, for a scheduler's address, a scheduler there
    (:func:`pipeline.batch.scheduler.check_address`): an argument error before any work."""
    import importlib.util

    if importlib.util.find_spec("distributed") is None:
        raise ArgumentError("--dask needs dask.distributed: pip install 'rocking-columns[dask]'")
    if address != "local":
        from .batch.scheduler import check_address

        check_address(address)


def _friction(value):
    """``friction=``: None, or a friction coefficient checked as ``--friction`` is."""
    from .args import parse_friction

    if value is not None and not _is_number(value):
        raise TypeError(f"friction: expected a number (a friction coefficient), got {type(value).__name__}")
    return None if value is None else parse_friction(repr(float(value)))


def _check_bodies(columns, options) -> None:
    """A rocking frame (``cap_mass_ratio``) of other than rectangular columns: an argument error."""
    from .args import ArgumentError

    if options.cap_mass_ratio and any(c.body != "rectangular" for c in columns):
        raise ArgumentError("--cap-mass-ratio: rocking frames are modelled for rectangular "
                            "columns only; give the circular columns (cyl:) without it")


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
