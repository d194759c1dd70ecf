"""Accuracy of the pulse fitter on synthetic records: the error-against-noise tables of docs/validation-fitting.md.

``python benchmarks/fit_accuracy.py [N] [LOW HIGH] [plain] [seed=K]`` prints a Markdown table (N
records per shape, Tp and noise level; default 10, fixed seeds; with a noise band LOW-HIGH Hz,
only the rows pooled over Tp; ``plain``: the fitter's plain least squares, ``weighting="plain"``,
instead of its weighted ones; ``seed=K``: every seed shifted by K, other records than the
tables', to check that a change is not fitted to those).  Each record (:func:`pulses.fit.synthetic.synthetic_record`):
one pulse of random polarity, amplitude 2-8 m/s^2 and arrival; 20 s long (8 Tp for long pulses)
at 200 Hz; background motion band-passed to 0.5-10 Hz whose RMS over the record is the stated
fraction of ap.  Columns:

- ``ap&Tp <3 %`` etc.: share of cases with both ap and Tp within that relative error (the fit of
  the true shape);
- ``shape``: share of cases whose best candidate is the true shape;
- ``arrival``: share with t0 within 5 % of Tp;
- ``limit ap / Tp``: the noise limit of plain least squares, the standard deviation of an exact
  least-squares fit of the true shape (:func:`pulses.fit.synthetic.least_squares_limit`), mean over
  the cases;
- ``weighted limit``: the same for the weighted least squares with the background's spectrum
  known (:func:`pulses.fit.synthetic.weighted_least_squares_limit`);
- ``RMS/limit``: RMS of (error / limit) over ap and Tp for the sine and the Rickers, against the
  limit of the least squares used, 1.0 for a fit at that limit;
- ``search fails`` (plain least squares only): cases whose fit of the true shape does worse on
  the fitter's objective than the true pulse itself (0 means every error is the data's, not the
  search's).
"""
from __future__ import annotations

import sys

import numpy as np

SHAPES = ("sine", "ricker-sym", "ricker-anti", "rect")
TPS = (0.2, 0.5, 1.0, 2.0, 5.0)
NOISES = (0.0, 0.05, 0.15, 0.30)
DT = 0.005


def _window_sse(x, p, t, lo, hi):
    r = (x - p)[lo:hi]
    A = np.column_stack([np.ones(hi - lo), t[lo:hi]])
    coef, *_ = np.linalg.lstsq(A, r, rcond=None)
    r = r - A @ coef
    return float(r @ r)


def cases(noise, tp, n, seed, band=(0.5, 10.0), weighting="background"):
    from pulses import fit_pulse
    from pulses.fit.synthetic import (least_squares_limit, sampled_pulse, synthetic_record,
                                  weighted_least_squares_limit)

    rng = np.random.default_rng(seed)
    duration = max(20.0, 8 * tp)
    rows = []
    for shape in SHAPES:
        for _ in range(n):
            t0 = rng.uniform(2.0 * tp, duration - 3.0 * tp)
            ap = rng.choice([-1.0, 1.0]) * rng.uniform(2.0, 8.0)
            rec = synthetic_record(shape, ap, tp, t0, duration, DT, noise=noise, seed=rng, band=band)
            fit = fit_pulse(rec, weighting=weighting)
            c = fit[shape]
            t = np.arange(rec.npts) * DT
            truth = sampled_pulse(shape, ap, tp, t0, t, DT)
            fail = False
            if c.fit_window is not None and weighting == "plain":
                lo, hi = (int(round(v / DT)) for v in c.fit_window)
                fitted = sampled_pulse(shape, c.ap, c.tp, c.t0, t, DT)
                floor = 1e-9 * float(rec.acc @ rec.acc)  # convergence tolerance (1e-7 Tp), for noise-free records
                fail = _window_sse(rec.acc, fitted, t, lo, hi + 1) > _window_sse(rec.acc, truth, t, lo, hi + 1) * (1 + 1e-9) + floor
            lim = least_squares_limit(shape, ap, tp, t0, duration, DT, noise, band=band) if noise > 0 else None
            wlim = weighted_least_squares_limit(shape, ap, tp, t0, duration, DT, noise, band=band) \
                if noise > 0 else None
            rows.append(dict(shape=shape, ok_shape=fit.best.shape == shape, e_ap=abs(c.ap / ap - 1),
                             e_tp=abs(c.tp / tp - 1), e_t0=abs(c.t0 - t0) / tp, lim=lim, wlim=wlim,
                             fail=fail if weighting == "plain" else None))
    return rows


