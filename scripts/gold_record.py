"""Record the headline numbers of every shipped scene in ``tests/gold/scenes.json``, or check against it.

::

    python scripts/gold_record.py                                # record every scene under geometries/
    python scripts/gold_record.py --only femur_stem westergaard  # re-record the scenes whose path contains these
    python scripts/gold_record.py --check                        # compare fresh runs with the record
    python scripts/gold_record.py --check --only sinusoid

A scene is every ``*.toml`` under ``geometries/`` that ``ngcontact check`` accepts (cell, macro,
two-scale, manufactured, direct scenes and ensembles; the cell scenes that other scenes reference are
scenes of their own).  Each is solved by ``ngcontact.solve`` (no output files) with ``NGCONTACT_CACHE``
set to a fresh temporary directory, so that every cell law is computed in the run and the user's cache is
left alone; the numbers kept and how they compare are those of ``tests/gold/record.py``.  The record holds
per scene its ``kind``, the ``keys``, ``expensive`` (a run longer than about a minute) and the package
commit it was recorded at (``-dirty`` with uncommitted changes in ``ngcontact/`` or ``geometries/``).
``--only`` re-records the scenes it names and keeps the others' entries.  ``--check`` writes nothing: it
prints per scene the largest relative difference, then a table of every key that moved beyond the
tolerance (scene, key, gold, new, relative difference), and exits with status 1 if there is one.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
GOLD = ROOT / "tests" / "gold" / "scenes.json"


def _load_record_module():
    spec = importlib.util.spec_from_file_location("gold_record_rules", ROOT / "tests" / "gold" / "record.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


R = _load_record_module()


def scenes() -> list[str]:
    """Paths (relative to the repository, ``/``-separated) of the shipped scenes ``ngcontact check`` accepts."""
    from ngcontact import runner
    from ngcontact.errors import SceneError

    out = []
    for path in sorted((ROOT / "geometries").rglob("*.toml")):
        rel = path.relative_to(ROOT).as_posix()
        try:
            runner.check(str(path))
        except SceneError as exc:
            print(f"{rel}: not a runnable scene ({exc}); skipped", file=sys.stderr)
            continue
        out.append(rel)
    return out


def run(rel: str) -> tuple[dict, float]:
    """The headline numbers of one scene, solved in a fresh cell-law cache, and the run's wall time [s]."""
    import ngcontact

    with tempfile.TemporaryDirectory(prefix="ngcontact-gold-") as cache:
        previous = os.environ.get("NGCONTACT_CACHE")
        os.environ["NGCONTACT_CACHE"] = cache
        try:
            t0 = time.perf_counter()
            report, _ = ngcontact.solve(str(ROOT / rel))
            seconds = time.perf_counter() - t0
        finally:
            if previous is None:
                del os.environ["NGCONTACT_CACHE"]
            else:
                os.environ["NGCONTACT_CACHE"] = previous
    return {"kind": report["kind"], "keys": R.extract(report)}, seconds


def _commit() -> str:
    """The checked-out commit, with ``-dirty`` when the package or the scenes have uncommitted changes."""
    def git(*args: str) -> str:
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()

    try:
        head = git("rev-parse", "HEAD")
        dirty = git("status", "--porcelain", "--", "ngcontact", "geometries")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("-dirty" if dirty else "")


def record(selected: list[str]) -> int:
    import ngcontact

    old = json.loads(GOLD.read_text()) if GOLD.exists() else {"scenes": {}}
    entries = dict(old.get("scenes", {}))
    commit = _commit()
    for rel in selected:
        entry, seconds = run(rel)
        entry["expensive"] = seconds > R.EXPENSIVE_SECONDS
        entry["commit"] = commit
        entries[rel] = entry
        print(f"{rel}: {len(entry['keys'])} keys, {seconds:.1f} s", flush=True)
    doc = {
        "version": ngcontact.__version__,
        "rtol": R.RTOL,
        "zero": R.ZERO,
        "scenes": {rel: entries[rel] for rel in sorted(entries)},
    }
    GOLD.parent.mkdir(parents=True, exist_ok=True)
    GOLD.write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n")
    print(f"wrote {GOLD.relative_to(ROOT)}: {len(entries)} scenes ({len(selected)} recorded at {commit})")
    return 0


def check(selected: list[str]) -> int:
    gold = json.loads(GOLD.read_text())["scenes"]
    rows = []
    for rel in selected:
        if rel not in gold:
            print(f"{rel}: not in the record")
            rows.append((rel, "(scene)", "recorded", None, float("inf")))
            continue
        entry, seconds = run(rel)
        bad = R.compare(gold[rel]["keys"], entry["keys"])
        worst = R.largest_difference(gold[rel]["keys"], entry["keys"])
        print(f"{rel}: {'ok' if not bad else f'{len(bad)} keys differ'}, "
              f"largest relative difference {worst:.2e}, {seconds:.1f} s", flush=True)
        rows += [(rel, *b) for b in bad]
    if rows:
        print()
        print(R.table(rows))
        return 1
    print(f"{len(selected)} scenes agree with the record (rtol {R.RTOL:g})")
    return 0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", metavar="NAME", default=[],
                    help="only the scenes whose path contains one of these strings")
    ap.add_argument("--check", action="store_true", help="compare with the record instead of writing it")
    args = ap.parse_args(argv)
    selected = [s for s in scenes() if not args.only or any(n in s for n in args.only)]
    if not selected:
        print(f"no scene matches {args.only}", file=sys.stderr)
        return 2
    return check(selected) if args.check else record(selected)


if __name__ == "__main__":
    sys.exit(main())
