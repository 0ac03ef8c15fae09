"""The two mesh sources of the peer benchmark, read into the plain data
ccx.py writes decks from: a Gmsh .msh 4.1 file (the line contact) and the
/mesh group of a contactlink result file (the sphere: the built-in
hertz-sphere mesh, nodes and cells in natural order).

Both give nodes {tag: (x, y, z)}, hexes [(tag, body, [8 node tags])],
facet sets {name: [[4 node tags]]} and node sets {name: [tags]}.
"""


def read_msh(path):
    """Nodes, hexes and the quads of each physical surface, by name, of an
    ASCII .msh 4.1 file (just what a hex8 mesh from Gmsh has)."""
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


def read_result_mesh(path):
    """Nodes, cells, facet sets and node sets of a contactlink result file's
    /mesh group (hex8, hex20, tet4 or tet10 cells, in VTK's node order, which
    is CalculiX's for these; tags are the 0-based rows plus one; facets
    carry their corners first)."""
    import h5py  # python3-h5py: only the cases built from a result file need it

    with h5py.File(path, "r") as f:
        m = f["mesh"]
        kind = m["cells"].attrs["cell_type"]
        if kind not in ("hex8", "hex20", "tet4", "tet10"):
            raise ValueError(f"{path}: cells are {kind}, not hex8, hex20, tet4 or tet10")
        xyz = m["nodes"][()]
        cells = m["cells"][()]
        body_of = m["cell_body"][()]
        bodies = [str(b) for b in m["cell_body"].attrs["bodies"]]
        nodes = {k + 1: tuple(float(c) for c in p) for k, p in enumerate(xyz)}
        cells = [(k + 1, bodies[body_of[k]], [int(t) + 1 for t in c])
                 for k, c in enumerate(cells)]
        facets = {name: [[int(t) + 1 for t in q if t >= 0] for q in g["nodes"][()]]
                  for name, g in m["facet_sets"].items()}
        node_sets = {name: [int(t) + 1 for t in d[()]] for name, d in m["node_sets"].items()}
    return nodes, cells, facets, node_sets
