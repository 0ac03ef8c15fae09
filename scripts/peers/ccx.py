"""CalculiX side of the peer benchmark: a deck from a mesh of hex8, hex20,
tet4 or tet10 cells and what its output files say (nodal contact pressure,
reaction totals, Newton iterations).

The mesh is given as plain Python data, whatever file it came from:
nodes {tag: (x, y, z)}, cells [(tag, body, [node tags])] with the nodes
numbered as CalculiX's C3D8, C3D20, C3D4 or C3D10 (which is contactlink's
and VTK's order; the type follows from the node count), node sets
{name: [tags]} and surfaces {name: [[node tags], ...]} (each facet a face
of some cell, its corners first).
"""
import re

# C3D8 faces (CalculiX/Abaqus numbering S1..S6) as local node indices of
# their corners; C3D20 has the same.
HEX_FACES = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1),
             (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)]
# C3D4 faces S1..S4; C3D10 has the same.
TET_FACES = [(0, 1, 2), (0, 3, 1), (1, 3, 2), (2, 3, 0)]

# Node count: (CalculiX type, faces by corners, relabelling that reverses
# an inverted cell: new[k] = old[mirror[k]]).
CELL_TYPES = {
    8: ("C3D8", HEX_FACES, [4, 5, 6, 7, 0, 1, 2, 3]),
    20: ("C3D20", HEX_FACES,
         [4, 5, 6, 7, 0, 1, 2, 3, 12, 13, 14, 15, 8, 9, 10, 11, 16, 17, 18, 19]),
    4: ("C3D4", TET_FACES, [0, 2, 1, 3]),
    10: ("C3D10", TET_FACES, [0, 2, 1, 3, 6, 5, 4, 7, 9, 8]),
}


def hex_volume_sign(nodes, conn):
    """Sign of the Jacobian at the centre of a hexahedron (corners)."""
    p = [nodes[t] for t in conn]

    def d(a, b):
        return [sum(p[k][c] for k in b) - sum(p[k][c] for k in a) for c in range(3)]
    gx = d((0, 3, 4, 7), (1, 2, 5, 6))
    gy = d((0, 1, 4, 5), (3, 2, 7, 6))
    gz = d((0, 1, 2, 3), (4, 5, 6, 7))
    return triple_sign(gx, gy, gz)


def tet_volume_sign(nodes, conn):
    """Sign of the volume of a tetrahedron (corners)."""
    p = [nodes[t] for t in conn[:4]]
    e = [[p[k][c] - p[0][c] for c in range(3)] for k in (1, 2, 3)]
    return triple_sign(*e)


def triple_sign(a, b, c):
    det = (a[0] * (b[1] * c[2] - b[2] * c[1])
           - a[1] * (b[0] * c[2] - b[2] * c[0])
           + a[2] * (b[0] * c[1] - b[1] * c[0]))
    return 1 if det > 0 else -1


def volume_sign(nodes, conn):
    return hex_volume_sign(nodes, conn) if len(conn) in (8, 20) else tet_volume_sign(nodes, conn)


def deck_lines(title, nodes, cells, bodies, nsets, surfaces, fixed, step, load_set,
               material=(1000.0, 0.3), pair=None):
    """The lines of a one-step linear-elastic static deck.

    bodies: the body names in element-set order (ELSET=E<BODY>); fixed: the
    *BOUNDARY lines of the model (homogeneous); step: the step's *BOUNDARY
    lines (prescribed displacements); load_set: the node set whose total
    reaction the .dat file gets; pair: (slave surface, master surface,
    penalty slope) for a penalty surface-to-surface contact pair, or None for
    a plain elastic solve of the same mesh.
    """
    face_of = {}
    out = [f"** {title}: written by scripts/bench_peers.py", "*NODE, NSET=NALL"]
    for t in sorted(nodes):
        x, y, z = nodes[t]
        out.append(f"{t}, {x:.15g}, {y:.15g}, {z:.15g}")
    for body in bodies:
        mine = [c for c in cells if c[1] == body]
        for n in sorted({len(conn) for _, _, conn in mine}):
            if n not in CELL_TYPES:
                raise ValueError(f"body {body}: cells of {n} nodes are no type this deck writes")
            ctype, faces, mirror = CELL_TYPES[n]
            out.append(f"*ELEMENT, TYPE={ctype}, ELSET=E{body.upper()}")
            for tag, _, conn in mine:
                if len(conn) != n:
                    continue
                if volume_sign(nodes, conn) < 0:
                    conn = [conn[k] for k in mirror]
                ids = [str(c) for c in conn]
                # At most 16 entries on a line: the rest continues the next.
                out.append(f"{tag}, " + ", ".join(ids[:15]) + ("," if len(ids) > 15 else ""))
                if len(ids) > 15:
                    out.append(", ".join(ids[15:]))
                for k, f in enumerate(faces):
                    face_of[frozenset(conn[i] for i in f)] = (tag, k + 1)
    for name in nsets:
        tags = sorted(set(nsets[name]))
        out.append(f"*NSET, NSET={name}")
        out.extend(", ".join(str(t) for t in tags[i:i + 12]) for i in range(0, len(tags), 12))
    for name in surfaces if pair else []:
        out.append(f"*SURFACE, NAME={name}, TYPE=ELEMENT")
        for q in surfaces[name]:
            # The facet's corners: 3 of a tri3/tri6, 4 of a quad4/quad8/quad9.
            key = frozenset(q[:3] if len(q) in (3, 6) else q[:4])
            if key not in face_of:
                raise ValueError(f"surface {name}: facet {list(q)} is no face of a cell")
            tag, face = face_of[key]
            out.append(f"{tag}, S{face}")
    youngs, poisson = material
    out += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{youngs}, {poisson}"]
    out += [f"*SOLID SECTION, ELSET=E{b.upper()}, MATERIAL=STEEL" for b in bodies]
    if pair:
        slave, master, penalty = pair
        out += [
            "*SURFACE INTERACTION, NAME=HERTZ",
            "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
            f"{penalty:.6g}",
            "*CONTACT PAIR, INTERACTION=HERTZ, TYPE=SURFACE TO SURFACE",
            f"{slave}, {master}",
        ]
    out += ["*BOUNDARY"] + list(fixed)
    out += ["*STEP", "*STATIC", "1.0, 1.0", "*BOUNDARY"] + list(step)
    out += [f"*NODE PRINT, NSET={load_set}, TOTALS=ONLY", "RF"]
    if pair:
        out += ["*CONTACT FILE", "CSTR"]
    out += ["*END STEP"]
    return out


def write_deck(path, *args, **kwargs):
    with open(path, "w") as f:
        f.write("\n".join(deck_lines(*args, **kwargs)) + "\n")


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


def read_dat_total(path, set_name):
    """The last total force of a node set in a .dat file."""
    with open(path) as f:
        text = f.read()
    blocks = re.findall(r"total force \(fx,fy,fz\) for set " + re.escape(set_name)
                        + r" .*?\n\s*\n\s*(\S+)\s+(\S+)\s+(\S+)", text, re.I)
    if not blocks:
        return None
    return [float(v) for v in blocks[-1]]


def ccx_newton(sta):
    """(Newton iterations summed over the increments, increments) of a .sta file."""
    total, increments = 0, 0
    with open(sta) as f:
        for line in f:
            v = line.split()
            if len(v) == 7 and v[0].isdigit() and v[1].isdigit():
                total += int(v[3])
                increments += 1
    return total, increments
