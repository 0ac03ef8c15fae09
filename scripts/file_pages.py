#!/usr/bin/python3
"""File-backed resident pages per library of running processes (docs/scaling.md, memory).

usage: file_pages.py SUBSTRING [SECONDS]

Polls every process whose executable's absolute path contains SUBSTRING
(e.g. `target/release/contactlink`)
for SECONDS (default 600) or until no such process is left after one was
seen, and at each process's highest VmRSS sample keeps /proc/PID/smaps. Then
prints, per process, the file-backed part of its resident set (Rss less
Anonymous of each file mapping: library code and read-only data, one copy
in the page cache for all the ranks of a node but counted in each rank's
VmHWM) grouped by library family, largest first. Start it, then the run:

  python3 scripts/file_pages.py target/release/contactlink &
  mpirun -n 4 target/release/contactlink run scripts/scenes/sphere-no-contact.toml
"""
import collections
import os
import re
import sys
import time

FAMILIES = [
    ("Trilinos (PETSc's ML; never called)", r"libtrilinos_"),
    ("TLS, crypto, Kerberos, curl (HDF5, MPI)", r"gnutls|crypto|ssl|p11-kit|nettle|hogweed|krb5|gssapi|"
                                                 r"curl|ldap|sasl|ssh2|rtmp|nghttp|tasn1|unistring|idn|gmp"),
    ("MPI (Open MPI, PMIx, hwloc, libevent)", r"libmpi|open-pal|open-rte|pmix|hwloc|event|/mca_"),
    ("MPI shared memory (/dev/shm, Open MPI's vader)", r"^/dev/shm/"),
    ("PETSc", r"libpetsc"),
    ("BLAS, LAPACK", r"openblas|liblapack|libblas"),
    ("HYPRE, MUMPS, SuperLU, ScaLAPACK, METIS, Scotch", r"HYPRE|mumps|superlu|scalapack|metis|scotch"),
    ("C, C++, Fortran runtimes", r"libc\.so|libstdc\+\+|libm\.so|libgfortran|libgcc_s|libquadmath|libgomp|ld-linux"),
]


def matching(substring):
    for p in os.listdir("/proc"):
        if not p.isdigit():
            continue
        try:
            exe = os.readlink(f"/proc/{p}/exe")
        except OSError:
            continue
        if substring in exe:
            yield int(p)


def file_backed(pid):
    """Per file mapping (path): resident KiB less its anonymous (copied-on-write) KiB."""
    out = collections.Counter()
    name = None
    with open(f"/proc/{pid}/smaps") as f:
        for line in f:
            parts = line.split()
            if re.match(r"^[0-9a-f]+-[0-9a-f]+$", parts[0]):
                name = parts[5] if len(parts) > 5 and parts[5].startswith("/") else None
            elif name and parts[0] == "Rss:":
                out[name] += int(parts[1])
            elif name and parts[0] == "Anonymous:":
                out[name] -= int(parts[1])
    return out


def family(path):
    for label, pattern in FAMILIES:
        if re.search(pattern, path):
            return label
    return os.path.basename(path) if "contactlink" in path else "other"


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    substring = sys.argv[1]
    end = time.time() + (float(sys.argv[2]) if len(sys.argv) > 2 else 600.0)
    best = {}
    while time.time() < end:
        pids = list(matching(substring))
        if best and not pids:
            break
        for pid in pids:
            try:
                rss = next(int(l.split()[1]) for l in open(f"/proc/{pid}/status") if l.startswith("VmRSS"))
                if pid not in best or rss > best[pid][0]:
                    best[pid] = (rss, file_backed(pid))
            except (OSError, StopIteration):
                pass
        time.sleep(0.3)
    for pid, (rss, files) in sorted(best.items()):
        groups = collections.Counter()
        for path, kib in files.items():
            groups[family(path)] += kib
        total = sum(groups.values())
        print(f"pid {pid}: highest VmRSS sampled {rss / 1024:.1f} MiB, file-backed {total / 1024:.1f} MiB")
        for label, kib in groups.most_common():
            print(f"  {kib / 1024:6.1f}  {label}")


if __name__ == "__main__":
    main()
