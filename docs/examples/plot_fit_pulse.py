"""
A pulse fitted on a record
==========================

Read a bundled record, fit every pulse shape to it, and draw the best fit over the record's
acceleration.  The score is the fraction of the record's acceleration the pulse explains
(1 is a perfect fit; below 0.3 a shape does not describe the record).
"""
import importlib.resources

import matplotlib.pyplot as plt

import pulses

path = importlib.resources.files("pipeline.data") / "synth_sine_055g_0.9s.sac"
rec = pulses.read_record(str(path))
fit = pulses.fit_pulse(rec)
best = fit.best
print(f"best: {best.shape}, ap = {best.ap_g:.2f} g, Tp = {best.tp:.2f} s, score {best.score:.2f}")

t = rec.time
fig, ax = plt.subplots(figsize=(8, 3.2), layout="constrained")
ax.plot(t, rec.acc / pulses.G, color="0.6", lw=0.8, label=f"record {rec.name}")
ax.plot(t, best.pulse(t) / pulses.G, color="#0072B2", lw=2,
        label=f"{best.shape} pulse: {best.ap_g:.2f} g, {best.tp:.2f} s")
ax.set_xlim(best.t0 - 3, best.t0 + best.tp + 3)
ax.set(xlabel="time (s)", ylabel="ground acceleration (g)")
ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1), frameon=False)
plt.show()
