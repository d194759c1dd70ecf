"""Plots of ``pipeline run`` (matplotlib, Agg backend, no display needed).

Figures are rendered to PNG bytes (so a worker on another machine can make them and the main process
writes them atomically) with no software-version or time metadata, so re-runs give identical files.
"""
from __future__ import annotations

import io
import math

import numpy as np

#: at most this many points per curve (long records are thinned for drawing only)
MAX_POINTS = 20000
#: resolution of the PNGs (8 in wide: 640 px)
DPI = 80


def _pyplot():
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def _png(fig) -> bytes:
    plt = _pyplot()
    buf = io.BytesIO()
    try:
        fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    finally:
        plt.close(fig)
    return buf.getvalue()


def _thin(t, y):
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.size > MAX_POINTS:
        step = int(math.ceil(t.size / MAX_POINTS))
        t, y = t[::step], y[::step]
    return t, y


def record_figure_png(record_id, record, fit, fitting, histories) -> bytes:
    """The record with its fitted pulses (paper's Fig. 4) and rotation histories (Figs. 9, 11).

    ``histories`` is a list of ``(column label, [(curve label, block, simulate result), ...])``.
    Drawn for speed (it is a third of ``pipeline run``'s time per record): fixed margins and
    title positions (no layout pass), :data:`DPI`.
    """
    from pulses import G

    plt = _pyplot()
    n = 1 + len(histories)
    height = 2.4 + 2.0 * len(histories)
    fig, axes = plt.subplots(n, 1, figsize=(8.0, height), squeeze=False)
    # fixed margins (in inches) rather than tight_layout, which draws the figure twice
    fig.subplots_adjust(left=0.09, right=0.98, top=1.0 - 0.35 / height, bottom=0.5 / height,
                        hspace=0.75 / 2.0)
    axes = axes[:, 0]
    ax = axes[0]
    t = record.time
    tt, aa = _thin(t, record.acc / G)
    ax.plot(tt, aa, color="0.55", lw=0.6, label="record")
    styles = ["-", "--", "-.", ":"]
    for i, c in enumerate(fitting):
        y = c.pulse(t) / G
        tt, yy = _thin(t, y)
        ax.plot(tt, yy, lw=1.6 if i == 0 else 1.1, ls=styles[i % 4],
                label=f"{c.shape}: ap {c.ap / G:+.3g} g, Tp {c.tp:.3g} s, score {c.score:.2f}")
    ax.set_ylabel("ground acc. (g)")
    ax.set_title(f"{record_id}: record and fitted pulse{'s' if len(fitting) > 1 else ''}", fontsize=10, y=1.0)
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(alpha=0.3)
    for ax, (label, curves) in zip(axes[1:], histories):
        for j, (curve_label, block, res) in enumerate(curves):
            th = np.asarray(res.theta, dtype=float) / block.alpha
            tt, yy = _thin(res.t, th)
            verdict = "overturns" if res.overturned else f"max {res.max_rotation_ratio:.3g} alpha"
            ax.plot(tt, yy, lw=1.0, ls="-" if j == 0 else "--", label=f"{curve_label}: {verdict}")
        ax.axhline(1.0, color="k", lw=0.5, ls=":")
        ax.axhline(-1.0, color="k", lw=0.5, ls=":")
        ax.set_ylabel("theta / alpha")
        ax.set_title(f"column {label} m under the full record", fontsize=9, y=1.0)
        ax.legend(fontsize=7, loc="upper right")
        ax.grid(alpha=0.3)
        ax.set_xlim(record.t_start, record.t_start + record.duration)
    axes[-1].set_xlabel("time (s)")
    axes[0].set_xlim(record.t_start, record.t_start + record.duration)
    return _png(fig)


def _num(row, key):
    v = row.get(key)
    try:
        v = float(v)
    except (TypeError, ValueError):
        return math.nan
    return v


def summary_figure_png(rows) -> bytes:
    """Required against actual tan(alpha), across records and columns."""
    plt = _pyplot()
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10.0, 4.6))
    blocks = [r for r in rows if r.get("column_kind") == "block"]
    hi = 0.0
    if blocks:
        x = np.array([_num(r, "tan_alpha") for r in blocks])
        y31 = np.array([_num(r, "governing_eq31_tan_alpha") for r in blocks])
        yv = np.array([_num(r, "verified_tan_alpha") for r in blocks])
        over = np.array([bool(r.get("overturns")) for r in blocks])
        ax1.scatter(x, y31, marker="o", facecolors="none", edgecolors="C0", label="Eq. 31 (governing pulse)")
        ax1.scatter(x[~over], yv[~over], marker="x", color="C2", label="verified, column survives")
        ax1.scatter(x[over], yv[over], marker="x", color="C3", label="verified, column overturns")
        hi = np.nanmax(np.concatenate([x, y31, yv, [0.0]]))
    hi = 1.1 * hi if hi > 0 else 1.0
    ax1.plot([0, hi], [0, hi], "k-", lw=0.6)
    ax1.set_xlim(0, hi)
    ax1.set_ylim(0, hi)
    ax1.set_xlabel("actual tan(alpha) of the column")
    ax1.set_ylabel("required tan(alpha)")
    ax1.set_title("columns as they stand (above the line: too slender)", fontsize=9)
    ax1.grid(alpha=0.3)
    if blocks:
        ax1.legend(fontsize=7)
    else:
        ax1.text(0.5, 0.5, "no column as it stands (--block) in this run", ha="center", va="center",
                 transform=ax1.transAxes, fontsize=9, color="0.4")
    x = np.array([_num(r, "eq31_width_tan_alpha") for r in rows])
    y = np.array([_num(r, "verified_tan_alpha") for r in rows])
    bad = np.array([bool(r.get("eq31_width_overturns")) for r in rows], dtype=bool)
    hi2 = np.nanmax(np.concatenate([x, y, [0.0]])) if rows else 0.0
    hi2 = 1.1 * hi2 if hi2 > 0 else 1.0
    if rows:
        ax2.scatter(x[~bad], y[~bad], marker="o", color="C0", label="Eq. 31 design survives the record")
        ax2.scatter(x[bad], y[bad], marker="o", color="C3", label="Eq. 31 design overturns")
        ax2.legend(fontsize=7)
    ax2.plot([0, hi2], [0, hi2], "k-", lw=0.6)
    ax2.set_xlim(0, hi2)
    ax2.set_ylim(0, hi2)
    ax2.set_xlabel("Eq. 31 design tan(alpha)")
    ax2.set_ylabel("verified tan(alpha) (full record)")
    ax2.set_title("Eq. 31 against verification (below the line: Eq. 31 conservative)", fontsize=9)
    ax2.grid(alpha=0.3)
    fig.tight_layout()
    return _png(fig)
