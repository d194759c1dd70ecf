"""Design for a site in ``pipeline run``: pairs of components in every direction, scaled suites,
velocity-pulse columns, suite results and collapse fragility.

A *task* of ``pipeline run`` is one ground motion to design for: a single component file, or one
horizontal direction of a pair of components (``--pair A B``, ``--pairs auto``).  For a pair the
directions are, by default, the two recorded components (0 and 90 deg from the first towards the
second), the direction of the strongest velocity pulse (``pulses.classify_pulse``) and its normal;
``--directions N`` adds ``k 180/N`` deg, ``k = 0..N-1`` (a direction and its opposite give the same
width: the column is symmetric).  The component at ``theta`` is ``pulses.component(a1, a2, theta)``.

After the run, the rows of every task are gathered here: ``pairs.csv`` (each pair's governing
direction: the widest verified width), ``suite.csv`` (widths and survival shares over the records
of the suite) and, with ``--fragility``, ``fragility.csv`` and ``fragility_curve.csv``.  Nothing
here re-implements the library: pairing, rotation and classification come from :mod:`pulses`,
widths, simulations and critical scales from :mod:`rocking`.
"""
from __future__ import annotations

import csv
import math
import os
import pathlib

from . import peer_inputs
from .args import SCALE_RANGE, ArgumentError, pair_files, parse_scale
from .report import Columns

#: directions closer than this (deg, modulo 180) are one direction
ANGLE_TOL_DEG = 1e-6
#: most evenly spaced directions accepted (``--directions``): 1 deg apart
MAX_DIRECTIONS = 180

NOT_PULSE_WARNING = "Eq. 31 assumes a pulse; the verified width does not"

# -- report columns ----------------------------------------------------------------------------------
SITE_COLUMNS = Columns(
    ("pair", "-", "The record this row belongs to in the suite: for a pair of components "
                  "(`--pair`, `--pairs auto`) the pair's id (the first file's id, `+`, what differs "
                  "in the second's), one per direction row; for a single component its record id."),
    ("file2", "-", "The second component's path for a pair (the first is `file`); blank for a single "
                   "component."),
    ("direction_deg", "deg", "Direction of the ground motion designed for, from the first component "
                             "towards the second (0..180; the component at theta is "
                             "a1 cos(theta) + a2 sin(theta)); blank for a single component."),
    ("direction_kind", "-", "Why this direction: `component-1`, `component-2` (the recorded "
                            "components), `pulse` (the strongest velocity pulse's direction, "
                            "`orientation_deg`), `pulse-normal` (90 deg from it) or `even` "
                            "(`--directions N`); blank for a single component."),
    ("direction_azimuth_deg", "deg", "Azimuth of that direction, clockwise from north (0..180), where "
                                     "the files state the components' azimuths; else blank."),
    ("scale", "-", "Factor every sample of the record was multiplied by (`--scale`, `--scales`; 1 "
                   "otherwise). Every other column describes the scaled record."),
    ("cap_mass_ratio", "-", "Mass of the cap beam over the columns' total mass (`--cap-mass-ratio`): "
                            "0 for a lone column, above 0 for a rocking frame of such columns "
                            "(SPEC section 8: the frame's p and restitution are used throughout)."),
    ("pulse_like", "-", "The record (for a pair: the pair) is pulse-like by Shahi & Baker's (2014) "
                        "velocity-pulse classification (`pulses.classify_pulse`). When it is not, "
                        "`warnings` notes that Eq. 31 assumes a pulse."),
    ("velocity_pulse_indicator", "-", "Shahi & Baker's pulse indicator PI (pulse-like when above 0, "
                                      "with an early enough arrival)."),
    ("velocity_tp_s", "s", "Pseudo-period Tp of the extracted velocity pulse."),
    ("peer_tp_s", "s", "PEER's pulse period of the record (`Tp-Pulse Period` of a PEER download's "
                       "`_SearchResults.csv`), to compare with `velocity_tp_s`; blank when PEER gives "
                       "none (`-`: not pulse-like in its search) or the record is not from a PEER download."),
    ("orientation_deg", "deg", "Direction of the strongest velocity pulse, from the first component "
                               "towards the second (0 for a single component)."),
    ("azimuth_deg", "deg", "Azimuth of the strongest velocity pulse, clockwise from north (0..180), "
                           "where the files state the azimuths; else blank."),
)

