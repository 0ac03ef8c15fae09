#!/usr/bin/python3
"""Peak memory per rank against the number of ranks (`make memory`).

usage: memory.py [--out bench-results] [--setup-ranks 1,2,4,8] [--solve-ranks 1,2,4]
                 [--setup-args ...] [--solve-args ...] [--mpirun "mpirun ..."]
                 [--table-dir docs/tables | --no-table]

Two cases, both of scripts/scenes/sphere-no-contact.toml (hertz-sphere's
mesh, materials and boundary conditions without the contact pair: a plain
elastic 3D run):
  set-up: mesh.level=1 (1,277,628 DOFs), `contactlink run --setup-only`
          (scene, mesh, partition, DOFs, matrix; no solve) on 1, 2, 4 and
          8 ranks (8 oversubscribed on small machines; run once each);
  solve:  the default mesh (167k DOFs), a full run on 1, 2 and 4 ranks.
Every run has CONTACTLINK_MEMORY=1, so besides each rank's peak (the
`memory:` summary line: largest and smallest rank) it prints the resident
memory of the largest rank after each set-up phase. Prints the largest and
the smallest rank's peak per rank count, their ratios to the 1-rank peak,
the largest peak less each rank's file-backed pages (program and library
code, shared by the ranks of a node), and the largest rank's ratio against
the targets (set-up on 8
ranks <= 0.2x, solve on 4 ranks <= 0.36x) and writes <out>/memory.csv and
the rows into docs/tables/memory-setup.md and docs/tables/memory-solve.md
(`make memory`; a case run on fewer rank counts replaces only those rows;
with other --setup-args or --solve-args give another --table-dir or
--no-table). Exits 0 whatever the ratios (a report, not a test); 1 when a
run fails.
"""
import argparse
import csv
import os
import re
import shlex
import sys

import benchrun

SCENE = "scripts/scenes/sphere-no-contact.toml"
SUMMARY = re.compile(r"memory: peak resident ([0-9.]+) MiB on the largest rank, ([0-9.]+) MiB on the smallest "
                     r"\((\d+) rank\(s\)\); set-up \([^)]*\) ([0-9.]+) s")
DOFS = re.compile(r"(\d+) DOFs")
CHECKPOINT = re.compile(r"memory: rank (\d+) of (\d+) after (.+?): resident ([0-9.]+) MiB, peak ([0-9.]+) MiB"
                        r"(?:, file-backed ([0-9.]+) MiB)?")
TARGETS = {("set-up", 8): 0.2, ("solve", 4): 0.36}


