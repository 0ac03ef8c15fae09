#!/usr/bin/python3
"""contactlink side by side with CalculiX on the same mesh.

usage: bench_peers.py [--cases line,sphere] [--sizes 5,10,20,40]
                      [--sphere-sizes 0.5,0.35] [--np 1] [--repeats 1]
                      [--sphere-repeats 1] [--dry-run]
                      [--out bench-results/peers] [--bin target/release/contactlink]
                      [--table-dir docs/tables | --no-table]

Two cases, each at a few mesh sizes:

line    The Hertz line contact (plane strain, one hex8 layer, half model): a
        quarter disc R = 1 pressed on a 4R x 4R block (the half of 8R x 4R),
        displacement controlled so that b is about 0.1 R, meshed by Gmsh from
        scripts/peers/hertz-line.geo with contact-zone size h_c = b/5 ... b/40
        (unstructured full-quad, graded to 0.25 R).
sphere  The Hertz point contact of the built-in `hertz-sphere` scene: a
        hemisphere R = 10 pressed 0.1 into a 20 x 20 x 10 block, both
        E = 1000, nu = 0.3, structured hex8 graded from h_c (--sphere-sizes)
        over a 2 x 2 zone at the contact point. CalculiX gets the mesh that
        contactlink's own result file holds (nodes and cells in natural order,
        the facet and node sets), so both codes solve the same mesh.

For each size the script

  1. runs contactlink twice: the contact solve, and the plain elastic solve
     of the same mesh, materials, conditions and solver without the contact
     pair (one linear-elastic step, as benches/solve_costs.rs defines it);
     on one rank (--np 1) the program is started directly, without mpirun;
  2. writes a CalculiX deck of the same mesh: the same nodes, C3D8 cells,
     element-face surfaces and boundary conditions, a penalty
     surface-to-surface contact pair with the linear pressure-overclosure
     slope 10 E / h_c, and runs `ccx` on one thread (OMP_NUM_THREADS=1);
  3. fits the Hertz profile p^2 = p0^2 (1 - s^2/w^2) to each code's contact
     pressures (the fit contactlink itself reports: least squares in
     (s^2, p^2) over the inner 90 % of the loaded zone; contactlink's nodal
     contact pressures, CalculiX's CPRESS at the slave nodes) and compares p0 and the
     half-width b (line) or radius a (sphere) with Hertz for the load each
     code's reaction force gives;

and prints one table per case: wall time of the whole process, Newton
iterations, errors, the time ratio ours/ccx, and contactlink's contact/plain
ratio of its own solve time (the `done:` line's seconds, start-up excluded).
Writes <out>/peers.csv (with the CPU seconds of each process too, user +
system, less dependent on the machine's load than wall time), and each
case's rows into docs/tables/peers-line.md and docs/tables/peers-sphere.md
(`make bench-peers`; a subset of sizes replaces only its rows). --dry-run writes the meshes, scenes and decks (the
sphere's mesh comes from one plain contactlink solve) and runs nothing else.
Needs gmsh, calculix-ccx and python3-h5py (`bash scripts/install-deps.sh
--peers` installs them).
"""
import argparse
import csv
import math
import os
import re
import subprocess
import sys

import benchrun

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "peers"))
import ccx  # noqa: E402
import hertz  # noqa: E402
import meshes  # noqa: E402

GEO = os.path.join(HERE, "peers", "hertz-line.geo")
YOUNGS, POISSON = 1000.0, 0.3
E_STAR = hertz.effective_modulus(YOUNGS, POISSON)

# --- line contact ---------------------------------------------------------------
RADIUS = 1.0
THICKNESS = 0.01  # the one hex layer (y), as in hertz-line.geo
# Approach of the cylinder's top that gives b ≈ 0.1 R on these meshes.
APPROACH = 0.0183
B_TARGET = 0.1 * RADIUS

# --- point contact (scenes/hertz-sphere.toml) -------------------------------------
SPHERE_RADIUS = 10.0
SPHERE_PUSH = 0.1

