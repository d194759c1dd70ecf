"""Every task of ``pipeline run`` from its arguments: one per file, pairs of components in every
direction (``--pair A B``, ``--pairs auto``), scaled suites (``--scale``, ``--scales``) and PEER
downloads.

For a pair the directions are, by default, the two recorded components (0 and 90 deg from the first
towards the second), the direction of the strongest velocity pulse (``pulses.classify_pulse``) and
its normal; ``--directions N`` adds ``k 180/N`` deg, ``k = 0..N-1``.  Pairs are read and classified
before their tasks are made (their directions depend on the pulse's), in worker processes under
``--jobs N``.
"""
from __future__ import annotations

import csv
import dataclasses
import math
import os
import pathlib
import sys

from . import peer_inputs

from ..reports import pulse_row
from ..values import ArgumentError, pair_files, parse_scale
from .tasks import Task, make_tasks, record_ids

#: directions closer than this (deg, modulo 180) are one direction
ANGLE_TOL_DEG = 1e-6



# -- the run's tasks ---------------------------------------------------------------------------------
def tasks_for(plan, downloads, paths, absent: list | None = None):
    """Every task of a run's ``plan`` (:class:`pipeline.plan.Plan`: its pairs, directions and scales
    as values): the files' (one per file, or pairs), then the PEER downloads'; None when there are
    no pairs, scales or downloads (the runner's own tasks, one per file)."""
    columns, options = plan.columns, plan.options
    if not downloads:
        if plan.peer_scales:
            raise ArgumentError("--peer-scales applies to PEER downloads (a .zip, or a folder holding "
                                "_SearchResults.csv); none was given")
        return _file_tasks(plan, paths)
    scale, scales = _scales(plan)
    if scales is not None and plan.peer_scales:
        raise ArgumentError("give --scales or --peer-scales, not both")
    say = (lambda msg: None) if plan.quiet else (lambda msg: print(msg, file=sys.stderr))
    others = []
    if paths or plan.pair:
        others = _file_tasks(plan, paths)
        if others is None:
            others = make_tasks(paths, columns, options)
    return combine(others, peer_tasks(downloads, columns, options, plan.directions, scale, scales,
                                      plan.peer_scales, say, absent))


def _file_tasks(plan, paths):
    """The tasks of the files when pairs or scales are asked for; None otherwise (the runner's own
    tasks, one per file)."""
    scale, scales = _scales(plan)
    if not plan.pair and plan.pairs == "none" and scale == 1.0 and scales is None:
        return None
    say = (lambda msg: None) if plan.quiet else (lambda msg: print(msg, file=sys.stderr))
    return pair_tasks(paths, pair_files(plan.pair), plan.pairs, plan.columns, plan.options, plan.directions,
                      scale, scales, say=say, jobs=plan.jobs)


def _scales(plan):
    """``(the --scale factor, the --scales table or None)`` of ``plan``, the table read."""
    if plan.scale is not None and plan.scales is not None:
        raise SiteError("give --scale or --scales, not both")
    scale = 1.0 if plan.scale is None else plan.scale
    return scale, None if plan.scales is None else read_scales(plan.scales)


# -- pairs and their directions ----------------------------------------------------------------------------
def directions(orientation, n_even: int = 0) -> list[tuple[float, str]]:
    """``(angle_deg, kind)`` of a pair's directions, sorted by angle in [0, 180).

    The recorded components (0, 90), the pulse direction ``orientation`` and its normal, and
    ``n_even`` evenly spaced directions; a direction met twice keeps its first kind.
    """
    wanted = [(0.0, "component-1"), (90.0, "component-2")]
    if orientation is not None and math.isfinite(orientation):
        wanted += [(orientation % 180.0, "pulse"), ((orientation + 90.0) % 180.0, "pulse-normal")]
    wanted += [(k * 180.0 / n_even, "even") for k in range(n_even)]
    out = []
    for angle, kind in wanted:
        angle = 0.0 if abs(angle - 180.0) < ANGLE_TOL_DEG else angle
        if not any(min(abs(angle - a), 180.0 - abs(angle - a)) < ANGLE_TOL_DEG for a, _ in out):
            out.append((angle, kind))
    return sorted(out)


