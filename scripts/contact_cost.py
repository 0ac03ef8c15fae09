#!/usr/bin/env python3
"""Contact solve against the plain elastic solve of the same mesh.

Usage: contact_cost.py EXE [REPEATS [CASE ...]] [--lines DIR]

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
"""
import os
import re
import statistics
import subprocess
import sys

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
    cmd = [exe, "run", *args, "-v"]
    if ranks > 1:
        cmd = ["mpirun", "-n", str(ranks), "--allow-run-as-root", "--oversubscribe", *cmd]
    p = subprocess.run(cmd, capture_output=True, text=True)
    text = p.stdout + p.stderr
    if p.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{text}")
    done = re.search(r"done: (\d+) steps, (\d+) Newton iterations, (\d+) DOFs.*?, ([\d.]+) s", text)
    solver = re.search(r"solver: (\d+) Uzawa iterations, (\d+) linear iterations", text)
    return {
        "steps": int(done.group(1)),
        "newton": int(done.group(2)),
        "dofs": int(done.group(3)),
        "seconds": float(done.group(4)),
        "uzawa": int(solver.group(1)) if solver else 0,
        "linear": int(solver.group(2)) if solver else 0,
    }


def main():
    argv = sys.argv[1:]
    lines = "/tmp/lines"
    if "--lines" in argv:
        i = argv.index("--lines")
        lines = argv[i + 1]
        del argv[i:i + 2]
    if not argv:
        sys.exit(__doc__)
    exe = argv[0]
    repeats = int(argv[1]) if len(argv) > 1 else 3
    wanted = argv[2:]
    chosen = [c for c in cases(lines) if not wanted or any(c[0].startswith(w) for w in wanted)]
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print("| case | DOFs | ranks | path | plain s | contact s | contact / plain | per round | "
          "steps, Newton / Uzawa / linear |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for name, ranks, path, plain_args, contact_args in chosen:
        plain, contact = [], []
        for _ in range(repeats):
            plain.append(run(exe, ranks, plain_args))
            contact.append(run(exe, ranks, contact_args))
        p = statistics.median(r["seconds"] for r in plain)
        c = statistics.median(r["seconds"] for r in contact)
        rounds = " ".join(f"{b['seconds'] / a['seconds']:.2f}" for a, b in zip(plain, contact))
        last = contact[-1]
        print(f"| {name} | {last['dofs']:,} | {ranks} | {path} | {p:.2f} | {c:.2f} | {c / p:.2f} | "
              f"{rounds} | {last['steps']}, {last['newton']} / {last['uzawa']} / {last['linear']} |",
              flush=True)
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
