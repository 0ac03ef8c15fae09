#!/usr/bin/env python3
"""Cost of the mortar formulation against the links on the same scenes.

Usage: mortar_cost.py EXE [REPEATS [SCENE ...]]

Runs every scene below with `formulation = "links"` and `"mortar"`,
alternated (links, mortar, links, mortar, ...) so both see the same load,
and prints per scene and formulation the DOFs, Newton and Uzawa iterations,
preconditioner builds, and the median over REPEATS (default 3) of the wall
time the run reports and of the process's CPU time (user + system), with
the load average before and after. Ratios are mortar / links. SCENE
names (prefixes of the names below) select scenes; a SCENE that is a
.toml file is run as given (e.g. the graded line meshes that
`python3 scripts/bench_peers.py --cases line --dry-run --out DIR` writes:
DIR/line-b40.toml).
"""
import os
import re
import resource
import statistics
import subprocess
import sys

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
    cmd = [exe, "run", *args, "-o", out, "--set", f"contact.formulation={formulation}"]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    p = subprocess.run(cmd, capture_output=True, text=True)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{p.stdout}\n{p.stderr}")
    text = p.stdout + p.stderr
    done = re.search(r"done: (\d+) steps, (\d+) Newton iterations, (\d+) DOFs.*?, ([\d.]+) s", text)
    solver = re.search(r"solver: (\d+) Uzawa iterations, (\d+) linear iterations, "
                       r"(?:preconditioner built (\d+) times|.*?Schur complement factored (\d+) time)",
                       text)
    contact = re.search(r"contact assembly ([\d.]+) s", text)
    linear = re.search(r"linear solve ([\d.]+) s", text)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return {
        "dofs": int(done.group(3)),
        "newton": int(done.group(2)),
        # Runs without a kept preconditioner (nonlinear bodies) print no
        # solver line.
        "uzawa": int(solver.group(1)) if solver else -1,
        "ksp": int(solver.group(2)) if solver else -1,
        # Factorisations: of the preconditioner, or of the contact Schur
        # complement on that path.
        "builds": int(solver.group(3) or solver.group(4)) if solver else -1,
        "wall": float(done.group(4)),
        "cpu": cpu,
        "contact": float(contact.group(1)),
        "linear": float(linear.group(1)),
    }


def main(exe, repeats, only):
    os.makedirs("out", exist_ok=True)
    print(f"load average before: {os.getloadavg()}")
    files = [o for o in only if o.endswith(".toml")]
    names = [o for o in only if not o.endswith(".toml")]
    scenes = [(n, a) for n, a in SCENES if not only or any(n.startswith(o) for o in names)]
    scenes += [(os.path.basename(f)[: -len(".toml")], [f]) for f in files]
    for name, args in scenes:
        runs = {"links": [], "mortar": []}
        for _ in range(repeats):
            for f in ("links", "mortar"):
                runs[f].append(run(exe, args, f))
        med = {f: {k: statistics.median(r[k] for r in rs) for k in rs[0]} for f, rs in runs.items()}
        l, m = med["links"], med["mortar"]
        for f in ("links", "mortar"):
            r = med[f]
            print(f"{name:22s} {f:6s} DOFs {r['dofs']:.0f} newton {r['newton']:.0f} uzawa {r['uzawa']:.0f} "
                  f"ksp {r['ksp']:.0f} factorisations {r['builds']:.0f} wall {r['wall']:.2f} s "
                  f"cpu {r['cpu']:.2f} s (linear solve {r['linear']:.2f} s, contact assembly {r['contact']:.2f} s)")
        print(f"{name:22s} ratio  wall {m['wall'] / l['wall']:.2f} cpu {m['cpu'] / l['cpu']:.2f}  "
              f"(load average {os.getloadavg()[0]:.1f})", flush=True)
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 3, sys.argv[3:])
