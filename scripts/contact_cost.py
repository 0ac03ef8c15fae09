#!/usr/bin/env python3
"""Contact solve against the plain elastic solve of the same mesh.

Usage: contact_cost.py EXE [REPEATS [CASE ...]] [--cases CASE,CASE] [--lines DIR]
                       [--table PATH | --no-table]

For each case below, runs the plain scene (the same mesh, materials and
Dirichlet conditions without the contact pair) and the contact scene in
turn, REPEATS times (default 3), and prints one markdown row per case: DOFs,
ranks, path, the medians of the solve seconds of the `done:` lines, their
ratio, the per-round ratios, and the contact run's Newton / Uzawa / linear
iterations. CASE names (prefixes of the names below) select cases ("line b"
the links' line cases, "line mortar" the same meshes with a mortar pair, the
default formulation; cases without "mortar" in their name ask for the links). The line
cases read the graded meshes that `python3 scripts/bench_peers.py --cases
line --dry-run --out DIR` writes (DIR defaults to /tmp/lines). Several ranks
run under mpirun (as root with --allow-run-as-root).

Writes its rows into docs/tables/contact-cost.md (`make contact-cost`).
"""
import argparse
import re

import benchrun

SPHERE = ["--set", "mesh.fine_size=0.35"]
SPHERE_DIRECT = SPHERE + ["--set", "solver.direct_max_dofs=200000"]
LINKS = ["--set", "contact.formulation=links"]
PLAIN_SPHERE = "scripts/scenes/sphere-no-contact.toml"


def cases(lines):
    out = []
    for ranks in (1, 2):
        for b in (5, 10, 20, 40):
            out.append((f"line b/{b}", ranks, "direct",
                        [f"{lines}/line-b{b}-plain.toml"], [f"{lines}/line-b{b}.toml", *LINKS]))
    # The same meshes with a mortar pair (the default formulation).
    for ranks in (1, 2):
        for b in (5, 10, 20, 40):
            out.append((f"line mortar b/{b}", ranks, "direct",
                        [f"{lines}/line-b{b}-plain.toml"],
                        [f"{lines}/line-b{b}.toml", "--set", "contact.formulation=mortar"]))
    for ranks in (1, 2):
        out.append(("sphere h=0.35", ranks, "Krylov",
                    [PLAIN_SPHERE, *SPHERE], ["hertz-sphere", *SPHERE, *LINKS]))
    for ranks in (1, 2):
        out.append(("sphere h=0.35 mortar", ranks, "Krylov",
                    [PLAIN_SPHERE, *SPHERE],
                    ["hertz-sphere", *SPHERE, "--set", "contact.formulation=mortar"]))
    out.append(("sphere h=0.35", 2, "direct",
                [PLAIN_SPHERE, *SPHERE_DIRECT], ["hertz-sphere", *SPHERE_DIRECT, *LINKS]))
    # The built-in sphere's own mesh (h = 0.25, 167,013 DOFs), links and mortar.
    for ranks in (1, 2):
        out.append(("sphere default", ranks, "Krylov", [PLAIN_SPHERE], ["hertz-sphere", *LINKS]))
        out.append(("sphere default mortar", ranks, "Krylov", [PLAIN_SPHERE],
                    ["hertz-sphere", "--set", "contact.formulation=mortar"]))
    return out


def run(exe, ranks, args):
    t = benchrun.run(benchrun.launcher(ranks, mpirun=None if ranks == 1 else
                                       "mpirun --allow-run-as-root --oversubscribe")
                     + [exe, "run", *args, "-v"], env=benchrun.mpi_env())
    text = t.text
    done = benchrun.DONE.search(text)
    solver = re.search(r"solver: (\d+) Uzawa iterations, (\d+) linear iterations", text)
    return {
        "steps": int(done.group(1)),
        "newton": int(done.group(2)),
        "dofs": int(done.group(3)),
        "seconds": float(done.group(5)),
        "uzawa": int(solver.group(1)) if solver else 0,
        "linear": int(solver.group(2)) if solver else 0,
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("exe")
    ap.add_argument("repeats", nargs="?", type=int, default=3)
    ap.add_argument("cases", nargs="*", help="case name prefixes")
    ap.add_argument("--cases", dest="case_list", default="",
                    help="case name prefixes, comma-separated (as `make contact-cost CASES=...`)")
    ap.add_argument("--lines", default="/tmp/lines",
                    help="where `bench_peers.py --cases line --dry-run` wrote the line meshes")
    benchrun.add_table_args(ap, "contact-cost")
    a = ap.parse_args()
    prov = benchrun.Provenance("contact-cost")
    wanted = a.cases + [c.strip() for c in a.case_list.split(",") if c.strip()]
    chosen = [c for c in cases(a.lines) if not wanted or any(c[0].startswith(w) for w in wanted)]
    print(f"load average before: {benchrun.load():.2f}")
    columns = ["case", "DOFs", "ranks", "path", "plain s", "contact s", "contact / plain",
               "per round", "steps, Newton / Uzawa / linear"]
    print("| " + " | ".join(columns) + " |")
    print("| " + " | ".join("---" for _ in columns) + " |")
    rows = []
    for name, ranks, path, plain_args, contact_args in chosen:
        runs = benchrun.alternate({"plain": lambda: run(a.exe, ranks, plain_args),
                                   "contact": lambda: run(a.exe, ranks, contact_args)}, a.repeats)
        plain, contact = runs["plain"], runs["contact"]
        p = benchrun.median(r["seconds"] for r in plain)
        c = benchrun.median(r["seconds"] for r in contact)
        rounds = " ".join(f"{b['seconds'] / x['seconds']:.2f}" for x, b in zip(plain, contact))
        last = contact[-1]
        row = [name, f"{last['dofs']:,}", str(ranks), path, f"{p:.2f}", f"{c:.2f}", f"{c / p:.2f}",
               rounds, f"{last['steps']}, {last['newton']} / {last['uzawa']} / {last['linear']}"]
        rows.append(row)
        print("| " + " | ".join(row) + " |", flush=True)
    print(f"load average after: {benchrun.load():.2f}")
    if not a.no_table:
        benchrun.write_table(
            a.table, "Contact solve against the plain elastic solve", columns, rows,
            prov.text(f"plain and contact in turn, medians of {a.repeats}"), key=4,
            intro="Seconds: the `done:` line's solve seconds (start-up excluded); per round: "
                  "each plain / contact pair's ratio. Plain: the same mesh, materials and "
                  "Dirichlet conditions without the contact pair.")


if __name__ == "__main__":
    main()
