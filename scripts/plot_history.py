#!/usr/bin/python3
"""Plots a contact pair's force history from contactlink's per-step CSV.

usage: plot_history.py HISTORY.csv OUT.png --pair NAME [--mu MU] [--title T]

Top: the pair's normal force (Σ pN w) and tangential force (Σ |tT| w) in the
contact frame, and the global x and z components of the contact force on the
slave. Bottom: tangential / normal force, with μ for reference: it equals μ
where every active point slides.
"""
import argparse
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("csv")
    ap.add_argument("png")
    ap.add_argument("--pair", required=True)
    ap.add_argument("--mu", type=float)
    ap.add_argument("--title", default="")
    a = ap.parse_args()
    with open(a.csv, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{a.csv}: no steps")
    key = f"{a.pair}.normal"
    if key not in rows[0]:
        sys.exit(f"{a.csv}: no pair '{a.pair}' (columns: {', '.join(rows[0])})")
    col = lambda k: [float(r[k]) for r in rows]  # noqa: E731
    t = col("load_factor")
    normal, tangential = col(f"{a.pair}.normal"), col(f"{a.pair}.tangential")
    fx, fz = col(f"{a.pair}.fx"), col(f"{a.pair}.fz")
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 6))
    top.plot(t, normal, "-o", ms=3, label="normal Σ pN w")
    top.plot(t, tangential, "-s", ms=3, label="tangential Σ |tT| w")
    top.plot(t, [abs(v) for v in fx], "--", label="|Fx| (global)")
    top.plot(t, [abs(v) for v in fz], ":", label="|Fz| (global)")
    top.set_ylabel("contact force on the slave")
    top.legend(fontsize=8)
    top.grid(alpha=0.3)
    ratio = [tt / n if n > 0 else float("nan") for tt, n in zip(tangential, normal)]
    bottom.plot(t, ratio, "-o", ms=3, label="tangential / normal")
    bottom.plot(t, [abs(x) / abs(z) if z else float("nan") for x, z in zip(fx, fz)],
                "--", label="|Fx| / |Fz| (global)")
    if a.mu is not None:
        bottom.axhline(a.mu, color="k", lw=0.8, label=f"μ = {a.mu}")
    bottom.set_xlabel("load factor")
    bottom.set_ylabel("force ratio")
    bottom.legend(fontsize=8)
    bottom.grid(alpha=0.3)
    fig.suptitle(a.title or a.pair)
    fig.tight_layout()
    fig.savefig(a.png, dpi=120)
    print(f"plot: {a.png}")


if __name__ == "__main__":
    main()
