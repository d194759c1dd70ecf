"""Fit every record in ../shared/records: the README's table of real records.

``python benchmarks/fit_records.py`` prints a Markdown table: for every record (the two-column
text files once per column, in cm/s^2 at dt = 0.005 s as their comments and MANIFEST.md say), its
PGA, PGV (baseline-corrected, :mod:`pulses.baseline`), the best shape and every shape's fitted
``|ap|`` (g), Tp (s) and score (share of the record's energy the pulse explains).
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


if __name__ == "__main__":
    print(table())
