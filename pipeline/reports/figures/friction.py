"""The friction a record's responses need against time (``plots/friction/<record>.png``): for
each column, the demand ``|F_x| / F_z`` of the column as it stands and at its design width
(:func:`rocking.friction_demand`), the impulse ratio at impacts, and ``--friction MU`` where given.
matplotlib's object API only; saved without the software-version text (the same bytes on a re-run).
"""
from __future__ import annotations

import io
import math

import numpy as np

DPI = 150
#: Okabe-Ito blue, orange and vermillion (apart with every common colour-vision deficiency)
COLOURS = ["#0072B2", "#E69F00", "#009E73"]
STYLES = ["-", "--", "-."]
MU_COLOUR = "#D55E00"


def friction_figure(record_id, frictions, mu=None):
    """One panel per column: ``frictions`` is ``[(column label, [(curve label, FrictionDemand)])]``."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.5, 0.6 + 2.2 * len(frictions)), dpi=DPI, layout="constrained")
    axes = fig.subplots(len(frictions), 1, squeeze=False, sharex=True)[:, 0]
    for ax, (label, curves) in zip(axes, frictions):
        top = 0.0
        for j, (name, need) in enumerate(curves):
            finite = np.isfinite(need.demand)
            ax.plot(need.t[finite], need.demand[finite], color=COLOURS[j % 3], ls=STYLES[j % 3],
                    lw=0.9, label=f"{name}: max {need.max_demand:.3g} at {need.t_max:.3g} s")
            top = max(top, float(np.max(need.demand[finite], initial=0.0)))
            if need.impacts.size and math.isfinite(need.impulse_ratio):
                ax.plot(need.impacts, np.full(need.impacts.size, need.impulse_ratio), ls="none",
                        marker="|", ms=6, color=COLOURS[j % 3], alpha=0.6,
                        label=f"{name}: impulse ratio at impacts {need.impulse_ratio:.3g}")
        if mu is not None:
            ax.axhline(mu, color=MU_COLOUR, lw=1.2, label=f"--friction {mu:g}: above it the column slides")
            top = max(top, mu)
        ax.set_ylim(0.0, 1.1 * top if top > 0 else 1.0)
        ax.set_ylabel("|F_x| / F_z", fontsize=10)
        ax.set_title(f"{record_id}, column {label}: friction needed to rock without sliding",
                     fontsize=10)
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=9)
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    axes[-1].set_xlabel("time (s)", fontsize=10)
    return fig


def friction_png(record_id, frictions, mu=None) -> bytes | None:
    """PNG bytes of :func:`friction_figure`; None without a column."""
    if not frictions:
        return None
    from .record import _LOCK

    with _LOCK:
        fig = friction_figure(record_id, frictions, mu)
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=DPI, metadata={"Software": None})
    return buf.getvalue()
