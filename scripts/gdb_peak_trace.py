"""Where a rank's resident memory peaks inside PETSc (docs/scaling.md, memory).

A gdb Python script: breakpoints on PETSc's matrix, product and set-up
functions print the process's VmHWM, VmRSS and RssFile (/proc/PID/status)
at each entry, with the two callers, and let the run go on. Run it on one
rank of an MPI job, e.g. rank 0 of 4:

  mpirun -n 1 gdb -q -batch -x scripts/gdb_peak_trace.py \\
      --args target/release/contactlink run scripts/scenes/sphere-no-contact.toml \\
    : -n 3 target/release/contactlink run scripts/scenes/sphere-no-contact.toml

MatAssemblyEnd is printed only when the resident set moved by more than
0.5 MiB since the last line (it is called often). Lines below 100 MiB of
peak are skipped (the set-up before the first solve).
"""
import gdb

FUNCS = ["PCSetUp_GAMG", "MatCreateGraph", "MatCoarsenApply", "MatMatMult", "MatPtAP",
         "MatTransposeMatMult", "MatProductSymbolic", "MatProductNumeric", "MatAssemblyEnd",
         "MatDuplicate", "MatConvert", "MatAYPX", "MatDiagonalScale", "KSPSolve",
         "MatProductClear", "MatTranspose", "MatCreateAIJ", "MatMPIAIJGetLocalMat",
         "MatHeaderReplace", "PCSetUp_MG"]
MIN_PEAK_MIB = 100
last_rss = [0.0]


def status():
    pid = gdb.selected_inferior().pid
    out = {}
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            key, _, value = line.partition(":")
            if key in ("VmHWM", "VmRSS", "RssFile"):
                out[key] = int(value.split()[0]) / 1024
    return out


def caller(frame, depth):
    for _ in range(depth):
        frame = frame.older() if frame else None
    return (frame.name() if frame else None) or "?"


class Trace(gdb.Breakpoint):
    def stop(self):
        s = status()
        moved = abs(s["VmRSS"] - last_rss[0]) > 0.5
        if s["VmHWM"] >= MIN_PEAK_MIB and (self.location != "MatAssemblyEnd" or moved):
            f = gdb.selected_frame()
            print(f"HWM {s['VmHWM']:.1f} RSS {s['VmRSS']:.1f} file {s['RssFile']:.1f} "
                  f"at {self.location} <- {caller(f, 1)} <- {caller(f, 2)}", flush=True)
        last_rss[0] = s["VmRSS"]
        return False


gdb.execute("set pagination off")
gdb.execute("set breakpoint pending on")
for name in FUNCS:
    Trace(name)
gdb.execute("run")
