"""``pipeline fit FILES...``: fit acceleration pulses to records and report every candidate shape.

One row per record and shape, ranked by the share of the record's energy each pulse explains
(the best is marked).  ``--csv`` writes the rows, ``--json`` prints them as JSON, ``--plot DIR``
draws each record with the fitted pulses over it (as in Fig. 4 of the paper).

Options for reading records (``--units``, ``--dt``, ``--column``, ``--format``, ``--trace``)
are those of :func:`pipeline.args.add_record_options`, shared with the other sub-commands.
"""
from __future__ import annotations

import json
import sys

from ..args import ShapeNames, add_record_options, add_weighting_option, record_options
from ..values import parse_shapes
from ..reports.cells import text_cell


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "fit", help="fit acceleration pulses (one-sine, Ricker, rectangular) to records",
        description="Fit every candidate pulse shape to each record by wavelet matching and least "
                    "squares; print ap, Tp, arrival, polarity, Lp and fit quality per shape, best "
                    "first. Exit status 0 when every record was fitted, 1 when some could not be "
                    "read, 2 for bad arguments.")
    p.add_argument("files", nargs="+", metavar="FILE", help="record files (AT2, SAC, MiniSEED, K-NET, text ...)")
    shapes = p.add_argument("--shapes", nargs="+", metavar="SHAPE",
                   help="shapes to fit: %(shapes)s or all (default: all)")
    shapes.shapes = ShapeNames()  # listed when the help is printed
    add_weighting_option(p)
    add_record_options(p)
    p.add_argument("--csv", metavar="FILE", help="write one row per record and shape to this CSV file")
    p.add_argument("--plot", metavar="DIR", help="draw each record with its fitted pulses into DIR/<record>.png")
    p.add_argument("--json", action="store_true", help="print the results as JSON instead of a table")
    p.set_defaults(func=main)


def main(args) -> int:
    import pulses

    shapes = parse_shapes(args.shapes)
    opts = record_options(args)
    from ..reports.outpaths import check_output_dir, check_output_file

    if args.plot is not None:
        check_output_dir(args.plot, "--plot", inputs=args.files)
    if args.csv is not None:
        check_output_file(args.csv, "--csv", "csv", inputs=args.files, command="fit")
    fits, rows, failures = [], [], 0
    for path in args.files:
        try:
            record = pulses.read_record(path, **opts)
            fit = pulses.fit_pulse(record, shapes=shapes, weighting=args.weighting)
        except (pulses.RecordError, ValueError) as exc:
            print(f"pipeline fit: {_with_path(path, exc)}", file=sys.stderr)
            failures += 1
            continue
        fits.append((path, record, fit))
        frame = fit.to_frame()
        frame.insert(1, "file", str(path))
        frame["units"] = record.metadata.get("units")
        frame["warnings"] = "; ".join(record.metadata.get("warnings", []))
        rows.append(frame)
        if args.plot:
            try:
                plot_fit(record, fit, args.plot, inputs=args.files)
            except OSError as exc:  # a file in the way: that plot only
                print(f"pipeline fit: {_with_path(path, exc)}", file=sys.stderr)
                failures += 1
    if args.json:
        out = []
        for path, record, fit in fits:
            d = fit.as_dict()
            d.update(file=str(path), units=record.metadata.get("units"),
                     warnings=record.metadata.get("warnings", []))
            out.append(d)
        print(json.dumps(out, indent=2, default=float))
    else:
        for path, record, fit in fits:
            print(format_fit(record, fit))
    if args.csv and rows:
        import pandas as pd

        frame = pd.concat(rows, ignore_index=True)
        for name in frame.columns:  # text cells a spreadsheet would evaluate: see report.text_cell
            frame[name] = frame[name].map(lambda v: text_cell(v) if isinstance(v, str) else v)
        from ..reports.outpaths import write_output

        write_output(args.csv, frame.to_csv(index=False, float_format="%.6g"), "csv", inputs=args.files)
    return 1 if failures else 0


def _with_path(path, exc) -> str:
    """One line naming the file (reader messages already start with the path)."""
    text = str(exc).strip().splitlines()
    text = text[0] if text else type(exc).__name__
    return text if text.startswith(str(path)) else f"{path}: {text}"


def format_fit(record, fit) -> str:
    """A plain-text table of one record's candidates, best first."""
    from pulses import G

    lines = [f"{fit.name}: PGA {fit.pga / G:.3f} g, PGV {fit.pgv:.3f} m/s, duration {fit.duration:.2f} s "
             f"(D5-95 {fit.significant_duration:.2f} s), units {record.metadata.get('units')}, "
             f"{fit.weighting} least squares"]
    for w in record.metadata.get("warnings", []):
        lines.append(f"  warning: {w}")
    lines.append("  rank shape         ap (g)   Tp (s)  t0 (s)  arrival (s)  Lp (m)  score  corr")
    for c in fit.candidates:
        mark = "*" if c.rank == 1 else " "
        lines.append(f"  {c.rank}{mark:<3} {c.shape:<12} {c.ap_g:+7.3f}  {c.tp:7.3f}  {c.t0:6.2f}  "
                     f"{c.arrival:11.2f}  {c.lp:6.2f}  {c.score:5.3f}  {c.correlation:+.3f}")
    return "\n".join(lines)


def plot_fit(record, fit, folder, inputs=()) -> str:
    """Record with every fitted pulse over it, like the paper's Fig. 4: acceleration (g) above,
    velocity below (the record's after the baseline correction of :mod:`pulses.fit.baseline`)."""
    import pathlib

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from pulses import G

    from pulses.fit.baseline import corrected_velocity, velocity

    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    t = record.time
    fig, (ax, axv) = plt.subplots(2, 1, figsize=(9, 5.4), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 2]})
    ax.plot(t, record.acc / G, color="0.35", lw=0.7, label=record.name)
    axv.plot(t, corrected_velocity(record.acc, record.dt), color="0.35", lw=0.8)
    styles = ["C3", "C0", "C2", "C1"]
    for c, color in zip(fit.candidates, styles):
        lw = 2.0 if c.rank == 1 else 1.1
        p = c.pulse(t)
        ax.plot(t, p / G, color=color, lw=lw,
                label=f"{c.shape}: ap {abs(c.ap_g):.2f} g, Tp {c.tp:.2f} s, score {c.score:.2f}")
        axv.plot(t, velocity(p, record.dt), color=color, lw=lw)
    best = fit.best
    lo, hi = best.pulse.support
    span = max(hi - lo, best.tp)
    ax.set_xlim(max(t[0], lo - 2 * span), min(t[-1], hi + 2 * span))
    for a in (ax, axv):
        a.axhline(0, color="k", lw=0.4)
    axv.set_xlabel("time (s)")
    ax.set_ylabel("ground acceleration (g)")
    axv.set_ylabel("velocity (m/s)")
    ax.set_title(f"{record.name}: pulses fitted (best: {best.shape})")
    ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in record.name)
    path = folder / f"{safe}.png"
    from ..reports.outpaths import figure_png, write_output

    data = figure_png(lambda buf: fig.savefig(buf, format="png", dpi=110, metadata={"Software": None}))
    plt.close(fig)
    write_output(path, data, "png", what="--plot", inputs=inputs)
    return str(path)