def _stem(path) -> str:
    return record_ids([path])[0]


def pair_name(path1, path2) -> str:
    """``RSN1063_NORTHR_RRS228+318``: the first file's id, ``+``, the second's after their common start."""
    s1, s2 = _stem(path1), _stem(path2)
    common = len(os.path.commonprefix([s1, s2]))
    return f"{s1}+{s2[common:] or s2}"


class SiteError(ArgumentError):
    """A site option that cannot be used (an argument error: exit status 2)."""


def read_scales(path) -> dict:
    """``--scales FILE.csv``: ``{record or file: scale}`` from a CSV with a ``record`` (or
    ``file``) column and a ``scale`` column."""
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise SiteError(f"--scales {path}: cannot read it: {exc}") from None
    if not rows:
        raise SiteError(f"--scales {path}: no rows")
    keys = {k.strip().lower(): k for k in rows[0] if k}
    name_key = keys.get("record") or keys.get("file")
    if name_key is None or "scale" not in keys:
        raise SiteError(f"--scales {path}: needs a 'record' (or 'file') column and a 'scale' column")
    out, lines = {}, {}
    for i, row in enumerate(rows, start=2):
        name = (row.get(name_key) or "").strip()
        if not name:
            raise SiteError(f"--scales {path}, line {i}: expected a record name and a scale")
        k = parse_scale(row.get(keys["scale"]) or "", f"--scales {path}, line {i}: the scale")
        if name in out:  # which one was meant is not known: never resolved silently
            raise SiteError(f"--scales {path}, lines {lines[name]} and {i}: two rows for {name}")
        out[name], lines[name] = k, i
    return out


def _scale_for(scales, default, names) -> float:
    if scales is None:
        return default
    found = {n: scales[n] for n in dict.fromkeys(names) if n in scales}
    if len(set(found.values())) > 1:  # rows naming one record differently (path, file, id)
        raise SiteError(f"--scales gives {names[0]} several scales: "
                        + ", ".join(f"{k:g} (as {n})" for n, k in found.items()))
    if found:
        return next(iter(found.values()))
    raise SiteError(f"--scales gives no scale for {names[0]} (looked up as {', '.join(dict.fromkeys(names))})")


def _lookup_names(path, *ids) -> list[str]:
    p = pathlib.PurePath(str(path))
    return [str(path), p.name, p.stem, *ids]


