"""A run of ``pipeline run``, checked: :class:`Plan` holds its records, columns, options and
settings as values, which :func:`pipeline.design` (from :func:`plan_from` here) and ``pipeline run``
(from its options, :mod:`pipeline.commands.run`) both build and :func:`pipeline.api.run_plan` runs.

Every argument of :func:`pipeline.design` is checked here by its type (the message names the forms
accepted: ``TypeError``) and by the rule of the value ``pipeline run`` applies to its option
(:mod:`pipeline.values`: ``ArgumentError``, a ``ValueError``, in the same words).  Numbers stay
numbers: nothing here is written as text to be read back.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field

from .values import ArgumentError, jobs_count

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
    from .batch.tasks import Column
    from .values import block_size, parse_column_block

    if isinstance(block, Column):  # the command line's own, already checked
        return block
    if isinstance(block, str):
        return Column(*parse_column_block(block))
    if isinstance(block, tuple) and len(block) == 2 and all(map(_is_number, block)):
        return Column(*block_size(block[0], block[1]))
    from rocking import Block

    if isinstance(block, Block):
        if block.height is None or block.width is None:
            raise ValueError("blocks: a rocking.Block with its full height and width (made by "
                             "Block.from_dimensions), not only p and alpha")
        return Column(*block_size(block.height, block.width), block.body.kind)
    raise TypeError(f"blocks: expected {_COLUMN_FORMS}; got {type(block).__name__} {block!r:.60}")


def _height(h):
    from .batch.tasks import Column
    from .values import parse_length

    if not _is_number(h):
        raise TypeError(f"heights: expected numbers (the column's full height in m), got "
                        f"{type(h).__name__} {h!r:.60}")
    return Column(parse_length(float(h), "heights (m)"))


def columns_from(blocks, heights) -> tuple:
    """The columns of a run, in order, each once: ``blocks`` (as they stand) then ``heights``."""
    columns = [_column(b) for b in _many(blocks, pair_is_one=True)]
    columns += [_height(h) for h in _many(heights)]
    if not columns:
        raise ValueError("give at least one column: blocks= (e.g. '7.5x1.8', a rocking.Block) or "
                         "heights= (m)")
    return tuple(dict.fromkeys(columns))


def _pairs(pairs) -> tuple[str, list, dict]:
    """``(pairs mode, explicit pairs [(A, B)], triplets {(A, B): V})``."""
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
        explicit.append((a, b))
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
    """A text argument (or None); ``whole``: a whole number too, as a number (``trace=2``: the
    third trace, as ``"2"`` says)."""
    if value is None or isinstance(value, str):
        return value
    if whole and _is_whole(value):
        return int(value)
    raise TypeError(f"{what}: expected {'a whole number or ' if whole else ''}text, got "
                    f"{type(value).__name__} {value!r:.60}")


def _path_option(value, what):
    if value is not None and not _is_path(value):
        raise TypeError(f"{what}: expected a file path (str or os.PathLike) or None, got {type(value).__name__}")
    return value


def _shapes(shapes):
    from .values import parse_shapes

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



_MORE = {"column": None, "format": None, "trace": None, "scales": None, "peer_scales": False,
         "cap_mass_ratio": 0.0, "fragility": False, "fragility_limit": None, "up_to": 10.0, "dask": None,
         "log": None, "glob": None,
         "hazard": None, "site": None, "site_row": None, "imt": None, "hazard_units": None, "years": 50,
         "age": None, "target_rate": None, "target_poe": None, "risk_seed": 0, "friction": None}


def plan_from(records, *, blocks, heights, pairs, directions, vertical, limit, restitution, jobs, out, shapes,
              weighting, units, dt, scale, plots, force, quiet, thorough, **more) -> Plan:
    """Every argument of :func:`pipeline.design` checked, as the :class:`Plan` it asks for: each
    value by the rule ``pipeline run`` applies to its option (:mod:`pipeline.values`), named as
    there."""
    from .values import parse_directions, parse_scale

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
    read = _read_options(units, dt, more)
    options = _options(read, more, plots=plots, out=out, thorough=thorough, shapes=shapes, weighting=weighting,
                       vertical=vertical, limit=limit, restitution=restitution)
    if more["dask"] is not None and not isinstance(more["dask"], str):
        raise TypeError(f"dask: expected 'local' or a scheduler address such as 'tcp://HOST:8786', "
                        f"got {type(more['dask']).__name__}")
    return Plan(
        records=_records(records), columns=columns_from(blocks, heights), options=options,
        pairs=mode, pair=explicit, triplets=triplets,
        directions=parse_directions(directions, "directions"),
        scale=None if scale is None else parse_scale(_number_option(scale, "scale"), "scale"),
        scales=_path_option(more["scales"], "scales"), peer_scales=_flag(more["peer_scales"], "peer_scales"),
        jobs=_jobs(jobs), out=out, force=_flag(force, "force"), quiet=_flag(quiet, "quiet"),
        dask=more["dask"], log=_path_option(more["log"], "log"), glob=_text_option(more["glob"], "glob"))


def _read_options(units, dt, more):
    """``units=``, ``dt=``, ``column=``, ``format=``, ``trace=``: how the records are read."""
    from .batch.tasks import ReadOptions
    from .values import parse_column, parse_dt, parse_units

    if units is not None and not isinstance(units, str):
        raise TypeError(f"units: expected a unit name (e.g. 'g', 'm/s2', 'cm/s2'), got {type(units).__name__}")
    column = more["column"]
    if column is not None and not (_is_whole(column) or isinstance(column, str)):
        raise TypeError(f"column: expected a whole number (counted from 1), got {type(column).__name__}")
    return ReadOptions(format=_text_option(more["format"], "format"), units=parse_units(units, "units"),
                       dt=None if dt is None else parse_dt(_number_option(dt, "dt"), "dt"),
                       column=parse_column(column, "column"),
                       trace=_text_option(more["trace"], "trace", whole=True))


def _options(read, more, *, plots, out, thorough, shapes, weighting, vertical, limit, restitution):
    """The batch's :class:`pipeline.batch.tasks.Options` of :func:`plan_from`'s arguments."""
    from .batch.tasks import Options
    from .values import parse_cap_mass_ratio, parse_up_to

    number = _number_option
    kw = dict(**_plots(plots, out), thorough=_flag(thorough, "thorough"), shapes=_shapes(shapes),
              weighting=_choice(weighting, "weighting", ("background", "plain")),
              vertical=_choice(vertical, "vertical", ("auto", "none")),
              cap_mass_ratio=parse_cap_mass_ratio(number(more["cap_mass_ratio"], "cap_mass_ratio"), "cap_mass_ratio"),
              fragility=_flag(more["fragility"], "fragility"),
              up_to=parse_up_to(number(more["up_to"], "up_to"), "up_to"),
              fragility_limit=_limit(more["fragility_limit"], "fragility_limit"),
              limit=_limit(limit), restitution=_restitution(restitution),
              friction=_friction(more["friction"]), read=read)
    return Options(**kw, risk=_risk(more, kw["restitution"]))


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
    from .values import parse_limit

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
    """A run, checked: what :func:`pipeline.design` and ``pipeline run`` hand to
    :func:`pipeline.api.run_plan`, every setting a value (:mod:`pipeline.batch.pairs` makes the
    tasks of its pairs, directions and scales)."""

    records: list
    #: the columns (:class:`pipeline.batch.tasks.Column`), each once
    columns: tuple
    #: the batch's :class:`pipeline.batch.tasks.Options` (how records are read among them)
    options: object
    #: ``"none"`` or ``"auto"`` (``--pairs``)
    pairs: str = "none"
    #: the ``--pair A B`` couples, ``(A, B)``
    pair: list = field(default_factory=list)
    #: ``--triplet H1 H2 V``: ``{(H1, H2): V}``
    triplets: dict = field(default_factory=dict)
    #: evenly spaced directions added for a pair (``--directions N``)
    directions: int = 0
    #: the factor every record is multiplied by (``--scale K``); None: not given
    scale: float | None = None
    #: ``--scales FILE.csv``: the file of scale factors per record, read with the tasks
    scales: str | None = None
    peer_scales: bool = False
    jobs: int | None = 1
    out: object = None
    force: bool = False
    quiet: bool = True
    dask: str | None = None
    log: object = None
    #: ``--glob``: the files of the folders given that are read
    glob: str | None = None


def _friction(value):
    """``friction=``: None, or a friction coefficient checked as ``--friction`` is."""
    from .values import parse_friction

    if value is not None and not _is_number(value):
        raise TypeError(f"friction: expected a number (a friction coefficient), got {type(value).__name__}")
    return None if value is None else parse_friction(float(value))


def check_bodies(columns, options) -> None:
    """A rocking frame (``cap_mass_ratio``) of other than rectangular columns: an argument error."""
    if options.cap_mass_ratio and any(c.body != "rectangular" for c in columns):
        raise ArgumentError("--cap-mass-ratio: rocking frames are modelled for rectangular "
                            "columns only; give the circular columns (cyl:) without it")