ENVELOPE_COLUMNS = Columns(
    ("envelope_width_m", "m", "Width a column of this height needs by the envelope rule "
                              "(`rocking.required_width`, rule envelope, with each fitting shape's "
                              "factor; fixed point in B): the widest over the shapes that fit."),
    ("envelope_width_overturns", "-", "The envelope design overturns under the full record."),
)

FRAGILITY_COLUMNS = Columns(
    ("critical_scale", "-", "`--fragility`: smallest factor k (on this row's record, already scaled "
                            "by `scale`) for which k times the record overturns the column as it "
                            "stands (`rocking.critical_scale`: a scan that respects safe islands, "
                            "refined to 1e-6); blank when no factor up to `fragility_up_to` does, or "
                            "without `--fragility`."),
    ("critical_pga_g", "g", "PGA of the record at its critical scale."),
    ("critical_islands", "-", "Factor ranges above `critical_scale` where the column survives again "
                              "(`a-b`, `;`-separated; the last may end at `fragility_up_to`)."),
    ("uplift_scale", "-", "Below this factor the column never uplifts (g tan(alpha) / PGA)."),
    ("fragility_up_to", "-", "Largest factor examined."),
)


def classification_fields(record, other=None, pair_fields=None) -> tuple[dict, str | None]:
    """The velocity-pulse columns of a row, and a warning (or None).

    ``pair_fields`` (already computed for the pair, in the main process) are used as they are.
    """
    from .cmd_classify import classify_fields

    blank = dict.fromkeys(["pulse_like", "velocity_pulse_indicator", "velocity_tp_s",
                           "orientation_deg", "azimuth_deg"])
    if pair_fields and "error" in pair_fields:  # the pair's classification failed: no direction
        return blank, f"velocity-pulse classification of the pair failed: {pair_fields['error']}"
    if pair_fields:
        fields = dict(pair_fields)
    else:
        try:
            fields = classify_fields(record, other)
        except Exception as exc:  # an unusual record: designed all the same, and said so
            return blank, f"velocity-pulse classification failed: {' '.join(str(exc).split())}"
    return fields, (None if fields.get("pulse_like") else NOT_PULSE_WARNING)


def pair_of(task) -> str:
    """The pair a task's rows belong to (``pair`` in the reports): a single record is its own."""
    return task.pair or task.record_id


def site_fields(task, record) -> tuple[dict, str | None]:
    """The :data:`SITE_COLUMNS` group of one task's rows, and the warning to add (or None)."""
    cls, warning = classification_fields(record, pair_fields=dict(task.pair_fields) or None)
    az = None
    if task.path2 is not None:
        az = record.metadata.get("azimuth")
        az = None if az is None else float(az) % 180.0
    fields = {"pair": pair_of(task), "file2": task.path2,
              "direction_deg": task.direction, "direction_kind": task.direction_kind or None,
              "direction_azimuth_deg": az, "scale": float(task.scale),
              "cap_mass_ratio": float(task.options.cap_mass_ratio)}
    fields.update(cls)
    fields["peer_tp_s"] = peer_inputs.tp(task)
    return SITE_COLUMNS.row(fields), warning


def read_task(task):
    """The ground motion of a task: one file, or the component of a pair in its direction; scaled."""
    import pulses

    if getattr(task, "peer", None) is not None:
        return peer_inputs.read_task(task)
    opts = task.options
    kw = dict(format=opts.format, units=opts.units, dt=opts.dt, column=opts.column, trace=opts.trace)
    if task.path2 is None:
        record = pulses.read_record(task.path, **kw)
    else:
        first, second = pulses.read_pair(task.path, task.path2, **kw)
        record = pulses.component(first, second, task.direction)
    return record.scaled(task.scale) if task.scale != 1.0 else record