def pair_tasks(paths, pairs, pairs_mode, columns, options, n_directions=0, scale=1.0, scales=None,
               say=print, jobs=None):
    """Tasks of ``pipeline run``: single files as today, pairs as one task per direction.

    ``pairs`` are the ``--pair A B`` couples; with ``pairs_mode == "auto"`` the other files are
    paired from what they say (:func:`pulses.pair_files`).  Pairs are read and classified here
    (their directions depend on the pulse's); a pair that cannot be read becomes one task that
    fails in the worker with the reader's message, as a bad single file does.
    """
    import pulses

    opts = options.read.kwargs()
    paired = {p for ab in pairs for p in ab}
    rest = [p for p in paths if p not in paired]
    units = [(a, b, True) for a, b in pairs]  # (first, second or None, named with --pair)
    if pairs_mode == "auto" and rest:
        meta = {}
        for p in rest:
            try:
                meta[p] = pulses.read_record(p, **opts).metadata
            except Exception:  # reported when the task reads it
                pass
        found = pulses.pair_files(rest, metadata=meta)
        for note in found.notes:
            say(f"pipeline run: note: {note}")
        for v in found.verticals:
            say(f"pipeline run: note: {v}: vertical component, left out")
        order = {p: i for i, p in enumerate(rest)}
        auto = [(order[a], a, b) for a, b in found.pairs] + [(order[s], s, None) for s in found.singles]
        units += [(a, b, False) for _, a, b in sorted(auto, key=lambda u: u[0])]
    else:
        units += [(p, None, False) for p in rest]

    specs = []  # (name for the id, path, path2, direction, kind, pair name, pair fields, lookup names)
    pair_names = record_ids([pair_name(a, b) + ".pair" if b is not None else a for a, b, _ in units])
    both = [(a, b, explicit, opts, n_directions) for a, b, explicit in units if b is not None]
    prepared = iter(_map_pairs(both, jobs))
    for (a, b, explicit), pname in zip(units, pair_names):
        if b is None:
            specs.append((a, a, None, None, "", "", (), _lookup_names(a, pname)))
            continue
        fields, angles, split = next(prepared)
        if split:
            say(f"pipeline run: note: {split}; designing {a} and {b} one by one")
            specs += [(p, p, None, None, "", "", (), _lookup_names(p)) for p in (a, b)]
            continue
        names = _lookup_names(a, pname) + _lookup_names(b)
        for angle, kind in angles:
            specs.append((f"{pname}_{angle:05.1f}deg.dir", a, b, angle, kind, pname,
                          tuple(fields.items()), names))
    ids = record_ids([s[0] for s in specs])
    tasks = []
    for i, (rid, (_, a, b, angle, kind, pname, fields, names)) in enumerate(zip(ids, specs)):
        k = _scale_for(scales, scale, names + [rid])
        tasks.append(Task(i, rid, str(a), tuple(columns), options, path2=None if b is None else str(b),
                          direction=angle, direction_kind=kind, pair=pname, scale=k, pair_fields=fields))
    return tasks


def prepare_pair(a, b, explicit, opts, n_directions):
    """``(pair fields, directions, split)`` of one pair: read and classified (its directions
    depend on the pulse's); ``split``: why a pair found by ``--pairs auto`` is designed one file at a
    time (None otherwise).  A pair that cannot be read gets one direction, whose task fails at
    reading with the reason, as a bad single file does."""
    import pulses

    try:
        first, second = pulses.read_pair(a, b, **opts)
        fields = pulse_row.pair_classification(first, second)
        return fields, directions(fields.get("orientation_deg"), n_directions), None
    except pulses.RecordError as exc:
        if not explicit and _both_readable(a, b, opts):
            return {}, [], str(exc)
    except Exception:  # unreadable: the task fails at reading, with the reason
        pass
    return {}, [(0.0, "component-1")], None


