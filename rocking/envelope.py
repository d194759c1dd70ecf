"""Derivation of the envelope rule and of the README's exact / Eq. 31 table and plots.

    python -m rocking.envelope [--out docs] [--quick]

1. Computes the exact minimum slenderness (:func:`rocking.slenderness_chart`) for the four
   pulse shapes over ``0.1 <= pTp <= 20`` (log-spaced) and ``0.1 <= ap/g <= 1.5``.
2. Fits, for every realisable shape together (one-sine and both Rickers; ``shape=None``) and for
   each shape alone, the smallest conservative coefficient of two closed-form families:

   * generalised Eq. 31, ``phi = x^n / (c + x^n)`` with ``x = pTp`` (Eq. 31 is ``n = c = 1``):
     for each ``n`` of :data:`HILL_N` the largest ``c`` with ``phi >= exact/(ap/g)`` everywhere;
   * Eq. 20, ``phi = 1 - exp(-lambda x)``: the smallest such ``lambda``;

   and keeps the candidate with the smallest median over-design ``rule / exact`` (every candidate
   is conservative on the whole grid by construction; a 1 % safety margin is added to the
   coefficient, see :data:`SAFETY`).
3. Writes ``design_exact_vs_eq31.csv`` (the full table), ``design_ratio.png`` (exact / Eq. 31
   against pTp, per shape) and ``design_chart.png`` (Fig. 8), and prints the Markdown tables
   for the README.
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys
import time

import numpy as np

from pulses.shapes import AntisymmetricRicker, OneSine, SymmetricRicker

#: exponents tried for the generalised Eq. 31
HILL_N = (1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0)
#: relative margin added to the fitted coefficient (c divided by, lambda multiplied by 1 + SAFETY)
SAFETY = 0.01
REALISABLE = (OneSine.shape, SymmetricRicker.shape, AntisymmetricRicker.shape)
#: table grid
PTP_TABLE = (0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 15.0, 20.0)
APG_TABLE = tuple(np.round(np.linspace(0.1, 1.5, 15), 6))


def phi_hill(x, n, c):
    x = np.asarray(x, dtype=float)
    return x**n / (c + x**n)


def phi_exp(x, lam):
    return -np.expm1(-lam * np.asarray(x, dtype=float))


def fit(frame, shapes):
    """Smallest conservative coefficients of each family for ``shapes``; returns candidates."""
    sub = frame[frame["shape"].isin(shapes)]
    x = sub["pTp"].to_numpy()
    phi = (sub["exact"] / sub["ap_over_g"]).to_numpy()
    ok = phi > 0
    cands = []
    for n in HILL_N:
        # x^n/(c + x^n) >= phi  <=>  c <= x^n (1 - phi)/phi
        c = float(np.min(x[ok] ** n * (1.0 - phi[ok]) / phi[ok])) / (1.0 + SAFETY)
        cands.append({"form": "hill", "n": n, "c": c})
    # 1 - exp(-lam x) >= phi  <=>  lam >= -ln(1 - phi)/x
    lam = float(np.max(-np.log1p(-np.minimum(phi[ok], 1 - 1e-15)) / x[ok])) * (1.0 + SAFETY)
    cands.append({"form": "exp", "lam": lam})
    for cand in cands:
        rule = evaluate(cand, x)
        over = rule[ok] / phi[ok]
        cand["min_margin"] = float(over.min())
        cand["median_margin"] = float(np.median(over))
        cand["max_margin"] = float(over.max())
        band = x[ok] >= 1.0
        cand["max_margin_pTp_ge_1"] = float(over[band].max()) if band.any() else float("nan")
    best = min(cands, key=lambda c: c["median_margin"])
    return best, cands


def evaluate(cand, x):
    if cand["form"] == "hill":
        return phi_hill(x, cand["n"], cand["c"])
    return phi_exp(x, cand["lam"])


def main(argv=None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    import rocking

    ap = argparse.ArgumentParser(prog="python -m rocking.envelope", description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="docs", help="folder for the CSV and PNG files")
    ap.add_argument("--quick", action="store_true", help="coarse grid (a smoke run)")
    ap.add_argument("--n-ptp", type=int, default=40, help="log-spaced pTp values for the fit")
    ap.add_argument("--from-csv", help="reuse a table written by an earlier run (no solving)")
    args = ap.parse_args(argv)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    n = 8 if args.quick else args.n_ptp
    ptp = np.unique(np.round(np.concatenate([np.geomspace(0.1, 20.0, n), PTP_TABLE]), 6))
    apg = np.array(APG_TABLE[::4] if args.quick else APG_TABLE)
    t0 = time.perf_counter()
    if args.from_csv:
        import pandas as pd

        frame = pd.read_csv(args.from_csv)
    else:
        frame = rocking.slenderness_chart(("rect",) + REALISABLE, ptp, apg)
        frame.to_csv(out / "design_exact_vs_eq31.csv", index=False, float_format="%.9g")
    elapsed = time.perf_counter() - t0
    print(f"# {len(frame)} exact minimum slenderness values in {elapsed:.1f} s", file=sys.stderr)

    fits = {}
    for key, shapes in [(None, REALISABLE)] + [(s, (s,)) for s in ("rect",) + REALISABLE]:
        best, cands = fit(frame, shapes)
        fits["all realisable" if key is None else key] = {"best": best, "candidates": cands}
    print(json.dumps({k: v["best"] for k, v in fits.items()}, indent=1))

    # README table 1: exact / Eq. 31, worst over ap/g, at the table's pTp values
    print("\n| pTp | " + " | ".join(("rect",) + REALISABLE) + " |")
    print("|---:|" + "---:|" * 4)
    for x in PTP_TABLE:
        cells = []
        for s in ("rect",) + REALISABLE:
            sub = frame[(frame["shape"] == s) & np.isclose(frame["pTp"], x)]
            cells.append(f"{sub['ratio'].min():.3f} - {sub['ratio'].max():.3f}")
        print(f"| {x:g} | " + " | ".join(cells) + " |")

    # plot: ratio against pTp, band over ap/g, per shape
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    colors = {"rect": "k", OneSine.shape: "tab:red", SymmetricRicker.shape: "tab:blue",
              AntisymmetricRicker.shape: "tab:green"}
    for s in ("rect",) + REALISABLE:
        sub = frame[frame["shape"] == s]
        g = sub.groupby("pTp")["ratio"]
        lo, hi = g.min(), g.max()
        axes[0].fill_between(lo.index, lo.values, hi.values, color=colors[s], alpha=0.25)
        axes[0].plot(hi.index, hi.values, color=colors[s], lw=1.4, label=s)
    axes[0].axhline(1.0, color="gray", lw=0.8, ls="--")
    axes[0].set_xscale("log")
    axes[0].set_xlabel("p Tp")
    axes[0].set_ylabel("exact / Eq. 31 (band over ap/g = 0.1-1.5)")
    axes[0].set_title("> 1: Eq. 31 unconservative", fontsize=9)
    axes[0].legend(fontsize=8)
    axes[0].grid(alpha=0.3, which="both")
    xs = np.geomspace(0.1, 20, 300)
    from rocking.design import ENVELOPE

    _, n_env, c_env = ENVELOPE[None]
    best = {"form": "hill", "n": n_env, "c": c_env}        # the rule as shipped (rounded down)
    for s in ("rect",) + REALISABLE:
        sub = frame[frame["shape"] == s]
        phi = sub.groupby("pTp").apply(lambda d: (d["exact"] / d["ap_over_g"]).max())
        axes[1].plot(phi.index, phi.values, "o", ms=3, color=colors[s], label=f"exact, {s}")
    axes[1].plot(xs, xs / (1 + xs), "k--", lw=1, label="Eq. 31")
    label = f"envelope: x^{n_env:g}/({c_env:g}+x^{n_env:g})"
    axes[1].plot(xs, evaluate(best, xs), "m-", lw=1.6, label=label)
    axes[1].set_xscale("log")
    axes[1].set_xlabel("p Tp")
    axes[1].set_ylabel("max over ap/g of  tan(alpha_min) / (ap/g)")
    axes[1].legend(fontsize=7)
    axes[1].grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out / "design_ratio.png", dpi=90)
    plt.close(fig)

    from rocking.spectrum import CHART_PTP

    chart = frame[frame["pTp"].isin(CHART_PTP)]
    rocking.plot_chart(chart, out / "design_chart.png", dpi=65)
    # Fig. 5: overturning spectra, alpha = 14 deg, for the three realisable pulses
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for ax, s in zip(axes, REALISABLE):
        spec = rocking.overturning_spectrum(math.radians(14.0), s, np.linspace(0.5, 12, 160),
                                            np.linspace(1.0, 6.0, 160))
        spec.plot(ax=ax)
    fig.tight_layout()
    fig.savefig(out / "spectrum_fig5.png", dpi=65)
    plt.close(fig)
    with open(out / "envelope_fit.json", "w") as fh:
        json.dump(fits, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