BODIES = """
[[body]]
name = "block"
material = "linear-elastic"
youngs = {e}
poisson = {nu}

[[body]]
name = "{indenter}"
material = "linear-elastic"
youngs = {e}
poisson = {nu}
"""

LINE_SCENE = """title = "Hertz line contact, half model, Gmsh mesh h_c = {hc:.5g}{what} (peer benchmark)"

[mesh]
generator = "gmsh"
file = "{msh}"
""" + BODIES + """
[[dirichlet]]
set = "block.bottom"

# Symmetry plane x = 0 (half model).
[[dirichlet]]
set = "block.symmetry"
components = ["x"]

[[dirichlet]]
set = "cylinder.symmetry"
components = ["x"]

# Plane strain: one cell thick, no displacement out of the plane.
[[dirichlet]]
set = "block.front"
components = ["y"]

[[dirichlet]]
set = "block.back"
components = ["y"]

[[dirichlet]]
set = "cylinder.front"
components = ["y"]

[[dirichlet]]
set = "cylinder.back"
components = ["y"]

[[dirichlet]]
set = "cylinder.top"
components = ["x", "z"]
value = [0.0, {approach}]
"""

LINE_CONTACT = """
[[contact]]
name = "hertz"
slave = "cylinder.curved"
master = "block.top"
"""

LINE_TAIL = """
[steps]
count = 1

[solver]
direct_max_dofs = 1000000
"""

# Half model: the pair carries half the line load, so the load per unit
# length is the force over half the thickness.
LINE_HERTZ = """
[hertz]
kind = "line"
pair = "hertz"
radius = {radius}
thickness = {half}
"""

SPHERE_SCENE = """title = "Hertz point contact, built-in hertz-sphere mesh h_c = {hc:.5g}{what} (peer benchmark)"

[mesh]
generator = "hertz-sphere"
radius = {radius}
block_width = 20.0
block_height = 10.0
fine_size = {hc}
fine_half_width = 2.0
level = 0
""" + BODIES + """
[[dirichlet]]
set = "block.bottom"

[[dirichlet]]
set = "sphere.top"
value = [0.0, 0.0, {push}]
"""

SPHERE_CONTACT = """
[[contact]]
name = "hertz"
slave = "sphere.curved"
master = "block.top"
"""

SPHERE_TAIL = """
[steps]
count = 1
"""

SPHERE_HERTZ = """
[hertz]
kind = "point"
pair = "hertz"
radius = {radius}
"""

DONE = re.compile(r"done: (\d+) steps, (\d+) Newton iterations, (\d+) DOFs on \d+ rank\(s\), ([0-9.]+) s")
HERTZ = re.compile(r"p0 computed ([-+0-9.e]+), analytic ([-+0-9.e]+) \(([-+0-9.]+) %\); "
                   r"half-width/radius computed ([-+0-9.e]+), analytic ([-+0-9.e]+) \(([-+0-9.]+) %\)")


def write_scenes(stem, base, contact, tail, hertz_part, **fmt):
    """<stem>.toml (the contact solve) and <stem>-plain.toml (the same mesh,
    materials, conditions and solver without the contact pair)."""
    paths = []
    for suffix, parts, what in ((".toml", (base, contact, tail, hertz_part), ""),
                                ("-plain.toml", (base, tail), ", no contact")):
        path = stem + suffix
        with open(path, "w") as f:
            f.write("".join(parts).format(what=what, **fmt))
        paths.append(path)
    return paths


def mpi_env():
    return dict(dict(OMPI_MCA_btl="self,vader",
                OMPI_MCA_btl_vader_single_copy_mechanism="none", OMPI_MCA_pml="ob1",
                OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                OMP_NUM_THREADS="1"), **os.environ)