def extra_fields(H, block, record, fitting, options, cache) -> dict:
    """The envelope design and (``--fragility``) the critical scale of one row."""
    import rocking

    g = options.cap_mass_ratio
    if ("envelope", H) not in cache:
        widths = [float(rocking.required_width(H, c.pulse, rule="envelope", shape=c.shape,
                                               cap_mass_ratio=g).width) for c in fitting]
        w = max(widths)
        res = rocking.simulate(rocking.Block.from_dimensions(H, w, cap_mass_ratio=g), record)
        cache[("envelope", H)] = ENVELOPE_COLUMNS.row({"envelope_width_m": w,
                                                       "envelope_width_overturns": bool(res.overturned)})
    fields = dict(cache[("envelope", H)])
    if not options.fragility or block is None:
        fields.update(FRAGILITY_COLUMNS.blank())
        return fields
    from pulses import G

    cs = rocking.critical_scale(block, record, up_to=options.up_to)
    fields.update(FRAGILITY_COLUMNS.row({
        "critical_scale": cs.scale,
        "critical_pga_g": None if cs.critical_pga is None else cs.critical_pga / G,
        "critical_islands": "; ".join(f"{a:.6g}-{b:.6g}" for a, b in cs.islands),
        "uplift_scale": float(cs.uplift_scale), "fragility_up_to": float(cs.up_to),
    }))
    return fields


# -- command line ----------------------------------------------------------------------------------
#: largest scale factor accepted (``--scale``, ``--scales``, ``--up-to``): :data:`pipeline.args.SCALE_RANGE`
MAX_SCALE = SCALE_RANGE[1]


def add_options(parser) -> None:
    """The site options of ``pipeline run``."""
    import argparse

    from .args import add_pair_options

    add_pair_options(parser, default="none", action="design, in several directions, for")
    parser.add_argument("--directions", metavar="N", default="0",
                        help="for pairs, add N evenly spaced directions over 0-180 deg to the two "
                             "components, the velocity-pulse direction and its normal")
    parser.add_argument("--scale", metavar="K", default=None, help="multiply every record by K")
    parser.add_argument("--scales", metavar="FILE.csv",
                        help="scale factors per record: a CSV with columns record (or file) and scale")
    parser.add_argument("--cap-mass-ratio", metavar="G", default="0",
                        help="design rocking frames: cap beam mass over the columns' mass (default 0, "
                             "lone columns)")
    parser.add_argument("--fragility", action=argparse.BooleanOptionalAction, default=False,
                        help="collapse fragility of each --block column as it stands: the critical "
                             "scale factor per record and direction, the suite's lognormal curve")
    parser.add_argument("--up-to", metavar="K", default="10",
                        help="--fragility: largest scale factor examined (default 10)")


def _number(text, what, lo, hi) -> float:
    try:
        value = float(str(text))
    except ValueError:
        raise SiteError(f"{what}: expected a number, got {text!r}") from None
    if not (math.isfinite(value) and lo <= value <= hi):
        raise SiteError(f"{what} must lie between {lo:g} and {hi:g}, got {text!r}")
    return value


def options_from_args(args) -> dict:
    """``cap_mass_ratio``, ``fragility``, ``up_to`` of :class:`pipeline.batch.Options`."""
    gamma = _number(args.cap_mass_ratio, "--cap-mass-ratio", 0.0, 1e3)
    up_to = parse_scale(args.up_to, "--up-to", low=1.0 + 1e-9)
    return {"cap_mass_ratio": gamma, "fragility": bool(args.fragility), "up_to": up_to}


def tasks_from_args(args, paths, columns, options):
    """The tasks of ``pipeline run`` when pairs or scales are asked for; None otherwise (the
    runner's own tasks, one per file)."""
    n, scale, scales = settings_from_args(args)
    if not args.pair and args.pairs == "none" and scale == 1.0 and scales is None:
        return None
    say = (lambda msg: None) if args.quiet else (lambda msg: print(msg, file=__import__("sys").stderr))
    return make_tasks(paths, pair_files(args.pair), args.pairs, columns, options, n, scale,
                      scales, say=say)


