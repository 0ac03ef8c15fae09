#!/usr/bin/python3
"""Plots a contact pressure profile from a contactlink result file (h5py +
matplotlib), as an example of reading the file without the Rust library.

usage: plot_pressure.py RESULT.h5 [OUT.png] [--pair NAME] [--step N]

The profile is drawn against s, the distance from the contact centre in the
x-y plane (|x| for a line contact along y, √(x² + y²) otherwise): the
pressure at the slave quadrature points (`/steps/<step>/contact/<pair>/
pressure` at `.../points`) and the nodal contact pressure on the pair's slave
nodes (`/steps/<step>/contact_pressure` at the deformed node positions
`/mesh/nodes + /steps/<step>/displacement`, the slave nodes from
`/contact_pairs` and `/mesh/facet_sets/<slave>/nodes`). When the run compared
itself against Hertz (a `/hertz` group), the closed-form profile for the
step's contact force is drawn too. Defaults: the last step, the first pair,
OUT.png next to RESULT.h5.

For example, after `target/release/examples/hertz_cylinder 0.25 out/h.h5`:
    MPLBACKEND=Agg python3 examples/plot_pressure.py out/h.h5
"""
import argparse
import math
import sys
from pathlib import Path

import h5py
import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

# The names of the result file, as src/output/layout.rs spells them.
MESH = "mesh"
STEPS = "steps"
CONTACT_PAIRS = "contact_pairs"
HERTZ = "hertz"
NODES = "nodes"
FACET_SETS = "facet_sets"
FACET_NODES = "nodes"
DISPLACEMENT = "displacement"
CONTACT_PRESSURE = "contact_pressure"
CONTACT = "contact"
PAIR_POINTS = "points"
PAIR_PRESSURE = "pressure"
PAIR_FORCE = "force"
HERTZ_KIND_ATTR = "kind"
HERTZ_RADIUS_ATTR = "radius"
HERTZ_EFFECTIVE_MODULUS_ATTR = "effective_modulus"
HERTZ_THICKNESS_ATTR = "thickness"
HERTZ_KIND_LINE = "line"


def pair_dataset(pair, name):
    """contact/<pair>/<name>, relative to a step group."""
    return f"{CONTACT}/{pair}/{name}"


def step_group_name(index):
    """The step group's name: six digits, zero-padded."""
    return f"{index:06d}"


def hertz_profile(h5, force):
    """(half-width, p0, is_line) of the Hertz solution for the step's force."""
    attrs = h5[HERTZ].attrs
    kind = attrs[HERTZ_KIND_ATTR]
    kind = kind.decode() if isinstance(kind, bytes) else str(kind)
    radius = float(attrs[HERTZ_RADIUS_ATTR])
    e_star = float(attrs[HERTZ_EFFECTIVE_MODULUS_ATTR])
    total = float(np.linalg.norm(force))
    if kind == HERTZ_KIND_LINE:
        load = total / float(attrs[HERTZ_THICKNESS_ATTR])
        b = math.sqrt(4.0 * load * radius / (math.pi * e_star))
        return b, 2.0 * load / (math.pi * b), True
    a = (3.0 * total * radius / (4.0 * e_star)) ** (1.0 / 3.0)
    return a, 3.0 * total / (2.0 * math.pi * a * a), False


def distance(xyz, line):
    return np.abs(xyz[:, 0]) if line else np.hypot(xyz[:, 0], xyz[:, 1])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("result")
    ap.add_argument("png", nargs="?")
    ap.add_argument("--pair")
    ap.add_argument("--step", type=int)
    a = ap.parse_args()
    path = Path(a.result)
    if not path.is_file():
        sys.exit(f"plot_pressure: {path}: no such file")
    with h5py.File(path, "r") as h5:
        if STEPS not in h5 or CONTACT_PAIRS not in h5:
            sys.exit(f"plot_pressure: {path}: not a contactlink result file with contact pairs")
        steps = sorted(h5[STEPS].keys())
        if not steps:
            sys.exit(f"plot_pressure: {path}: holds no steps")
        step = steps[-1] if a.step is None else step_group_name(a.step)
        if step not in h5[STEPS]:
            sys.exit(f"plot_pressure: {path}: no step {a.step} (steps {int(steps[0])}..{int(steps[-1])})")
        pairs = sorted(h5[CONTACT_PAIRS].attrs.keys())
        pair = a.pair or pairs[0]
        if pair not in pairs:
            sys.exit(f"plot_pressure: {path}: no pair '{pair}' (pairs: {', '.join(pairs)})")
        slave = h5[CONTACT_PAIRS].attrs[pair]
        slave = slave.decode() if isinstance(slave, bytes) else str(slave)
        g = h5[STEPS][step]
        points = g[pair_dataset(pair, PAIR_POINTS)][()]
        pressure = g[pair_dataset(pair, PAIR_PRESSURE)][()].ravel()
        force = g[pair_dataset(pair, PAIR_FORCE)][()].ravel()
        nodes = np.unique(h5[f"{MESH}/{FACET_SETS}/{slave}/{FACET_NODES}"][()].ravel())
        xyz = h5[f"{MESH}/{NODES}"][()][nodes] + g[DISPLACEMENT][()][nodes]
        nodal = g[CONTACT_PRESSURE][()].ravel()[nodes]
        hertz = hertz_profile(h5, force) if HERTZ in h5 else None

    line = hertz[2] if hertz else bool(np.ptp(points[:, 1]) > 10 * np.ptp(points[:, 0]))
    s_points, s_nodes = distance(points, line), distance(xyz, line)
    loaded = s_nodes[nodal > 0]
    if loaded.size == 0:
        sys.exit(f"plot_pressure: {path}: pair '{pair}' carries no pressure at step {int(step)}")
    # Twice the loaded zone (or the Hertz width) is enough to see the edge.
    reach = 2.0 * max(loaded.max(), hertz[0] if hertz else 0.0)
    near_p, near_n = s_points <= reach, s_nodes <= reach

    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(s_points[near_p], pressure[near_p], ".", ms=3, alpha=0.5,
            label="quadrature points pN")
    ax.plot(s_nodes[near_n], nodal[near_n], "o", ms=4, mfc="none", label="nodal contact pressure")
    if hertz:
        b, p0, _ = hertz
        s = np.linspace(0.0, b, 200)
        ax.plot(s, p0 * np.sqrt(1.0 - (s / b) ** 2), "k-", lw=1,
                label=f"Hertz (p0 = {p0:.4g}, {'b' if line else 'a'} = {b:.4g})")
    ax.set_xlabel("|x|" if line else "√(x² + y²)")
    ax.set_ylabel("contact pressure")
    ax.set_title(f"{path.name}: pair '{pair}', step {int(step)}")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = Path(a.png) if a.png else path.with_suffix(".png")
    fig.savefig(out, dpi=120)
    print(f"plot_pressure: pair '{pair}', step {int(step)}: {near_n.sum()} slave nodes, "
          f"peak nodal pressure {nodal.max():.4g}"
          + (f" (Hertz p0 {hertz[1]:.4g})" if hertz else "") + f" -> {out}")


if __name__ == "__main__":
    main()