def run_contactlink(a, scene, contact=True):
    """One contactlink run: on one rank the program is started by itself (a
    single MPI process needs no launcher, as ccx needs none), on more under
    mpirun."""
    launch = [] if a.np == 1 else ["mpirun", "--allow-run-as-root", "--oversubscribe",
                                    "-n", str(a.np)]
    cmd = launch + [a.bin, "run", scene, "-o", scene[:-5] + ".h5"] + a.extra
    t = benchrun.run(cmd, env=mpi_env(), check=False)
    wall, cpu, out = t.wall, t.cpu, t.text
    d, h = DONE.search(out), HERTZ.search(out)
    if t.returncode != 0 or not d or (contact and not h):
        sys.exit(f"contactlink failed on {scene}:\n{out[-2000:]}")
    with open(scene[:-5] + ".csv") as f:
        rows = list(csv.DictReader(f))
    r = {"wall": wall, "cpu": cpu, "solve": float(d[4]), "steps": int(d[1]), "newton": int(d[2]),
         "dofs": int(d[3]), "uzawa": sum(int(r["uzawa"]) for r in rows)}
    if contact:
        r.update(e_p0=float(h[3]) / 100, e_w=float(h[6]) / 100)
    return r


def median_run(a, scene, repeats, contact=True):
    runs = benchrun.repeat(lambda: run_contactlink(a, scene, contact), repeats)
    return benchrun.medians(runs, ["wall", "cpu", "solve"])


def run_peer(deck, repeats):
    """(wall, CPU seconds, Newton iterations, increments) of ccx on a deck,
    on one thread; medians of `repeats` runs."""
    job = deck[:-4]

    def once():
        t = benchrun.run(["ccx", "-i", os.path.basename(job)], check=False,
                         env=dict(os.environ, OMP_NUM_THREADS="1"),
                         cwd=os.path.dirname(job) or ".")
        if t.returncode != 0 or "Job finished" not in t.text:
            sys.exit(f"ccx failed on {deck}:\n{t.text[-2000:]}")
        return t

    runs = benchrun.repeat(once, repeats)
    newton, increments = ccx.ccx_newton(job + ".sta")
    return (benchrun.median(r.wall for r in runs), benchrun.median(r.cpu for r in runs),
            newton, increments)


def ccx_fit(job, nodes, slave_nodes, load_of, exact_of, point):
    """(p0 error, width error) of a CalculiX run against Hertz for the load
    its own reaction gives."""
    force = ccx.read_dat_total(job + ".dat", "NTOP")
    pressure = ccx.read_frd_pressure(job + ".frd")
    if force is None or not pressure:
        sys.exit(f"{job}: no total force or contact pressure in the CalculiX output")
    slave = sorted(set(slave_nodes))
    fit = hertz.fit_profile([nodes[t] for t in slave], [pressure.get(t, 0.0) for t in slave],
                            point=point)
    if fit is None:
        sys.exit(f"{job}: too few loaded slave nodes for a Hertz fit")
    return hertz.errors(exact_of(load_of(force)), *fit)


def line_contact_size(nodes, quads):
    """The smallest in-plane (x-z) edge of the slave surface near the first
    contact point: the h_c the mesh really has."""
    best = math.inf
    for q in quads["cylinder.curved"]:
        for a, b in zip(q, q[1:] + q[:1]):
            pa, pb = nodes[a], nodes[b]
            if abs(pa[1] - pb[1]) > 1e-12 or max(abs(pa[0]), abs(pb[0])) > 2 * B_TARGET:
                continue
            best = min(best, math.hypot(pa[0] - pb[0], pa[2] - pb[2]))
    return best


