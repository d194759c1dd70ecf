"""
A restitution from a free-rocking test
======================================

A block released from a tilt rocks freely and loses the share ``1 - r = 1 - eta^2`` of its
energy at each impact; the energies at its successive peaks fall as ``r^n``.  Here the test is
simulated: a 1 m x 0.25 m specimen with a known restitution (``eta = 0.85``, below Eq. 5's 0.91,
as on a soft interface), its rotation sampled at 200 Hz with a noise of 0.5 % of its slenderness.
``rocking.fit_restitution`` fits the decay and gives the restitution with its uncertainty, and
the band a design takes.
"""
import matplotlib.pyplot as plt
import numpy as np

import pulses
import rocking

eta_true, dt = 0.85, 0.005
specimen = rocking.Block.from_dimensions(1.0, 0.25, eta=eta_true)
still = pulses.Record(np.zeros(int(12.0 / dt)), dt)          # no ground motion: free rocking
test = rocking.simulate(specimen, still, theta0=0.8 * specimen.alpha)
rng = np.random.default_rng(1)
theta = test.theta + rng.normal(0.0, 0.005 * specimen.alpha, test.theta.size)

fit = rocking.fit_restitution(test.t, theta, alpha=specimen.alpha)
print(f"eta = {fit.eta:.4f} +- {fit.eta_std:.4f} (true {eta_true}); r = {fit.r:.4f}; "
      f"{fit.n} impacts; {fit.factor(specimen.alpha):.3f} x Eq. 5")
print(f"as a design input: {fit.as_restitution()}")

fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(10, 3.4), layout="constrained",
                               gridspec_kw={"width_ratios": [2, 1]})
ax1.plot(test.t, theta / specimen.alpha, color="0.4", lw=0.7, label="measured rotation (noisy)")
ax1.plot(fit.times, np.interp(fit.times, test.t, np.abs(theta)) / specimen.alpha, "o",
         color="#0072B2", ms=4, label="peaks fitted")
ax1.set(xlabel="time (s)", ylabel="theta / alpha", title="free rocking after release")
ax1.legend(loc="upper right", frameon=False)
n = np.arange(fit.values.size) + 1
ax2.plot(n, fit.values, "o", color="#0072B2", label="each impact's own eta")
ax2.axhline(fit.eta, color="k", lw=1.2, label=f"fit {fit.eta:.4f} +- {fit.eta_std:.4f}")
ax2.axhline(eta_true, color="#D55E00", lw=1, ls="--", label=f"true {eta_true}")
ax2.set(xlabel="impact", ylabel="eta", title="restitution")
ax2.legend(loc="lower left", frameon=False, fontsize=8)
plt.show()