def run(mpirun, np_, args):
    cmd = benchrun.launcher(np_, mpirun) + ["target/release/contactlink", "run", SCENE] + args
    t = benchrun.run(cmd, env=benchrun.mpi_env(CONTACTLINK_MEMORY="1"), check=False)
    out = t.text
    m = SUMMARY.search(out)
    if t.returncode != 0 or not m:
        sys.exit(f"{' '.join(cmd)} failed:\n{out[-800:]}")
    # Phase -> resident memory of the largest rank after it (first occurrence
    # of each phase; load steps keep their first).
    phases = {}
    # Per rank, the last checkpoint's peak less its file-backed pages (the
    # program's and libraries' code, one copy per node for all its ranks).
    private = {}
    for c in CHECKPOINT.finditer(out):
        name, rss = c[3], float(c[4])
        phases.setdefault(name, {})
        rank = int(c[1])
        phases[name].setdefault(rank, rss)
        if c[6] is not None:
            private[rank] = float(c[5]) - float(c[6])
    d = DOFS.search(out)
    return {
        "ranks": np_, "dofs": int(d[1]) if d else 0,
        "peak_largest_mib": float(m[1]), "peak_smallest_mib": float(m[2]),
        "setup_seconds": float(m[4]),
        "private_largest_mib": max(private.values()) if private else float("nan"),
        "phases": {k: max(v.values()) for k, v in phases.items()},
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default="bench-results")
    ap.add_argument("--setup-ranks", default="1,2,4,8")
    ap.add_argument("--solve-ranks", default="1,2,4")
    ap.add_argument("--setup-args", default="--set mesh.level=1")
    ap.add_argument("--solve-args", default="")
    ap.add_argument("--mpirun", default=os.environ.get("MPIRUN", "mpirun --allow-run-as-root --oversubscribe"))
    ap.add_argument("--table-dir", default=benchrun.TABLES,
                    help="where memory-setup.md and memory-solve.md go (default docs/tables)")
    ap.add_argument("--no-table", action="store_true", help="write no table file")
    a = ap.parse_args()
    prov = benchrun.Provenance("memory")
    os.makedirs(a.out, exist_ok=True)
    cases = [("set-up", a.setup_ranks, ["--setup-only"] + shlex.split(a.setup_args)),
             ("solve", a.solve_ranks, shlex.split(a.solve_args))]
    rows = []
    for kind, ranks, args in cases:
        base = None
        for np_ in [int(n) for n in ranks.split(",") if n]:
            r = run(a.mpirun, np_, args)
            r["kind"] = kind
            base = base or r["peak_largest_mib"]
            r["ratio"] = r["peak_largest_mib"] / base
            r["ratio_smallest"] = r["peak_smallest_mib"] / base
            target = TARGETS.get((kind, np_))
            verdict = "" if target is None else (
                f"  target <= {target:.2f}x: {'met' if r['ratio'] <= target else 'NOT met'}")
            print(f"{kind:7} {np_} rank(s) {r['dofs']:>8} DOFs  peak largest {r['peak_largest_mib']:8.1f} MiB"
                  f"  smallest {r['peak_smallest_mib']:8.1f} MiB  ratio to 1 rank {r['ratio']:.3f}x"
                  f"  set-up {r['setup_seconds']:.2f} s{verdict}", flush=True)
            rows.append(r)
    print("\npeak resident memory per rank against the ranks (MiB; ratios to the 1-rank peak):")
    for kind in ("set-up", "solve"):
        mine = [r for r in rows if r["kind"] == kind]
        if not mine:
            continue
        base = mine[0]["peak_largest_mib"]
        print(f"  {kind}: {mine[0]['dofs']} DOFs, 1-rank reference {base:.1f} MiB"
              + ("" if mine[0]["ranks"] == 1 else f" (taken from {mine[0]['ranks']} ranks)"))
        pbase = mine[0]["private_largest_mib"]
        print(f"    {'ranks':>5} {'largest':>9} {'smallest':>9} {'largest/1':>10} {'smallest/1':>11}"
              f"   {'largest less file-backed':>24} {'/1':>7}")
        for r in mine:
            p = r["private_largest_mib"]
            print(f"    {r['ranks']:>5} {r['peak_largest_mib']:9.1f} {r['peak_smallest_mib']:9.1f}"
                  f" {r['peak_largest_mib'] / base:9.3f}x {r['peak_smallest_mib'] / base:10.3f}x"
                  f"   {p:24.1f} {p / pbase:6.3f}x")
    print("  (largest less file-backed: the largest over the ranks of the peak less the rank's file-backed\n"
          "   pages at its last checkpoint, the program's and libraries' code that all ranks of a node share)")
    print("\nresident memory of the largest rank after each phase (MiB):")
    for kind in ("set-up", "solve"):
        mine = [r for r in rows if r["kind"] == kind]
        if not mine:
            continue
        names = list(dict.fromkeys(n for r in mine for n in r["phases"]))
        print(f"  {kind}: " + " | ".join(f"{r['ranks']} rank(s)" for r in mine))
        for n in names:
            vals = " | ".join(f"{r['phases'].get(n, float('nan')):9.1f}" for r in mine)
            print(f"    {n:52} {vals}")
    keys = ["kind", "ranks", "dofs", "peak_largest_mib", "peak_smallest_mib", "ratio", "ratio_smallest",
            "private_largest_mib", "setup_seconds"]
    with open(f"{a.out}/memory.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    print(f"memory: {a.out}/memory.csv (machine load inflates the set-up seconds, not the memory)")
    if a.no_table:
        return
    for kind, name, args in (("set-up", "setup", a.setup_args), ("solve", "solve", a.solve_args)):
        mine = [r for r in rows if r["kind"] == kind]
        if not mine:
            continue
        what = f"`{SCENE}`" + (f" with `{args}`" if args else "")
        cells = [[str(r["ranks"]), f"{r['dofs']:,}", f"{r['peak_largest_mib']:.1f}",
                  f"{r['peak_smallest_mib']:.1f}", f"{r['ratio']:.3f}",
                  f"{r['private_largest_mib']:.1f}", f"{r['setup_seconds']:.2f}"] for r in mine]
        target = {"set-up": "≤ 0.2 on 8 ranks", "solve": "≤ 0.36 on 4 ranks"}[kind]
        benchrun.write_table(
            os.path.join(a.table_dir, f"memory-{name}.md"),
            f"Peak memory per rank, {kind}: {what}",
            ["ranks", "DOFs", "largest rank MiB", "smallest rank MiB",
             "largest / 1 rank (same run)", "largest less file-backed MiB",
             "set-up s"],
            cells, prov.text("one run per rank count"),
            intro=f"Peak resident set (VmHWM) of each rank, from the `memory:` line. Target of the "
                  f"largest rank against 1 rank: {target}. File-backed pages (program and library "
                  f"code) are one copy per node, counted in every rank's peak.")


if __name__ == "__main__":
    main()
