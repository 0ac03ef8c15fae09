#!/usr/bin/python3
"""Strong and weak scaling of the Hertz line contact.

usage: scaling.py [--repeats 3] [--out bench-results]

Strong: hertz-cylinder at mesh.level=1 (152,316 DOFs) on 1 and 2 ranks
(median of --repeats runs of the solve time printed by contactlink), and on
4 ranks with --oversubscribe for correctness only (2 cores). The scene sets
`[solver] direct_max_dofs = 200000`, so this is the sparse direct path
(MUMPS LDLT inside GMRES); the iterative path (GAMG + GMRES, `--set
solver.direct_max_dofs=20000`) does not converge on this thin plane-strain
mesh (8 cutbacks in the first step). Weak: about 16k DOFs per rank
(h = 0.2 on 1 rank, h = 0.1414 on 2). Prints a table, the parallel
efficiency, the CPU seconds of the whole run summed over the ranks (user +
system of the mpirun process tree: less sensitive to other jobs on the
machine than wall time; MPI's busy-waiting counts as CPU, so on a quiet
machine CPU1 / CPU2 is close to T1 / (2 T2)), the work per rank (cells and
contact slave facets, largest/smallest: the `partition:` line contactlink
prints with CONTACTLINK_MEMORY=1), the halo volume, the peak memory per
rank (largest and smallest), and that 2 and 4 ranks reproduce 1 rank's
Hertz figures; ends with the headline lines: the 2-rank strong-scaling
efficiency T1/(2*T2), its CPU-time counterpart, the work balance and the
2-rank peak memory of the largest rank against 1 rank's. Writes
<out>/scaling.csv. Set MPIRUN to change the launcher (a multi-node
launcher needs its own OMPI_MCA_btl, e.g. self,vader,tcp).
"""
import argparse
import csv
import os
import re
import resource
import shlex
import statistics
import subprocess

DONE = re.compile(r"done: \d+ steps, (\d+) Newton iterations, (\d+) DOFs on (\d+) rank\(s\), ([0-9.]+) s")
HERTZ = re.compile(r"\(([+-]?[0-9.]+) %\).*\(([+-]?[0-9.]+) %\)")
MEMORY = re.compile(r"memory: peak resident ([0-9.]+) MiB on the largest rank, ([0-9.]+) MiB on the smallest")
BALANCE = re.compile(r"partition: cells per rank (\d+)/(\d+) \(largest/smallest\), contact slave facets per rank (\d+)/(\d+)")
HALO = re.compile(r"halo \(all ranks\): (\d+) ghost displacement values per residual, (\d+) ghost multiplier")


