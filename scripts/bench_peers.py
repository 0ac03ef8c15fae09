#!/usr/bin/python3
"""contactlink side by side with CalculiX on the same mesh.

usage: bench_peers.py [--sizes 5,10,20,40] [--np 1] [--repeats 1]
                      [--out bench-results/peers] [--bin target/release/contactlink]

The Hertz line contact (plane strain, one hex8 layer, half model): a quarter
disc R = 1 pressed on a 4R x 4R block (the half of 8R x 4R), displacement
controlled so that b is about 0.1 R, meshed by Gmsh from
scripts/peers/hertz-line.geo with contact-zone size h_c = b/5 ... b/40
(unstructured full-quad, graded to 0.25 R). For each size the script

  1. runs contactlink on the .msh (a scene written next to it);
  2. writes a CalculiX deck from the same .msh: the same nodes, C3D8 cells,
     element-face surfaces and boundary conditions, a penalty surface-to-surface
     contact pair with the linear pressure-overclosure slope 10 E / h_c, and
     runs `ccx` on one thread (OMP_NUM_THREADS=1);
  3. fits the Hertz profile p^2 = p0^2 (1 - x^2/b^2) to each code's contact
     pressures (the fit contactlink itself reports: least squares in
     (x^2, p^2) over the inner 90 % of the loaded zone) and compares p0 and b
     with Hertz for the load each code's reaction force gives;

and prints one table (wall time of the whole process, Newton iterations,
errors, time ratio). Writes <out>/peers.csv. Needs gmsh and calculix-ccx
(`bash scripts/install-deps.sh --peers` installs them).
"""
import argparse
import csv
import math
import os
import re
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
GEO = os.path.join(HERE, "peers", "hertz-line.geo")
YOUNGS, POISSON = 1000.0, 0.3
RADIUS = 1.0
THICKNESS = 0.01  # the one hex layer (y), as in hertz-line.geo
# Approach of the cylinder's top that gives b ≈ 0.1 R on these meshes.
APPROACH = 0.0183
B_TARGET = 0.1 * RADIUS
E_STAR = 1.0 / (2.0 * (1.0 - POISSON ** 2) / YOUNGS)

# C3D8 faces (CalculiX/Abaqus numbering S1..S6) as local node indices; Gmsh
# numbers a hexahedron's nodes like CalculiX does.
HEX_FACES = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1),
             (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)]


# --- Gmsh .msh 4.1 (ASCII), just what this mesh has -----------------------

def read_msh(path):
    """Nodes {tag: (x, y, z)}, hexes [(tag, body, [8 tags])], quads per
    physical surface name {name: [[4 tags]]}."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    names, ent_phys = {}, {}
    nodes, hexes, quads = {}, [], {}

    def section(name):
        nonlocal i
        while lines[i].strip() != name:
            i += 1
        i += 1

    section("$PhysicalNames")
    for _ in range(int(lines[i])):
        i += 1
        dim, tag, name = lines[i].split(maxsplit=2)
        names[(int(dim), int(tag))] = name.strip('"')
    section("$Entities")
    counts = [int(v) for v in lines[i].split()]
    i += 1
    for dim in range(4):
        for _ in range(counts[dim]):
            v = lines[i].split()
            i += 1
            tag = int(v[0])
            at = 4 if dim == 0 else 7
            nphys = int(v[at])
            ent_phys[(dim, tag)] = [int(p) for p in v[at + 1:at + 1 + nphys]]
    section("$Nodes")
    nblocks = int(lines[i].split()[0])
    i += 1
    for _ in range(nblocks):
        n = int(lines[i].split()[3])
        i += 1
        tags = [int(lines[i + k]) for k in range(n)]
        i += n
        for k in range(n):
            nodes[tags[k]] = tuple(float(c) for c in lines[i + k].split())
        i += n
    section("$Elements")
    nblocks = int(lines[i].split()[0])
    i += 1
    for _ in range(nblocks):
        dim, ent, etype, n = (int(v) for v in lines[i].split())
        i += 1
        phys = [names[(dim, p)] for p in ent_phys.get((dim, ent), [])]
        for k in range(n):
            v = [int(x) for x in lines[i + k].split()]
            if etype == 5:
                body = phys[0] if phys else "unnamed"
                hexes.append((v[0], body, v[1:9]))
            elif etype == 3:
                for p in phys:
                    quads.setdefault(p, []).append(v[1:5])
        i += n
    return nodes, hexes, quads


def hex_volume_sign(nodes, conn):
    """Sign of the Jacobian at the centre of a hexahedron."""
    p = [nodes[t] for t in conn]

    def d(a, b):
        return [sum(p[k][c] for k in b) - sum(p[k][c] for k in a) for c in range(3)]
    gx = d((0, 3, 4, 7), (1, 2, 5, 6))
    gy = d((0, 1, 4, 5), (3, 2, 7, 6))
    gz = d((0, 1, 2, 3), (4, 5, 6, 7))
    det = (gx[0] * (gy[1] * gz[2] - gy[2] * gz[1])
           - gx[1] * (gy[0] * gz[2] - gy[2] * gz[0])
           + gx[2] * (gy[0] * gz[1] - gy[1] * gz[0]))
    return 1 if det > 0 else -1


def contact_size(nodes, quads):
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


# --- the Hertz fit (as contactlink reports it) -------------------------------

def fit_profile(xs, ps):
    loaded = [(x * x, p) for x, p in zip(xs, ps) if p > 0.0]
    if len(loaded) < 3:
        return None
    s2_max = max(s for s, _ in loaded)
    inner = [(s, p * p) for s, p in loaded if s <= 0.81 * s2_max]
    n = len(inner)
    if n < 3:
        return None
    mx = sum(s for s, _ in inner) / n
    my = sum(q for _, q in inner) / n
    sxx = sum((s - mx) ** 2 for s, _ in inner)
    sxy = sum((s - mx) * (q - my) for s, q in inner)
    if sxx <= 0:
        return None
    slope = sxy / sxx
    icpt = my - slope * mx
    if icpt <= 0 or slope >= 0:
        return None
    return math.sqrt(icpt), math.sqrt(icpt / -slope)


def hertz_errors(load, p0, b):
    b_exact = math.sqrt(4 * load * RADIUS / (math.pi * E_STAR))
    p0_exact = 2 * load / (math.pi * b_exact)
    return (p0 - p0_exact) / p0_exact, (b - b_exact) / b_exact


# --- contactlink ---------------------------------------------------------------

SCENE = """title = "Hertz line contact, half model, Gmsh mesh h_c = {hc:.5g} (peer benchmark)"

