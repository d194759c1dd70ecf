"""The verdict against the width for one record and one column height: a *barcode* of the widths
that survive and those that overturn, with the search width and the failing slivers above it
marked (docs/slivers.md).  matplotlib's public object API only (a new
:class:`matplotlib.figure.Figure` per plot, saved without the software-version text, so a re-run
gives the same bytes)."""
from __future__ import annotations

import io

import numpy as np

from ..answer import excess_text

#: dots per inch; the figures are 9 in wide: 1350 px
DPI = 150
WIDTH_IN = 9.0
#: Okabe-Ito sky blue (pale) and vermillion: apart with every common colour-vision deficiency
SAFE, FAIL = "#cde6f7", "#D55E00"


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    return buf.getvalue()


def _bars(ax, x, failed, scale=1.0, offset=0.0):
    """A failing width drawn as a vermillion line, the rest of the row pale blue (safe)."""
    ax.axhspan(0.0, 1.0, color=SAFE, lw=0)
    xf = (np.asarray(x)[failed] - offset) * scale
    ax.vlines(xf, 0.0, 1.0, color=FAIL, lw=1.0)
    ax.set_yticks([])
    ax.set_ylim(0.0, 1.0)


def widths_figure(title, width, widths, failed, widest_failing=None, near=0.05):
    """Two barcodes of the verdict against the width ``B`` under one record.

    Parameters
    ----------
    title : str
    width : float
        The search width, m (a black line; :attr:`rocking.RequiredWidth.search_width`).
    widths, failed : array_like
        Widths examined (m) and whether each overturned: a fine grid, or the check's widths.
    widest_failing : float, optional
        The widest failing width to mark (m; default: the widest failing one of ``widths``).
    near : float
        The lower panel shows ``B / width - 1`` from 1e-4 to this (log scale): the slivers just
        above the search width.
    """
    from matplotlib.figure import Figure

    x = np.asarray(widths, dtype=float)
    f = np.asarray(failed, dtype=bool)
    order = np.argsort(x)
    x, f = x[order], f[order]
    above = f & (x > width)
    if widest_failing is None and above.any():
        widest_failing = float(x[above].max())
    fig = Figure(figsize=(WIDTH_IN, 3.4), dpi=DPI, layout="constrained")
    ax1, ax2 = fig.subplots(2, 1)
    _bars(ax1, x, f)
    ax1.set_xlim(x[0], x[-1])
    ax1.axvline(width, color="k", lw=2, label=f"search width {width:.4g} m")
    if widest_failing is not None:
        ax1.axvline(widest_failing, color=FAIL, lw=2, ls="--",
                    label=f"widest failing width {widest_failing:.4g} m "
                          f"({excess_text(widest_failing, width)})")
    ax1.set_xlabel("column width B (m): vermillion overturns, pale blue survives")
    ax1.set_title(f"{title}: {x.size} widths, {int(f.sum())} overturn, "
                  f"{int(above.sum())} of them above the search width", fontsize=9)
    ax1.legend(loc="upper right", fontsize=7, framealpha=0.9)
    d = x / width - 1.0
    sel = (d > 0) & (d <= near)
    _bars(ax2, x[sel], f[sel], scale=100.0 / width, offset=width)
    ax2.set_xscale("log")
    ax2.set_xlim(1e-2, 100.0 * near)
    ax2.set_xlabel("just above the search width: B / search width - 1 (%)")
    return fig


def widths_figure_png(title, width, widths, failed, widest_failing=None) -> bytes:
    """PNG bytes of :func:`widths_figure`."""
    return _png(widths_figure(title, width, widths, failed, widest_failing))


def record_widths_png(record_id, designs) -> bytes | None:
    """``plots/widths/<record>.png``: the barcode of the check above each column height's search
    width (``designs``: ``{label: RequiredWidth}``) where it found failing widths; None where it
    found none."""
    found = [(label, v) for label, v in designs.items()
             if v.check_widths is not None and v.widest_failing_width is not None]
    if not found:
        return None
    from matplotlib.figure import Figure

    fig = Figure(figsize=(WIDTH_IN, 1.9 * len(found) + 0.5), dpi=DPI, layout="constrained")
    axes = fig.subplots(len(found), 1, squeeze=False)[:, 0]
    for ax, (label, v) in zip(axes, found):
        x, f = np.asarray(v.check_widths), np.asarray(v.check_failed, dtype=bool)
        w = v.search_width if v.search_width else v.width      # the check starts above it
        pct = 100.0 / w
        _bars(ax, x, f, scale=pct, offset=w)
        ax.set_xscale("log")
        ax.set_xlim(max(1e-3, 0.5 * (x[0] - w) * pct), (max(v.check_top, x[-1]) - w) * pct)
        ax.axvline((v.widest_failing_width - w) * pct, color=FAIL, lw=2, ls="--",
                   label=f"widest failing width {v.widest_failing_width:.4g} m "
                         f"({excess_text(v.widest_failing_width, w)})")
        ax.axvline((v.width - w) * pct, color="k", lw=1,
                   label=f"design width {v.width:.4g} m ({excess_text(v.width, w) or '+0 %'})")
        ax.set_title(f"{record_id}, column height {label}: design width {v.width:.4g} m (the "
                     f"search's first transition {w:.4g} m); the check above it: {x.size} widths, "
                     f"{int(f.sum())} fail (share {v.failing_share:.3g})", fontsize=9)
        ax.legend(loc="upper right", fontsize=7, framealpha=0.9)
        ax.set_xlabel("B / search width - 1 (%, log scale): vermillion fails, pale blue survives")
    return _png(fig)
