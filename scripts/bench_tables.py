#!/usr/bin/env python3
"""The tables of `make bench` from the CSV its cargo benchmarks wrote.

Usage: bench_tables.py [--results bench-results] [--table-dir docs/tables]

`make bench` runs benches/assembly.rs and benches/solve_costs.rs on 1 and 2
ranks and benches/search.rs serially, each printing CSV into bench-results/
(assembly-N.csv, solve-costs-N.csv, search.csv). This script turns whichever
of them exist into docs/tables/bench-assembly.md, bench-solve-costs.md,
bench-reuse.md and bench-search.md, the rows marked with this run (the CSV
files' modification date). Medians are the benchmarks' own (assembly: of 5
residuals and 3 tangents; solve costs: of 3 runs, the slowest rank; search:
of 3 passes).
"""
import argparse
import csv
import io
import os
import time

import benchrun


def sections(path):
    """The CSV sections of a file: a line with commas and no digit starts one
    (its header), the lines with digits after it are its rows."""
    out, cur = [], None
    with open(path) as f:
        for line in f:
            line = line.strip()
            if "," not in line:
                continue
            if not any(ch.isdigit() for ch in line):
                cur = [line]
                out.append(cur)
            elif cur is not None:
                cur.append(line)
    return [list(csv.DictReader(io.StringIO("\n".join(s)))) for s in out]


def date_of(paths):
    return time.strftime("%Y-%m-%d", time.localtime(max(os.path.getmtime(p) for p in paths)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--results", default="bench-results")
    ap.add_argument("--table-dir", default=benchrun.TABLES)
    a = ap.parse_args()
    f = lambda name: os.path.join(a.results, name)  # noqa: E731

    def provenance(paths):
        return (f"{date_of(paths)} (when {', '.join(paths)} were written), {benchrun.machine()}, "
                f"commit `{benchrun.commit()}`: `make bench`, tables by `{benchrun.command()}`")

    assembly = [p for p in (f("assembly-1.csv"), f("assembly-2.csv")) if os.path.exists(p)]
    if assembly:
        cells = []
        for p in assembly:
            for s in sections(p):
                for r in s:
                    cells.append([f"{int(r['dofs']):,}", r["ranks"], f"{1e3 * float(r['residual_s']):.1f} ms",
                                  f"{1e3 * float(r['tangent_s']):.0f} ms",
                                  f"{float(r['tangent_cells_per_s']) / 1e3:.1f}k",
                                  f"{float(r['solve_s']):.2f} s", f"{r['newton']} / {r['linear_its']}"])
        benchrun.write_table(
            os.path.join(a.table_dir, "bench-assembly.md"), "Bulk assembly and solve against size",
            ["DOFs", "ranks", "residual", "tangent", "tangent cells/s", "solve", "Newton / linear"],
            cells, provenance(assembly), key=2,
            intro="benches/assembly.rs: a Neo-Hookean box under pressure; medians of 5 residual and "
                  "3 tangent assemblies, slowest rank; one Newton solve (direct up to "
                  "`direct_max_dofs`, CG + GAMG above).")
    costs = [p for p in (f("solve-costs-1.csv"), f("solve-costs-2.csv")) if os.path.exists(p)]
    if costs:
        reuse, ratio = [], []
        for p in costs:
            for s in sections(p):
                for r in s:
                    if "reuse" in r:
                        reuse.append([r["reuse"], r["ranks"], f"{float(r['with_s']):.3f} s",
                                      f"{float(r['without_s']):.3f} s", f"{float(r['without/with']):.2f}"])
                    else:
                        ratio.append([r["mesh"], r["ranks"], f"{int(r['dofs']):,}",
                                      f"{float(r['contact_s']):.3f} s ({r['contact_newton']})",
                                      f"{float(r['plain_s']):.3f} s ({r['plain_newton']})",
                                      f"{float(r['ratio']):.2f}"])
        if ratio:
            benchrun.write_table(
                os.path.join(a.table_dir, "bench-solve-costs.md"),
                "Contact solve against a plain elastic solve, timed in one process",
                ["mesh", "ranks", "DOFs", "contact solve (Newton)", "plain solve (Newton)", "ratio"],
                ratio, provenance(costs), key=2,
                intro="benches/solve_costs.rs: the scene and the same mesh without its contact pair, "
                      "timed in one process, median of 3 (the spheres: one run), slowest rank.")
        if reuse:
            benchrun.write_table(
                os.path.join(a.table_dir, "bench-reuse.md"), "What each reuse saves",
                ["reuse", "ranks", "with", "without", "without / with"],
                reuse, provenance(costs), key=2,
                intro="benches/solve_costs.rs: the default hertz-cylinder with each reuse switched "
                      "off in turn, one process, median of 3.")
    if os.path.exists(f("search.csv")):
        cells = []
        for s in sections(f("search.csv")):
            for r in s:
                cells.append([r["master"], f"{float(r['gap_over_h']):g} h", f"{int(r['slave_points']):,}",
                              r["order"], f"{float(r['points_per_s']):.2e}", f"{float(r['build_s']):.3f} s"])
        benchrun.write_table(
            os.path.join(a.table_dir, "bench-search.md"), "Contact search against slave points",
            ["master", "gap", "points", "order", "points/s", "index build"],
            cells, provenance([f("search.csv")]), key=4,
            intro="benches/search.rs, serial: a master of 300 × 300 quads (90,000 facets), slave "
                  "points in or near contact (0.3 h) and far out in the 10 h search distance (3 h); "
                  "median of 3 passes.")


if __name__ == "__main__":
    main()
