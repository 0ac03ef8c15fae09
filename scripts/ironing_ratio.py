#!/usr/bin/env python3
"""The die's global force ratio |Fx|/|Fz| over the drag steps of ironing runs.

Usage: ironing_ratio.py HISTORY.csv [HISTORY.csv ...] [--table PATH | --no-table]

For each per-step history (the CSV next to the HDF5 output) prints, over the
steps at load factor >= 0.3 (the drag starts at 0.2; every contact point
slides from there): mean, max - min and standard deviation of |Fx|/|Fz|,
the range of the contact-frame ratio T/N, and the Newton iterations and
cutbacks of the run. Writes one row per history into
docs/tables/ironing.md (`make ironing-compare`), named by the file:
`out/ironing-links.csv` is the row "links" (the formulation).
"""
import argparse
import csv
import os
import statistics

import benchrun


def label(path):
    name = os.path.splitext(os.path.basename(path))[0]
    return name.removeprefix("ironing-")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("histories", nargs="+")
    benchrun.add_table_args(ap, "ironing")
    a = ap.parse_args()
    prov = benchrun.Provenance("ironing-compare")
    cells = []
    for path in a.histories:
        rows = list(csv.DictReader(open(path)))
        drag = [r for r in rows if float(r["load_factor"]) >= 0.3 - 1e-12]
        ratio = [abs(float(r["ironing.fx"])) / abs(float(r["ironing.fz"])) for r in drag]
        tn = [float(r["ironing.tangential"]) / float(r["ironing.normal"]) for r in drag]
        newton = sum(int(r["newton"]) for r in rows)
        cutbacks = sum(int(r.get("cutbacks", 0)) for r in rows)
        mean, spread, std = statistics.mean(ratio), max(ratio) - min(ratio), statistics.pstdev(ratio)
        print(
            f"{path}: {len(drag)} drag steps, |Fx|/|Fz| mean {mean:.4f}, "
            f"max-min {spread:.4f}, std {std:.4f}; "
            f"T/N in [{min(tn):.6f}, {max(tn):.6f}]; {newton} Newton iterations, {cutbacks} cutbacks"
        )
        cells.append([label(path), str(len(rows)), str(len(drag)), f"{mean:.4f}", f"{spread:.4f}",
                      f"{std:.4f}", f"{min(tn):.6f}–{max(tn):.6f}", str(newton), str(cutbacks)])
    if not a.no_table:
        benchrun.write_table(
            a.table, "Ironing: the die's force ratio over the drag",
            ["formulation", "steps", "drag steps", "mean \\|Fx\\|/\\|Fz\\|", "max − min", "std", "T/N",
             "Newton", "cutbacks"],
            cells, prov.text("the histories `make ironing-compare` wrote"),
            intro="`ironing` (μ = 0.3), links and mortar on the same mesh; over the steps at "
                  "load factor ≥ 0.3, where every contact point slides.")


if __name__ == "__main__":
    main()