def one_line(a, divisor):
    hc = B_TARGET / divisor
    stem = os.path.join(a.out, f"line-b{divisor}")
    msh = stem + ".msh"
    subprocess.run(["gmsh", "-3", "-format", "msh41", "-setnumber", "hc", str(hc),
                    "-setnumber", "t", str(THICKNESS), GEO, "-o", msh],
                   check=True, capture_output=True)
    nodes, hexes, quads = meshes.read_msh(msh)
    scene, plain = write_scenes(stem, LINE_SCENE, LINE_CONTACT, LINE_TAIL, LINE_HERTZ,
                                hc=hc, msh=os.path.basename(msh), e=YOUNGS, nu=POISSON,
                                indenter="cylinder", approach=-APPROACH, radius=RADIUS,
                                half=THICKNESS / 2)
    nsets = {"NBOTTOM": [t for q in quads["block.bottom"] for t in q],
             "NSYM": [t for s in ("block.symmetry", "cylinder.symmetry") for q in quads[s] for t in q],
             "NTOP": [t for q in quads["cylinder.top"] for t in q]}
    surfaces = {"SSLAVE": quads["cylinder.curved"], "SMASTER": quads["block.top"]}
    fixed = ["NBOTTOM, 1, 3, 0.0", "NSYM, 1, 1, 0.0", "NALL, 2, 2, 0.0"]
    step = ["NTOP, 1, 1, 0.0", f"NTOP, 3, 3, {-APPROACH}"]
    deck = os.path.join(a.out, f"ccx-line-b{divisor}.inp")
    # The pair's penalty: slope 10 E / h_c.
    ccx.write_deck(deck, "Hertz line contact, half model", nodes, hexes, ["block", "cylinder"],
                   nsets, surfaces, fixed, step, "NTOP", (YOUNGS, POISSON),
                   pair=("SSLAVE", "SMASTER", 10.0 * YOUNGS / hc))
    row = {"case": "line", "size": f"b/{divisor}", "hc": hc,
           "hc_mesh": line_contact_size(nodes, quads), "deck": deck}
    if a.dry_run:
        return row
    row.update(median_run(a, scene, a.repeats))
    p = median_run(a, plain, a.repeats, contact=False)
    row.update(plain_wall=p["wall"], plain_cpu=p["cpu"], plain_solve=p["solve"],
               plain_newton=p["newton"])
    (row["ccx_wall"], row["ccx_cpu"], row["ccx_newton"],
     row["ccx_increments"]) = run_peer(deck, a.repeats)
    # Half model: the load per unit length is the force over half the thickness.
    row["ccx_e_p0"], row["ccx_e_w"] = ccx_fit(
        deck[:-4], nodes, [t for q in quads["cylinder.curved"] for t in q],
        lambda f: 2.0 * abs(f[2]) / THICKNESS, lambda p: hertz.line(p, RADIUS, E_STAR), False)
    return row


def one_sphere(a, hc):
    stem = os.path.join(a.out, f"sphere-h{hc:g}")
    scene, plain = write_scenes(stem, SPHERE_SCENE, SPHERE_CONTACT, SPHERE_TAIL, SPHERE_HERTZ,
                                hc=hc, e=YOUNGS, nu=POISSON, indenter="sphere",
                                radius=SPHERE_RADIUS, push=-SPHERE_PUSH)
    # The plain solve first: its result file holds the mesh the deck is
    # written from (the contact solve's is the same mesh).
    p = median_run(a, plain, 1 if a.dry_run else a.sphere_repeats, contact=False)
    nodes, hexes, facets, node_sets = meshes.read_result_mesh(plain[:-5] + ".h5")
    nsets = {"NBOTTOM": node_sets["block.bottom"], "NTOP": node_sets["sphere.top"]}
    surfaces = {"SSLAVE": facets["sphere.curved"], "SMASTER": facets["block.top"]}
    fixed = ["NBOTTOM, 1, 3, 0.0"]
    step = ["NTOP, 1, 2, 0.0", f"NTOP, 3, 3, {-SPHERE_PUSH}"]
    deck = os.path.join(a.out, f"ccx-sphere-h{hc:g}.inp")
    ccx.write_deck(deck, "Hertz point contact, built-in hertz-sphere mesh", nodes, hexes,
                   ["block", "sphere"], nsets, surfaces, fixed, step, "NTOP", (YOUNGS, POISSON),
                   pair=("SSLAVE", "SMASTER", 10.0 * YOUNGS / hc))
    row = {"case": "sphere", "size": f"h={hc:g}", "hc": hc, "hc_mesh": hc, "deck": deck,
           "plain_wall": p["wall"], "plain_cpu": p["cpu"], "plain_solve": p["solve"],
           "plain_newton": p["newton"]}
    if a.dry_run:
        return row
    row.update(median_run(a, scene, a.sphere_repeats))
    (row["ccx_wall"], row["ccx_cpu"], row["ccx_newton"],
     row["ccx_increments"]) = run_peer(deck, a.sphere_repeats)
    row["ccx_e_p0"], row["ccx_e_w"] = ccx_fit(
        deck[:-4], nodes, [t for q in facets["sphere.curved"] for t in q],
        lambda f: abs(f[2]), lambda f: hertz.point(f, SPHERE_RADIUS, E_STAR), True)
    return row


