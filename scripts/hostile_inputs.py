"""Run ``ngcontact`` on hostile inputs, as a new user would, and tally what each ends in.

Each case is a shipped scene with one edit (or a hostile file or ``--out``
target); the command runs as a separate process with a time limit, and the
table records its exit status, the number of lines on stderr, its wall
time, whether a pre-existing output directory survived byte for byte, and
whether a run that exited 0 reported ``converged`` with a finite report.

    python scripts/hostile_inputs.py --out results/hostile

writes ``hostile.csv`` and ``hostile.png`` (cases per outcome).  A case
"passes" when it ends in exit 2 or 3 with exactly one line, or in exit 0
with a converged report, within its time limit, and leaves the user's
files as they were.
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchmark_doc  # noqa: E402  (the sibling module writes docs/benchmarks.md)

ROOT = Path(__file__).resolve().parents[1]
GEO = ROOT / "geometries"
TIMEOUT = 120


def read(rel: str) -> str:
    return (GEO / rel).read_text()


def sub(text: str, old: str, new: str) -> str:
    if old not in text:
        raise SystemExit(f"case template lacks {old!r}")
    return text.replace(old, new, 1)


def cases(work: Path) -> list[dict]:
    """``{name, scene text or path, extra files, argv extras, out}`` of every case."""
    flat, tab = read("cells/flat_patch.toml"), read("cells/tabulated_profile.toml")
    hmap, semi = read("cells/height_map.toml"), read("cells/ex27_semicircular.toml")
    femur, block = read("femur_stem.toml"), read("macro/block_on_sawtooth.toml")
    linear_block = sub(block, 'cell = "sawtooth_cell.toml"', 'law = "linear"\nkn = 1e12\nkt = 1e11')
    out: list[dict] = []

    def case(name, text=None, *, files=None, command="run", out_dir=None, argv=()):
        out.append({"name": name, "text": text, "files": files or {}, "command": command, "out": out_dir,
                    "argv": list(argv)})

    case("valid flat cell (control)", flat)
    case("valid femur scene (control)", femur, files={"cells": GEO / "cells"})
    for k in ("1e16", "1e30", "1e308", "1e-300"):
        case(f"cell k_n = {k}", sub(flat, "k_n = 1.0e3", f"k_n = {k}"))
    for P in ("1e-15", "1e-4", "1e30", "1e100"):
        case(f"cell period = {P}", sub(flat, "period = 1.0", f"period = {P}"))
    case("cell maxh = 1e-3", sub(flat, "maxh = 0.25", "maxh = 0.001"))
    case("cell order = 100", sub(flat, "order = 2", "order = 100"))
    case("cell order = 2**31", sub(flat, "order = 2", "order = 2147483648"))
    case("kind as a list", sub(flat, 'kind = "cell"', 'kind = ["cell"]'))
    case("arrays nested 5000 deep", 'kind = "cell"\nx = ' + "[" * 5000 + "]" * 5000 + "\n")
    case("UTF-16 scene", flat.encode("utf-16"))
    case("semicircle radius 0.4999999", sub(semi, "radius = 0.3", "radius = 0.4999999"))
    case("semicircle radius 1e-9", sub(semi, "radius = 0.3", "radius = 1e-9"))
    prof = 'file = "data/profile_example.csv"'
    case("profile file is a FIFO", sub(tab, prof, 'file = "fifo.csv"'), files={"fifo.csv": "FIFO"})
    case("profile file is /dev/zero", sub(tab, prof, 'file = "/dev/zero"'))
    case("profile of 1e5 rows", sub(tab, prof, 'file = "big.csv"'),
         files={"big.csv": "x,y\n" + "".join(f"{i / 100000!r},0.0\n" for i in range(100001))})
    case("profile in UTF-16", sub(tab, prof, 'file = "u16.csv"'),
         files={"u16.csv": "x,y\n0,0\n0.5,-0.1\n1,0\n".encode("utf-16")})
    case("profile above the counter body", sub(tab, prof, 'file = "high.csv"'),
         files={"high.csv": "x,y\n0,0.5\n0.5,0.9\n1,0.5\n"})
    case("profile echoing a secret line", sub(tab, prof, 'file = "s.csv"'),
         files={"s.csv": "x,y\n0,0\nroot:$6$hash:19000:0:99999:7:::\n1,0\n"})
    hm = 'file = "data/height_map_example.npy"'
    case("height map /dev/urandom", sub(hmap, hm, 'file = "/dev/urandom"'))
    case("height map empty .npy", sub(hmap, hm, 'file = "e.npy"'), files={"e.npy": b""})
    case("macro base held only in x", sub(linear_block, '[[supports]]\nboundary = "bottom"',
                                          '[[supports]]\nboundary = "bottom"\ncomponents = ["x"]'))
    case("macro pull-off, normal-only bundle", sub(sub(block, 'cell = "sawtooth_cell.toml"',
                                                       'law = "bundle"\ndirections = [[1.0, 0.0]]\nweights = [1e12]'),
                                                   "pressure = 10e6", "pressure = -10e6"))
    case("macro support given twice", sub(linear_block, '[[supports]]\nboundary = "bottom"',
                                          '[[supports]]\nboundary = "bottom"\n\n[[supports]]\nboundary = "bottom"\n'
                                          'components = ["y"]\ndisplacement = [1e-5]'))
    case("macro 1e14 Pa (a strain of 476: refused)", sub(linear_block, "pressure = 10e6", "pressure = 1e14"))
    case("femur gap table short of the interface",
         sub(femur, "gap_table = [[0.05, 20e-6], [0.09, 0.0], [0.13, -50e-6], [0.18, -50e-6]]",
             "gap_table = [[0.07, 20e-6], [0.09, 0.0], [0.13, -50e-6]]"), files={"cells": GEO / "cells"})
    case("femur with friction, load x5", sub(femur, "pressure = 1e6", "pressure = 5e6"), files={"cells": GEO / "cells"})
    case("--out . (holds the scene)", flat, out_dir=".")
    case("--out .. (holds the scene)", flat, out_dir="..")
    case("--out with the user's files", flat, out_dir="mine")
    case("--out holding a foreign report.json", flat, out_dir="foreign")
    case("--out is a symlink", flat, out_dir="link")
    case("scene names itself as its cell", "SELF")
    case("epsilon study --periods 3 3 3", str(GEO / "direct" / "block_rect_valleys.toml"), command="study",
         argv=["--periods", "3", "3", "3"])
    return out


def run_case(c: dict, base: Path) -> dict:
    work = base / c["name"].replace(" ", "_").replace("/", "_")
    work.mkdir(parents=True)
    for name, content in c["files"].items():
        target = work / name
        if content == "FIFO":
            os.mkfifo(target)
        elif isinstance(content, Path):
            target.symlink_to(content, target_is_directory=True)
        elif isinstance(content, bytes):
            target.write_bytes(content)
        else:
            target.write_text(content)
    scene = work / "scene.toml"
    text = c["text"]
    if text == "SELF":
        text = sub(read("macro/femur_stem_from_cell.toml"), 'cell = "hip_cell.toml"', 'cell = "scene.toml"')
    if c["command"] == "study":
        scene = Path(text)
    elif isinstance(text, bytes):
        scene.write_bytes(text)
    else:
        scene.write_text(text)
    (work / "mine").mkdir()
    (work / "mine" / "notes.txt").write_text("the user's notes")
    (work / "foreign").mkdir()
    (work / "foreign" / "report.json").write_text("{}")
    (work / "target").mkdir()
    (work / "link").symlink_to(work / "target", target_is_directory=True)
    scene_bytes = scene.read_bytes() if scene.is_file() else b""
    out = c["out"] or "out"
    cmd = [sys.executable, "-m", "ngcontact.cli"]
    cmd += ["study", "epsilon", str(scene)] if c["command"] == "study" else ["run", str(scene)]
    cmd += ["--out", out, "--quiet", *c["argv"]]
    t0 = time.perf_counter()
    try:
        done = subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=TIMEOUT)
        code, err = done.returncode, done.stderr
    except subprocess.TimeoutExpired:
        code, err = "timeout", ""
    seconds = time.perf_counter() - t0
    lines = [ln for ln in err.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("ngcontact: error:")]
    converged = ""
    report = work / out / "report.json" if c["out"] in (None, "mine", "link") else None
    if code == 0 and report is not None and report.exists():
        data = json.loads(report.read_text())
        converged = str(bool(data.get("solver", {}).get("converged", True)))
    # the user's files outside the run's own output must be as they were
    intact = ((work / "mine" / "notes.txt").read_text() == "the user's notes"
              and (work / "foreign" / "report.json").read_text() == "{}"
              and (work / "link").is_symlink()
              and (scene.read_bytes() if scene.is_file() else b"") == scene_bytes)
    ok = (code in (2, 3) and len(errors) == 1 and len(lines) == 1) or (code == 0 and converged != "False")
    return {"case": c["name"], "exit": code, "stderr_lines": len(lines), "seconds": round(seconds, 2),
            "user_files_intact": intact, "converged": converged, "pass": ok and intact,
            "message": (errors[0] if errors else (lines[0] if lines else ""))[:300]}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, required=True)
    benchmark_doc.add_flag(ap)
    args = ap.parse_args(argv)
    base = Path(tempfile.mkdtemp(prefix="ngcontact-hostile-"))
    try:
        rows = []
        for c in cases(base):
            row = run_case(c, base)
            rows.append(row)
            print(f"{row['exit']!s:>7} {row['seconds']:6.1f} s  {'ok ' if row['pass'] else 'BAD'}  {row['case']}: "
                  f"{row['message'][:110]}", flush=True)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "hostile.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    kinds = {"exit 0": 0, "exit 2": 0, "exit 3": 0, "other": 0}
    for r in rows:
        kinds[f"exit {r['exit']}" if r["exit"] in (0, 2, 3) else "other"] += 1
    fig, ax = plt.subplots(figsize=(5, 3))
    ax.bar(list(kinds), list(kinds.values()), color=["tab:green", "tab:blue", "tab:orange", "tab:red"])
    ax.set_ylabel("cases")
    ax.set_title(f"{len(rows)} hostile inputs, {sum(r['pass'] for r in rows)} handled well")
    fig.tight_layout()
    fig.savefig(args.out / "hostile.png", dpi=120)
    bad = [r["case"] for r in rows if not r["pass"]]
    print(f"{len(rows)} cases: " + ", ".join(f"{k} {v}" for k, v in kinds.items())
          + f"; handled well {len(rows) - len(bad)}" + (f"; not: {bad}" if bad else ""))
    if args.publish:
        benchmark_doc.publish("hostile_inputs", "Hostile inputs: what each run ends in", str(args.out / "hostile.csv"),
                              columns=["case", "exit", "stderr_lines", "seconds", "user_files_intact", "converged",
                                       "pass"],
                              note="Each case is a shipped scene with one hostile edit (or a hostile file or "
                                   "`--out` target) run by `ngcontact` in its own process; it passes when it ends "
                                   "in exit 2 or 3 with one line, or in exit 0 with a converged report, and leaves "
                                   "the user's files as they were. The message column of the CSV is left out here.",
                              png=str(args.out / "hostile.png"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
