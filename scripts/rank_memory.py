"""A rank's resident memory by phase, and a guard of the machine's memory around a large run.

:class:`Phases` samples ``VmRSS`` of /proc/self/status in a thread and
records, per phase of a run (the stages of its clock, the mesh's
distribution, the assemblies, the tangent solves, the round-off floors,
the writing of the outputs), the memory at its start and end and the
largest sample in between: what Python's own tracing cannot see, since
NGSolve allocates in C++.  Each phase also has its wall time and the
process's CPU time over it (all its threads): a rank waiting in MPI's
polling calls spends CPU time as fast as wall time.  :class:`MemoryGuard` starts a command only with
enough memory available and ends its whole process group when the
machine's available memory falls below a floor (a large run on a machine
shared with other jobs).  Used by ``scripts/macro_mpi_scaling.py``.
"""
from __future__ import annotations

import json
import os
import subprocess
import time

def _status_mb(key: str) -> float:
    """``key`` (``VmRSS``, ``VmHWM``) of /proc/self/status [MB]."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(key + ":"):
                return float(line.split()[1]) / 1024.0
    return float("nan")


class Phases:
    """Resident memory of this process per phase of a run: at its start and end, and its largest sample
    in between (a thread reads ``VmRSS`` every ``every`` seconds; C++ allocations are invisible to
    Python's own tracing).  Phases nest (a stage's assemblies and solves); each is one row."""

    def __init__(self, every: float = 0.05):
        import threading
        self.rows: list[dict] = []
        self._open: list[dict] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._sample, args=(every,), daemon=True)
        self._thread.start()

    def _sample(self, every: float) -> None:
        while not self._stop.wait(every):
            rss = _status_mb("VmRSS")
            for row in self._open:
                row["peak_mb"] = max(row["peak_mb"], rss)

    def enter(self, name: str) -> None:
        rss = _status_mb("VmRSS")
        row = {"phase": name, "start_mb": rss, "peak_mb": rss, "end_mb": rss, "t0": time.perf_counter(),
               "c0": time.process_time()}
        self._open.append(row)
        self.rows.append(row)

    def leave(self) -> None:
        row = self._open.pop()
        row["end_mb"] = _status_mb("VmRSS")
        row["peak_mb"] = max(row["peak_mb"], row["end_mb"])
        row["seconds"] = round(time.perf_counter() - row.pop("t0"), 2)
        row["cpu_s"] = round(time.process_time() - row.pop("c0"), 2)

    def wrap(self, owner, attr: str, name: str) -> None:
        """``owner.attr`` (a function or method) recorded as phase ``name`` at each call."""
        original = getattr(owner, attr)

        def recorded(*args, **kwargs):
            self.enter(name)
            try:
                return original(*args, **kwargs)
            finally:
                self.leave()
        setattr(owner, attr, recorded)

    def install(self) -> None:
        """The stages of a run (its clock's) and, inside them, what holds memory: the distribution of the
        mesh, the assemblies (BDDC is built by the whole form's), the tangent solves."""
        from contextlib import contextmanager

        import ngsolve as ng

        from ngcontact.distributed import macro_run
        from ngcontact.output.report import Clock
        from ngcontact.solvers import linear_solver, newton
        stage = Clock.stage

        @contextmanager
        def staged(clock, name):
            self.enter(name)
            try:
                with stage(clock, name):
                    yield
            finally:
                self.leave()
        Clock.stage = staged  # type: ignore[method-assign]
        self.wrap(macro_run, "distribute", "distribute the mesh")
        self.wrap(ng.BilinearForm, "Assemble", "assemble a matrix (and its BDDC)")
        self.wrap(ng.BilinearForm, "AssembleLinearization", "assemble a tangent (and its BDDC)")
        self.wrap(linear_solver.TangentSolve, "apply", "tangent solve (CG)")
        self.wrap(newton, "roundoff_floors", "round-off floors")

    def table(self) -> list[dict]:
        """Consecutive calls of one phase merged (Newton's steps): their largest peak, the last end."""
        self._stop.set()
        merged: list[dict] = []
        for row in self.rows:
            if merged and merged[-1]["phase"] == row["phase"]:
                last = merged[-1]
                last.update(peak_mb=max(last["peak_mb"], row["peak_mb"]), end_mb=row["end_mb"],
                            seconds=round(last.get("seconds", 0) + row.get("seconds", 0), 2),
                            cpu_s=round(last.get("cpu_s", 0) + row.get("cpu_s", 0), 2),
                            calls=last["calls"] + 1)
            else:
                merged.append(dict(row, calls=1))
        return [{k: round(v, 1) if isinstance(v, float) else v for k, v in r.items()} for r in merged]


PHASE_KEYS = ("rank", "phase", "calls", "seconds", "cpu_s", "start_mb", "peak_mb", "end_mb")
#: one row per rank of a run: its resident memory [MB] at the start, the largest within each phase
#: (phases by their names in :class:`Phases`, merged where several make one column), left after the solve
PHASE_COLUMNS = {"mesh_mb": ("mesh", "distribute the mesh"),
                 "assembly_mb": ("assemble a matrix (and its BDDC)", "assemble a tangent (and its BDDC)"),
                 "cg_mb": ("tangent solve (CG)",), "floors_mb": ("round-off floors",), "solve_mb": ("solve",),
                 "post_mb": ("post-processing",), "write_mb": ("write the outputs",)}
PHASE_TABLE_KEYS = ("code", "scene", "ndof", "order", "ranks", "rank", "start_mb", *PHASE_COLUMNS,
                    "after_solve_mb", "peak_mb")


def phase_table(phases: list[dict], peaks: list[float], run: dict) -> list[dict]:
    """Per rank: ``run``'s columns and the memory of its phases (:data:`PHASE_COLUMNS`)."""
    rows = []
    for r, peak in enumerate(peaks):
        mine = [p for p in phases if p["rank"] == r]
        row = dict(run, rank=r, start_mb=mine[0]["start_mb"] if mine else "", peak_mb=peak)
        for column, names in PHASE_COLUMNS.items():
            row[column] = max((p["peak_mb"] for p in mine if p["phase"] in names), default="")
        row["after_solve_mb"] = next((p["end_mb"] for p in mine if p["phase"] == "solve"), "")
        rows.append(row)
    return rows


def phase_rows(out: str, ranks: int) -> list[dict]:
    """The phases of every rank of the run written to ``out`` (:class:`Phases`)."""
    rows = []
    for r in range(ranks):
        with open(f"{out}_phases_rank{r}.json") as fh:
            rows += [dict(row, rank=r) for row in json.load(fh)]
    return rows


MEMINFO = "/proc/meminfo"


def available_gb() -> float:
    """The machine's ``MemAvailable`` [GB] (/proc/meminfo)."""
    with open(MEMINFO) as fh:
        for line in fh:
            if line.startswith("MemAvailable:"):
                return float(line.split()[1]) / 1024.0 ** 2
    return float("nan")


def descendants(pid: int) -> list[int]:
    """The processes below ``pid`` (children, theirs, ...), from the parent ids in /proc/*/stat."""
    parent: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as fh:
                    parent[int(entry)] = int(fh.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
    found, todo = [], [pid]
    while todo:
        below = [p for p, q in parent.items() if q == todo[-1]]
        todo.pop()
        found += below
        todo += below
    return found


def _commands(pids: list[int]) -> dict[int, bytes]:
    """The command lines of those of ``pids`` that still run."""
    found = {}
    for pid in pids:
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as fh:
                found[pid] = fh.read()
        except OSError:
            continue
    return found


class MemoryGuard:
    """A large run on a machine shared with other jobs: it starts only with ``start_gb`` available
    (``MemAvailable``; else it waits ``wait_s`` and looks again, ``tries`` times, then gives up), and a
    watchdog ends the whole run once less than ``floor_gb`` is left: ``mpiexec`` is asked to stop (it
    passes the signal to the ranks, which its process manager starts in sessions of their own), and
    whatever of it still runs ``grace_s`` later is killed, process by process.  ``low_gb``: the least
    available memory seen during the run."""

    def __init__(self, start_gb: float, floor_gb: float, tries: int = 5, wait_s: float = 120.0,
                 every_s: float = 1.0, grace_s: float = 5.0):
        self.start_gb, self.floor_gb, self.tries, self.wait_s = start_gb, floor_gb, tries, wait_s
        self.every_s, self.grace_s = every_s, grace_s
        self.low_gb = float("inf")

    def wait_for_memory(self) -> None:
        for attempt in range(self.tries):
            have = available_gb()
            if have >= self.start_gb:
                return
            print(f"memory guard: {have:.1f} GB available < {self.start_gb:g} GB "
                  f"(attempt {attempt + 1} of {self.tries}); waiting {self.wait_s:g} s", flush=True)
            time.sleep(self.wait_s)
        raise RuntimeError(f"memory guard: less than {self.start_gb:g} GB available after {self.tries} attempts; "
                           "the run was not started")

    def end(self, proc: subprocess.Popen, seen: dict[int, bytes]) -> None:
        """Stop ``proc`` and everything it started (``seen``: its descendants met while it ran, by id, with
        their command lines, so that a process given a reused id is left alone)."""
        import signal
        seen.update(_commands(descendants(proc.pid)))
        proc.terminate()
        try:
            proc.wait(self.grace_s)
        except subprocess.TimeoutExpired:
            pass
        for pid, command in seen.items():
            if _commands([pid]).get(pid) == command:
                os.kill(pid, signal.SIGKILL)
        if proc.poll() is None:
            proc.kill()

    def run(self, cmd: list[str], env: dict) -> None:
        """``cmd`` under the guard; raises where it failed or the watchdog ended it."""
        self.wait_for_memory()
        proc = subprocess.Popen(cmd, env=env)
        seen: dict[int, bytes] = {}
        while proc.poll() is None:
            have = available_gb()
            self.low_gb = min(self.low_gb, have)
            seen.update(_commands(descendants(proc.pid)))
            if have < self.floor_gb:
                print(f"memory guard: {have:.2f} GB available < {self.floor_gb:g} GB: ending the run", flush=True)
                self.end(proc, seen)
                raise RuntimeError(f"memory guard: the run was ended below {self.floor_gb:g} GB available")
            time.sleep(self.every_s)
        if proc.returncode:
            raise subprocess.CalledProcessError(proc.returncode, cmd)
        print(f"memory guard: at least {self.low_gb:.1f} GB stayed available", flush=True)
