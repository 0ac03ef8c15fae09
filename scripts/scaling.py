#!/usr/bin/python3
"""Strong scaling of a 3D contact solve on the iterative path (`make scaling`).

usage: scaling.py [--case sphere|sphere-links|cylinder-direct] [--repeats 3] [--four]
                  [--no-plain] [--out bench-results] [--table PATH | --no-table]
                  [-- extra contactlink args]

Default case, `sphere`: hertz-sphere at its default mesh (h = 0.25,
167,013 DOFs), one load step, above `direct_max_dofs`, so GMRES + GAMG
with the rigid-body near-null space (the iterative path), the default
formulation (the mortar; `sphere-links`: the links, with the
Eisenstat-Walker forcing capped at 0.01, see CASES), on 1 and 2 ranks
(median of --repeats runs each, run alternately so both see the same
conditions), and with --four once on 4 ranks oversubscribed (2 cores:
correctness, not speed). Next to it, the ceiling of the machine: the same
mesh without its contact pair (scripts/scenes/sphere-no-contact.toml, one
CG + GAMG solve) on 1 and 2 ranks. On a 2-core machine two ranks share the
memory bandwidth, and a sparse solve is bandwidth-bound, so the plain
solve's 2-rank efficiency is what the contact solve can reach at best.
`cylinder-direct`: the earlier case, hertz-cylinder mesh.level=1 (152,316
DOFs) on the sparse direct path (the scene raises direct_max_dofs; MUMPS).

Prints one table (ranks, DOFs, Newton / Uzawa / KSP iterations, solve
wall seconds, whole-run CPU seconds summed over the ranks, efficiency
T1/(P*TP), peak resident memory of the largest and smallest rank, the
work per rank and the halo), a table of the time per phase, and the
headline lines. Writes <out>/scaling.csv and the table's rows into
docs/tables/scaling-<case>.md (`make scaling`; with extra contactlink
arguments, e.g. a smaller mesh, give another --table or --no-table). The load average is printed with
every run: wall seconds only mean something on a quiet machine (load
average below 1 at the start); iteration counts, memory and the work per
rank mean something always. When 1 and 2 ranks do not take the same
Newton/Uzawa/KSP iterations the efficiency mixes parallel speed with a
different solve path, and the script says so; the per-iteration
efficiency (seconds per Newton iteration) is printed beside it.

Each run's result file is <out>/scaling-run-<P>-ranks.h5 (the next run on
P ranks overwrites it). Set MPIRUN to change the
launcher (a multi-node launcher needs its own OMPI_MCA_btl, e.g. self,vader,tcp).
"""
import argparse
import csv
import os
import re

import benchrun

DONE = re.compile(r"done: \d+ steps, (\d+) Newton iterations, (\d+) DOFs on (\d+) rank\(s\), ([0-9.]+) s")
PHASES = re.compile(r"time per phase \(largest over ranks\): (.*)")
PHASE = re.compile(r"([A-Za-z ]+?) ([0-9.]+) s \([0-9.]+ %\)")
HERTZ = re.compile(r"\(([+-]?[0-9.]+) %\).*\(([+-]?[0-9.]+) %\)")
MEMORY = re.compile(r"memory: peak resident ([0-9.]+) MiB on the largest rank, ([0-9.]+) MiB on the smallest")
BALANCE = re.compile(r"partition: cells per rank (\d+)/(\d+) \(largest/smallest\), contact slave facets per rank (\d+)/(\d+)")
HALO = re.compile(r"halo \(all ranks\): (\d+) ghost displacement values per residual, (\d+) ghost multiplier")

PHASE_NAMES = ["bulk assembly", "contact search", "contact assembly", "linear solve",
               "halo exchange", "Uzawa update", "output", "other"]

CASES = {
    # name: (scene, args, plain scene or None, description)
    # The forcing ceiling at 0.01 instead of the program's 0.1: with the
    # looser one each inexact Newton step differs between 1 and 2 ranks (GAMG
    # aggregates per rank) by up to a tenth, and the two runs took different
    # paths through the contact set (43 against 25 Newton iterations, 274
    # against 250 GMRES); at 0.01 they stay within one Newton iteration per
    # Uzawa iteration (18 against 16 Newton, 362 against 335 GMRES, 7 Uzawa
    # each, the same Hertz errors).
    "sphere-links": ("hertz-sphere", ["--set", "contact.formulation=links",
                                      "-snes_ksp_ew_rtolmax", "0.01"],
                     "scripts/scenes/sphere-no-contact.toml",
                     "hertz-sphere h = 0.25, links, iterative path (GMRES + GAMG, -snes_ksp_ew_rtolmax 0.01)"),
    # The default formulation, the mortar: its GMRES solves go to a fixed
    # 1e-4 (no Eisenstat-Walker forcing), the same on 1 and 2 ranks.
    "sphere": ("hertz-sphere", [], "scripts/scenes/sphere-no-contact.toml",
               "hertz-sphere h = 0.25, mortar (the default), iterative path (GMRES + GAMG to 1e-4)"),
    "cylinder-direct": ("hertz-cylinder", ["--set", "mesh.level=1"], None,
                        "hertz-cylinder level=1, direct path (MUMPS)"),
}


