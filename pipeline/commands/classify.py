"""``pipeline classify FILES...``: is each record (or pair of components) pulse-like?

Shahi & Baker's (2014) velocity-pulse classification (:func:`pulses.classify_pulse`): one row per
pair of horizontal components or per single component, with the pulse indicator, the pulse
period Tp, the peak velocity and the orientation of the strongest pulse.  Files are paired from
what they say (``--pairs auto``, the default: NGA-West2 names, ``_1``/``_2``, the header's
station and event; verticals are left out) or as named with ``--pair A B``.

:mod:`pipeline.reports.pulse_row` gives this command's rows and the columns ``pipeline run`` adds to its
reports, from one place.
"""
from __future__ import annotations

import json
import sys

from ..args import add_pair_options, add_record_options, record_options
from ..values import ArgumentError, pair_files
from ..reports.pulse_row import COLUMNS, RUN_COLUMNS, classify_fields, result_row  # noqa: F401 (this command's row)

def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "classify", help="is the record pulse-like? velocity pulses (Shahi & Baker 2014)",
        description="Classify records, or pairs of horizontal components, as pulse-like or not "
                    "(Shahi & Baker 2014): pulse indicator, Tp, PGV and orientation of the "
                    "strongest velocity pulse. Exit status 0 when every file was classified, 1 "
                    "when some could not be read or paired, 2 for bad arguments.")
    p.add_argument("files", nargs="*", metavar="FILE",
                   help="record files (AT2, SAC, MiniSEED, K-NET, text ...) or folders of them")
    add_pair_options(p, default="auto", action="classify")
    add_record_options(p)
    p.add_argument("--csv", metavar="FILE", help="write one row per pair or component to this CSV file")
    p.add_argument("--json", action="store_true", help="print the rows as JSON instead of a table")
    p.add_argument("--plot", metavar="DIR", help="draw each classification into DIR/<name>.png")
    p.set_defaults(func=main)


def _message(path, exc) -> str:
    text = str(exc).strip().splitlines()
    text = text[0] if text else type(exc).__name__
    return text if text.startswith(str(path)) else f"{path}: {text}"


def main(args) -> int:
    from ..batch.tasks import expand_inputs, skipped_note

    if not args.files and not args.pair:
        raise ArgumentError("no records given: pipeline classify FILE... [--pair A B]")
    opts = record_options(args)
    args.pair = pair_files(args.pair)
    skipped = []
    files = expand_inputs(args.files, skipped)
    if skipped:
        print(f"pipeline classify: note: {skipped_note(skipped, glob_option=False)}", file=sys.stderr)
    inputs = files + [p for pair in args.pair for p in pair]
    _check_outputs(args, inputs)
    records, failures = _read_all(inputs, opts)
    rows, failed = _classify_all(_units(args, files, records), records, args, inputs)
    if args.json:
        print(json.dumps(rows, indent=2))
    elif rows:
        print(format_rows(rows))
    if args.csv and rows:
        from ..reports.columns import csv_text
        from ..reports.outpaths import write_output

        write_output(args.csv, csv_text(COLUMNS, [{c: row[c] for c in COLUMNS} for row in rows]), "csv",
                     inputs=inputs)
    return 1 if failures or failed else 0


def _read_all(paths, opts):
    """``({path: record or None}, failures)``: every file read once; one that cannot be read is
    said and counted."""
    import pulses

    records, failures = {}, 0
    for path in paths:
        if path in records:
            continue
        try:
            records[path] = pulses.read_record(path, **opts)
        except (pulses.RecordError, ValueError, OSError) as exc:
            print(f"pipeline classify: {_message(path, exc)}", file=sys.stderr)
            records[path] = None
            failures += 1
    return records, failures


def _units(args, files, records) -> list:
    """``(first, second or None, named with --pair)`` in order: the ``--pair`` couples, then the
    other readable files, paired by what they say with ``--pairs auto``."""
    import pulses

    units, paired = [], set()
    for a, b in args.pair:
        units.append((a, b, True))
        paired.update((a, b))
    rest = [p for p in files if p not in paired and records.get(p) is not None]
    if args.pairs != "auto":
        return units + [(p, None, False) for p in rest]
    found = pulses.pair_files(rest, metadata={p: records[p].metadata for p in rest})
    for note in found.notes:
        print(f"pipeline classify: note: {note}", file=sys.stderr)
    for v in found.verticals:
        print(f"pipeline classify: note: {v}: vertical component, left out", file=sys.stderr)
    order = {p: i for i, p in enumerate(rest)}
    found_units = [(order[a], a, b) for a, b in found.pairs] + [(order[s], s, None) for s in found.singles]
    return units + [(a, b, False) for _, a, b in sorted(found_units, key=lambda u: u[0])]


