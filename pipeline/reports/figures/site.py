"""Plots of a suite (``pipeline run``): share of the suite covered against width, and the collapse
fragility curves.  matplotlib's public object API only (a new :class:`matplotlib.figure.Figure` per
plot, saved without the software-version text, so a re-run gives the same bytes)."""
from __future__ import annotations

import io

import numpy as np

#: dots per inch; the figures are 9 in wide: 1350 px
DPI = 150
WIDTH_IN = 9.0


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    return buf.getvalue()


def _governing(rows, label, key):
    """Per record (pair) of the column ``label``: the largest ``key`` over its directions."""
    out = {}
    for r in rows:
        if r["column"] == label and r[key] is not None:
            out[r["pair"]] = max(out.get(r["pair"], -np.inf), float(r[key]))
    return np.array(sorted(out.values()))


def _governing_checked(rows, label):
    """Per record (pair) of the column ``label``: the largest of its design widths and the
    failing widths the check above them found (docs/slivers.md), sorted."""
    out = {}
    for r in rows:
        if r["column"] == label and r["design_width_m"] is not None:
            need = max(float(r["design_width_m"]), float(r.get("widest_failing_width_m") or 0.0))
            out[r["pair"]] = max(out.get(r["pair"], -np.inf), need)
    return np.array(sorted(out.values()))


def suite_figure(rows, suite):
    """One panel per column: share of the records whose governing design width is at most
    ``B``, against ``B``; the column's width and the records' Eq. 31 widths marked."""
    from matplotlib.figure import Figure

    n = len(suite)
    fig = Figure(figsize=(WIDTH_IN, 3.2 * n + 0.6), dpi=DPI, layout="constrained")
    axes = fig.subplots(n, 1, squeeze=False)[:, 0]
    for ax, s in zip(axes, suite):
        label = s["column"]
        widths = _governing(rows, label, "design_width_m")
        eq31 = _governing(rows, label, "eq31_width_m")
        share = np.arange(1, widths.size + 1) / widths.size
        x = np.concatenate([[0.0], widths])
        y = np.concatenate([[0.0], share])
        ax.step(x, y, where="post", color="C0", lw=2, label="records whose design width is at most B (governing direction)")
        checked = _governing_checked(rows, label)
        if checked.size and np.any(checked > widths):
            # the same share with each record's widest failing width (the check above its
            # search width, docs/slivers.md) as its requirement
            ax.step(np.concatenate([[0.0], checked]), y, where="post", color="C0", lw=1, ls="--",
                    label="... and wider than every failing width the check found")
        for i, w in enumerate(eq31):
            ax.axvline(w, color="C1", lw=0.8, ls=":", label="Eq. 31 width of a record" if i == 0 else None)
        if s["width_m"] is not None:
            ax.axvline(float(s["width_m"]), color="C3", lw=2, label=f"column: {float(s['width_m']):.3g} m")
        ax.axvline(float(s["width_all_m"]), color="k", lw=1, ls="--",
                   label=f"width_all_m = {float(s['width_all_m']):.3g} m")
        top = max([float(s["width_all_m"]), *(eq31.tolist() or [0.0]),
                   float(s["width_m"] or 0.0)]) * 1.1
        ax.set_xlim(0.0, top)
        ax.set_ylim(0.0, 1.05)
        ax.set_xlabel("column width B (m)")
        ax.set_ylabel("share of the suite covered")
        ax.set_title(f"column {label}: {s['n_records']} records, {s['n_rows']} record directions")
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    return fig


def suite_figure_png(rows, suite) -> bytes:
    return _png(suite_figure(rows, suite))


def fragility_figure(fits):
    """Two panels: probability of overturning against the scale factor and against the scaled PGA
    (g); the fitted lognormal curves and the records' critical values (empirical shares)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(WIDTH_IN, 4.0), dpi=DPI, layout="constrained")
    ax_s, ax_a = fig.subplots(1, 2)
    for i, (label, (fs, fp, _)) in enumerate(fits.items()):
        colour = f"C{i % 10}"
        for ax, f in ((ax_s, fs), (ax_a, fp)):
            x = f.median * np.exp(np.linspace(-2.5, 2.5, 200) * f.beta)
            ax.plot(x, f.probability(x), color=colour,
                    label=f"{label}: median {f.median:.3g}, beta {f.beta:.2f}")
            xe, pe = f.empirical()
            ax.plot(xe, pe, "o", ms=4, color=colour, alpha=0.7)
    ax_s.set_xlabel("scale factor on the records")
    ax_a.set_xlabel("PGA of the scaled record (g)")
    for ax in (ax_s, ax_a):
        ax.set_ylabel("probability of overturning")
        ax.set_ylim(0.0, 1.02)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower right", fontsize=8)
    fig.suptitle("Collapse fragility of the columns as they stand (points: records, weakest direction)")
    return fig


def fragility_figure_png(fits) -> bytes:
    return _png(fragility_figure(fits))