def load():
    return benchrun.load()


def run(np_, scene, args):
    cmd = benchrun.launcher(np_, os.environ.get("MPIRUN", "mpirun --allow-run-as-root --oversubscribe")) + \
        ["target/release/contactlink", "run", scene, "-o", f"{OUT}/scaling-run-{np_}-ranks.h5"] + args
    load_before = load()
    # CONTACTLINK_MEMORY for the `partition:` balance line (the memory
    # checkpoints come along).
    t = benchrun.run(cmd, env=benchrun.mpi_env(CONTACTLINK_MEMORY="1"), check=False)
    wall, cpu, out = t.wall, t.cpu, t.text
    d = DONE.search(out)
    if t.returncode != 0 or not d:
        # The memory checkpoints (stderr) would bury the error message.
        lines = [ln for ln in out.splitlines() if not ln.startswith("memory: rank")]
        tail = "\n".join(lines[-30:])
        raise SystemExit(f"{' '.join(cmd)} failed (exit code {t.returncode}):\n{tail}")
    # Iterations from the run's machine output (every solve path writes them).
    h5 = f"{OUT}/scaling-run-{np_}-ranks.h5"
    counts = benchrun.totals(h5)
    record = benchrun.run_attrs(h5)
    h = HERTZ.search(out.split("Hertz:")[-1]) if "Hertz:" in out else None
    halo = HALO.search(out)
    mem = MEMORY.search(out)
    bal = BALANCE.search(out)
    phases = {}
    ph = PHASES.search(out)
    if ph:
        for name, secs in PHASE.findall(ph[1]):
            phases[name.strip(" ,")] = float(secs)
    return {
        "ranks": np_, "dofs": int(d[2]), "newton": int(d[1]), "seconds": float(d[4]),
        "uzawa": counts["uzawa"],
        "ksp": counts["linear"],
        "pc_builds": record.get("preconditioner_builds", 0),
        "run_wall_seconds": wall, "cpu_seconds": cpu,
        "load_start": load_before, "load_end": load(),
        "cells_largest": int(bal[1]) if bal else 0, "cells_smallest": int(bal[2]) if bal else 0,
        "slave_largest": int(bal[3]) if bal else 0, "slave_smallest": int(bal[4]) if bal else 0,
        "e_p0": float(h[1]) if h else None, "e_b": float(h[2]) if h else None,
        "peak_largest_mib": float(mem[1]) if mem else 0.0,
        "peak_smallest_mib": float(mem[2]) if mem else 0.0,
        "halo_u": int(halo[1]) if halo else 0, "halo_lambda": int(halo[2]) if halo else 0,
        **{f"t_{k}": phases.get(k, 0.0) for k in PHASE_NAMES},
    }


def series(kind, scene, args, ranks, repeats):
    """Median of `repeats` runs per rank count, the rank counts alternating
    (1, 2, 1, 2, ...) so that a change of load hits both alike."""
    def one(n):
        r = run(n, scene, args)
        print(f"  {kind:<8} {n} rank(s): {r['seconds']:7.2f} s solve, "
              f"{r['cpu_seconds']:7.2f} s CPU, Newton {r['newton']}, KSP {r['ksp']}, "
              f"load average {r['load_start']:.1f} -> {r['load_end']:.1f}", flush=True)
        return r

    runs = benchrun.alternate({n: (lambda n=n: one(n)) for n in ranks}, repeats)
    rows = []
    for n in ranks:
        rs = runs[n]
        row = benchrun.medians(rs, ["seconds", "run_wall_seconds", "cpu_seconds", "peak_largest_mib",
                                    "peak_smallest_mib"] + [f"t_{p}" for p in PHASE_NAMES])
        row.update(kind=kind, repeats=len(rs), seconds_spread=benchrun.spread(r["seconds"] for r in rs))
        row["load_start"] = max(r["load_start"] for r in rs)
        row["load_end"] = max(r["load_end"] for r in rs)
        # Iteration counts of every repeat (they should not vary).
        row["counts_stable"] = all((r["newton"], r["uzawa"], r["ksp"]) == (rs[0]["newton"], rs[0]["uzawa"], rs[0]["ksp"])
                                   for r in rs)
        rows.append(row)
    return rows


