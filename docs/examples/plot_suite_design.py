"""
A column sized for a suite of records
=====================================

Design for a site asks for the width that survives every record of a suite.  Here the five
records bundled with the package stand in for a PEER suite (a download is read the same way,
``pulses.PeerDownload``): the design width of a 7.5 m high column under each, and the suite's
design width, the widest of them.
"""
from importlib.resources import files

import matplotlib.pyplot as plt

import pulses
import rocking

height = 7.5
paths = sorted(p for p in files("pipeline.data").iterdir() if p.name.endswith(".sac"))
names, widths = [], []
for path in paths:
    rec = pulses.read_record(str(path))
    names.append(rec.name.removesuffix(".sac"))
    widths.append(rocking.required_width(height, rec, rule="exact").width)
design = max(widths)
for name, width in zip(names, widths):
    print(f"{name:30s} {width:6.3f} m")
print(f"design width for the suite: {design:.3f} m (governed by {names[widths.index(design)]})")

fig, ax = plt.subplots(figsize=(8, 3.2), layout="constrained")
ax.barh(names, widths, color="#0072B2")
ax.axvline(design, color="#D55E00", lw=2, ls="--", label=f"design width {design:.2f} m")
ax.axvline(1.8, color="k", lw=1.5, label="the column as built, 1.8 m")
ax.set(xlabel="design width of a 7.5 m high column (m)")
ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
plt.show()
