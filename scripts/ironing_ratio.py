#!/usr/bin/env python3
"""The die's global force ratio |Fx|/|Fz| over the drag steps of ironing runs.

Usage: ironing_ratio.py HISTORY.csv [HISTORY.csv ...]

For each per-step history (the CSV next to the HDF5 output) prints, over the
steps at load factor >= 0.3 (the drag starts at 0.2; every contact point
slides from there): mean, max - min and standard deviation of |Fx|/|Fz|,
the range of the contact-frame ratio T/N, and the Newton iterations of the
run.
"""
import csv
import statistics
import sys


def main(paths):
    for path in paths:
        rows = list(csv.DictReader(open(path)))
        drag = [r for r in rows if float(r["load_factor"]) >= 0.3 - 1e-12]
        ratio = [abs(float(r["ironing.fx"])) / abs(float(r["ironing.fz"])) for r in drag]
        tn = [float(r["ironing.tangential"]) / float(r["ironing.normal"]) for r in drag]
        newton = sum(int(r["newton"]) for r in rows)
        print(
            f"{path}: {len(drag)} drag steps, |Fx|/|Fz| mean {statistics.mean(ratio):.4f}, "
            f"max-min {max(ratio) - min(ratio):.4f}, std {statistics.pstdev(ratio):.4f}; "
            f"T/N in [{min(tn):.6f}, {max(tn):.6f}]; {newton} Newton iterations"
        )


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