def settings_from_args(args):
    """``(directions N, --scale factor, --scales table or None)``, checked."""
    try:
        n = int(str(args.directions))
    except ValueError:
        raise SiteError(f"--directions expects a whole number, got {args.directions!r}") from None
    if not 0 <= n <= MAX_DIRECTIONS:
        raise SiteError(f"--directions must be 0 to {MAX_DIRECTIONS}, got {n}")
    if args.scale is not None and args.scales is not None:
        raise SiteError("give --scale or --scales, not both")
    scale = 1.0 if args.scale is None else parse_scale(args.scale, "--scale")
    scales = None if args.scales is None else read_scales(args.scales)
    return n, scale, scales


def output_files(options) -> list[str]:
    """The fixed files the site part writes into ``--out``."""
    files = [PAIRS_CSV, SUITE_CSV]
    if options.plots:
        files.append(SUITE_PLOT)
    if options.fragility:
        files += [FRAGILITY_CSV, FRAGILITY_CURVE_CSV] + ([FRAGILITY_PLOT] if options.plots else [])
    return files


# -- directions and tasks ----------------------------------------------------------------------------
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
    from .batch import record_ids

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


def make_tasks(paths, pairs, pairs_mode, columns, options, n_directions=0, scale=1.0, scales=None,
               say=print):
    """Tasks of ``pipeline run``: single files as today, pairs as one task per direction.

    ``pairs`` are the ``--pair A B`` couples; with ``pairs_mode == "auto"`` the other files are
    paired from what they say (:func:`pulses.pair_files`).  Pairs are read and classified here
    (their directions depend on the pulse's); a pair that cannot be read becomes one task that
    fails in the worker with the reader's message, as a bad single file does.
    """
    import pulses

    from .batch import Task, record_ids

    opts = dict(format=options.format, units=options.units, dt=options.dt, column=options.column,
                trace=options.trace)
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
    for (a, b, explicit), pname in zip(units, pair_names):
        if b is None:
            specs.append((a, a, None, None, "", "", (), _lookup_names(a, pname)))
            continue
        try:
            first, second = pulses.read_pair(a, b, **opts)
            fields = _pair_classification(first, second)
            angles = directions(fields.get("orientation_deg"), n_directions)
        except pulses.RecordError as exc:
            if not explicit and _both_readable(a, b, opts):
                say(f"pipeline run: note: {exc}; designing {a} and {b} one by one")
                specs += [(p, p, None, None, "", "", (), _lookup_names(p)) for p in (a, b)]
                continue
            fields, angles = {}, [(0.0, "component-1")]  # the task fails at reading, with the reason
        except Exception:  # unreadable: the task fails at reading, with the reason
            fields, angles = {}, [(0.0, "component-1")]
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


def _pair_classification(first, second) -> dict:
    """The pair's velocity-pulse fields; where the classification fails, ``{"error": reason}``:
    the pair is then designed in its recorded components and every row says why."""
    from .cmd_classify import classify_fields

    try:
        return classify_fields(first, second)
    except Exception as exc:
        return {"error": " ".join(str(exc).split()) or type(exc).__name__}


def _both_readable(a, b, opts) -> bool:
    import pulses

    try:
        pulses.read_record(a, **opts)
        pulses.read_record(b, **opts)
    except Exception:
        return False
    return True


# -- after the run: pairs, suite, fragility -----------------------------------------------------------
PAIR_COLUMNS = Columns(
    ("n_directions", "-", "Directions designed for (rows of this pair and column in `summary.csv`)."),
    ("n_directions_failed", "-", "Directions of this pair that failed (in `failures.csv`): where not "
                                 "0, the governing direction is the widest of the others only."),
    ("governing_direction_deg", "deg", "The direction whose verified width is widest (the first such "
                                       "in angle order); blank for a single component."),
)


def _groups(rows):
    """``{(column label, pair): [rows]}`` in first-seen order."""
    out = {}
    for r in rows:
        out.setdefault((r["column"], r["pair"]), []).append(r)
    return out


