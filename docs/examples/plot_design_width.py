"""
A design width and its barcode
==============================

The design width is the narrowest column of a given height that survives the whole
record at that width and at every larger one found.  Here the 7.5 m high column under a bundled record: the
verdict at each width of a fine grid (the barcode), the design width, and Eq. 31's width for
the record's fitted pulse beside it.
"""
from importlib.resources import files

import matplotlib.pyplot as plt
import numpy as np

import pulses
import rocking

rec = pulses.read_record(str(files("pipeline.data") / "synth_ricker_sym_045g_1.2s.sac"))
height = 7.5
design = rocking.required_width(height, rec, rule="exact")
best = pulses.fit_pulse(rec).best
eq31 = rocking.required_width(height, best.pulse, rule="eq31")
print(f"design width {design.width:.3f} m; Eq. 31 for the fitted {best.shape} pulse "
      f"{eq31.width:.3f} m")

# the verdict on a grid of widths, all in one compiled batch
widths = np.linspace(0.5 * design.width, 1.1 * max(design.width, eq31.width), 600)
blocks = [rocking.Block.from_dimensions(height, b) for b in widths]
failed = rocking.simulate_many(blocks, rec).overturned

fig, ax = plt.subplots(figsize=(8, 2.6), layout="constrained")
step = widths[1] - widths[0]
ax.bar(widths, 1, width=step, color=np.where(failed, "#D55E00", "#56B4E9"), linewidth=0)
ax.axvline(design.width, color="k", lw=2)
ax.axvline(eq31.width, color="#CC79A7", lw=2, ls="--")
handles = [plt.Rectangle((0, 0), 1, 1, color="#D55E00"), plt.Rectangle((0, 0), 1, 1, color="#56B4E9"),
           plt.Line2D([], [], color="k", lw=2), plt.Line2D([], [], color="#CC79A7", lw=2, ls="--")]
ax.legend(handles, ["overturns", "survives", f"design width {design.width:.2f} m",
                    f"Eq. 31 width {eq31.width:.2f} m"],
          loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
ax.set(xlabel="column width B (m), height 7.5 m", yticks=[], xlim=(widths[0], widths[-1]),
       title=rec.name)
plt.show()