[mesh]
generator = "gmsh"
file = "{msh}"

[[body]]
name = "block"
material = "linear-elastic"
youngs = {e}
poisson = {nu}

[[body]]
name = "cylinder"
material = "linear-elastic"
youngs = {e}
poisson = {nu}

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

[[contact]]
name = "hertz"
slave = "cylinder.curved"
master = "block.top"

[steps]
count = 1

[solver]
direct_max_dofs = 1000000

# Half model: the pair carries half the line load, so the load per unit
# length is the force over half the thickness.
[hertz]
kind = "line"
pair = "hertz"
radius = {radius}
thickness = {half}
"""

DONE = re.compile(r"done: (\d+) steps, (\d+) Newton iterations, (\d+) DOFs")
HERTZ = re.compile(r"p0 computed ([-+0-9.e]+), analytic ([-+0-9.e]+) \(([-+0-9.]+) %\); "
                   r"half-width/radius computed ([-+0-9.e]+), analytic ([-+0-9.e]+) \(([-+0-9.]+) %\)")


def mpi_env():
    return dict(dict(OMPI_MCA_btl="self,vader",
                OMPI_MCA_btl_vader_single_copy_mechanism="none",
                OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
                OMP_NUM_THREADS="1"), **os.environ)


def run_contactlink(binary, np_, scene, extra):
    cmd = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(np_),
           binary, "run", scene, "-o", scene[:-5] + ".h5"] + extra
    t0 = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=mpi_env())
    wall = time.perf_counter() - t0
    out = p.stdout + p.stderr
    d, h = DONE.search(out), HERTZ.search(out)
    if p.returncode != 0 or not d or not h:
        sys.exit(f"contactlink failed on {scene}:\n{out[-2000:]}")
    with open(scene[:-5] + ".csv") as f:
        rows = list(csv.DictReader(f))
    return {
        "wall": wall, "steps": int(d[1]), "newton": int(d[2]), "dofs": int(d[3]),
        "uzawa": sum(int(r["uzawa"]) for r in rows),
        "ksp": sum(int(r["ksp"]) for r in rows) if "ksp" in rows[0] else None,
        "cutbacks": sum(int(r.get("cutbacks", 0)) for r in rows),
        "e_p0": float(h[3]) / 100, "e_b": float(h[6]) / 100,
    }


# --- CalculiX ---------------------------------------------------------------------

def write_deck(path, nodes, hexes, quads, penalty):
    """The CalculiX deck of the same mesh, boundary conditions and load."""
    face_of = {}
    out = ["** Hertz line contact, half model: written by scripts/bench_peers.py",
           "*NODE, NSET=NALL"]
    for t in sorted(nodes):
        x, y, z = nodes[t]
        out.append(f"{t}, {x:.15g}, {y:.15g}, {z:.15g}")
    for body in ("block", "cylinder"):
        out.append(f"*ELEMENT, TYPE=C3D8, ELSET=E{body.upper()}")
        for tag, b, conn in hexes:
            if b != body:
                continue
            if hex_volume_sign(nodes, conn) < 0:
                conn = conn[4:] + conn[:4]
            out.append(f"{tag}, " + ", ".join(str(c) for c in conn))
            for k, f in enumerate(HEX_FACES):
                face_of[frozenset(conn[i] for i in f)] = (tag, k + 1)

    def nset(name, sets):
        tags = sorted({n for s in sets for q in quads[s] for n in q})
        out.append(f"*NSET, NSET={name}")
        out.extend(", ".join(str(t) for t in tags[i:i + 12]) for i in range(0, len(tags), 12))

    def surface(name, set_name):
        out.append(f"*SURFACE, NAME={name}, TYPE=ELEMENT")
        for q in quads[set_name]:
            tag, face = face_of[frozenset(q)]
            out.append(f"{tag}, S{face}")

    nset("NBOTTOM", ["block.bottom"])
    nset("NSYM", ["block.symmetry", "cylinder.symmetry"])
    nset("NTOP", ["cylinder.top"])
    surface("SSLAVE", "cylinder.curved")
    surface("SMASTER", "block.top")
    out += [
        "*MATERIAL, NAME=STEEL",
        "*ELASTIC",
        f"{YOUNGS}, {POISSON}",
        "*SOLID SECTION, ELSET=EBLOCK, MATERIAL=STEEL",
        "*SOLID SECTION, ELSET=ECYLINDER, MATERIAL=STEEL",
        "*SURFACE INTERACTION, NAME=HERTZ",
        "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
        f"{penalty:.6g}",
        "*CONTACT PAIR, INTERACTION=HERTZ, TYPE=SURFACE TO SURFACE",
        "SSLAVE, SMASTER",
        "*BOUNDARY",
        "NBOTTOM, 1, 3, 0.0",
        "NSYM, 1, 1, 0.0",
        "NALL, 2, 2, 0.0",
        "*STEP",
        "*STATIC",
        "1.0, 1.0",
        "*BOUNDARY",
        "NTOP, 1, 1, 0.0",
        f"NTOP, 3, 3, {-APPROACH}",
        "*NODE PRINT, NSET=NTOP, TOTALS=ONLY",
        "RF",
        "*CONTACT FILE",
        "CSTR",
        "*END STEP",
    ]
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")


def run_ccx(deck):
    job = deck[:-4]
    t0 = time.perf_counter()
    p = subprocess.run(["ccx", "-i", os.path.basename(job)], capture_output=True, text=True,
                       cwd=os.path.dirname(job), env=dict(os.environ, OMP_NUM_THREADS="1"))
    wall = time.perf_counter() - t0
    out = p.stdout + p.stderr
    if p.returncode != 0 or "Job finished" not in out:
        sys.exit(f"ccx failed on {deck}:\n{out[-2000:]}")
    return wall


def read_frd_pressure(path):
    """CPRESS at the nodes of the last CONTACT block of a .frd file."""
    pressure, inside = {}, False
    with open(path) as f:
        for line in f:
            if line.startswith(" -4"):
                inside = line.split()[1] == "CONTACT"
                if inside:
                    pressure = {}
            elif inside and line.startswith(" -1"):
                # Fixed columns: " -1", node id (10), then 12-wide values.
                node = int(line[3:13])
                vals = [float(line[13 + 12 * k:25 + 12 * k]) for k in range(6)]
                pressure[node] = vals[3]
            elif inside and line.startswith(" -3"):
                inside = False
    return pressure


def read_dat_total(path):
    """The last total force of set NTOP in a .dat file."""
    with open(path) as f:
        text = f.read()
    blocks = re.findall(r"total force \(fx,fy,fz\) for set NTOP.*?\n\s*\n\s*(\S+)\s+(\S+)\s+(\S+)", text)
    if not blocks:
        return None
    return [float(v) for v in blocks[-1]]


def ccx_newton(sta):
    """Newton iterations summed over the increments of a .sta file."""
    total, increments = 0, 0
    with open(sta) as f:
        for line in f:
            v = line.split()
            if len(v) == 7 and v[0].isdigit() and v[1].isdigit():
                total += int(v[3])
                increments += 1
    return total, increments


def ccx_errors(job, nodes, quads):
    """(p0 error, b error) of a CalculiX run against Hertz for its own load."""
    force = read_dat_total(job + ".dat")
    pressure = read_frd_pressure(job + ".frd")
    if force is None or not pressure:
        sys.exit(f"{job}: no total force or contact pressure in the CalculiX output")
    slave = sorted({t for q in quads["cylinder.curved"] for t in q})
    fit = fit_profile([nodes[t][0] for t in slave], [pressure.get(t, 0.0) for t in slave])
    if fit is None:
        sys.exit(f"{job}: too few loaded slave nodes for a Hertz fit")
    # Half model: the load per unit length is the force over half the thickness.
    return hertz_errors(2.0 * abs(force[2]) / THICKNESS, *fit)


def one_size(a, divisor):
    hc = B_TARGET / divisor
    tag = f"b{divisor}"
    msh = os.path.join(a.out, f"line-{tag}.msh")
    subprocess.run(["gmsh", "-3", "-format", "msh41", "-setnumber", "hc", str(hc),
                    "-setnumber", "t", str(THICKNESS), GEO, "-o", msh],
                   check=True, capture_output=True)
    nodes, hexes, quads = read_msh(msh)
    h_measured = contact_size(nodes, quads)
    scene = os.path.join(a.out, f"line-{tag}.toml")
    with open(scene, "w") as f:
        f.write(SCENE.format(hc=hc, msh=os.path.basename(msh), e=YOUNGS, nu=POISSON,
                             approach=-APPROACH, radius=RADIUS, half=THICKNESS / 2))
    ours = [run_contactlink(a.bin, a.np, scene, a.extra) for _ in range(a.repeats)]
    row = dict(ours[0])
    row["wall"] = statistics.median(r["wall"] for r in ours)
    deck = os.path.join(a.out, f"ccx-{tag}.inp")
    # The pair's penalty as the task states it: slope 10 E / h_c.
    write_deck(deck, nodes, hexes, quads, 10.0 * YOUNGS / hc)
    walls = []
    for _ in range(a.repeats):
        walls.append(run_ccx(deck))
    ccx_newton_its, ccx_increments = ccx_newton(deck[:-4] + ".sta")
    e_p0, e_b = ccx_errors(deck[:-4], nodes, quads)
    row.update(size=f"b/{divisor}", hc=hc, hc_mesh=h_measured,
               ccx_wall=statistics.median(walls), ccx_newton=ccx_newton_its,
               ccx_increments=ccx_increments, ccx_e_p0=e_p0, ccx_e_b=e_b)
    row["ratio"] = row["wall"] / row["ccx_wall"]
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="5,10,20,40", help="h_c = b / each")
    ap.add_argument("--np", type=int, default=1, help="contactlink ranks (CalculiX: one thread)")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--out", default="bench-results/peers")
    ap.add_argument("--bin", default="target/release/contactlink")
    ap.add_argument("--set", dest="extra", action="append", default=[],
                    help="a contactlink --set override for every run (repeatable)")
    a = ap.parse_args()
    a.extra = [x for s in a.extra for x in ("--set", s)]
    for tool in ("gmsh", "ccx"):
        if subprocess.run(["which", tool], capture_output=True).returncode != 0:
            sys.exit(f"{tool} not found: run `bash scripts/install-deps.sh --peers`")
    os.makedirs(a.out, exist_ok=True)
    rows = []
    print(f"Hertz line contact, half model, b ≈ 0.1 R; contactlink on {a.np} rank(s), "
          f"CalculiX on one thread; wall time of the whole process, median of {a.repeats}")
    head = (f"{'h_c':>6} {'DOFs':>8} | {'ours s':>7} {'Newton':>6} {'Uzawa':>5} {'steps':>5} "
            f"{'e_p0':>8} {'e_b':>8} | {'ccx s':>7} {'Newton':>6} {'incs':>4} "
            f"{'e_p0':>8} {'e_b':>8} | {'ours/ccx':>8}")
    print(head)
    for d in [int(v) for v in a.sizes.split(",")]:
        r = one_size(a, d)
        rows.append(r)
        print(f"{r['size']:>6} {r['dofs']:>8} | {r['wall']:7.2f} {r['newton']:6d} {r['uzawa']:5d} "
              f"{r['steps']:5d} {100 * r['e_p0']:+7.2f}% {100 * r['e_b']:+7.2f}% | "
              f"{r['ccx_wall']:7.2f} {r['ccx_newton']:6d} {r['ccx_increments']:4d} "
              f"{100 * r['ccx_e_p0']:+7.2f}% {100 * r['ccx_e_b']:+7.2f}% | {r['ratio']:8.2f}",
              flush=True)
    keys = ["size", "hc", "hc_mesh", "dofs", "wall", "newton", "uzawa", "steps", "cutbacks",
            "e_p0", "e_b", "ccx_wall", "ccx_newton", "ccx_increments", "ccx_e_p0", "ccx_e_b",
            "ratio"]
    path = os.path.join(a.out, "peers.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    print(f"bench-peers: {path}")


if __name__ == "__main__":
    main()
