"""
The vertical component's effect
===============================

Vertical ground acceleration changes the column's effective weight: upward acceleration
stabilises it, downward destabilises it.  The same column under the same horizontal record,
without and with a vertical motion (here a made-up one, 0.3 g at 3 Hz; a real station's upward
vertical is read like any record).
"""
from importlib.resources import files

import matplotlib.pyplot as plt
import numpy as np

import pulses
import rocking

rec = pulses.read_record(str(files("pipeline.data") / "synth_sine_055g_0.9s.sac"))
t = rec.time - rec.t_start
vertical = pulses.Record(0.3 * pulses.G * np.sin(2 * np.pi * 3.0 * t), dt=rec.dt,
                         t_start=rec.t_start, name="vertical_UP", metadata={"vertical": True})
column = rocking.Block.from_dimensions(7.5, 1.8)
alone = rocking.simulate(column, rec)
with_vertical = rocking.simulate(column, rec, vertical=vertical)
for label, res in (("horizontal only", alone), ("with the vertical", with_vertical)):
    print(f"{label}: overturned {res.overturned}, max |theta|/alpha = "
          f"{res.max_rotation_ratio:.2f} ({res.model})")

fig, ax = plt.subplots(figsize=(8, 3.4), layout="constrained")
ax.plot(alone.t, alone.theta / column.alpha, color="k", lw=1.5, label="horizontal only")
ax.plot(with_vertical.t, with_vertical.theta / column.alpha, color="#E69F00", lw=1.5,
        label="with 0.3 g vertical at 3 Hz")
ax.set(xlabel="time (s)", ylabel="rotation theta / alpha", xlim=(5, 15))
ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
plt.show()
