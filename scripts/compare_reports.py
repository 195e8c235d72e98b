"""Record every shipped scene's report and compare two such records.

Used to prove that a refactoring changed no result::

    python scripts/compare_reports.py record before/      # on the old commit
    python scripts/compare_reports.py record after/       # on the new one
    python scripts/compare_reports.py compare before/ after/ --rtol 1e-10
    python scripts/compare_reports.py summary before/ after/   # largest difference per report

``record`` solves every scene under ``geometries/`` (the epsilon study's
scenes as plain runs) and writes ``<dir>/<scene path with / -> __>.json``;
a scene that fails is recorded with its error message.  ``compare`` walks
both JSON trees and lists every number that differs by more than ``rtol``
relative (``atol`` absolute floor); wall-clock timings, the package version
and the scene's own path are not compared.  Exit status 1 when anything
differs or a scene is missing on one side.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IGNORED_KEYS = {"timings", "version", "wall_time", "seconds", "time", "elapsed"}


def record(out: Path, only: list[str]) -> int:
    import ngsolve

    import ngcontact

    # NGSolve's threaded assembly sums in a varying order: one thread makes a
    # run reproducible to the last bit, which the comparison needs
    ngsolve.SetNumThreads(1)

    out.mkdir(parents=True, exist_ok=True)
    scenes = sorted((ROOT / "geometries").rglob("*.toml"))
    for path in scenes:
        rel = path.relative_to(ROOT / "geometries").as_posix()
        if only and not any(s in rel for s in only):
            continue
        t0 = time.perf_counter()
        try:
            report, _ = ngcontact.solve(str(path))
        except Exception as exc:  # recorded so that both sides can be compared
            report = {"error": f"{type(exc).__name__}: {exc}"}
        name = rel.replace("/", "__").removesuffix(".toml") + ".json"
        (out / name).write_text(json.dumps(report, indent=1, sort_keys=True, default=str))
        print(f"{rel}: {time.perf_counter() - t0:.1f} s{'  ' + report['error'] if 'error' in report else ''}",
              flush=True)
    return 0


def _walk(a, b, path: str, rtol: float, atol: float, diffs: list[str], ignore: tuple[str, ...] = ()) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if key in IGNORED_KEYS or key.endswith("_seconds") or key.startswith("time_"):
                continue
            if f"{path}.{key}" in ignore:
                continue
            if key not in a or key not in b:
                diffs.append(f"{path}.{key}: only on {'after' if key in b else 'before'} side")
                continue
            _walk(a[key], b[key], f"{path}.{key}", rtol, atol, diffs, ignore)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            diffs.append(f"{path}: length {len(a)} != {len(b)}")
            return
        for i, (x, y) in enumerate(zip(a, b)):
            _walk(x, y, f"{path}[{i}]", rtol, atol, diffs, ignore)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if math.isnan(a) and math.isnan(b):
            return
        if not abs(a - b) <= atol + rtol * max(abs(a), abs(b)):
            diffs.append(f"{path}: {a!r} != {b!r}")
    elif a != b:
        diffs.append(f"{path}: {a!r} != {b!r}")


def compare(before: Path, after: Path, rtol: float, atol: float, ignore: tuple[str, ...] = ()) -> int:
    names = sorted({p.name for p in before.glob("*.json")} | {p.name for p in after.glob("*.json")})
    bad = 0
    for name in names:
        pa, pb = before / name, after / name
        if not (pa.exists() and pb.exists()):
            print(f"{name}: missing on the {'before' if not pa.exists() else 'after'} side")
            bad += 1
            continue
        diffs: list[str] = []
        _walk(json.loads(pa.read_text()), json.loads(pb.read_text()), "", rtol, atol, diffs, ignore)
        print(f"{name}: {'same' if not diffs else f'{len(diffs)} differences'}")
        for line in diffs[:20]:
            print("   ", line)
        bad += bool(diffs)
    print(f"{len(names)} reports, {bad} differ (rtol {rtol:g}, atol {atol:g})")
    return 1 if bad else 0


def _numbers(obj, path: str, out: dict, scale: float = 0.0) -> None:
    """``{path: (value, scale)}``; a number in a list is measured against the list's largest magnitude."""
    if isinstance(obj, dict):
        for key, value in obj.items():
            if key in IGNORED_KEYS or key.endswith("_seconds") or key.startswith("time_"):
                continue
            _numbers(value, f"{path}.{key}", out)
    elif isinstance(obj, list):
        flat = [abs(v) for v in obj if isinstance(v, (int, float)) and not isinstance(v, bool)]
        for i, value in enumerate(obj):
            _numbers(value, f"{path}[{i}]", out, max(flat, default=0.0))
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        out[path] = (float(obj), scale)


def summary(before: Path, after: Path, skip: tuple[str, ...]) -> int:
    """Per report: the largest relative difference of any number both sides hold, and where.

    Paths containing any of ``skip`` (e.g. ``.solver``: residual histories at
    round-off) are left out; a number in a list is measured against the
    largest magnitude in that list (a round-off zero beside 1e-2 is no 100 %
    difference); a number that is zero on both sides is equal.
    """
    for pa in sorted(before.glob("*.json")):
        pb = after / pa.name
        if not pb.exists():
            print(f"{pa.name}: missing on the after side")
            continue
        na: dict = {}
        nb: dict = {}
        _numbers(json.loads(pa.read_text()), "", na)
        _numbers(json.loads(pb.read_text()), "", nb)
        worst, where = 0.0, ""
        for key in sorted(set(na) & set(nb)):
            if any(s in key for s in skip):
                continue
            (a, sa), (b, sb) = na[key], nb[key]
            scale = max(abs(a), abs(b), sa, sb)
            d = abs(a - b) / scale if scale > 0 else 0.0
            if d > worst:
                worst, where = d, key
        print(f"{pa.name:45s} max relative difference {worst:.1e} {where}")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("record")
    r.add_argument("out", type=Path)
    r.add_argument("--only", nargs="*", default=[], help="substrings of scene paths to run")
    c = sub.add_parser("compare")
    c.add_argument("before", type=Path)
    c.add_argument("after", type=Path)
    c.add_argument("--rtol", type=float, default=1e-10)
    c.add_argument("--atol", type=float, default=1e-300)
    c.add_argument("--ignore", nargs="*", default=[], metavar="PATH",
                   help="key paths left out, as printed (e.g. .scene.solver.coulomb_rtol for a key a change added)")
    m = sub.add_parser("summary", help="the largest relative difference per report")
    m.add_argument("before", type=Path)
    m.add_argument("after", type=Path)
    m.add_argument("--skip", nargs="*", default=[".solver", "newton", "residual", "coulomb_iterations", "elements",
                                                 "ndof"],
                   help="substrings of key paths to leave out (default: solver histories)")
    args = ap.parse_args(argv)
    if args.cmd == "summary":
        return summary(args.before, args.after, tuple(args.skip))
    if args.cmd == "record":
        return record(args.out, args.only)
    return compare(args.before, args.after, args.rtol, args.atol, tuple(args.ignore))


if __name__ == "__main__":
    sys.exit(main())