def _map_pairs(args, jobs):
    """:func:`prepare_pair` of every pair (``args``: its arguments), in input order: in a pool of
    ``jobs`` worker processes where there are several pairs, so that reading and classifying them
    does not hold up this process (issue: no serial ceiling); here otherwise."""
    if not jobs or jobs <= 1 or len(args) < 2:
        return [prepare_pair(*a) for a in args]
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    from .lifeline import lifeline
    from .quiet import quiet_now

    methods = multiprocessing.get_all_start_methods()
    ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
    with ProcessPoolExecutor(min(jobs, len(args)), mp_context=ctx, initializer=_ignore_interrupts,
                             initargs=(lifeline(), quiet_now())) as pool:
        return list(pool.map(_prepare_packed, args, chunksize=max(1, len(args) // (4 * jobs))))


def _ignore_interrupts(line=None, quiet: bool = False) -> None:
    """Ctrl-C left to the main process (a worker interrupted on its own would print a traceback);
    the worker ends when the main process does (``line``, :mod:`pipeline.batch.lifeline`);
    ``quiet``: no warning printed (pipeline.batch.worker.quieted)."""
    import signal
    import warnings

    from .lifeline import hold

    hold(line)
    if quiet:
        warnings.simplefilter("ignore")

    signal.signal(signal.SIGINT, signal.SIG_IGN)


def _prepare_packed(args):
    return prepare_pair(*args)


def _both_readable(a, b, opts) -> bool:
    import pulses

    try:
        pulses.read_record(a, **opts)
        pulses.read_record(b, **opts)
    except Exception:
        return False
    return True


# -- PEER downloads ---------------------------------------------------------------------------------
def peer_tasks(downloads, columns, options, n_directions, scale, scales, peer_scales: bool, say,
               absent: list | None = None):
    """The tasks of the PEER downloads: each complete record a pair in every direction
    (:func:`directions`), each incomplete one a task that fails when read, with the
    reason; the records not downloaded at all go to ``absent``, when given
    (:func:`pipeline.batch.peer_inputs.record_units`).  Indices and record ids are set by :func:`combine`."""
    from pulses import RecordError, check_pair

    tasks = []
    for download in downloads:
        for entry, src in peer_inputs.record_units(download, peer_scales, say, absent):
            if entry is None:  # the download itself cannot be read: one failure for it
                tasks.append(Task(0, _download_stem(download) + ".zip", download, tuple(columns), options,
                                  peer=src))
                continue
            d = peer_inputs.open_download(download)
            path1, path2 = d.display(src.h1), d.display(src.h2) if src.h2 else None
            pname = pair_name(path1, path2 or path1)
            k = peer_inputs.scale_of(entry) if (peer_scales and not src.missing) else 1.0
            names = [path1, pname, f"RSN{entry.rsn}", src.h1 or ""]
            if scales is not None:
                k *= _scale_for(scales, 1.0, names)
            k *= scale
            fields, angles = {}, [(0.0, "component-1")]
            if not src.missing:
                try:
                    first, second = check_pair(d.read_component(src.h1), d.read_component(src.h2))
                    fields = pulse_row.pair_classification(first, second)
                    angles = directions(fields.get("orientation_deg"), n_directions)
                except RecordError:
                    pass  # the task fails at reading, with the reason
            if src.missing:  # a failure of the record, not of a direction
                tasks.append(Task(0, pname + ".pair", path1, tuple(columns), options, path2=path2,
                                  pair=pname, scale=k, peer=src))
                continue
            for angle, kind in angles:
                tasks.append(Task(0, f"{pname}_{angle:05.1f}deg.dir", path1, tuple(columns), options,
                                  path2=path2, direction=angle, direction_kind=kind, pair=pname,
                                  scale=k, pair_fields=tuple(fields.items()), peer=src))
    return tasks


def _download_stem(path) -> str:
    return os.path.splitext(os.path.basename(os.path.normpath(str(path))))[0] or "download"


def _distinct_pairs(tasks) -> list:
    """``tasks`` with one pair name per pair of files: two pairs of the same file names (two PEER
    downloads holding ``A000.AT2`` and ``A090.AT2``) were one pair of reports, one download's
    metadata with the other's numbers; the later one becomes ``NAME-2``."""
    owner, renamed = {}, {}
    for t in tasks:
        if t.pair is None or (t.pair, t.path, t.path2) in renamed:
            continue
        name, k = t.pair, 1
        while owner.get(name.lower(), (t.path, t.path2)) != (t.path, t.path2):
            k += 1
            name = f"{t.pair}-{k}"
        owner[name.lower()] = (t.path, t.path2)
        renamed[(t.pair, t.path, t.path2)] = name
    out = []
    for t in tasks:
        new = renamed.get((t.pair, t.path, t.path2), t.pair) if t.pair is not None else None
        if new != t.pair:
            rid = new + t.record_id[len(t.pair):] if t.record_id.startswith(t.pair) else t.record_id
            t = dataclasses.replace(t, pair=new, record_id=rid)
        out.append(t)
    return out


def combine(*groups) -> list:
    """Tasks of several sources as one batch: indices in order, record ids unique over all."""
    tasks = _distinct_pairs([t for g in groups for t in g])
    # a PEER task's id is still its name with an extension (``.dir``); the others' are final
    names = [t.record_id if t.peer is not None else t.record_id + ".id" for t in tasks]
    ids = record_ids(names)
    return [dataclasses.replace(t, index=i, record_id=rid) for i, (t, rid) in enumerate(zip(tasks, ids))]
