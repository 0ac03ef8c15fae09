"""What every benchmark script shares: running a command N times (min /
median / max of its wall and CPU seconds), reading a run's machine output,
and writing a table into docs/tables/ with its provenance.

A table file (docs/tables/<name>.md) lists the runs that measured its rows
(date, machine, git commit, load average, the exact command) and one row
per case, each marked with the run that measured it. A script writes its
rows with `write_table`: a row whose key (its first cells) is already in
the file is replaced, other rows stay, and runs no row refers to any more
are dropped. So re-running a benchmark, or a subset of its cases,
replaces exactly the figures it measured; history lives in git.

Imported by the scripts next to it (`import benchrun`); run directly,
`python3 scripts/benchrun.py TABLE.md` prints a table file's runs.
"""
import csv
import os
import platform
import re
import resource
import shlex
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass, field

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TABLES = os.path.join(ROOT, "docs", "tables")


# --- provenance ---------------------------------------------------------------


def today():
    return time.strftime("%Y-%m-%d")


def os_name():
    try:
        with open("/etc/os-release") as f:
            for line in f:
                if line.startswith("PRETTY_NAME="):
                    return line.split("=", 1)[1].strip().strip('"')
    except OSError:
        pass
    return platform.system()


def machine():
    """`host (N cores, OS)` of this machine."""
    return f"host `{platform.node()}` ({os.cpu_count()} cores, {os_name()})"


def commit():
    """The checked-out commit, `-dirty` when tracked files differ from it."""
    def git(*args):
        p = subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True)
        return p.stdout.strip() if p.returncode == 0 else ""
    head = git("rev-parse", "--short", "HEAD") or "unknown"
    # Changes to the documentation (the tables themselves, the README) do
    # not make a run dirty: only what is built or run does.
    dirty = git("status", "--porcelain", "--untracked-files=no", "--", ".", ":(exclude)docs",
                ":(exclude)*.md")
    return head + ("-dirty" if dirty else "")


def command():
    """The command line that started this script, as one could type it."""
    exe = sys.executable if sys.executable else "python3"
    script = os.path.relpath(os.path.abspath(sys.argv[0]), os.getcwd())
    return shlex.join([exe, script, *sys.argv[1:]])


def load():
    return os.getloadavg()[0]


class Provenance:
    """Started when a benchmark starts (load average then); `text()` at the
    end gives the run's line of a table file."""

    def __init__(self, make_target=None):
        self.date = today()
        self.load_start = load()
        # The program measured is the one checked out when the run starts.
        self.commit = commit()
        # Named only when make started the script.
        self.make_target = make_target if os.environ.get("MAKELEVEL") else None

    def text(self, note=""):
        make = f" (`make {self.make_target}`)" if self.make_target else ""
        extra = f"; {note}" if note else ""
        return (f"{self.date}, {machine()}, commit `{self.commit}`, load average "
                f"{self.load_start:.1f} → {load():.1f}{extra}: `{command()}`{make}")


# --- running ------------------------------------------------------------------


def mpi_env(**extra):
    """The environment for contactlink under mpirun on one machine: the
    Makefile's local defaults where the caller set nothing (a cluster sets
    its own), and `extra` on top."""
    env = dict(os.environ)
    for k, v in (("OMPI_MCA_btl", "self,vader"),
                 ("OMPI_MCA_btl_vader_single_copy_mechanism", "none"),
                 ("OMPI_MCA_pml", "ob1"),
                 ("OMPI_ALLOW_RUN_AS_ROOT", "1"), ("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"),
                 ("OMPI_MCA_rmaps_base_oversubscribe", "1")):
        env.setdefault(k, v)
    env.update(extra)
    return env


def launcher(ranks, mpirun=None):
    """[] on one rank (a single MPI process needs no launcher), else mpirun."""
    if ranks == 1 and mpirun is None:
        return []
    mpirun = mpirun or os.environ.get("MPIRUN", "mpirun --allow-run-as-root --oversubscribe")
    return shlex.split(mpirun) + ["-n", str(ranks)]


@dataclass
class Timed:
    """One finished command: wall seconds, CPU seconds of it and its children
    (user + system), exit code and output."""
    cmd: list
    wall: float
    cpu: float
    returncode: int
    stdout: str
    stderr: str

    @property
    def text(self):
        return self.stdout + self.stderr


