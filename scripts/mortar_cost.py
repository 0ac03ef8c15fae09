#!/usr/bin/env python3
"""Cost of the mortar formulation against the links on the same scenes.

Usage: mortar_cost.py EXE [REPEATS [SCENE ...]] [--table PATH | --no-table]

Runs every scene below with `formulation = "links"` and `"mortar"`,
alternated (links, mortar, links, mortar, ...) so both see the same load,
and prints per scene and formulation the DOFs, Newton and Uzawa iterations,
factorisations (of the preconditioner, or of the contact Schur complement
on that path), and the median over REPEATS (default 3) of the solve
seconds the run records and of the process's CPU time (user + system),
with the load average before and after. Ratios are mortar / links. The
counts and seconds come from each run's machine output (its history CSV
and its result file's `/run`). SCENE names (prefixes of the names below)
select scenes; a SCENE that is a .toml file is run as given (e.g. the
graded line meshes that `python3 scripts/bench_peers.py --cases line
--dry-run --out DIR` writes: DIR/line-b40.toml).

Writes its rows into docs/tables/mortar-cost.md (`make mortar-cost`).
"""
import argparse
import os

import benchrun

SCENES = [
    ("hertz-cylinder h=0.2", ["hertz-cylinder", "--set", "mesh.fine_size=0.2"]),
    ("hertz-cylinder h=0.1", ["hertz-cylinder"]),
    ("hertz-sphere h=0.7", ["hertz-sphere", "--set", "mesh.fine_size=0.7"]),
    ("patch-test", ["patch-test"]),
    ("block-slide-stacked", ["scripts/scenes/block-slide-stacked.toml"]),
    ("ironing", ["ironing"]),
    ("sphere-block (tet4, Gmsh)", ["scenes/sphere-block.toml"]),
    ("impact (dynamics)", ["impact"]),
]


def run(exe, args, formulation):
    out = f"out/mortar-cost-{formulation}.h5"
    t = benchrun.run([exe, "run", *args, "-q", "-o", out,
                      "--set", f"contact.formulation={formulation}"])
    counts = benchrun.totals(out)
    rec = benchrun.run_attrs(out)
    rows = benchrun.history(out)
    phase = lambda k: sum(float(r[k]) for r in rows)  # noqa: E731
    # Factorisations: of the contact Schur complement on that path, else
    # of the preconditioner (0 where SNES's own lag decides: nonlinear bodies).
    schur = rec.get("schur_path", "none") != "none"
    return {
        "dofs": rec["dofs"],
        "newton": counts["newton"],
        "uzawa": counts["uzawa"],
        "ksp": counts["linear"],
        "builds": rec["schur_factorisations"] if schur else rec["preconditioner_builds"],
        "wall": rec["wall_seconds"],
        "cpu": t.cpu,
        "contact": phase("t_contact"),
        "linear": phase("t_linear"),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("exe")
    ap.add_argument("repeats", nargs="?", type=int, default=3)
    ap.add_argument("scenes", nargs="*", help="scene name prefixes or .toml files")
    benchrun.add_table_args(ap, "mortar-cost")
    a = ap.parse_args()
    prov = benchrun.Provenance("mortar-cost")
    os.makedirs("out", exist_ok=True)
    print(f"load average before: {os.getloadavg()}")
    files = [o for o in a.scenes if o.endswith(".toml")]
    names = [o for o in a.scenes if not o.endswith(".toml")]
    scenes = [(n, s) for n, s in SCENES if not a.scenes or any(n.startswith(o) for o in names)]
    scenes += [(os.path.basename(f)[: -len(".toml")], [f]) for f in files]
    table = []
    keys = ["dofs", "newton", "uzawa", "ksp", "builds", "wall", "cpu", "contact", "linear"]
    for name, args in scenes:
        runs = benchrun.alternate({f: (lambda f=f: run(a.exe, args, f)) for f in ("links", "mortar")},
                                  a.repeats)
        med = {f: benchrun.medians(rs, keys) for f, rs in runs.items()}
        lk, mo = med["links"], med["mortar"]
        for f in ("links", "mortar"):
            r = med[f]
            print(f"{name:22s} {f:6s} DOFs {r['dofs']:.0f} newton {r['newton']:.0f} uzawa {r['uzawa']:.0f} "
                  f"ksp {r['ksp']:.0f} factorisations {r['builds']:.0f} wall {r['wall']:.2f} s "
                  f"cpu {r['cpu']:.2f} s (linear solve {r['linear']:.2f} s, contact assembly {r['contact']:.2f} s)")
        cpu = benchrun.spread(m["cpu"] / l["cpu"] for l, m in zip(runs["links"], runs["mortar"]))
        print(f"{name:22s} ratio  wall {mo['wall'] / lk['wall']:.2f} cpu {mo['cpu'] / lk['cpu']:.2f} "
              f"(pairs {cpu.min:.2f}–{cpu.max:.2f}; load average {os.getloadavg()[0]:.1f})", flush=True)
        cell = lambda r: (f"{r['newton']:.0f} / {r['uzawa']:.0f} / {r['builds']:.0f} / "  # noqa: E731
                          f"{r['cpu']:.2f} s")
        table.append([name, f"{lk['dofs']:,.0f}", cell(lk), cell(mo),
                      f"{mo['cpu'] / lk['cpu']:.2f} ({mo['wall'] / lk['wall']:.2f})"])
    print(f"load average after: {os.getloadavg()}")
    if not a.no_table:
        benchrun.write_table(
            a.table, "Mortar cost against the links",
            ["scene", "DOFs", "links: Newton / Uzawa / factorisations / CPU",
             "mortar: Newton / Uzawa / factorisations / CPU", "mortar / links CPU (solve s)"],
            table, prov.text(f"medians of {a.repeats}, links and mortar alternated, 1 rank"),
            intro="CPU: the process's user + system seconds. Solve s: the seconds the run "
                  "records (`/run` wall_seconds). Factorisations: of the contact Schur complement "
                  "on that path, else of the preconditioner (0 where SNES's own lag decides).")


if __name__ == "__main__":
    main()
