"""Plots of ``pipeline run``, drawn with matplotlib's object API.

Each figure is a new :class:`matplotlib.figure.Figure` (no pyplot: nothing global to register,
select or close) saved to PNG bytes, so a worker process, possibly on another machine, draws it and
the main process writes the file atomically.  ``savefig`` is told to write no software metadata
(matplotlib's PNGs carry no date), so a re-run in the same environment gives the same bytes, and a
record's figure depends on nothing drawn before it.
"""
from __future__ import annotations

import io
import math
import threading

import numpy as np
# imported at module level: ``pipeline run`` preloads this module in the fork server (its workers
# then start with matplotlib loaded) and in a thread of the main process (for the summary)
from matplotlib.figure import Figure

#: at most this many points per curve (long records are thinned for drawing only)
MAX_POINTS = 20000
#: resolution of the PNGs: the record figure (8 in wide) is 1200 px wide, the summary 1500 px
DPI = 150
#: font sizes in points; at :data:`DPI` 8 pt is 17 px on a screen, and an 8 in figure shrunk to a
#: report's 16 cm text width keeps 8 pt text at 6.4 pt
TITLE_SIZE, LABEL_SIZE, TICK_SIZE, LEGEND_SIZE = 11, 10, 9, 8
#: most fitted pulses drawn on a record (``pipeline run`` keeps the shapes within FIT_TOLERANCE of
#: the best: at most one per shape, four shapes)
MAX_PULSES = 4
#: most curves per rotation-history panel (the column as it stands, the Eq. 31 design, the
#: design width, and under a performance level the verge beside it)
MAX_CURVES = 4
#: Okabe-Ito colours (apart with every common colour-vision deficiency); styles tell curves apart too
PALETTE = ["#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9"]
_PULSE_STYLES = ["-", "--", "-.", ":"]
_CURVE_STYLES = ["-", "--", "-.", ":"]
#: record figure in inches: margins (room for the y label and tick labels as wide as "-0.0075",
#: the legends beside the panels, off the curves and the +-alpha lines, the x tick labels and
#: label, the first title), height of a panel, gap between panels (a title)
_RECORD_LEFT, _RECORD_RIGHT, _RECORD_TOP, _RECORD_BOTTOM = 0.95, 3.35, 0.36, 0.55
_PANEL, _GAP = 1.75, 0.45
#: matplotlib is not thread-safe and dask may run tasks in threads of one process
_LOCK = threading.Lock()


def _figure(width, height, layout=None) -> Figure:
    """A new figure, sizes in inches."""
    return Figure(figsize=(width, height), dpi=DPI, layout=layout)