def run(np_, args):
    env = dict(dict(OMPI_MCA_btl="self,vader",
               OMPI_MCA_btl_vader_single_copy_mechanism="none",
               OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1"), **os.environ)
    # For the `partition:` balance line (the memory checkpoints come along).
    env["CONTACTLINK_MEMORY"] = "1"
    mpirun = shlex.split(os.environ.get("MPIRUN", "mpirun --allow-run-as-root --oversubscribe"))
    cmd = mpirun + ["-n", str(np_), "target/release/contactlink", "run", "hertz-cylinder"] + args
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, capture_output=True, text=True, env=env)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    out = p.stdout + p.stderr
    d = DONE.search(out)
    if p.returncode != 0 or not d:
        raise SystemExit(f"{' '.join(cmd)} failed:\n{out[-600:]}")
    h = HERTZ.search(out.split("Hertz:")[-1])
    halo = HALO.search(out)
    mem = MEMORY.search(out)
    bal = BALANCE.search(out)
    return {
        "cpu_seconds": cpu,
        "cells_largest": int(bal[1]) if bal else 0, "cells_smallest": int(bal[2]) if bal else 0,
        "slave_largest": int(bal[3]) if bal else 0, "slave_smallest": int(bal[4]) if bal else 0,
        "ranks": np_, "dofs": int(d[2]), "newton": int(d[1]), "seconds": float(d[4]),
        "e_p0": float(h[1]), "e_b": float(h[2]),
        "peak_largest_mib": float(mem[1]) if mem else 0.0,
        "peak_smallest_mib": float(mem[2]) if mem else 0.0,
        "halo_u": int(halo[1]) if halo else 0, "halo_lambda": int(halo[2]) if halo else 0,
    }


def median_run(np_, args, repeats):
    runs = [run(np_, args) for _ in range(repeats)]
    row = dict(runs[0])
    row["seconds"] = statistics.median(r["seconds"] for r in runs)
    for k in ("peak_largest_mib", "peak_smallest_mib", "cpu_seconds"):
        row[k] = statistics.median(r[k] for r in runs)
    row["repeats"] = repeats
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--out", default="bench-results")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    rows = []
    strong = ["--set", "mesh.level=1"]
    for np_ in (1, 2):
        rows.append(dict(median_run(np_, strong, a.repeats), kind="strong"))
    rows.append(dict(median_run(4, strong, 1), kind="strong (4 ranks on 2 cores: correctness only)"))
    rows.append(dict(median_run(1, ["--set", "mesh.fine_size=0.2"], a.repeats), kind="weak"))
    rows.append(dict(median_run(2, ["--set", "mesh.fine_size=0.1414"], a.repeats), kind="weak"))
    t1 = rows[0]["seconds"]
    for r in rows:
        if r["kind"] == "strong":
            r["efficiency"] = t1 / (r["ranks"] * r["seconds"])
            r["cpu_efficiency"] = rows[0]["cpu_seconds"] / r["cpu_seconds"]
    w1 = rows[3]
    rows[4]["efficiency"] = w1["seconds"] / rows[4]["seconds"] * (rows[4]["dofs"] / rows[4]["ranks"]) / w1["dofs"]
    keys = ["kind", "ranks", "dofs", "repeats", "seconds", "efficiency", "cpu_seconds", "cpu_efficiency",
            "newton", "cells_largest", "cells_smallest", "slave_largest", "slave_smallest",
            "peak_largest_mib", "peak_smallest_mib",
            "e_p0", "e_b", "halo_u", "halo_lambda"]
    with open(f"{a.out}/scaling.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    for r in rows:
        eff = f"{100 * r['efficiency']:.0f} %" if "efficiency" in r else "-"
        print(f"{r['kind']:<48} {r['ranks']} ranks {r['dofs']:>7} DOFs {r['seconds']:7.2f} s "
              f"eff {eff:>6}  CPU {r['cpu_seconds']:7.2f} s  Newton {r['newton']:3d}  p0 {r['e_p0']:+.3f} % b {r['e_b']:+.3f} %  "
              f"halo {r['halo_u']} u / {r['halo_lambda']} λ  "
              f"peak memory {r['peak_largest_mib']:.0f}/{r['peak_smallest_mib']:.0f} MiB (largest/smallest rank)")
    same = all(abs(r["e_p0"] - rows[0]["e_p0"]) < 1e-3 and abs(r["e_b"] - rows[0]["e_b"]) < 1e-3
               for r in rows[:3])
    print("strong-scaling runs agree on the Hertz figures:", same)
    one, two = rows[0], rows[1]
    print(f"2-rank parallel efficiency T1/(2*T2): {100 * two['efficiency']:.0f} % "
          f"({one['dofs']} DOFs, iterative path, median of {a.repeats}: "
          f"T1 {one['seconds']:.2f} s, T2 {two['seconds']:.2f} s)")
    print(f"2-rank CPU-time efficiency CPU1/CPU2 (whole runs, summed over ranks): "
          f"{100 * two['cpu_efficiency']:.0f} % ({one['cpu_seconds']:.2f} s against {two['cpu_seconds']:.2f} s)")
    print(f"work per rank on 2 ranks (largest/smallest): cells {two['cells_largest']}/{two['cells_smallest']}, "
          f"contact slave facets {two['slave_largest']}/{two['slave_smallest']}")
    print(f"peak memory per rank: 1 rank {one['peak_largest_mib']:.0f} MiB; 2 ranks largest "
          f"{two['peak_largest_mib']:.0f} MiB, smallest {two['peak_smallest_mib']:.0f} MiB "
          f"({two['peak_largest_mib'] / one['peak_largest_mib']:.2f}x of 1 rank)")
    print(f"scaling: {a.out}/scaling.csv")


if __name__ == "__main__":
    main()