def summarise(rows):
    e_ap = np.array([r["e_ap"] for r in rows])
    e_tp = np.array([r["e_tp"] for r in rows])
    both = np.maximum(e_ap, e_tp)
    out = {"n": len(rows), "3": np.mean(both < 0.03), "5": np.mean(both < 0.05), "15": np.mean(both < 0.15),
           "shape": np.mean([r["ok_shape"] for r in rows]), "arrival": np.mean([r["e_t0"] < 0.05 for r in rows]),
           "med_ap": np.median(e_ap), "med_tp": np.median(e_tp),
           "fails": None if rows[0]["fail"] is None else sum(r["fail"] for r in rows)}
    lims = [r["lim"] for r in rows if r["lim"] is not None]
    if lims:
        out["lim_ap"] = np.mean([lim["ap"] for lim in lims])
        out["lim_tp"] = np.mean([lim["tp"] for lim in lims])
        out["wlim_ap"] = np.mean([r["wlim"]["ap"] for r in rows])
        out["wlim_tp"] = np.mean([r["wlim"]["tp"] for r in rows])
        key = "lim" if rows[0]["fail"] is not None else "wlim"
        z = [r["e_ap"] / r[key]["ap"] for r in rows if r["shape"] != "rect"] + \
            [r["e_tp"] / r[key]["tp"] for r in rows if r["shape"] != "rect"]
        out["ratio"] = float(np.sqrt(np.mean(np.square(z))))
    return out


def table(n=10, band=(0.5, 10.0), pooled_only=False, weighting="background", seed=0):
    lines = ["| noise | Tp (s) | cases | ap&Tp <3 % | <5 % | <15 % | shape | arrival | median err ap / Tp | "
             "limit ap / Tp | weighted limit | RMS/limit | search fails |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for k, noise in enumerate(NOISES):
        pooled = []
        for j, tp in enumerate(TPS):
            rows = cases(noise, tp, n, seed=1000 * k + j + seed, band=band, weighting=weighting)
            pooled += rows
            if not pooled_only:
                lines.append(_line(f"{noise:.0%}", f"{tp:g}", summarise(rows)))
        lines.append(_line(f"**{noise:.0%}**", "**all**", summarise(pooled)))
    return "\n".join(lines)


def _line(noise, tp, s):
    pct = lambda v: f"{100 * v:.1f}".rstrip("0").rstrip(".") + " %"  # 99.5 % is not 100 %
    lim = f"{100 * s['lim_ap']:.1f} / {100 * s['lim_tp']:.1f} %" if "lim_ap" in s else "0"
    wlim = f"{100 * s['wlim_ap']:.2g} / {100 * s['wlim_tp']:.2g} %" if "wlim_ap" in s else "0"
    ratio = f"{s['ratio']:.2f}" if "ratio" in s else "-"
    fails = "-" if s["fails"] is None else s["fails"]
    return (f"| {noise} | {tp} | {s['n']} | {pct(s['3'])} | {pct(s['5'])} | {pct(s['15'])} | {pct(s['shape'])} | "
            f"{pct(s['arrival'])} | {100 * s['med_ap']:.2g} / {100 * s['med_tp']:.2g} % | {lim} | {wlim} | {ratio} | "
            f"{fails} |")


if __name__ == "__main__":
    # python benchmarks/fit_accuracy.py [N] [LOW HIGH] [plain] [seed=K]: N records per cell,
    # noise band in Hz, seeds shifted by K
    args = [a for a in sys.argv[1:] if a != "plain" and not a.startswith("seed=")]
    weighting = "plain" if "plain" in sys.argv[1:] else "background"
    shift = sum(int(a[5:]) for a in sys.argv[1:] if a.startswith("seed="))
    n = int(args[0]) if args else 10
    band = (float(args[1]), float(args[2])) if len(args) > 2 else (0.5, 10.0)
    print(table(n, band, pooled_only=len(args) > 2, weighting=weighting, seed=shift))
