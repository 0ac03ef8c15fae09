"""CalculiX side of the peer benchmark: a deck from a hex8 mesh and what its
output files say (nodal contact pressure, reaction totals, Newton
iterations).

The mesh is given as plain Python data, whatever file it came from:
nodes {tag: (x, y, z)}, hexes [(tag, body, [8 node tags])] with the nodes
numbered as CalculiX's C3D8 (bottom face counter-clockwise seen from the
top, then the top face), node sets {name: [tags]} and surfaces
{name: [[4 node tags], ...]} (each quad a face of some hex).
"""
import re

# C3D8 faces (CalculiX/Abaqus numbering S1..S6) as local node indices.
HEX_FACES = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1),
             (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)]


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


def deck_lines(title, nodes, hexes, bodies, nsets, surfaces, fixed, step, load_set,
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
        out.append(f"*ELEMENT, TYPE=C3D8, ELSET=E{body.upper()}")
        for tag, b, conn in hexes:
            if b != body:
                continue
            if hex_volume_sign(nodes, conn) < 0:
                conn = conn[4:] + conn[:4]
            out.append(f"{tag}, " + ", ".join(str(c) for c in conn))
            for k, f in enumerate(HEX_FACES):
                face_of[frozenset(conn[i] for i in f)] = (tag, k + 1)
    for name in nsets:
        tags = sorted(set(nsets[name]))
        out.append(f"*NSET, NSET={name}")
        out.extend(", ".join(str(t) for t in tags[i:i + 12]) for i in range(0, len(tags), 12))
    for name in surfaces if pair else []:
        out.append(f"*SURFACE, NAME={name}, TYPE=ELEMENT")
        for q in surfaces[name]:
            key = frozenset(q)
            if key not in face_of:
                raise ValueError(f"surface {name}: facet {list(q)} is no face of a hexahedron")
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