def _classify_all(units, records, args, inputs):
    """``(rows, failures)``: each pair (or single file) of ``units`` classified, and drawn with
    ``--plot``; a pair found by ``--pairs auto`` that is no pair is classified one file at a time."""
    import pulses

    rows, failures = [], 0
    stems = set()  # plot file names taken: two inputs named alike never share a PNG
    for a, b, explicit in units:
        first, second = records.get(a), records.get(b) if b is not None else None
        if first is None or (b is not None and second is None):
            continue  # already reported as unreadable
        alone = [(a, b)]
        if second is not None:
            try:
                pulses.check_pair(first, second)
            except pulses.RecordError as exc:
                print(f"pipeline classify: {exc}", file=sys.stderr)
                if explicit:
                    failures += 1
                    continue
                print(f"pipeline classify: note: classifying {a} and {b} one by one", file=sys.stderr)
                alone = [(a, None), (b, None)]
        for x, y in alone:
            try:
                result = pulses.classify_pulse(records[x], records[y] if y is not None else None)
            except (pulses.RecordError, ValueError) as exc:
                print(f"pipeline classify: {_message(x, exc)}", file=sys.stderr)
                failures += 1
                continue
            rows.append(result_row(result, x, y or ""))
            if args.plot:
                failures += _plot(result, args.plot, records, x, y, stems, inputs)
    return rows, failures


def _plot(result, folder, records, x, y, stems, inputs) -> int:
    """Draw one classification into ``folder``; 1 where it cannot be written (its row fails), else 0."""
    from ..reports.figures.classify import plot_classification

    try:
        plot_classification(result, folder, records[x], records[y] if y is not None else None,
                            stem=_unique_stem(result.name, stems), inputs=inputs)
    except OSError as exc:  # one plot that cannot be written fails its row only
        print(f"pipeline classify: {_message(x, exc)}", file=sys.stderr)
        return 1
    return 0


def _unique_stem(name, taken) -> str:
    """A file-system-safe stem for ``name`` not in ``taken`` (``-2``, ``-3``, ... appended)."""
    from ..batch.tasks import record_ids

    base = record_ids([name])[0]
    stem, k = base, 1
    while stem.lower() in taken:
        k += 1
        stem = f"{base}-{k}"
    taken.add(stem.lower())
    return stem


def _check_outputs(args, inputs) -> None:
    """Argument errors before any work (:mod:`pipeline.reports.outpaths`): ``--csv`` that is a folder, one
    of the inputs or a file this command did not write; ``--plot`` that is not a folder."""
    from ..reports.outpaths import check_output_dir, check_output_file

    if args.csv is not None:
        check_output_file(args.csv, "--csv", "csv", inputs=inputs, command="classify")
    if args.plot is not None:
        check_output_dir(args.plot, "--plot", inputs=inputs)


def format_rows(rows) -> str:
    """A plain-text table of the rows."""
    lines = ["pulse  PI      Tp (s)  PGV (m/s)  orient.  azimuth  arrival (s)  late  PGVr   Er     file(s)"]
    for r in rows:
        az = "   -   " if r["azimuth_deg"] is None else f"{r['azimuth_deg']:6.1f} "
        files = r["file"] + (f" + {r['file2']}" if r["file2"] else "")
        lines.append(f"{'yes' if r['pulse_like'] else 'no ':<5}  {r['velocity_pulse_indicator']:+6.2f}  "
                     f"{r['velocity_tp_s']:6.2f}  {r['pgv_m_s']:9.3f}  {r['orientation_deg']:+7.1f}  {az}  "
                     f"{r['arrival_s']:11.2f}  {'yes' if r['late'] else 'no ':<4}  {r['pgv_ratio']:5.3f}  "
                     f"{r['energy_ratio']:5.3f}  {files}")
    lines += [f"{r['file']}: {r['pulse_like_reason']}" for r in rows if r.get("pulse_like_reason")]
    return "\n".join(lines)
