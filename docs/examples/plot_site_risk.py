"""
Risk at a site: the rate of overturning, and the width for a target
====================================================================

The Temple column (7.5 m x 1.8 m) under a hazard curve of PGA made for this example, with the five
bundled records as the site's suite: each record's critical PGA gives the column's fragility, the
fragility against the hazard curve its annual rate of overturning, and a scan of widths the
narrowest column that meets a target of 2 % in 50 years.
"""
from importlib.resources import files

import matplotlib.pyplot as plt
import numpy as np

import pulses
import rocking
from rocking.risk import HazardCurve

x = np.geomspace(0.01, 3.0, 60)
curve = HazardCurve("PGA", x, 2e-4 * x ** -2.5, units="g", source="made for this example")
paths = sorted(p for p in files("pipeline.data").iterdir() if p.name.endswith(".sac"))
records = [pulses.read_record(str(p)) for p in paths]
res = rocking.risk(records, curve, height=7.5, width=1.8, target_poe="2%/50", n_boot=50)
stands = res.modes[0]
target = res.target
print(f"as it stands: {res.rate:.2e} per year ({100 * stands.rate.probability_in(50):.1f} % in 50 years)")
print(f"width for 2 % in 50 years: {target.width:.3f} m (rate {target.rate:.2e})")

fig, (ax_f, ax_w) = plt.subplots(1, 2, figsize=(9, 3.6), layout="constrained")
f = stands.fragility
xs = np.geomspace(0.05, 3.0, 200)
ax_f.plot(xs, f.probability(xs), color="#0072B2", lw=2, label=f"fragility: median {f.median:.2f} g")
crit, share = f.empirical()
ax_f.plot(crit, share, "o", color="#D55E00", label="records' critical PGA")
ax_h = ax_f.twinx()
ax_h.loglog(x, curve.rates, color="0.5", ls="--")
ax_h.set_ylabel("hazard: rate PGA > x (1/yr)", color="0.4")
ax_f.set(xscale="log", xlabel="PGA (g)", ylabel="probability of overturning", ylim=(0, 1))
ax_f.legend(loc="upper left", fontsize=8)
widths = target.sorted()
ax_w.semilogy([w.width for w in widths], [w.rate for w in widths], "o-", color="#0072B2")
ax_w.axhline(target.target_rate, color="k", ls=":", label="2 % in 50 years")
ax_w.axvline(target.width, color="#D55E00", ls="--", label=f"width for it: {target.width:.3f} m")
ax_w.set(xlabel="width B (m)", ylabel="annual rate of overturning")
ax_w.legend(fontsize=8)
plt.show()
