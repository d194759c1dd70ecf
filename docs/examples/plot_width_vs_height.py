"""
Width against height under each rule
====================================

For one pulse, the width a column needs as its height grows, by each design rule: Eq. 31 of
Makris & Vassiliou (2012), Eq. 20, the conservative envelope rule and the exact answer (the
width found by time histories under the pulse).  Taller columns are more stable for the same slenderness, so
the width grows less than in proportion to the height.
"""
import matplotlib.pyplot as plt
import numpy as np

import pulses
import rocking

pulse = pulses.OneSine(ap=0.5 * pulses.G, tp=1.0)
heights = np.linspace(3, 15, 13)
rules = {"eq31": ("Eq. 31", "#0072B2", "-"), "eq20": ("Eq. 20", "#E69F00", ":"),
         "envelope": ("envelope rule", "#009E73", "--"), "exact": ("exact (time histories)", "k", "-")}

fig, ax = plt.subplots(figsize=(8, 3.6), layout="constrained")
for rule, (label, colour, style) in rules.items():
    widths = [rocking.required_width(h, pulse, rule=rule).width for h in heights]
    ax.plot(heights, widths, color=colour, ls=style, lw=2, marker="o", ms=3, label=label)
ax.plot(7.5, 1.8, "s", color="#D55E00", ms=9, label="the Temple of Apollo column, 7.5 x 1.8 m")
ax.set(xlabel="column height H (m)", ylabel="required width B (m)",
       title="one-sine pulse, ap = 0.5 g, Tp = 1 s")
ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
plt.show()
