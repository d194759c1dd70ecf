"""
The friction a rocking column needs
===================================

Housner's model lets a column rock but never slide; that holds only while the base's friction can
carry the horizontal force the rocking asks of it.  Here the 7.5 m column as it stands (1.8 m)
and a wider one under a bundled record: the friction coefficient each needs at every instant
(``rocking.friction_demand``), with a base friction of 0.3 drawn across.  At uplift it is
Shenton's boundary between rocking and slide-rock; it grows with the width.
"""
from importlib.resources import files

import matplotlib.pyplot as plt

import pulses
import rocking

rec = pulses.read_record(str(files("pipeline.data") / "synth_sine_055g_0.9s.sac"))
mu = 0.3
fig, ax = plt.subplots(figsize=(9, 3.4), layout="constrained")
for width, colour in ((1.8, "#0072B2"), (2.4, "#E69F00")):
    column = rocking.Block.from_dimensions(7.5, width)
    need = rocking.friction_demand(rocking.simulate(column, rec), rec)
    check = need.judge(mu)
    print(f"{width} m: needs up to {need.max_demand:.3f} at {need.t_max:.2f} s; {check.describe()}")
    ax.plot(need.t, need.demand, color=colour, lw=0.8,
            label=f"7.5 x {width} m: max {need.max_demand:.3f}")
ax.axhline(mu, color="#D55E00", lw=1.2, label=f"base friction {mu}: above it the column slides")
ax.set(xlabel="time (s)", ylabel="|F_x| / F_z", title=f"{rec.name}: friction needed to rock",
       xlim=(4, 16))
ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
plt.show()
