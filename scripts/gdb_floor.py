"""A rank's peak memory without GAMG's set-up (docs/scaling.md, memory).

A gdb Python script: when PCSetUp_GAMG returns (the first time), it
prints the process's VmHWM and VmRSS and resets the high-water mark to the
current resident set (`echo 5 > /proc/PID/clear_refs`; getrusage's
ru_maxrss, which the program's `memory:` line prints, follows it). The
peak the run then reports is the highest the rank reached after the
preconditioner's set-up: the Krylov solve and the end of the run. That is
the floor which no saving inside GAMG's set-up can go below. Run it on
every rank of an MPI job, e.g. 4 ranks:

  mpirun -n 4 gdb -q -batch -x scripts/gdb_floor.py \\
      --args target/release/contactlink run scripts/scenes/sphere-no-contact.toml

Each rank prints `rank R at the return of PCSetUp_GAMG: HWM ... RSS ...;
reset -> HWM ...` (R from OMPI_COMM_WORLD_RANK), then the run's own
`memory:` lines carry the peaks after the reset.
"""
import os

import gdb


def status():
    pid = gdb.selected_inferior().pid
    out = {}
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            key, _, value = line.partition(":")
            if key in ("VmHWM", "VmRSS"):
                out[key] = int(value.split()[0]) / 1024
    return out


class Return(gdb.FinishBreakpoint):
    """Stops when the PCSetUp_GAMG frame it was made in returns."""

    def stop(self):
        before = status()
        with open(f"/proc/{gdb.selected_inferior().pid}/clear_refs", "w") as f:
            f.write("5")
        after = status()
        rank = os.environ.get("OMPI_COMM_WORLD_RANK", "?")
        print(f"rank {rank} at the return of PCSetUp_GAMG: HWM {before['VmHWM']:.1f} "
              f"RSS {before['VmRSS']:.1f}; reset -> HWM {after['VmHWM']:.1f}", flush=True)
        return False


class Entry(gdb.Breakpoint):
    def stop(self):
        Return(gdb.newest_frame(), internal=True)
        self.enabled = False
        return False


gdb.execute("set pagination off")
gdb.execute("set breakpoint pending on")
Entry("PCSetUp_GAMG")
gdb.execute("run")