def _png(fig: Figure) -> bytes:
    """PNG bytes of ``fig``, without the software-version text (the same bytes on a re-run)."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    return buf.getvalue()


def _thin(t, y):
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.size > MAX_POINTS:
        step = int(math.ceil(t.size / MAX_POINTS))
        t, y = t[::step], y[::step]
    return t, y


def _style(ax) -> None:
    ax.grid(alpha=0.3)
    ax.tick_params(labelsize=TICK_SIZE)


def record_figure(record_id, record, fit, fitting, histories, velocity=None) -> Figure:
    """The record with its fitted pulses (paper's Fig. 4) and rotation histories (Figs. 9, 11).

    Parameters
    ----------
    record_id : str
        Name in the title.
    record : pulses.Record
        The ground motion (acceleration in m/s^2, time in s); drawn in g.
    fit : pulses.FitResult
        The fit of the record (unused: the fitted pulses drawn are ``fitting``).
    fitting : sequence of pulses.Candidate
        At most :data:`MAX_PULSES` fitted pulses, the best first (drawn thicker).
    histories : list of (str, list of (str, rocking.Block, rocking.SimulationResult))
        One panel per column: its label (metres, in the title) and at most :data:`MAX_CURVES`
        curves ``(curve label, block, result)``, the rotation drawn as theta / alpha.

    velocity : pulses.PulseClassification, optional
        The record's velocity-pulse classification (:func:`pulses.classify_pulse`): when given, a
        panel under the record draws its velocity in the pulse's direction and the extracted
        velocity pulse that decided whether it is pulse-like.

    Returns
    -------
    matplotlib.figure.Figure
        ``1 + len(histories)`` panels (one more with ``velocity``) sharing the time axis, 8 in wide.
    """
    from pulses import G

    fitting = list(fitting)
    if len(fitting) > MAX_PULSES:
        raise ValueError(f"at most {MAX_PULSES} fitted pulses per record figure, got {len(fitting)}")
    n_top = 1 if velocity is None else 2
    n_gaps = len(histories) + n_top - 1
    width, height = 7.85 + _RECORD_RIGHT, _RECORD_TOP + _RECORD_BOTTOM + (n_top + len(histories)) * _PANEL + n_gaps * _GAP
    fig = _figure(width, height)
    # margins fixed in inches (room for these labels, checked by tests/test_plots.py): a layout
    # engine measures every text before drawing it, which made the figure half as costly again
    fig.subplots_adjust(left=_RECORD_LEFT / width, right=1.0 - _RECORD_RIGHT / width, top=1.0 - _RECORD_TOP / height,
                        bottom=_RECORD_BOTTOM / height, hspace=_GAP / _PANEL)
    axes = fig.subplots(n_top + len(histories), 1, sharex=True, squeeze=False)[:, 0]
    ax = axes[0]
    t = record.time
    ax.plot(*_thin(t, record.acc / G), color="0.55", lw=0.6, label="record")
    for i, c in enumerate(fitting):
        ax.plot(*_thin(t, c.pulse(t) / G), color=PALETTE[i], lw=1.6 if i == 0 else 1.1, ls=_PULSE_STYLES[i],
                label=f"{c.shape}: ap {c.ap / G:+.3g} g, Tp {c.tp:.3g} s, score {c.score:.2f}")
    ax.set_ylabel("ground acc. (g)", fontsize=LABEL_SIZE)
    # titles at a given height (y=1): matplotlib otherwise measures the axes' ticks to place them
    ax.set_title(f"{record_id}: record and fitted pulse{'s' if len(fitting) > 1 else ''}", fontsize=TITLE_SIZE,
                 y=1.0)
    if velocity is not None:
        _velocity_panel(axes[1], velocity)
    for ax, (label, curves) in zip(axes[n_top:], histories):
        if len(curves) > MAX_CURVES:
            raise ValueError(f"at most {MAX_CURVES} curves per history panel, got {len(curves)}")
        for j, (curve_label, block, res) in enumerate(curves):
            verdict = verdict_words(res)
            ax.plot(*_thin(res.t, np.asarray(res.theta, dtype=float) / block.alpha), color=PALETTE[j], lw=1.0,
                    ls=_CURVE_STYLES[j], label=f"{curve_label}: {verdict}")
        ax.axhline(1.0, color="k", lw=0.5, ls=":")  # overturning starts past |theta| = alpha
        ax.axhline(-1.0, color="k", lw=0.5, ls=":")
        ax.set_ylabel("theta / alpha", fontsize=LABEL_SIZE)
        ax.set_title(f"column {label} m under the full record", fontsize=TITLE_SIZE - 1, y=1.0)
    for ax in axes:
        _style(ax)
        if ax.get_legend_handles_labels()[0]:
            # beside the panel, off the data ('best' would search every point of every curve)
            ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=LEGEND_SIZE, frameon=False)
    axes[0].set_xlim(record.t_start, record.t_start + record.duration)
    axes[-1].set_xlabel("time (s)", fontsize=LABEL_SIZE)
    fig.align_ylabels(axes)
    return fig


def _velocity_panel(ax, cls) -> None:
    """The record's velocity in the pulse's direction and the extracted velocity pulse."""
    t = cls.time
    verdict = "pulse-like" if cls.is_pulse else "not pulse-like"
    ax.plot(*_thin(t, cls.velocity), color="0.55", lw=0.6, label="ground velocity")
    ax.plot(*_thin(t, cls.pulse), color=PALETTE[3], lw=1.4,
            label=f"velocity pulse: Tp {cls.tp:.3g} s, PI {cls.indicator:+.3g} ({verdict})")
    ax.set_ylabel("velocity (m/s)", fontsize=LABEL_SIZE)
    ax.set_title("velocity in the pulse's direction and the extracted velocity pulse (Shahi & Baker 2014)",
                 fontsize=TITLE_SIZE - 1, y=1.0)


def record_figure_png(record_id, record, fit, fitting, histories, velocity=None) -> bytes:
    """PNG bytes of :func:`record_figure` (same parameters)."""
    with _LOCK:
        return _png(record_figure(record_id, record, fit, fitting, histories, velocity=velocity))


def verdict_words(res) -> str:
    """A run's outcome in a legend: ``overturns``, ``passes alpha, max 1.005 alpha`` (it passes its
    slenderness angle and comes back) or ``max 0.74 alpha``."""
    if res.overturned:
        return "overturns"
    ratio = float(res.max_rotation_ratio)
    return f"passes alpha, max {ratio:.4g} alpha" if ratio >= 1.0 else f"max {ratio:.3g} alpha"


def run_figure_png(record_id, record, fit, fitting, histories, velocity=None) -> bytes:
    """The figure of ``pipeline run`` for one record: :func:`record_figure_png` with the record's
    velocity pulse: ``velocity``, the classification given (a lone record's, made once for its
    rows), else classified here on the record as designed (for a pair, the component in the
    row's direction); without it where the record cannot be classified."""
    import pulses

    if velocity is None:
        try:
            velocity = pulses.classify_pulse(record)
        except Exception:  # an unusual record: its rows say why; drawn without the panel
            velocity = None
    return record_figure_png(record_id, record, fit, fitting, histories, velocity=velocity)


def _num(row, key):
    v = row.get(key)
    try:
        v = float(v)
    except (TypeError, ValueError):
        return math.nan
    return v


def summary_figure(rows) -> Figure:
    """Required against actual tan(alpha), across records and columns.

    Parameters
    ----------
    rows : list of dict
        Rows of ``summary.csv`` (values as written there, numbers or their text).

    Returns
    -------
    matplotlib.figure.Figure
        Two panels, 10 in wide: the columns as they stand (``column_kind`` "block"), and the Eq. 31
        design against the design width of every row.
    """
    # drawn once a run: a layout engine places the labels
    fig = _figure(10.0, 4.8, layout="constrained")
    ax1, ax2 = fig.subplots(1, 2)
    blocks = [r for r in rows if r.get("column_kind") == "block"]
    hi = 0.0
    if blocks:
        x = np.array([_num(r, "tan_alpha") for r in blocks])
        y31 = np.array([_num(r, "governing_eq31_tan_alpha") for r in blocks])
        yv = np.array([_num(r, "design_tan_alpha") for r in blocks])
        over = np.array([bool(r.get("overturns")) for r in blocks])
        ax1.scatter(x, y31, marker="o", facecolors="none", edgecolors=PALETTE[0], label="Eq. 31 (governing pulse)")
        ax1.scatter(x[~over], yv[~over], marker="x", color=PALETTE[2], label="design width, column survives")
        ax1.scatter(x[over], yv[over], marker="x", color=PALETTE[3], label="design width, column overturns")
        hi = np.nanmax(np.concatenate([x, y31, yv, [0.0]]))
    hi = 1.1 * hi if hi > 0 else 1.0
    ax1.plot([0, hi], [0, hi], "k-", lw=0.6)
    ax1.set_xlim(0, hi)
    ax1.set_ylim(0, hi)
    ax1.set_xlabel("actual tan(alpha) of the column", fontsize=LABEL_SIZE)
    ax1.set_ylabel("required tan(alpha)", fontsize=LABEL_SIZE)
    ax1.set_title("columns as they stand (above the line: too slender)", fontsize=TITLE_SIZE - 1)
    if blocks:
        ax1.legend(fontsize=LEGEND_SIZE)
    else:
        ax1.text(0.5, 0.5, "no column as it stands (--block) in this run", ha="center", va="center",
                 transform=ax1.transAxes, fontsize=LABEL_SIZE, color="0.4")
    x = np.array([_num(r, "eq31_width_tan_alpha") for r in rows])
    y = np.array([_num(r, "design_tan_alpha") for r in rows])
    bad = np.array([bool(r.get("eq31_width_overturns")) for r in rows], dtype=bool)
    hi2 = np.nanmax(np.concatenate([x, y, [0.0]])) if rows else 0.0
    hi2 = 1.1 * hi2 if hi2 > 0 else 1.0
    if rows:
        ax2.scatter(x[~bad], y[~bad], marker="o", color=PALETTE[0], label="Eq. 31 design survives the record")
        ax2.scatter(x[bad], y[bad], marker="o", color=PALETTE[3], label="Eq. 31 design overturns")
        ax2.legend(fontsize=LEGEND_SIZE)
    ax2.plot([0, hi2], [0, hi2], "k-", lw=0.6)
    ax2.set_xlim(0, hi2)
    ax2.set_ylim(0, hi2)
    ax2.set_xlabel("Eq. 31 design tan(alpha)", fontsize=LABEL_SIZE)
    ax2.set_ylabel("design tan(alpha) (full record)", fontsize=LABEL_SIZE)
    ax2.set_title("Eq. 31 against the design width (below the line: conservative)", fontsize=TITLE_SIZE - 1)
    for ax in (ax1, ax2):
        _style(ax)
    return fig


def summary_figure_png(rows) -> bytes:
    """PNG bytes of :func:`summary_figure` (same parameters)."""
    with _LOCK:
        return _png(summary_figure(rows))
