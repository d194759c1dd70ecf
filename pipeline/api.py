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

from .plan import Plan, check_bodies, plan_from  # noqa: F401 (Plan: what run_plan takes)
from .values import ArgumentError


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
        from .batch.row import FIELDS

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
        from .reports.suite import SUITE_COLUMNS

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


def _frame(rows, columns):
    """A DataFrame of ``rows`` (dicts of typed values: text stays text, ``record`` ``"1063"``
    included) with ``columns`` in order."""
    import pandas as pd

    return pd.DataFrame([[r.get(c) for c in columns] for r in rows], columns=list(columns))


def design(records, *, blocks=None, heights=None, pairs=None, directions: int = 0, vertical: str = "auto",
           limit=0.5, restitution=None, jobs: int = 1, out=None, shapes=None, weighting: str = "background",
           units=None, dt=None, scale=None, plots=None, force: bool = False, quiet: bool = True,
           thorough: bool = False, **more) -> DesignRun:
    """Design columns for a batch of records, as ``pipeline run`` does, and return the tables.

    Parameters
    ----------
    records : path or list of paths
        Record files (any format :func:`pulses.read_record` reads), folders of them, or PEER downloads
        (docs/peer.md).  A file missing or unreadable is a row of :attr:`DesignRun.failures`.
    blocks : Block, str, (float, float) or a list of them
        Columns as they stand (``--block``): a :class:`rocking.Block`, ``"HxW"`` (full height x full
        width, m; ``"cyl:HxD"`` a circular column of diameter D) or ``(height, width)`` in m.
    heights : float or list of float
        Heights (m) of columns whose width is only to be sized (``--height``).
    pairs : {"none", "auto"} or list of (A, B) or (A, B, V)
        Horizontal components designed as pairs in every direction (``--pair``, ``--triplet`` with
        a vertical ``V``, ``--pairs auto``).  Default: every file alone.
    directions : int
        Evenly spaced directions added for a pair (``--directions``).
    vertical : {"auto", "none"}
        Use a pair's known vertical component (``--vertical``).
    limit : float or None
        The level R of the design width (``--limit``): max|theta|/alpha <= R, at least the verge;
        default 0.5, the paper's dependable design; None (or ``"none"``): the verge alone.
    restitution : str, float or rocking.restitution.Restitution, optional
        ``--restitution``: ``0.97`` (a factor of Eq. 5), ``"eta=0.9"``, ``"r=0.81"`` or a band ``"0.95:1.05"``.
    jobs, out : optional
        Worker processes (0: one per CPU; the tables do not depend on it); the folder to write every
        report into (``--out``; None, the default: nothing is written).
    shapes, weighting : optional
        Pulse shapes to fit (``--shapes``; default the fitter's set); the fit's least squares
        (``--weighting``: ``"background"``, the default, or ``"plain"``).
    units, dt, scale : optional
        What a file does not say (``--units``, ``--dt``); a factor on every record (``--scale``).
    plots : bool or {"governing", "all", "none"}, optional
        The figures (default: when ``out`` is given): True or ``"governing"`` (of a pair's governing
        direction), ``"all"`` (of every direction), False or ``"none"``.  ``--plots``, ``--no-plots``.
    force, quiet, thorough : bool
        ``--force`` (compute every record again), ``--quiet`` (False prints what ``pipeline run``
        prints), ``--thorough`` (a pair's check in every direction).
    **more
        The other options of ``pipeline run`` by their names: ``column``, ``format``, ``trace``, ``scales``,
        ``peer_scales``, ``cap_mass_ratio``, ``fragility``, ``up_to``, ``dask``, ``log``, ``glob``, ``friction``
        (docs/validity.md), ``fragility_limit`` (the level R of the critical scales; None: collapse); risk
        (docs/risk.md): ``hazard`` (a file or a :class:`rocking.risk.HazardCurve`), ``site`` ((lon, lat)),
        ``site_row``, ``imt``, ``hazard_units``, ``years``, ``age``, ``target_rate``, ``target_poe``, ``risk_seed``.

    Returns
    -------
    DesignRun
        ``.design``, ``.summary``, ``.failures`` and ``.suite`` (DataFrames).

    Raises
    ------
    TypeError, ValueError
        An argument of a type not accepted (the message names the forms accepted), a value out of
        range (a negative height, an unknown shape ...), in the words ``pipeline run`` uses for it.
    RuntimeError
        ``jobs > 1`` (or ``dask="local"``) at the top level of a script without the ``if __name__
        == "__main__":`` guard (docs/notebook.md; a notebook needs nothing).

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
    return run_plan(plan_from(records, blocks=blocks, heights=heights, pairs=pairs, directions=directions,
                              vertical=vertical, limit=limit, restitution=restitution, jobs=jobs, out=out,
                              shapes=shapes, weighting=weighting, units=units, dt=dt, scale=scale, plots=plots,
                              force=force, quiet=quiet, thorough=thorough, **more))


def _paths(plan, say):
    """``(downloads, record paths)`` of a run's inputs; the files of its folders that are plainly
    not records are skipped with a note."""
    from .batch import peer_inputs
    from .reports.cells import display
    from .batch.tasks import expand_inputs, skipped_note

    if not plan.records and not plan.pair:
        raise ArgumentError("no records given: pipeline run RECORD... --block HxW")
    downloads, others = peer_inputs.split_inputs(plan.records, plan.options.read.format)
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
    plan = dataclasses.replace(plan, pair=list(plan.pair) + list(plan.triplets))
    downloads, paths = _paths(plan, say)
    absent = [] if downloads else None
    tasks = pairs.tasks_for(plan, downloads, paths, absent)
    if tasks is not None and plan.options.vertical == "auto":
        found = {}
        if plan.pairs == "auto":
            rest = [p for p in paths if p not in {q for ab in plan.pair for q in ab}]
            found = vertical.auto_verticals(rest, plan.options.read, say)
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

    check_bodies(plan.columns, plan.options)
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
        from .reports.answer import table_text

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