def efficiencies(rows):
    one = next(r for r in rows if r["ranks"] == 1)
    for r in rows:
        p = r["ranks"]
        r["efficiency"] = one["seconds"] / (p * r["seconds"])
        r["cpu_efficiency"] = one["cpu_seconds"] / r["cpu_seconds"]
        # Seconds per Newton iteration: the same ratio with the solve path
        # factored out when the counts differ.
        r["newton_efficiency"] = (one["seconds"] / one["newton"]) / (p * r["seconds"] / r["newton"])
        r["same_counts"] = (r["newton"], r["uzawa"], r["ksp"]) == (one["newton"], one["uzawa"], one["ksp"])


def count(v):
    return "-" if v is None else str(v)


def table(rows):
    head = (f"{'kind':<8} {'ranks':>5} {'DOFs':>8} {'Newton':>6} {'Uzawa':>5} {'KSP':>5} {'solve s':>8} "
            f"{'CPU s':>8} {'eff':>6} {'eff/Newton':>10} {'peak MiB L/S':>13} {'cells L/S':>13} "
            f"{'slave L/S':>9} {'halo u/λ':>10} {'p0, radius err %':>17} {'load':>9}")
    print(head)
    print("-" * len(head))
    for r in rows:
        note = " (oversubscribed: correctness only)" if r.get("oversubscribed") else ""
        eff = "-" if r["ranks"] == 1 else f"{100 * r['efficiency']:.0f} %"
        effn = "-" if r["ranks"] == 1 else f"{100 * r['newton_efficiency']:.0f} %"
        hertz = "-" if r["e_p0"] is None else f"{r['e_p0']:+.3f}, {r['e_b']:+.3f}"
        print(f"{r['kind']:<8} {r['ranks']:>5} {r['dofs']:>8} {r['newton']:>6} {count(r['uzawa']):>5} {count(r['ksp']):>5} "
              f"{r['seconds']:>8.2f} {r['cpu_seconds']:>8.2f} {eff:>6} {effn:>10} "
              f"{r['peak_largest_mib']:>6.0f}/{r['peak_smallest_mib']:<6.0f} "
              f"{r['cells_largest']:>6}/{r['cells_smallest']:<6} {r['slave_largest']:>4}/{r['slave_smallest']:<4} "
              f"{r['halo_u']:>5}/{r['halo_lambda']:<4} {hertz:>17} {r['load_start']:>4.1f}-{r['load_end']:<4.1f}{note}")


def phase_table(rows):
    print("time per phase, seconds (largest over ranks; median of the repeats):")
    print(f"{'kind':<8} {'ranks':>5} " + " ".join(f"{p:>12}" for p in PHASE_NAMES))
    for r in rows:
        print(f"{r['kind']:<8} {r['ranks']:>5} " + " ".join(f"{r['t_' + p]:>12.2f}" for p in PHASE_NAMES))


