"""Plots of risk at a site (``pipeline run --hazard``): the annual rate of failure against the
width, with the target and the width for it; and where the rate comes from (its share per band of
the measure).  Drawn from the rows of ``risk_widths.csv`` and ``risk_disaggregation.csv``, so a
figure and its table say the same."""
from __future__ import annotations

import numpy as np

from .site import DPI, WIDTH_IN, _png


def widths_figure(width_rows, risk_rows):
    """Rate against width per column height (log scale), the target and the width for it."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(WIDTH_IN, 4.5), dpi=DPI, layout="constrained")
    ax = fig.subplots()
    by_column = {}
    for r in width_rows:
        by_column.setdefault(r["column"], []).append(r)
    for i, (label, rows) in enumerate(by_column.items()):
        c = f"C{i % 10}"
        w = np.array([r["width_m"] for r in rows], dtype=float)
        rate = np.array([r["rate_per_year"] for r in rows], dtype=float)
        shown = np.where(rate > 0, rate, np.nan)
        ax.semilogy(w, shown, "o-", color=c, ms=4, label=f"H = {label} m")
        for t in (t for t in risk_rows if t["what"] == "width for target" and t["column"].split("x")[0] == label):
            if t["width_m"] is not None:
                ax.axvline(t["width_m"], color=c, ls="--", lw=1)
                ax.annotate(f" {t['width_m']:.3f} m", (t["width_m"], t["target_rate_per_year"]),
                            color=c, fontsize=8)
    targets = {t["target_rate_per_year"] for t in risk_rows if t["target_rate_per_year"]}
    for t in targets:
        ax.axhline(t, color="k", lw=0.8, ls=":")
    ax.set_xlabel("width B (m)")
    ax.set_ylabel("annual rate of failure (1/yr)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Annual rate of failure against the width (dotted: the target; dashed: the width for it)")
    return fig


def widths_figure_png(width_rows, risk_rows) -> bytes:
    return _png(widths_figure(width_rows, risk_rows))


def disaggregation_figure(disagg_rows, measure="intensity measure"):
    """The share of each column's rate per interval of the hazard curve (bars on a log axis)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(WIDTH_IN, 4.0), dpi=DPI, layout="constrained")
    ax = fig.subplots()
    groups = {}
    for r in disagg_rows:
        groups.setdefault((r["column"], r["mode"]), []).append(r)
    n = max(len(groups), 1)
    for i, ((label, mode), rows) in enumerate(groups.items()):
        lo = np.array([r["low"] if r["low"] is not None else r["high"] / 2 for r in rows], dtype=float)
        hi = np.array([r["high"] for r in rows], dtype=float)
        share = np.array([r["share"] for r in rows], dtype=float)
        left = lo * (hi / lo) ** (i / n)
        right = lo * (hi / lo) ** ((i + 1) / n)
        ax.bar(left, 100 * share, width=right - left, align="edge", color=f"C{i % 10}", alpha=0.8,
               label=f"{label}, {mode} (first bar: below the curve's first level)")
    ax.set_xscale("log")
    ax.set_xlabel(measure)
    ax.set_ylabel("share of the rate (%)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Where the rate of failure comes from: its share per interval of the hazard curve")
    return fig


def disaggregation_figure_png(disagg_rows, measure="intensity measure") -> bytes:
    return _png(disaggregation_figure(disagg_rows, measure))