def run(cmd, env=None, check=True, cwd=None):
    """Runs `cmd` once (in `cwd`); with `check`, a non-zero exit ends the
    script with the command and the end of its output."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    p = subprocess.run(cmd, capture_output=True, text=True, env=env, cwd=cwd)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    t = Timed(list(cmd), wall, cpu, p.returncode, p.stdout, p.stderr)
    if check and p.returncode != 0:
        sys.exit(f"{shlex.join(cmd)} failed (exit code {p.returncode}):\n{t.text[-3000:]}")
    return t


def repeat(fn, n):
    """fn() n times; the list of its results."""
    return [fn() for _ in range(n)]


def alternate(fns, n):
    """Each callable of the dict `fns` in turn, n rounds (a, b, a, b, ...),
    so that a change of the machine's load hits all of them alike; the
    results per name."""
    out = {name: [] for name in fns}
    for _ in range(n):
        for name, fn in fns.items():
            out[name].append(fn())
    return out


@dataclass
class Spread:
    min: float
    median: float
    max: float
    values: list = field(default_factory=list)

    def __str__(self):
        return f"{self.median:.2f} ({self.min:.2f}–{self.max:.2f})"


def spread(values):
    """min / median / max of a list of numbers."""
    v = list(values)
    return Spread(min(v), statistics.median(v), max(v), v)


def median(values):
    return statistics.median(list(values))


def medians(runs, keys):
    """A dict of the first run with `keys` replaced by their medians over
    `runs` (dicts)."""
    row = dict(runs[0])
    for k in keys:
        row[k] = statistics.median(r[k] for r in runs)
    return row


# --- a run's machine output ------------------------------------------------------

DONE = re.compile(r"done: (\d+) steps, (\d+) Newton iterations, (\d+) DOFs on (\d+) rank\(s\), "
                  r"([0-9.]+) s")


def history(h5):
    """The per-step history CSV written next to result file `h5`: one dict
    per converged step (column name → text)."""
    with open(os.path.splitext(h5)[0] + ".csv", newline="") as f:
        return list(csv.DictReader(f))


def totals(h5):
    """Steps and the Newton, Uzawa and linear iterations and cutbacks summed
    over the steps of the history next to `h5`."""
    rows = history(h5)
    out = {"steps": len(rows)}
    for k in ("newton", "uzawa", "linear", "cutbacks"):
        out[k] = sum(int(r[k]) for r in rows) if rows and k in rows[0] else 0
    return out


def run_attrs(h5):
    """The attributes of `/run` in result file `h5` (the run's totals: DOFs,
    ranks, seconds, preconditioner builds, ...) and of `/hertz` (the Hertz
    comparison of the last step, when the scene has one), as one dict; the
    `/hertz` ones prefixed `hertz.`. Needs h5py."""
    import h5py
    out = {}
    with h5py.File(h5, "r") as f:
        for group, prefix in (("run", ""), ("hertz", "hertz.")):
            if group in f:
                for k, v in f[group].attrs.items():
                    if isinstance(v, bytes):
                        v = v.decode()
                    elif hasattr(v, "item"):
                        v = v.item()
                    out[prefix + k] = v
    return out


# --- table files -----------------------------------------------------------------

RUN_LINE = re.compile(r"^- \*\*([a-z]+)\*\*: (.*)$")


def table_path(name):
    return os.path.join(TABLES, name + ".md")


def add_table_args(ap, name):
    """`--table PATH` (default docs/tables/NAME.md) and `--no-table` on an
    argparse parser."""
    ap.add_argument("--table", default=table_path(name),
                    help=f"markdown table to update (default docs/tables/{name}.md)")
    ap.add_argument("--no-table", action="store_true", help="write no table file")


def _cells(line):
    # Cells split at unescaped pipes (a cell may hold `\|x\|`).
    inner = line.strip()[1:-1]
    return [c.strip() for c in re.split(r"(?<!\\)\|", inner)]


def read_table(path):
    """(runs {id: text}, columns, rows [[run id, cells...]]) of a table file,
    or ({}, None, []) when it does not exist."""
    if not os.path.exists(path):
        return {}, None, []
    runs, columns, rows = {}, None, []
    with open(path) as f:
        lines = f.read().splitlines()
    for i, line in enumerate(lines):
        m = RUN_LINE.match(line)
        if m:
            runs[m[1]] = m[2]
        elif line.startswith("| ") and columns is None:
            columns = _cells(line)[1:]
        elif line.startswith("| ") and not line.startswith("| ---"):
            rows.append(_cells(line))
    return runs, columns, rows


def _run_id(i):
    letters = ""
    i += 1
    while i:
        i, r = divmod(i - 1, 26)
        letters = chr(ord("a") + r) + letters
    return letters


def write_table(path, title, columns, rows, provenance, key=1, intro=""):
    """Writes `rows` (lists of cells, as `columns`) into the table file
    `path`, marked as measured by the run `provenance` (its text). Rows of
    the file with the same first `key` cells are replaced; the file's other
    rows stay with their runs. A file with other columns is replaced whole."""
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    old_runs, old_columns, old_rows = read_table(path)
    if old_columns != list(columns):
        old_runs, old_rows = {}, []
    new = [[None] + [str(c) for c in r] for r in rows]
    keys = {tuple(r[1:1 + key]) for r in new}
    merged, placed = [], set()
    for r in old_rows:
        k = tuple(r[1:1 + key])
        if k in keys:
            if k not in placed:
                merged.extend(n for n in new if tuple(n[1:1 + key]) == k)
                placed.add(k)
        else:
            merged.append(r)
    merged.extend(n for n in new if tuple(n[1:1 + key]) not in placed)
    # Runs renamed a, b, ... in order of first appearance.
    texts = dict(old_runs)
    texts[None] = provenance
    order = []
    for r in merged:
        if r[0] not in order:
            order.append(r[0])
    ids = {old: _run_id(i) for i, old in enumerate(order)}
    out = [f"# {title}", "",
           "<!-- Written by the benchmark script named in the runs below (through "
           "scripts/benchrun.py): re-running it replaces the rows it measures. -->", ""]
    if intro:
        out += [intro, ""]
    out += ["Runs:", ""]
    out += [f"- **{ids[o]}**: {texts[o]}" for o in order]
    out += ["", "| run | " + " | ".join(columns) + " |",
            "| --- | " + " | ".join("---" for _ in columns) + " |"]
    out += ["| " + " | ".join([ids[r[0]]] + r[1:]) + " |" for r in merged]
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    print(f"table: {os.path.relpath(path, os.getcwd())}")


def seeded(date, where, cmd, note="", machine_text="Debian 12, 2 cores, this CI machine kind"):
    """The provenance text of rows copied from figures the docs stated as
    measured (not re-run since)."""
    extra = f"; {note}" if note else ""
    return (f"{date}, {machine_text}: seeded from the figures {where} stated as measured then, "
            f"not re-run since{extra}: `{cmd}`")


if __name__ == "__main__":
    for p in sys.argv[1:]:
        runs, columns, rows = read_table(p)
        print(f"{p}: {len(rows)} rows, columns {columns}")
        for k, v in runs.items():
            print(f"  {k}: {v}")