def governing_rows(rows, failed=None) -> list[dict]:
    """One row per pair (or single record) and column: its direction with the widest verified width.
    ``failed``: ``{pair: directions that failed}``."""
    out = []
    for (_, pair), group in _groups(rows).items():
        gov = max(group, key=lambda r: r["verified_width_m"])  # first of equal widths
        row = PAIR_COLUMNS.row({"n_directions": len(group), "n_directions_failed": (failed or {}).get(pair, 0),
                                "governing_direction_deg": gov["direction_deg"]})
        row.update(gov)
        out.append(row)
    return out


SUITE_COLUMNS = Columns(
    ("column", "-", "The column as given (`HxW` or `H`)."),
    ("column_kind", "-", "`block` or `height` (as in `summary.csv`)."),
    ("height_m", "m", "Full height of the column."),
    ("width_m", "m", "Full width of the column as it stands (blank for `--height`)."),
    ("cap_mass_ratio", "-", "Cap beam mass over the columns' mass (0: a lone column)."),
    ("n_records", "-", "Records of the suite with results: a pair counts once, whatever its directions."),
    ("n_rows", "-", "Record directions with results (rows of `summary.csv` for this column)."),
    ("width_all_m", "m", "Width that survives every record in every direction: the largest verified "
                         "width of the suite."),
    ("width_all_but_one_m", "m", "Width that survives all records but one (each record counted by its "
                                 "governing direction): the second largest governing verified width "
                                 "(blank with fewer than two records)."),
    ("verified_width_median_m", "m", "Median of the records' governing verified widths."),
    ("verified_width_p84_m", "m", "84th percentile of the records' governing verified widths (linear "
                                  "interpolation between order statistics, numpy's default)."),
    ("eq31_width_max_m", "m", "Largest Eq. 31 width over the records and directions."),
    ("share_column_survives", "-", "Share of the records under which the column as it stands does not "
                                   "overturn, in any direction (blank for `--height`)."),
    ("share_column_verified", "-", "Share of the records whose governing verified width the column as it "
                                   "stands reaches (so it survives them with no safe island)."),
    ("share_column_checked", "-", "Share of the records whose governing verified width the column as it "
                                  "stands reaches and that the check above the verified width "
                                  "(`failing_share`, docs/slivers.md) found no failing width at or above "
                                  "the column's width, in any direction: verified with the same check as "
                                  "each record's `widest_failing_width_m` (blank for `--height`)."),
    ("share_eq31_survives", "-", "Share of the records under which the column's Eq. 31 design (for each "
                                 "direction, its own Eq. 31 width) does not overturn, in any direction."),
    ("share_envelope_survives", "-", "Same for the envelope-rule design (`envelope_width_m`)."),
)


def checked(row, width) -> bool:
    """A column ``width`` wide reaches the row's verified width and is wider than every failing
    width the check above it found (docs/slivers.md)."""
    widest = row.get("widest_failing_width_m")
    return (width is not None and float(width) >= float(row["verified_width_m"])
            and (widest is None or float(width) > float(widest)))


def suite_rows(rows) -> list[dict]:
    """``suite.csv``: one row per column over every record of the suite."""
    import numpy as np

    by_column = {}
    for r in rows:
        by_column.setdefault(r["column"], []).append(r)
    out = []
    for label, crows in by_column.items():
        groups = _groups(crows)
        gov = np.array([max(r["verified_width_m"] for r in g) for g in groups.values()])
        first = crows[0]
        is_block = first["column_kind"] == "block"

        def share(pred):
            return sum(all(pred(r) for r in g) for g in groups.values()) / len(groups)

        ranked = np.sort(gov)[::-1]
        out.append(SUITE_COLUMNS.row({
            "column": label, "column_kind": first["column_kind"], "height_m": first["height_m"],
            "width_m": first["width_m"], "cap_mass_ratio": first["cap_mass_ratio"],
            "n_records": len(groups), "n_rows": len(crows),
            "width_all_m": float(ranked[0]),
            "width_all_but_one_m": float(ranked[1]) if ranked.size > 1 else None,
            "verified_width_median_m": float(np.median(gov)),
            "verified_width_p84_m": float(np.percentile(gov, 84)),
            "eq31_width_max_m": max(float(r["eq31_width_m"]) for r in crows),
            "share_column_survives": share(lambda r: not r["overturns"]) if is_block else None,
            "share_column_verified": share(lambda r: bool(r["verified_adequate"])) if is_block else None,
            "share_column_checked": share(lambda r: checked(r, first["width_m"])) if is_block else None,
            "share_eq31_survives": share(lambda r: not r["eq31_width_overturns"]),
            "share_envelope_survives": share(lambda r: not r["envelope_width_overturns"]),
        }))
    return out


