"""
A collapse fragility curve
==========================

Scale each record of a suite up until the column overturns (its critical scale), then fit a
lognormal fragility to those factors: the probability that the column overturns when the suite
is scaled by a given factor.  The five bundled records stand in for the suite.
"""
from importlib.resources import files

import matplotlib.pyplot as plt
import numpy as np

import pulses
import rocking

column = rocking.Block.from_dimensions(7.5, 1.8)
paths = sorted(p for p in files("pipeline.data").iterdir() if p.name.endswith(".sac"))
critical = [rocking.critical_scale(column, pulses.read_record(str(p))) for p in paths]
curve = rocking.fragility(critical)
print(f"median critical scale {curve.median:.2f}, dispersion beta {curve.beta:.2f}")

x = np.linspace(0.05, 4, 300)
fig, ax = plt.subplots(figsize=(8, 3.4), layout="constrained")
ax.plot(x, curve.probability(x), color="#0072B2", lw=2, label="lognormal fit")
found = np.sort([c.scale for c in critical if c.scale is not None])
ax.plot(found, (np.arange(found.size) + 0.5) / len(critical), "o", color="#D55E00",
        label="critical scale of each record")
ax.set(xlabel="scale factor on the records", ylabel="probability of overturning", ylim=(0, 1))
ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
plt.show()