def main():
    global OUT
    ap = argparse.ArgumentParser()
    ap.add_argument("--case", choices=sorted(CASES), default="sphere")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--four", action="store_true", help="also one run on 4 ranks, oversubscribed")
    ap.add_argument("--no-plain", action="store_true", help="skip the plain elastic ceiling")
    ap.add_argument("--out", default="bench-results")
    ap.add_argument("extra", nargs="*", help="more contactlink arguments (after --)")
    ap.add_argument("--table", default=None,
                    help="markdown table to update (default docs/tables/scaling-CASE.md)")
    ap.add_argument("--no-table", action="store_true", help="write no table file")
    a = ap.parse_args()
    prov = benchrun.Provenance("scaling")
    OUT = a.out
    os.makedirs(a.out, exist_ok=True)
    scene, args, plain, what = CASES[a.case]
    args = args + a.extra
    if a.extra:
        what += " with " + " ".join(a.extra)
    quiet = load() < 1.0
    print(f"strong scaling: {what}; load average {load():.2f} at the start"
          + ("" if quiet else " (not a quiet machine: the seconds below are not meaningful, the counts are)"),
          flush=True)
    rows = series("contact", scene, args, [1, 2], a.repeats)
    if a.four:
        four = series("contact", scene, args, [4], 1)[0]
        four["oversubscribed"] = True
        rows.append(four)
    efficiencies(rows)
    plain_rows = []
    if plain and not a.no_plain:
        plain_rows = series("plain", plain, ["-ksp_converged_reason"] + a.extra, [1, 2], a.repeats)
        efficiencies(plain_rows)
    everything = rows + plain_rows
    keys = ["kind", "ranks", "dofs", "repeats", "newton", "uzawa", "ksp", "pc_builds", "seconds", "efficiency",
            "newton_efficiency", "run_wall_seconds", "cpu_seconds", "cpu_efficiency",
            "peak_largest_mib", "peak_smallest_mib", "cells_largest", "cells_smallest",
            "slave_largest", "slave_smallest", "halo_u", "halo_lambda", "e_p0", "e_b",
            "load_start", "load_end", "oversubscribed"] + [f"t_{p}" for p in PHASE_NAMES]
    with open(f"{a.out}/scaling.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(everything)
    print()
    table(everything)
    print()
    phase_table(everything)
    print()
    one, two = rows[0], rows[1]
    hertz = [r for r in rows if r["e_p0"] is not None]
    if hertz:
        spread = max(max(abs(r["e_p0"] - one["e_p0"]), abs(r["e_b"] - one["e_b"])) for r in hertz)
        print(f"Hertz errors on 1 rank: p0 {one['e_p0']:+.3f} %, radius {one['e_b']:+.3f} %; every rank count within "
              f"{spread:.3f} percentage points of them")
    apart = max(abs(one[k] - two[k]) / max(one[k], 1) if one[k] is not None and two[k] is not None else 1.0
                for k in ("newton", "uzawa", "ksp"))
    if two["same_counts"]:
        counts = "the same"
    elif apart <= 0.15:
        counts = (f"nearly the same, within {100 * apart:.0f} %: the efficiency includes that difference;"
                  " the per-Newton-iteration figure factors it out")
    else:
        counts = (f"DIFFERENT, {100 * apart:.0f} % apart: the efficiency mixes parallel speed with a different"
                  " solve path; see the per-Newton-iteration figure")
    print(f"iterations, 1 against 2 ranks: Newton {one['newton']}/{two['newton']}, "
          f"Uzawa {count(one['uzawa'])}/{count(two['uzawa'])}, KSP {count(one['ksp'])}/{count(two['ksp'])} ({counts})")
    if not all(r["counts_stable"] for r in everything):
        print("warning: the iteration counts varied between repeats of one rank count")
    print(f"2-rank parallel efficiency T1/(2*T2), contact, {one['dofs']} DOFs, {what}: "
          f"{100 * two['efficiency']:.0f} % (target >= 85 %; median of {a.repeats}: T1 {one['seconds']:.2f} s, "
          f"T2 {two['seconds']:.2f} s; per Newton iteration {100 * two['newton_efficiency']:.0f} %)")
    if plain_rows:
        p1, p2 = plain_rows
        print(f"ceiling of this machine, plain elastic solve of the same mesh (CG + GAMG, {p1['ksp']}/{p2['ksp']} "
              f"CG iterations): {100 * p2['efficiency']:.0f} % (T1 {p1['seconds']:.2f} s, T2 {p2['seconds']:.2f} s)")
    print(f"2-rank CPU-time efficiency CPU1/CPU2 (whole runs, summed over the ranks; MPI's busy waiting counts): "
          f"{100 * two['cpu_efficiency']:.0f} % ({one['cpu_seconds']:.2f} s against {two['cpu_seconds']:.2f} s)")
    print(f"work per rank on 2 ranks (largest/smallest): cells {two['cells_largest']}/{two['cells_smallest']}, "
          f"contact slave facets {two['slave_largest']}/{two['slave_smallest']}")
    print(f"peak memory per rank: 1 rank {one['peak_largest_mib']:.0f} MiB; 2 ranks largest "
          f"{two['peak_largest_mib']:.0f} MiB, smallest {two['peak_smallest_mib']:.0f} MiB "
          f"({two['peak_largest_mib'] / one['peak_largest_mib']:.2f}x of 1 rank)")
    print(f"load average during the runs: at most {max(r['load_end'] for r in everything):.1f}"
          + ("" if quiet else "; re-run on a quiet machine for meaningful seconds"))
    print(f"scaling: {a.out}/scaling.csv")
    if not a.no_table:
        cells = []
        for r in everything:
            eff = "" if r["ranks"] == 1 else f"{100 * r['efficiency']:.0f} % (per Newton {100 * r['newton_efficiency']:.0f} %)"
            cells.append([r["kind"], str(r["ranks"]), f"{r['dofs']:,}",
                          f"{r['newton']} / {count(r['uzawa'])} / {count(r['ksp'])}",
                          str(r["seconds_spread"]), f"{r['cpu_seconds']:.2f}", eff,
                          f"{r['peak_largest_mib']:.0f} / {r['peak_smallest_mib']:.0f}"])
        benchrun.write_table(
            a.table or benchrun.table_path(f"scaling-{a.case}"), f"Strong scaling: {what}",
            ["kind", "ranks", "DOFs", "Newton / Uzawa / KSP", "solve s, median (min–max)",
             "whole-run CPU s", "efficiency T1/(P·TP)", "peak MiB largest / smallest"],
            cells, prov.text(f"medians of {a.repeats}, rank counts alternated"), key=2,
            intro="Contact: the scene as shipped; plain: the same mesh without its contact pair "
                  "(one CG + GAMG solve), the machine's ceiling for a bandwidth-bound solve.")


OUT = "bench-results"

if __name__ == "__main__":
    main()
