"""
A rocking frame
===============

Columns capped by a free beam rock like a single, larger column (Makris & Vassiliou 2013): the
heavier the beam (``cap_mass_ratio``, the beam's mass over the columns'), the more stable the
frame.  The same 7.5 x 1.8 m columns under one pulse, alone and capped by beams of growing mass.
"""
import matplotlib.pyplot as plt

import pulses
import rocking

pulse = pulses.OneSine(ap=0.5 * pulses.G, tp=1.0)
fig, ax = plt.subplots(figsize=(8, 3.4), layout="constrained")
colours = ["k", "#0072B2", "#E69F00", "#009E73"]
for gamma, colour in zip([0.0, 0.5, 1.0, 3.0], colours):
    frame = rocking.Block.from_dimensions(7.5, 1.8, cap_mass_ratio=gamma)
    res = rocking.simulate(frame, pulse, duration=6.0)
    label = "lone column" if gamma == 0 else f"frame, beam {gamma:g} x the columns' mass"
    print(f"{label}: max |theta|/alpha = {res.max_rotation_ratio:.2f}")
    ax.plot(res.t, res.theta / frame.alpha, color=colour, lw=1.5, label=label)
ax.axhline(1, color="0.5", lw=0.8, ls=":")
ax.axhline(-1, color="0.5", lw=0.8, ls=":")
ax.set(xlabel="time (s)", ylabel="rotation theta / alpha",
       title="one-sine pulse, ap = 0.5 g, Tp = 1 s; |theta|/alpha = 1 is the verge of overturning")
ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
plt.show()
