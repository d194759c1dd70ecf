"""Fit every record in ../shared/records: the table of real records in docs/validation-fitting.md.

``python benchmarks/fit_records.py`` prints a Markdown table: for every record (the two-column
text files once per column, in cm/s^2 at dt = 0.005 s as their comments and MANIFEST.md say), its
PGA, PGV (baseline-corrected, :mod:`pulses.fit.baseline`), the best shape and every shape's fitted
``|ap|`` (g), Tp (s) and score (share of the record's energy the pulse explains).

``python benchmarks/fit_records.py compare`` prints, for every record, where the weighted least
squares (``weighting="background"``, the default) and the plain ones (``weighting="plain"``)
differ: the best shape, and each shape's ``|ap|`` and Tp when they move by more than 1 %.
"""
from __future__ import annotations

import pathlib

RAW = pathlib.Path(__file__).resolve().parents[1].parent / "shared" / "records" / "raw"
SHAPES = ("sine", "ricker-sym", "ricker-anti", "rect")
#: text files state cm/s^2 and dt = 0.005 s in their comments (newhall.txt in its scripts, MANIFEST.md)
TEXT_OPTIONS = {"units": "cm/s2", "dt": 0.005}


def records():
    """``(label, path, read_record keyword arguments)`` for every shared record."""
    out = []
    for path in sorted(RAW.rglob("*")):
        if not path.is_file():
            continue
        rel = path.relative_to(RAW).as_posix()
        if path.suffix == ".txt":
            for col in (1, 2):
                out.append((f"{rel} col {col}", path, dict(TEXT_OPTIONS, column=col)))
        else:
            out.append((rel, path, {}))
    return out


def table():
    from pulses import G, fit_pulse, read_record

    head = ("| record | PGA (g) | PGV (m/s) | best | " +
            " | ".join(f"{s}: ap (g), Tp (s), score" for s in SHAPES) + " |")
    lines = [head, "|" + "---|" * (4 + len(SHAPES))]
    for label, path, kw in records():
        rec = read_record(path, **kw)
        fit = fit_pulse(rec)
        cells = []
        for s in SHAPES:
            c = fit[s]
            cell = f"{abs(c.ap_g):.3g}, {c.tp:.2f}, {c.score:.2f}"
            cells.append(f"**{cell}**" if c.rank == 1 else cell)
        lines.append(f"| {label} | {fit.pga / G:.3f} | {fit.pgv:.2f} | {fit.best.shape} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def compare(threshold=0.01):
    """Markdown table of the records whose fits change from plain to weighted least squares."""
    from pulses import G, fit_pulse, read_record

    lines = ["| record | best (plain -> weighted) | changes over 1 %: shape ap (g), Tp (s) plain -> weighted |",
             "|---|---|---|"]
    unchanged = 0
    for label, path, kw in records():
        rec = read_record(path, **kw)
        plain, weighted = fit_pulse(rec, weighting="plain"), fit_pulse(rec, weighting="background")
        moves = []
        for s in SHAPES:
            a, b = plain[s], weighted[s]
            if abs(b.ap / a.ap - 1) > threshold or abs(b.tp / a.tp - 1) > threshold:
                moves.append(f"{s} {abs(a.ap) / G:.3g}, {a.tp:.2f} -> {abs(b.ap) / G:.3g}, {b.tp:.2f}")
        best = plain.best.shape if plain.best.shape == weighted.best.shape else \
            f"**{plain.best.shape} -> {weighted.best.shape}**"
        if moves or plain.best.shape != weighted.best.shape:
            lines.append(f"| {label} | {best} | {'; '.join(moves) or '-'} |")
        else:
            unchanged += 1
    lines.append(f"\n{unchanged} other records: no shape's ap or Tp moves by more than {threshold:.0%}.")
    return "\n".join(lines)


if __name__ == "__main__":
    import sys

    print(compare() if sys.argv[1:] == ["compare"] else table())
