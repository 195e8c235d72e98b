"""The 3D press fit on 1 and 2 MPI ranks at growing sizes: wall time and peak memory per rank against dofs.

The scene is the quarter of two coaxial tubes pressed together (interference
2 um, 5 MPa on the top; the scene of ``tests/distributed/test_mpi_macro.py``)
at order 2, ``solver.linear = "iterative"`` (BDDC-CG, what runs distributed),
refined by ``discretization.maxh``.  Each run is ``ngcontact run`` in its own
processes: one process for 1 rank, ``mpiexec -n 2`` for 2 ranks (mesh made on
rank 0 and distributed; rank 0 gathers the solution and post-processes:
:mod:`ngcontact.distributed.macro_run`).  Per run: dofs, wall time of the
command, the report's solve stage, and every rank's peak resident memory
(``VmHWM``) at its exit: rank 0 (which holds the whole mesh and the
post-processing) and the largest of the others (a part of the mesh each;
empty for one rank).

    python scripts/macro_mpi_scaling.py [OUT] [--maxh 0.004 0.002 0.001] [--ranks 1 2] [--publish]

Writes ``OUT/macro_mpi_scaling.csv`` and ``.png`` (default ``results/macro_mpi_scaling``).
"""
from __future__ import annotations

import argparse
import atexit
import json
import os
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

from ngcontact.output.writer import write_csv  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
KEYS = ("ranks", "maxh", "ndof", "wall_s", "solve_s", "newton", "cg_iterations", "peak_mb_rank0",
        "peak_mb_other_ranks")

SCENE = """\
kind = "macro"
title = "3D press fit of two tubes, a quarter (MPI scaling)"
[materials.steel]
E = 210e9
nu = 0.3
[materials.bone]
E = 17e9
nu = 0.3
[bodies]
rough = "steel"
counter = "bone"
[geometry]
shape = "coaxial"
setting = "3d"
[geometry.dimensions]
a = 0.004
b = 0.008
c = 0.014
height = 0.01
[interface]
law = "linear"
kn = 1e13
kt = 1e12
gap = -2e-6
[[supports]]
boundary = "bottom"
[[supports]]
boundary = "sym_x"
components = ["x"]
[[supports]]
boundary = "sym_y"
components = ["y"]
[[loads]]
boundary = "top"
pressure = 5e6
[discretization]
order = 2
maxh = {maxh}
[solver]
linear = "iterative"
"""


def _peak_mb() -> float:
    """This process's peak resident memory [MB] (``VmHWM`` of /proc/self/status)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return float(line.split()[1]) / 1024.0
    return float("nan")


def child(scene: str, out: str) -> int:
    """One rank of a run: ``ngcontact run``, then its peak memory into ``out/peak_rank<R>.txt``."""
    from ngcontact import cli
    from ngcontact.distributed.world import launched_rank
    rank = launched_rank()
    mem = os.path.join(os.path.dirname(out), f"{os.path.basename(out)}_peak_rank{rank}.txt")
    atexit.register(lambda: open(mem, "w").write(f"{_peak_mb()}\n"))
    return cli.main(["run", scene, "--out", out, "--quiet"])


def measure(maxh: float, ranks: int, work: str) -> dict:
    """One run of the press fit at ``maxh`` on ``ranks`` ranks."""
    tag = f"h{maxh:g}_r{ranks}"
    scene = os.path.join(work, f"{tag}.toml")
    with open(scene, "w") as fh:
        fh.write(SCENE.format(maxh=maxh))
    out = os.path.join(work, tag)
    cmd = [sys.executable, os.path.abspath(__file__), "--child", scene, out]
    if ranks > 1:
        cmd = ["mpiexec", "-n", str(ranks)] + cmd
    env = dict(os.environ, MPLBACKEND="Agg")
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=env)
    wall = time.perf_counter() - t0
    with open(os.path.join(out, "report.json")) as fh:
        rep = json.load(fh)
    peaks = []
    for r in range(ranks):
        with open(f"{out}_peak_rank{r}.txt") as fh:
            peaks.append(float(fh.read()))
    return {"ranks": ranks, "maxh": maxh, "ndof": rep["ndof"], "wall_s": round(wall, 2),
            "solve_s": round(rep["timings"]["solve"], 2), "newton": rep["solver"]["iterations"],
            "cg_iterations": sum(rep["solver"]["linear"].get("cg_iterations", [])),
            "peak_mb_rank0": round(peaks[0], 1),
            "peak_mb_other_ranks": round(max(peaks[1:]), 1) if ranks > 1 else ""}


def plot(data: list[dict], path: str) -> None:
    import matplotlib.pyplot as plt
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(10, 4))
    for r in sorted({d["ranks"] for d in data}):
        rows = sorted((d for d in data if d["ranks"] == r), key=lambda d: d["ndof"])
        n = [d["ndof"] for d in rows]
        ax.loglog(n, [d["solve_s"] for d in rows], "o-", label=f"{r} rank(s): solve")
        ax.loglog(n, [d["wall_s"] for d in rows], "s--", label=f"{r} rank(s): whole command")
        bx.loglog(n, [d["peak_mb_rank0"] for d in rows], "o-", label=f"{r} rank(s): rank 0")
        if r > 1:
            bx.loglog(n, [d["peak_mb_other_ranks"] for d in rows], "s--", label=f"{r} ranks: largest other")
    ax.set_xlabel("dofs")
    ax.set_ylabel("time [s]")
    bx.set_xlabel("dofs")
    bx.set_ylabel("peak memory per rank [MB]")
    ax.legend(fontsize=8)
    bx.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--child"]:
        return child(argv[1], argv[2])
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", default=os.path.join("results", "macro_mpi_scaling"), help="output directory")
    ap.add_argument("--maxh", type=float, nargs="+", default=[0.004, 0.002, 0.001], help="mesh sizes [m]")
    ap.add_argument("--ranks", type=int, nargs="+", default=[1, 2], help="numbers of MPI ranks")
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    work = os.path.abspath(os.path.join(args.out, "runs"))
    os.makedirs(work, exist_ok=True)
    data = [measure(h, r, work) for h in args.maxh for r in args.ranks]
    csv_path = os.path.join(args.out, "macro_mpi_scaling.csv")
    write_csv(csv_path, list(KEYS), [[d[k] for k in KEYS] for d in data])
    plot(data, os.path.join(args.out, "macro_mpi_scaling.png"))
    for d in data:
        print(" ".join(f"{k}={d[k]}" for k in KEYS))
    if args.publish:
        benchmark_doc.publish("macro_mpi_scaling", "The 3D press fit on 1 and 2 MPI ranks", csv_path,
                              note="`ngcontact run` of the 3D press fit (order 2, BDDC-CG) in one process and "
                              "under `mpiexec -n 2`; wall time of the whole command and of the solve stage, "
                              "peak resident memory of rank 0 (whole mesh, post-processing) and of the other "
                              "rank (its part of the mesh). Small sizes only, on a machine shared with other "
                              "jobs: the times are indicative.",
                              png=os.path.join(args.out, "macro_mpi_scaling.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