FRAGILITY_SUMMARY_COLUMNS = Columns(
    ("column", "-", "The column as it stands (`HxW`)."),
    ("n_records", "-", "Records fitted; each record counts by its weakest direction (the smallest "
                       "critical scale over its directions)."),
    ("n_overturned", "-", "Records that overturn the column at some factor up to `fragility_up_to` "
                          "(the others are right-censored there)."),
    ("median_scale", "-", "Median critical scale factor (lognormal fit by maximum likelihood, "
                          "`rocking.fragility`)."),
    ("beta_scale", "-", "Lognormal dispersion of the critical scale factors."),
    ("median_pga_g", "g", "Median critical PGA (PGA of the critically scaled records)."),
    ("beta_pga", "-", "Lognormal dispersion of the critical PGAs."),
    ("error", "-", "Why no curve could be fitted (e.g. fewer than two records overturn); else blank."),
)
FRAGILITY_CURVE_COLUMNS = Columns(
    ("column", "-", "The column as it stands."),
    ("scale", "-", "Scale factor on the records."),
    ("p_overturn_scale", "-", "Fitted probability of overturning at this scale factor."),
    ("pga_g", "g", "Scaled PGA."),
    ("p_overturn_pga", "-", "Fitted probability of overturning at this PGA."),
)
#: points of each fragility curve in ``fragility_curve.csv``
CURVE_POINTS = 60


def _critical(group):
    """The weakest direction of one record: a :class:`rocking.CriticalScale`-like entry for
    :func:`rocking.fragility` (scale, PGA and the largest factor examined)."""
    from pulses import G
    from rocking.fragility import CriticalScale

    def key(r):
        return math.inf if r["critical_scale"] is None else r["critical_scale"]

    r = min(group, key=key)
    pga = r["pga_g"] * G
    return CriticalScale(scale=r["critical_scale"], islands=[], up_to=r["fragility_up_to"],
                         uplift_scale=r["uplift_scale"], pga=pga, n_scan=0, step=0.0, resolution=0.0,
                         near=0.0, rtol=0.0, runs=0, calls=0)


def fragility_tables(rows):
    """``(summary rows, curve rows, fits)`` of ``--fragility``; ``fits`` maps a column to
    ``(Fragility by scale, Fragility by PGA, critical entries)`` for the plot."""
    import numpy as np
    import rocking

    by_column = {}
    for r in rows:
        if r["column_kind"] == "block" and r["fragility_up_to"] is not None:
            by_column.setdefault(r["column"], []).append(r)
    summary, curve, fits = [], [], {}
    for label, crows in by_column.items():
        entries = [_critical(g) for g in _groups(crows).values()]
        n_over = sum(e.scale is not None for e in entries)
        base = {"column": label, "n_records": len(entries), "n_overturned": n_over}
        try:
            fs = rocking.fragility(entries, measure="scale")
            fp = rocking.fragility(entries, measure="pga")
        except ValueError as exc:
            summary.append(FRAGILITY_SUMMARY_COLUMNS.row({**base, "median_scale": None, "beta_scale": None,
                                                          "median_pga_g": None, "beta_pga": None,
                                                          "error": str(exc)}))
            continue
        summary.append(FRAGILITY_SUMMARY_COLUMNS.row({**base, "median_scale": fs.median, "beta_scale": fs.beta,
                                                      "median_pga_g": fp.median, "beta_pga": fp.beta,
                                                      "error": None}))
        fits[label] = (fs, fp, entries)
        zs = np.linspace(-2.5, 2.5, CURVE_POINTS)
        for z in zs:
            s, a = fs.median * math.exp(z * fs.beta), fp.median * math.exp(z * fp.beta)
            curve.append(FRAGILITY_CURVE_COLUMNS.row({"column": label, "scale": s,
                                                      "p_overturn_scale": fs.probability(s),
                                                      "pga_g": a, "p_overturn_pga": fp.probability(a)}))
    return summary, curve, fits


