"""Plots of ``pipeline run`` (matplotlib, Agg backend, no display needed).

Figures are rendered to PNG bytes (so a worker on another machine can make them and the main process
writes them atomically) with no software-version or time metadata, so re-runs give identical files.
"""
from __future__ import annotations

import io
import math
import threading

import numpy as np
# imported here, not on first use: ``pipeline run`` preloads this module in the fork server (its
# workers then start with matplotlib loaded) and in a thread of the main process (for the summary)
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

#: at most this many points per curve (long records are thinned for drawing only)
MAX_POINTS = 20000
#: resolution of the PNGs (8 in wide: 640 px)
DPI = 80


def _figure(figsize):
    """A new figure on the Agg canvas (no pyplot: nothing global to register or close)."""
    fig = Figure(figsize=figsize, dpi=DPI)
    FigureCanvasAgg(fig)
    return fig


def _png(fig) -> bytes:
    """PNG bytes, no metadata that varies; zlib level 1 (a fifth of the drawing time at level 6,
    and for these line plots the files are no larger)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None},
                pil_kwargs={"compress_level": 1})
    return buf.getvalue()


def _thin(t, y):
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.size > MAX_POINTS:
        step = int(math.ceil(t.size / MAX_POINTS))
        t, y = t[::step], y[::step]
    return t, y


#: most fitted pulses drawn on a record (``pipeline run`` keeps the shapes within FIT_TOLERANCE of
#: the best: at most one per shape, four shapes)
MAX_PULSES = 4
#: most curves per rotation-history panel (the column as it stands and the Eq. 31 design)
MAX_CURVES = 2
_PULSE_STYLES = ["-", "--", "-.", ":"]


class _RecordFigure:
    """One reusable record figure with ``n_hist`` history panels (a process draws many records).

    Building a figure (axes, their ticks and text) cost as much as drawing it; here every artist is
    made once and each record only updates data, labels, visibility and limits.  Every property
    that differs between records is set on every draw (nothing is inherited from the previous
    record: explicit colours, no colour cycle, no ``ax.plot``), so a record's PNG bytes do not
    depend on what the figure drew before (``tests/test_pipeline_run.py`` checks it).
    """

    def __init__(self, n_hist):
        height = 2.4 + 2.0 * n_hist
        fig = _figure((8.0, height))
        axes = fig.subplots(1 + n_hist, 1, squeeze=False)[:, 0]
        # fixed margins (in inches) rather than tight_layout, which draws the figure twice
        fig.subplots_adjust(left=0.09, right=0.98, top=1.0 - 0.35 / height, bottom=0.5 / height,
                            hspace=0.75 / 2.0)
        self.fig, self.axes = fig, axes
        ax = axes[0]
        self.record_line, = ax.plot([], [], color="0.55", lw=0.6, label="record")
        self.pulse_lines = [ax.plot([], [], color=f"C{i}", lw=1.6 if i == 0 else 1.1,
                                    ls=_PULSE_STYLES[i % 4])[0] for i in range(MAX_PULSES)]
        ax.set_ylabel("ground acc. (g)")
        ax.grid(alpha=0.3)
        self.hist_lines = []
        for ax in axes[1:]:
            self.hist_lines.append([ax.plot([], [], color=f"C{j}", lw=1.0, ls="-" if j == 0 else "--")[0]
                                    for j in range(MAX_CURVES)])
            ax.axhline(1.0, color="k", lw=0.5, ls=":")
            ax.axhline(-1.0, color="k", lw=0.5, ls=":")
            ax.set_ylabel("theta / alpha")
            ax.grid(alpha=0.3)
        axes[-1].set_xlabel("time (s)")
        for ax in axes[:-1]:  # every panel spans the same time: its labels only at the bottom
            ax.tick_params(labelbottom=False)

    @staticmethod
    def _show(ax, lines, data, xlim):
        """Lines get ``data`` (``[(t, y, label), ...]``, the rest hidden), legend, limits."""
        if len(data) > len(lines):
            raise ValueError(f"at most {len(lines)} curves per panel, got {len(data)}")
        for line, d in zip(lines, data + [None] * (len(lines) - len(data))):
            if d is None:
                line.set_visible(False)
                line.set_data([], [])
                line.set_label("_hidden")
            else:
                line.set_visible(True)
                line.set_data(d[0], d[1])
                line.set_label(d[2])
        shown = lines[:len(data)]
        ax.legend(shown, [ln.get_label() for ln in shown], fontsize=7, loc="upper right")
        ax.relim(visible_only=True)
        ax.set_autoscaley_on(True)
        ax.autoscale_view(scalex=False, scaley=True)
        ax.set_xlim(*xlim)

    def draw(self, record_id, record, fitting, histories) -> bytes:
        from pulses import G

        xlim = (record.t_start, record.t_start + record.duration)
        t = record.time
        ax = self.axes[0]
        pulses = [(*_thin(t, c.pulse(t) / G),
                   f"{c.shape}: ap {c.ap / G:+.3g} g, Tp {c.tp:.3g} s, score {c.score:.2f}")
                  for c in fitting]
        self._show(ax, [self.record_line] + self.pulse_lines,
                   [(*_thin(t, record.acc / G), "record")] + pulses, xlim)
        ax.set_title(f"{record_id}: record and fitted pulse{'s' if len(fitting) > 1 else ''}",
                     fontsize=10, y=1.0)
        for ax, lines, (label, curves) in zip(self.axes[1:], self.hist_lines, histories):
            data = []
            for curve_label, block, res in curves:
                th = np.asarray(res.theta, dtype=float) / block.alpha
                verdict = "overturns" if res.overturned else f"max {res.max_rotation_ratio:.3g} alpha"
                data.append((*_thin(res.t, th), f"{curve_label}: {verdict}"))
            self._show(ax, lines, data, xlim)
            ax.set_title(f"column {label} m under the full record", fontsize=9, y=1.0)
        return _png(self.fig)


#: one record figure per number of history panels, per process (see :class:`_RecordFigure`)
_RECORD_FIGURES: dict = {}
#: matplotlib figures are not thread-safe (dask may run tasks in threads)
_LOCK = threading.Lock()


def record_figure_png(record_id, record, fit, fitting, histories) -> bytes:
    """The record with its fitted pulses (paper's Fig. 4) and rotation histories (Figs. 9, 11).

    ``histories`` is a list of ``(column label, [(curve label, block, simulate result), ...])``.
    Drawn for speed (it was the costliest stage of ``pipeline run`` per record): one figure per
    process reused for every record (:class:`_RecordFigure`), fixed margins and title positions
    (no layout pass), :data:`DPI`.
    """
    n = len(histories)
    with _LOCK:
        fig = _RECORD_FIGURES.get(n)
        if fig is None:
            fig = _RECORD_FIGURES[n] = _RecordFigure(n)
        try:
            return fig.draw(record_id, record, list(fitting), histories)
        except BaseException:
            _RECORD_FIGURES.pop(n, None)  # never reuse a figure left half-updated
            raise


def _num(row, key):
    v = row.get(key)
    try:
        v = float(v)
    except (TypeError, ValueError):
        return math.nan
    return v


def summary_figure_png(rows) -> bytes:
    """Required against actual tan(alpha), across records and columns."""
    fig = _figure((10.0, 4.6))
    ax1, ax2 = fig.subplots(1, 2)
    # fixed margins (what tight_layout gives for these labels) rather than a second layout draw
    fig.subplots_adjust(left=0.067, right=0.974, top=0.929, bottom=0.127, wspace=0.187)
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
    return _png(fig)
