#!/usr/bin/python3
"""Work-precision sweep for the Hertz scenes: run time against error.

usage: work_precision.py --scene hertz-cylinder [--np 2] [--repeats 3]
                         [--sizes 0.4,0.2,0.1] [--penalties 0.1,1,10]
                         [--tols 1e-2,1e-3,1e-4] [--out bench-results]
                         [--bin target/release/contactlink] [--table PATH | --no-table]

Every configuration (contact-zone element size h, penalty as a multiple of
the default 10·E/h, Uzawa tolerance for both penetration and multiplier
change) runs `--repeats` times under mpirun; the row keeps the median wall
time (the whole process, what a user waits), the DOFs, Newton and Uzawa
iteration counts and the relative errors of p0 and of b (or a) against
Hertz (the counts and errors from the run's history CSV and the `/run` and
`/hertz` attributes of its result file). Writes <out>/wp-<scene>.csv, a
log-log PNG of max(|e_p0|, |e_b|) against wall time with the Pareto front
(no other run is both faster and more accurate) marked, and every row into
docs/tables/work-precision-<scene>.md (`make work-precision`).
"""
import argparse
import csv
import os
import sys

import benchrun

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

YOUNGS = 1000.0  # both Hertz scenes use E = 1000 on both bodies


def run_once(binary, scene, np_, args, h5):
    cmd = benchrun.launcher(np_, "mpirun --allow-run-as-root --oversubscribe") + \
        [binary, "run", scene, "-q", "-o", h5] + args
    t = benchrun.run(cmd, env=benchrun.mpi_env(), check=False)
    if t.returncode != 0:
        return None, t.text
    rec = benchrun.run_attrs(h5)
    if "hertz.p0_error" not in rec:
        return None, t.text + "\n(no Hertz comparison in the result file)"
    counts = benchrun.totals(h5)
    return {
        "wall": t.wall, "steps": counts["steps"], "newton": counts["newton"],
        "dofs": rec["dofs"], "uzawa": counts["uzawa"],
        "e_p0": rec["hertz.p0_error"], "e_b": rec["hertz.width_error"],
    }, t.text


def pareto(rows):
    front = []
    for r in sorted(rows, key=lambda r: (r["wall"], r["error"])):
        if not front or r["error"] < front[-1]["error"]:
            front.append(r)
    return front


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="hertz-cylinder")
    ap.add_argument("--np", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--sizes", default="0.4,0.2,0.1")
    ap.add_argument("--penalties", default="0.1,1,10")
    ap.add_argument("--tols", default="1e-2,1e-3,1e-4")
    ap.add_argument("--out", default="bench-results")
    ap.add_argument("--bin", default="target/release/contactlink",
                    help="the contactlink binary (a copy lets a sweep run while you rebuild)")
    ap.add_argument("--table", default=None,
                    help="markdown table to update (default docs/tables/work-precision-SCENE.md)")
    ap.add_argument("--no-table", action="store_true", help="write no table file")
    a = ap.parse_args()
    prov = benchrun.Provenance("work-precision")
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for h in [float(v) for v in a.sizes.split(",")]:
        for k in [float(v) for v in a.penalties.split(",")]:
            for tol in [float(v) for v in a.tols.split(",")]:
                args = ["--set", f"mesh.fine_size={h}",
                        "--set", f"contact.penalty={k * 10 * YOUNGS / h}",
                        "--set", f"contact.penetration_tol={tol}",
                        "--set", f"contact.multiplier_tol={tol}",
                        "--set", "contact.max_uzawa=60",
                        "--set", "solver.direct_max_dofs=200000"]
                done = benchrun.repeat(
                    lambda: run_once(a.bin, a.scene, a.np, args, f"{a.out}/wp-{a.scene}-run.h5"),
                    a.repeats)
                failed = [out for r, out in done if r is None]
                if failed:
                    print(f"h={h} penalty×{k} tol={tol}: failed\n{failed[0][-400:]}",
                          file=sys.stderr)
                    continue
                runs = [r for r, _ in done]
                row = benchrun.medians(runs, ["wall"])
                row.update(h=h, penalty_factor=k, tol=tol, repeats=len(runs))
                row["error"] = max(abs(row["e_p0"]), abs(row["e_b"]))
                rows.append(row)
                print(f"h={h:<5} penalty×{k:<4} tol={tol:<6} DOFs {row['dofs']:>7} "
                      f"wall {row['wall']:6.2f} s  Newton {row['newton']:3d} "
                      f"Uzawa {row['uzawa']:3d}  e_p0 {100 * row['e_p0']:+.3f} % "
                      f"e_b {100 * row['e_b']:+.3f} %", flush=True)
    if not rows:
        sys.exit("no run succeeded")
    front = pareto(rows)
    for r in rows:
        r["pareto"] = int(r in front)
    keys = ["h", "penalty_factor", "tol", "dofs", "wall", "repeats", "steps",
            "newton", "uzawa", "e_p0", "e_b", "error", "pareto"]
    path = f"{a.out}/wp-{a.scene}.csv"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    fig, ax = plt.subplots(figsize=(7, 5))
    for h in sorted({r["h"] for r in rows}, reverse=True):
        sel = [r for r in rows if r["h"] == h]
        ax.scatter([r["wall"] for r in sel], [r["error"] for r in sel], label=f"h = {h}")
    ax.plot([r["wall"] for r in front], [r["error"] for r in front], "k--",
            label="Pareto front")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel(f"wall time on {a.np} ranks [s] (median of {a.repeats})")
    ax.set_ylabel("max(|error p0|, |error b|)")
    ax.set_title(f"{a.scene}: work against precision")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(f"{a.out}/wp-{a.scene}.png", dpi=120)
    print(f"work-precision: {path}, {a.out}/wp-{a.scene}.png")
    print("Pareto front:")
    for r in front:
        print(f"  h={r['h']} penalty×{r['penalty_factor']} tol={r['tol']}: "
              f"{r['wall']:.2f} s, error {100 * r['error']:.3f} %")
    if not a.no_table:
        width = "e_b" if a.scene == "hertz-cylinder" else "e_a (or e_b)"
        cells = [[f"{r['h']:g}", f"×{r['penalty_factor']:g}", f"{r['tol']:g}", f"{r['dofs']:,}",
                  f"{r['wall']:.2f} s", f"{r['newton']} / {r['uzawa']}",
                  f"{100 * r['e_p0']:+.3f} %", f"{100 * r['e_b']:+.3f} %",
                  "yes" if r["pareto"] else ""] for r in rows]
        benchrun.write_table(
            a.table or benchrun.table_path(f"work-precision-{a.scene}"),
            f"Work against precision: {a.scene}",
            ["h", "penalty", "Uzawa tol", "DOFs", "wall", "Newton / Uzawa", "e_p0", width, "front"],
            cells, prov.text(f"{a.np} rank(s), medians of {a.repeats} (whole process)"), key=3,
            intro="Penalty: a multiple of the default 10·E/h; Uzawa tol: penetration and "
                  "multiplier change alike. Front: on the Pareto front of max(|e_p0|, |e_b|) "
                  "against wall time (no run both faster and more accurate), over the rows of "
                  "the run that measured them.")


if __name__ == "__main__":
    main()