# -- files -----------------------------------------------------------------------------------------------
PAIRS_CSV, SUITE_CSV, FRAGILITY_CSV, FRAGILITY_CURVE_CSV = ("pairs.csv", "suite.csv", "fragility.csv",
                                                           "fragility_curve.csv")
SUITE_PLOT, FRAGILITY_PLOT = "plots/suite.png", "plots/fragility.png"


def write_outputs(outputs, rows, fields, options, failed=None) -> None:
    """Write ``pairs.csv``, ``suite.csv`` (and their plots) and, with ``--fragility``, the fragility
    files, from every row of the run (``failed``: ``{pair: directions that failed}``)."""
    from . import report

    pair_fields = list(PAIR_COLUMNS.names) + list(fields)
    outputs.write(PAIRS_CSV, report.csv_text(pair_fields, governing_rows(rows, failed)))
    suite = suite_rows(rows) if rows else []
    outputs.write(SUITE_CSV, report.csv_text(list(SUITE_COLUMNS.names), suite))
    if options.plots and rows:
        from .plot_site import suite_figure_png

        outputs.write(SUITE_PLOT, suite_figure_png(rows, suite))
    if options.fragility:
        summary, curve, fits = fragility_tables(rows)
        outputs.write(FRAGILITY_CSV, report.csv_text(list(FRAGILITY_SUMMARY_COLUMNS.names), summary))
        outputs.write(FRAGILITY_CURVE_CSV, report.csv_text(list(FRAGILITY_CURVE_COLUMNS.names), curve))
        if options.plots and fits:
            from .plot_site import fragility_figure_png

            outputs.write(FRAGILITY_PLOT, fragility_figure_png(fits))


def columns_markdown() -> str:
    """The sections of ``columns.md`` for the site files."""
    cell = lambda text: text.replace("|", "\\|")

    def table(title, intro, columns):
        lines = ["", f"## {title}", "", intro, "", "| column | unit | meaning |", "|---|---|---|"]
        return lines + [f"| `{n}` | {u} | {cell(d)} |" for n, u, d in columns]

    lines = table("Columns of `pairs.csv`",
                  "One row per record of the suite (a pair, or a single component) and column: the "
                  "row of `summary.csv` of its governing direction (the widest verified width), "
                  "after these two columns.", PAIR_COLUMNS.columns)
    lines += table("Columns of `suite.csv`",
                   "One row per column, over every record of the suite (failed records left out; "
                   "they are in `failures.csv`). A record's *governing* verified width is the widest "
                   "over its directions. `plots/suite.png`: share of the records whose governing "
                   "verified width is at most a given width, with the column's width and the Eq. 31 "
                   "widths marked.", SUITE_COLUMNS.columns)
    lines += table("Columns of `fragility.csv` (`--fragility`)",
                   "One row per column as it stands: the lognormal collapse fragility of the suite. "
                   "`fragility_curve.csv` gives the fitted curves point by point, and "
                   "`plots/fragility.png` draws them with the records' critical values.",
                   FRAGILITY_SUMMARY_COLUMNS.columns)
    lines += table("Columns of `fragility_curve.csv`", "The fitted curves, 60 points each "
                   "(median x exp(z beta), z from -2.5 to 2.5).", FRAGILITY_CURVE_COLUMNS.columns)
    return "\n".join(lines) + "\n"
