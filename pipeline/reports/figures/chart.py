"""Required width against column height for one pulse, under every design rule
(``pipeline chart --heights``): the chart an engineer sizes a column from.

The widths are computed as one table (height, rule, width) and drawn from it; colours are the
Okabe-Ito palette (distinct with every common colour-vision deficiency) and each rule also has
its own line style, so the chart reads in grey too.  Legends sit outside the axes.
"""
from __future__ import annotations

#: the rules of ``rocking.required_width``, with their label, colour and line style
RULES = {
    "eq31": ("Eq. 31 (the paper's design rule)", "#0072B2", "-"),
    "eq20": ("Eq. 20", "#E69F00", ":"),
    "envelope": ("envelope rule (conservative closed form)", "#009E73", "--"),
    "exact": ("exact: time histories under the pulse", "#000000", "-"),
}


def widths_by_height(pulse, heights, rules=tuple(RULES), body=None, eta=None):
    """The width (m) each rule asks for, per height (m): a :class:`pandas.DataFrame` with
    columns ``height_m``, ``rule``, ``width_m``, ``slenderness`` (``width / height``); of
    ``body``'s shape (rocking.bodies; default rectangular); ``eta``: the restitution of the exact
    rule (the closed forms do not depend on it; a band: the width covering it)."""
    import pandas as pd

    import rocking

    rows = []
    for rule in rules:
        for h in heights:
            width = rocking.required_width(float(h), pulse, rule=rule, body=body,
                                           eta=eta if rule == "exact" else None).width
            rows.append({"height_m": float(h), "rule": rule, "width_m": width,
                         "slenderness": width / float(h)})
    return pd.DataFrame(rows)


def width_figure(frame, title, column=None):
    """Draw ``frame`` (from :func:`widths_by_height`): width against height, one line per rule;
    ``column`` ``(height, width)`` in m, when given, is marked (the user's column as it stands)."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.2, 4.0), layout="constrained")
    ax = fig.subplots()
    for rule, sub in frame.groupby("rule", sort=False):
        label, colour, style = RULES.get(rule, (rule, "0.4", "-"))
        ax.plot(sub["height_m"], sub["width_m"], color=colour, ls=style, lw=2, marker="o", ms=3,
                label=label)
    if column is not None:
        h, b = column
        ax.plot([h], [b], "s", color="#D55E00", ms=9, label=f"your column, {h:g} x {b:g} m")
    ax.set_xlabel("column height H (m)")
    ax.set_ylabel("required width B (m)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), frameon=False, fontsize=8)
    return fig
