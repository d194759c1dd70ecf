"""Overturning spectra (the paper's Fig. 5) and the minimum-slenderness chart (Fig. 8).

Both use the similarity law (docs/theory.md section 4): the response depends only on ``omega_p/p``,
``tan(alpha)`` and ``ap/g``.  A spectrum is therefore one batch-solver call on a grid of
blocks (one ``p`` per ``omega_p/p``, with a unit pulse of period 1 s) times amplitude scales.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pulses import G, SHAPES, make_pulse

from .block import Block
from .closed_forms import eq31
from .search import DEFAULT_SETTINGS, _batch
from .slenderness import min_slenderness_batch


@dataclass
class OverturningSpectrum:
    """Survive/overturn grid of Fig. 5 for one block slenderness and pulse shape.

    Arrays are indexed ``[i, j]`` with ``i`` over :attr:`wp_over_p` and ``j`` over
    :attr:`ap_over_gtan` (the order of the arguments of :func:`overturning_spectrum`).

    Examples
    --------
    >>> import rocking
    >>> spec = rocking.overturning_spectrum(0.2, "sine", [2.0, 4.0], [1.0, 3.0])
    >>> spec.minimum_overturning().tolist()
    [3.0, 3.0]
    """

    alpha: float
    shape: str
    wp_over_p: np.ndarray
    ap_over_gtan: np.ndarray
    overturned: np.ndarray
    exceeded_alpha: np.ndarray
    max_rotation_ratio: np.ndarray
    #: the restitution: ``eta`` (velocity ratio) at ``alpha``, or the band (a
    #: :class:`rocking.restitution.Restitution`) whose values were all run: a point then overturns
    #: (passes alpha) where any value's does, ``max_rotation_ratio`` the largest of them
    eta: object
    #: under a band, the number of its values run (0: no band)
    band_runs: int = 0

    def minimum_overturning(self) -> np.ndarray:
        """For each ``omega_p/p``: the smallest ``ap/(g tan alpha)`` on the grid that overturns (NaN if none)."""
        out = np.full(self.wp_over_p.size, np.nan)
        for i in range(self.wp_over_p.size):
            hit = np.nonzero(self.overturned[i])[0]
            if hit.size:
                out[i] = self.ap_over_gtan[hit[0]]
        return out

    def safe_islands(self) -> np.ndarray:
        """Boolean grid: surviving points lying above an overturning point of the same ``omega_p/p``."""
        seen = np.cumsum(self.overturned, axis=1) > 0
        return seen & ~self.overturned

    def as_dict(self) -> dict:
        """The grid and its verdicts as nested lists (``[i][j]`` as the arrays): plain, JSON-safe."""
        from pulses.export import fields_dict

        return fields_dict(self)

    def to_frame(self):
        """Long-format :class:`pandas.DataFrame`, one row per grid point."""
        import pandas as pd

        w, a = np.meshgrid(self.wp_over_p, self.ap_over_gtan, indexing="ij")
        return pd.DataFrame({
            "wp_over_p": w.ravel(), "ap_over_gtan": a.ravel(),
            "overturned": self.overturned.ravel(), "exceeded_alpha": self.exceeded_alpha.ravel(),
            "max_rotation_ratio": self.max_rotation_ratio.ravel(),
        })

    def plot(self, path=None, ax=None, mark=None):
        """Draw the spectrum as in Fig. 5 (x: ``omega_p/p``, y: ``ap/(g tan alpha)``) on ``ax``, or
        on a new figure (a :class:`matplotlib.figure.Figure`, outside pyplot: no backend is
        chosen for the caller) saved to ``path`` when given.  ``mark``, ``(omega_p/p,
        ap/(g tan alpha))``, puts one's own column under one's own pulse on it.  Colours are
        Okabe-Ito's (distinct with every common colour-vision deficiency), named in a legend
        beside the axes."""
        from matplotlib.colors import ListedColormap
        from matplotlib.figure import Figure
        from matplotlib.patches import Patch

        fig = None
        if ax is None:
            fig = Figure(figsize=(7.2, 4.5), layout="constrained")
            ax = fig.subplots()
        state = np.where(self.overturned, 2, np.where(self.exceeded_alpha, 1, 0)).T
        colours = ["#56B4E9", "#F0E442", "#D55E00"]
        ax.pcolormesh(self.wp_over_p, self.ap_over_gtan, state, cmap=ListedColormap(colours),
                      vmin=0, vmax=2, shading="nearest")
        handles = [Patch(color=c, label=lab) for c, lab in
                   zip(colours, ["survives", "survives, |theta| > alpha", "overturns"])]
        if mark is not None:
            handles += ax.plot([mark[0]], [mark[1]], "o", color="k", mfc="white", mew=2, ms=9,
                               label="your column under your pulse")
        ax.set_xlabel(r"$\omega_p / p$")
        ax.set_ylabel(r"$a_p / (g \tan\alpha)$")
        ax.set_title(f"{self.shape} pulse, alpha = {math.degrees(self.alpha):.3g} deg", fontsize=9)
        ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False,
                  fontsize=8)
        if fig is not None and path is not None:
            fig.savefig(path, dpi=110)
        return ax


def overturning_spectrum(alpha, shape, wp_over_p, ap_over_gtan, *, eta=None, model="fast"):
    """Fig. 5: which blocks of slenderness ``alpha`` overturn under a ``shape`` pulse.

    Parameters
    ----------
    alpha : float
        Slenderness angle, rad.
    shape : str
        A name of :data:`pulses.SHAPES` (the shapes of docs/theory.md section 2).
    wp_over_p : array_like
        Frequency ratios ``omega_p / p`` (x axis of Fig. 5).
    ap_over_gtan : array_like
        Amplitude ratios ``ap / (g tan alpha)`` (y axis; 1 is the uplift limit).
    eta : float or rocking.restitution.Restitution, optional
        Restitution (default Eq. 5 for ``alpha``): a velocity ratio, or a
        :class:`~rocking.restitution.Restitution` (a factor of Eq. 5, an ``eta``, an ``r``).  A
        band gives the spectrum covering it: each of its :data:`rocking.band.BAND_VALUES` values
        run, a point overturning where any of them overturns.

    Returns
    -------
    OverturningSpectrum
        ``.overturned[i, j]`` for ``wp_over_p[i]`` and ``ap_over_gtan[j]``.

    All points are solved in one batch call: by similarity, ``Tp = 1 s`` and ``p = 2 pi /
    (omega_p/p)``, amplitudes as scales of a unit pulse.

    Examples
    --------
    >>> import rocking
    >>> spec = rocking.overturning_spectrum(0.2, "sine", [2.0, 4.0], [1.0, 3.0])
    >>> spec.overturned.tolist()           # [omega_p/p][ap/(g tan alpha)]
    [[False, True], [False, True]]
    """
    from . import band

    if shape not in SHAPES:
        raise ValueError(f"unknown pulse shape {shape!r}; choose one of {', '.join(SHAPES)}")
    eta = band.plain(eta)
    if band.is_band(eta):
        specs = [overturning_spectrum(alpha, shape, wp_over_p, ap_over_gtan, eta=v, model=model)
                 for v in band.singles(eta)]
        first = specs[0]
        return OverturningSpectrum(
            alpha=first.alpha, shape=shape, wp_over_p=first.wp_over_p, ap_over_gtan=first.ap_over_gtan,
            overturned=np.logical_or.reduce([s.overturned for s in specs]),
            exceeded_alpha=np.logical_or.reduce([s.exceeded_alpha for s in specs]),
            max_rotation_ratio=np.maximum.reduce([s.max_rotation_ratio for s in specs]),
            eta=eta, band_runs=len(specs))
    alpha = float(alpha)
    wp = np.atleast_1d(np.asarray(wp_over_p, dtype=float)).ravel()
    ratio = np.atleast_1d(np.asarray(ap_over_gtan, dtype=float)).ravel()
    if np.any(wp <= 0) or not np.all(np.isfinite(wp)):
        raise ValueError("wp_over_p must be positive and finite")
    if np.any(ratio < 0) or not np.all(np.isfinite(ratio)):
        raise ValueError("ap_over_gtan must be non-negative and finite")
    probe = Block(1.0, alpha, eta)
    blocks = [Block(2.0 * math.pi / w, alpha, probe.eta) for w in wp]
    pulse = make_pulse(shape, 1.0, 1.0)
    res = _batch(blocks, pulse, ratio * G * math.tan(alpha), grid=True, model=model)
    shp = (wp.size, ratio.size)
    over = np.asarray(res.overturned, dtype=bool).reshape(shp)
    exc = np.asarray(res.exceeded_alpha, dtype=bool).reshape(shp) | over
    mrr = getattr(res, "max_rotation_ratio", None)
    mrr = (np.asarray(mrr, dtype=float).reshape(shp) if mrr is not None
           else np.asarray(res.max_rotation, dtype=float).reshape(shp) / alpha)
    return OverturningSpectrum(alpha=alpha, shape=shape, wp_over_p=wp, ap_over_gtan=ratio,
                               overturned=over, exceeded_alpha=exc, max_rotation_ratio=mrr,
                               eta=probe.eta)


#: pTp values of the chart (Fig. 8 shows curves for several pTp)
CHART_PTP = (0.5, 1.0, 2.0, 3.0, 4.0, 6.0, 10.0, 20.0)
#: ap/g values of the chart
CHART_APG = tuple(np.round(np.linspace(0.075, 1.5, 20), 6))


def slenderness_chart(shapes=tuple(SHAPES), p_tp=CHART_PTP,
                      ap_over_g=CHART_APG, *, criterion="overturn", n_scan=None, rtol=None,
                      model="fast", settings=DEFAULT_SETTINGS, eta=None):
    """Fig. 8: exact minimum ``tan(alpha)`` against ``ap/g`` for several ``pTp``, beside Eq. 31.

    Returns a :class:`pandas.DataFrame` with columns ``shape, pTp, ap_over_g, exact, eq31,
    ratio`` (``exact / eq31``; above 1 where Eq. 31 is unconservative), ``transitions`` (how
    many verdict changes the scan found) and ``islands`` (how many safe islands lie below the
    answer).  ``eta``: the restitution (:func:`rocking.min_slenderness`'s; a band gives the
    answer covering it, with the columns ``restitution`` and, for a band, ``restitution_governing``:
    the value whose answer governs at that point).

    Examples
    --------
    >>> import rocking
    >>> frame = rocking.slenderness_chart(shapes=("sine",), p_tp=(2.0,), ap_over_g=(0.3, 0.6))
    >>> frame[["shape", "pTp", "ap_over_g"]].values.tolist()
    [['sine', 2.0, 0.3], ['sine', 2.0, 0.6]]
    >>> frame["ratio"].round(2).tolist()
    [1.05, 0.99]
    """
    import pandas as pd

    if isinstance(shapes, str):
        shapes = tuple(SHAPES) if shapes == "all" else (shapes,)
    pt, ag = np.meshgrid(np.asarray(p_tp, float), np.asarray(ap_over_g, float), indexing="ij")
    rows = []
    for shape in shapes:
        results = min_slenderness_batch(shape, pt.ravel(), ag.ravel(), criterion=criterion,
                                        n_scan=n_scan, rtol=rtol, model=model,
                                        settings=settings, eta=eta)
        for x, a, r in zip(pt.ravel(), ag.ravel(), results):
            e31 = float(eq31(a * G, 1.0, x))
            row = {"shape": shape, "pTp": float(x), "ap_over_g": float(a),
                   "exact": r.tan_alpha, "eq31": e31, "ratio": r.tan_alpha / e31,
                   "transitions": len(r.transitions), "islands": len(r.safe_islands)}
            if eta is not None:   # the columns of the default chart stay as they were
                row["restitution"] = str(eta)
                if r.band is not None:
                    row["restitution_governing"] = str(r.eta)
            rows.append(row)
    return pd.DataFrame(rows)


def plot_chart(frame, path=None, dpi=110, mark=None):
    """Draw Fig. 8 from :func:`slenderness_chart`: one panel per shape, Eq. 31 dashed over it
    (a :class:`matplotlib.figure.Figure`, outside pyplot: no backend is chosen for the caller).

    ``mark``, ``(shape, pTp, ap/g, tan alpha)``, puts one's own column under one's own pulse on
    the panel of its shape (survives where it lies above the exact curve of its ``pTp``).
    Colours: viridis (ordered, readable with every common colour-vision deficiency); the legend
    sits beside the panels, off the curves.

    Examples
    --------
    >>> import rocking
    >>> frame = rocking.slenderness_chart(shapes=("sine",), p_tp=(2.0,), ap_over_g=(0.3, 0.6))
    >>> fig = rocking.plot_chart(frame, mark=("sine", 1.38, 0.5, 0.24))
    >>> len(fig.axes)
    1
    """
    import matplotlib
    from matplotlib.figure import Figure

    shapes = list(dict.fromkeys(frame["shape"]))
    n = len(shapes)
    ncol = 2 if n > 1 else 1
    nrow = int(math.ceil(n / ncol))
    fig = Figure(figsize=(5.2 * ncol + 1.6, 4.2 * nrow), layout="constrained")
    axes = fig.subplots(nrow, ncol, squeeze=False)
    ptps = sorted(set(frame["pTp"]))
    colors = matplotlib.colormaps["viridis"](np.linspace(0, 0.9, len(ptps)))
    for ax, shape in zip(axes.ravel(), shapes):
        sub = frame[frame["shape"] == shape]
        for c, x in zip(colors, ptps):
            s = sub[sub["pTp"] == x].sort_values("ap_over_g")
            ax.plot(s["ap_over_g"], s["exact"], "-", color=c, lw=1.5, label=f"pTp = {x:g}")
            ax.plot(s["ap_over_g"], s["eq31"], "--", color=c, lw=0.9)
        if mark is not None and mark[0] == shape:
            ax.plot([mark[2]], [mark[3]], "s", color="#D55E00", ms=8,
                    label=f"your column (pTp = {mark[1]:.3g})")
        ax.set_title(f"{shape}: exact (solid) vs Eq. 31 (dashed)", fontsize=9)
        ax.set_xlabel("ap / g")
        ax.set_ylabel("minimum tan(alpha)")
        ax.grid(alpha=0.3)
    handles, labels = {}, {}
    for ax in axes.ravel()[:n]:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    fig.legend(list(handles.values()), list(handles), loc="outside right upper", fontsize=7,
               frameon=False)
    for ax in axes.ravel()[n:]:
        ax.set_visible(False)
    if path is not None:
        fig.savefig(path, dpi=dpi)
    return fig
