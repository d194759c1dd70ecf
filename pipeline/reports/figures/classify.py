"""Plot of a velocity-pulse classification, like Fig. 4 of Baker (2007): the record's velocity in
the pulse's direction, the extracted pulse and the residual, on one scale; and the direction.

matplotlib's object interface only (a :class:`matplotlib.figure.Figure` saved with ``savefig``):
no pyplot state, no backend selection; the PNG carries no software tag, so the same result
always gives the same file.
"""
from __future__ import annotations

import io
import math
import pathlib

import numpy as np

from ..outpaths import write_output

#: figure size in inches and resolution: 1100 x 720 pixels
FIGSIZE, DPI = (11.0, 7.2), 100


def _safe(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_.+" else "_" for ch in name)


def plot_classification(result, folder, first=None, second=None, stem=None, inputs=()) -> str:
    """Draw ``result`` (a :class:`pulses.PulseClassification`) into ``folder/<stem>.png``.

    Parameters
    ----------
    result : pulses.PulseClassification
    folder : str or path-like
        Created if needed.
    first, second : pulses.Record, optional
        The component records, for their names and azimuths in the direction sketch.
    stem : str, optional
        File name without ``.png`` (default: the result's name made file-system safe).

    Returns
    -------
    str
        Path of the PNG file.
    """
    from matplotlib.figure import Figure

    folder = pathlib.Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    t = result.time
    v, p, r = result.velocity * 100, result.pulse * 100, result.residual * 100  # cm/s
    fig = Figure(figsize=FIGSIZE, dpi=DPI)
    grid = fig.add_gridspec(3, 2, width_ratios=[4.2, 1.0], hspace=0.12, wspace=0.12,
                            left=0.07, right=0.98, top=0.89, bottom=0.08)
    axes = [fig.add_subplot(grid[i, 0]) for i in range(3)]
    for ax in axes[1:]:
        ax.sharex(axes[0])
        ax.sharey(axes[0])
    panels = [(v, "0.2", "record, in the pulse's direction"), (p, "C3", f"extracted pulse, Tp = {result.tp:.2f} s"),
              (r, "0.45", "residual (record minus pulse)")]
    for ax, (y, color, label) in zip(axes, panels):
        ax.plot(t, y, color=color, lw=0.9, label=label)
        ax.axhline(0.0, color="k", lw=0.4)
        ax.legend(loc="upper right", fontsize=8, frameon=False)
    peak = max(float(np.max(np.abs(v))), 1e-12)
    axes[0].set_ylim(-1.1 * peak, 1.1 * peak)
    axes[0].set_xlim(t[0], t[-1])
    axes[0].axvline(result.arrival, color="C0", lw=0.8, ls="--")
    axes[0].text(result.arrival, 1.0 * peak, f" arrival {result.arrival:.2f} s", color="C0", fontsize=8, va="top")
    for ax in axes[:2]:
        ax.tick_params(labelbottom=False)
    axes[1].set_ylabel("velocity (cm/s)")
    axes[2].set_xlabel("time (s)")
    verdict = "pulse-like" if result.is_pulse else "not pulse-like"
    extra = " (late)" if result.late else ""
    names = result.name if first is None else " + ".join(
        f"{i}: {rec.name}" for i, rec in enumerate((first, second), 1) if rec is not None)
    fig.suptitle(f"{names}\n{verdict}{extra}: PI = {result.indicator:+.2f}, Tp = {result.tp:.2f} s, "
                 f"PGV = {result.pgv * 100:.1f} cm/s, PGV ratio {result.pgv_ratio:.2f}, "
                 f"energy ratio {result.energy_ratio:.2f}", fontsize=10)
    _direction(fig.add_subplot(grid[0:2, 1]), result, first, second)
    path = folder / f"{stem or _safe(result.name)}.png"
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    # a temporary file and a rename (never half a PNG), and never over a file this package did
    # not write (pipeline.reports.outpaths)
    write_output(path, buf.getvalue(), "png", what="--plot", inputs=inputs)
    return str(path)


def _direction(ax, result, first, second) -> None:
    """Sketch seen from above: the components' directions and the pulse's axis.  With azimuths
    known, north is up; otherwise the first component points up."""
    az1 = (first.metadata.get("azimuth") if first is not None else None)
    az2 = (second.metadata.get("azimuth") if second is not None else None)
    known = az1 is not None and (second is None or az2 is not None)
    if known:
        pulse_az = result.azimuth if result.azimuth is not None else float(az1)
        dirs = [(float(az1), "1", "0.3")]
        if second is not None:
            dirs.append((float(az2), "2", "0.55"))
        title = f"pulse direction\n{pulse_az:.0f} / {(pulse_az + 180) % 360:.0f} deg from north"
    else:
        pulse_az = result.orientation
        dirs = [(0.0, "1", "0.3")]
        if second is not None:
            dirs.append((90.0, "2", "0.55"))
        title = f"pulse direction\n{result.orientation:+.1f} deg from component 1\ntowards component 2"
    for az, name, color in dirs:
        x, y = math.sin(math.radians(az)), math.cos(math.radians(az))
        ax.annotate("", xy=(0.8 * x, 0.8 * y), xytext=(0, 0),
                    arrowprops=dict(arrowstyle="->", color=color, lw=1.2))
        ax.text(1.08 * x, 1.08 * y, name, fontsize=9, color=color, ha="center", va="center")
    x, y = math.sin(math.radians(pulse_az)), math.cos(math.radians(pulse_az))
    ax.plot([-x, x], [-y, y], color="C3", lw=2.5)
    if known:
        ax.text(0, 1.12, "N", ha="center", va="center", fontsize=9)
    ax.set_xlim(-1.25, 1.25)
    ax.set_ylim(-1.25, 1.25)
    ax.set_aspect("equal")
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(title, fontsize=8)