def print_row(r):
    print(f"{r['size']:>6} {r['dofs']:>8} | {r['wall']:7.2f} {r['newton']:6d} {r['uzawa']:5d} "
          f"{r['steps']:5d} {100 * r['e_p0']:+7.2f}% {100 * r['e_w']:+7.2f}% | "
          f"{r['ccx_wall']:7.2f} {r['ccx_newton']:6d} {r['ccx_increments']:4d} "
          f"{100 * r['ccx_e_p0']:+7.2f}% {100 * r['ccx_e_w']:+7.2f}% | {r['ratio']:8.2f} | "
          f"{r['solve']:7.2f} {r['plain_solve']:7.2f} {r['plain_newton']:6d} "
          f"{r['contact_plain']:7.2f}", flush=True)


def write_table(a, prov, case, title, repeats, rows):
    """The case's rows into <table-dir>/peers-<case>.md."""
    pct = lambda v: f"{100 * v:+.2f} %"  # noqa: E731
    cells = [[f"{case} {r['size']}", f"{r['dofs']:,}",
              f"{r['wall']:.2f} s / {r['newton']} / {r['uzawa']} / {r['steps']}",
              f"{pct(r['e_p0'])} / {pct(r['e_w'])}",
              f"{r['ccx_wall']:.2f} s / {r['ccx_newton']} / {r['ccx_increments']}",
              f"{pct(r['ccx_e_p0'])} / {pct(r['ccx_e_w'])}",
              f"{r['ratio']:.2f}",
              f"{r['solve']:.2f} / {r['plain_solve']:.2f} s = {r['contact_plain']:.2f}"]
             for r in rows]
    columns = ["mesh", "DOFs", "contactlink: wall / Newton / Uzawa / steps", "e_p0 / e_w",
               "CalculiX: wall / Newton / increments", "e_p0 / e_w", "ours / ccx",
               "contactlink contact / plain solve"]
    benchrun.write_table(
        os.path.join(a.table_dir, f"peers-{case}.md"), f"{title}: contactlink beside CalculiX",
        columns, cells,
        prov.text(f"contactlink on {a.np} rank(s), CalculiX 2.20 on one thread; median of {repeats}"),
        intro="Wall: the whole process. e_p0 / e_w: the errors of p0 and of the half-width "
              "(line) or contact radius (sphere) against Hertz, each code's nodal pressures "
              "fitted the same way. Contact / plain: contactlink's solve seconds (`done:` line) "
              "against the same mesh solved without the contact pair.")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", default="line,sphere", help="line, sphere or both")
    ap.add_argument("--sizes", default="5,10,20,40", help="line: h_c = b / each")
    ap.add_argument("--sphere-sizes", default="0.5,0.35", help="sphere: h_c, each")
    ap.add_argument("--np", type=int, default=1, help="contactlink ranks (CalculiX: one thread)")
    ap.add_argument("--repeats", type=int, default=1, help="runs per line size (median)")
    ap.add_argument("--sphere-repeats", type=int, default=1, help="runs per sphere size (median)")
    ap.add_argument("--out", default="bench-results/peers")
    ap.add_argument("--bin", default="target/release/contactlink")
    ap.add_argument("--set", dest="extra", action="append", default=[],
                    help="a contactlink --set override for every run (repeatable)")
    ap.add_argument("--dry-run", action="store_true",
                    help="write meshes, scenes and decks; run no solve but the sphere's plain one")
    ap.add_argument("--table-dir", default=benchrun.TABLES,
                    help="where peers-line.md and peers-sphere.md go (default docs/tables)")
    ap.add_argument("--no-table", action="store_true", help="write no table file")
    a = ap.parse_args()
    prov = benchrun.Provenance("bench-peers")
    a.extra = [x for s in a.extra for x in ("--set", s)]
    cases = [c.strip() for c in a.cases.split(",") if c.strip()]
    for c in cases:
        if c not in ("line", "sphere"):
            sys.exit(f"--cases: '{c}' is not line or sphere")
    for tool in ("gmsh",) * ("line" in cases) + (() if a.dry_run else ("ccx",)):
        if subprocess.run(["which", tool], capture_output=True).returncode != 0:
            sys.exit(f"{tool} not found: run `bash scripts/install-deps.sh --peers`")
    if "sphere" in cases:
        try:
            import h5py  # noqa: F401 (the sphere's mesh is read from a result file)
        except ImportError:
            sys.exit(f"--cases sphere reads contactlink's result file with h5py, which "
                     f"{sys.executable} lacks: run it with /usr/bin/python3 (Debian's "
                     f"python3-h5py, which `make bench-peers` uses)")
    os.makedirs(a.out, exist_ok=True)
    plan = [("line", one_line, [int(v) for v in a.sizes.split(",")], a.repeats,
             "Hertz line contact, half model, b ≈ 0.1 R"),
            ("sphere", one_sphere, [float(v) for v in a.sphere_sizes.split(",")],
             a.sphere_repeats, "Hertz point contact, built-in hertz-sphere mesh, a ≈ 0.1 R")]
    rows = []
    for case, run, sizes, repeats, title in plan:
        if case not in cases:
            continue
        if a.dry_run:
            for s in sizes:
                r = run(a, s)
                rows.append(r)
                print(f"{case} {r['size']}: deck {r['deck']}")
            continue
        print(f"{title}; contactlink on {a.np} rank(s), CalculiX on one thread; wall time of "
              f"the whole process, median of {repeats}; contact/plain: contactlink's solve "
              f"seconds (`done:` line)")
        print(f"{'h_c':>6} {'DOFs':>8} | {'ours s':>7} {'Newton':>6} {'Uzawa':>5} {'steps':>5} "
              f"{'e_p0':>8} {'e_w':>8} | {'ccx s':>7} {'Newton':>6} {'incs':>4} "
              f"{'e_p0':>8} {'e_w':>8} | {'ours/ccx':>8} | {'solve':>7} {'plain':>7} "
              f"{'Newton':>6} {'c/plain':>7}")
        mine = []
        for s in sizes:
            r = run(a, s)
            r["ratio"] = r["wall"] / r["ccx_wall"]
            r["cpu_ratio"] = r["cpu"] / r["ccx_cpu"]
            r["contact_plain"] = r["solve"] / r["plain_solve"]
            rows.append(r)
            mine.append(r)
            print_row(r)
        if not a.no_table:
            write_table(a, prov, case, title, repeats, mine)
    if a.dry_run:
        return
    keys = ["case", "size", "hc", "hc_mesh", "dofs", "wall", "cpu", "solve", "newton", "uzawa",
            "steps", "e_p0", "e_w", "ccx_wall", "ccx_cpu", "ccx_newton", "ccx_increments",
            "ccx_e_p0", "ccx_e_w", "ratio", "cpu_ratio", "plain_wall", "plain_cpu", "plain_solve",
            "plain_newton", "contact_plain"]
    path = os.path.join(a.out, "peers.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    print(f"bench-peers: {path}")


if __name__ == "__main__":
    main()
