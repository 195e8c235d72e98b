"""Part 5 of ``scaling_3d.py`` and issue 38's aim: the bisinusoid posed as a user poses it, and the verdict.

Issue 38 aims at the 3D FE cell on the bisinusoid (``scripts/bisinusoid_accuracy.py``) within 1 % of the
converged contact fraction at ``p/p* = 0.005, 0.02, 0.05`` in at most 60 s per load.  Part 4 assembles FE
solves itself (fixed edge sizes, their extrapolation made by the script); part 5, ``scene``, runs the scene
of ``scripts/bisinusoid_scene_accuracy.py`` (its ``start`` and ``finish``: exact contact, ``method = "fe"``,
``tolerance = 0.01``, every other key at its default), one ``python -m ngcontact run`` per load with
``NGCONTACT_THREADS = 1``, the loads side by side: what ``ngcontact run`` reports, the contact fraction of its
contact-edge ladder (:mod:`ngcontact.cell.fe.contact_edge_refinement`) with its estimate.  Its rows carry the
run's CPU seconds (``cpu_seconds``: on one thread the time the run takes alone, whatever the load of the
machine) beside its wall seconds (``seconds``), and their errors are against the same converged value as
part 4's (:func:`bisinusoid_accuracy.converged`).

Part 5 measures the scene rather than re-reading the section ``bisinusoid_scene_accuracy``: that section
keeps no rows but its Markdown table (four significant digits, 0.04 % of a contact fraction of 0.014), and a
row here is kept with the other rows of ``scaling_3d`` (docs/benchmarks/scaling_3d) and the note of the
command and commit that measured it.

:func:`aim_status` says, per load, whether the aim is met as a scene and by the fastest of part 4's rows.
"""
from __future__ import annotations

import json
import os

from bisinusoid_accuracy import ACC_RATIOS, converged

#: the solver of a scene's row: what ``ngcontact run`` solves on this scene
SCENE_SOLVER = "ngcontact run: fe exact order 2, contact-edge ladder"
#: the threads of a scene's run (its CPU seconds then its time alone)
SCENE_THREADS = "1"


def scene_row(row: dict, symmetry: dict | None) -> dict:
    """A row of ``bisinusoid_scene_accuracy.finish`` as a row of ``scaling_3d`` (part ``scene``): its cell the
    quarter where the report's ``symmetry`` says it was used, ``size`` its levels (the scene's mesh and the
    refined edge sizes); a run that ended without a report (exit 3) has no contact fraction."""
    out = {"part": "scene", "solver": SCENE_SOLVER, "cell": "" if symmetry is None else
           "quarter" if symmetry["used"] else "period", "size": f"{row['levels']} levels" if "levels" in row else "",
           "seconds": row["seconds"], "cpu_seconds": row["cpu_seconds"], "pressure": row["pressure"]}
    out.update({k: row[k] for k in ("ndof", "contact_fraction", "relative_error", "estimate", "effectivity")
                if row.get(k) not in (None, "")})
    return out


def scene_rows(out: str, ratios=ACC_RATIOS) -> list[dict]:
    """Part 5 (module docstring): one scene per load in ``out``, run side by side on ``SCENE_THREADS``
    thread(s) each, as rows of ``scaling_3d``; the converged values solved first."""
    import bisinusoid_scene_accuracy as scene
    os.makedirs(out, exist_ok=True)
    references = [converged(r) for r in ratios]
    before = os.environ.get("NGCONTACT_THREADS")
    os.environ["NGCONTACT_THREADS"] = SCENE_THREADS
    try:
        runs = [scene.start(out, r, "default") for r in ratios]
    finally:
        if before is None:
            del os.environ["NGCONTACT_THREADS"]
        else:
            os.environ["NGCONTACT_THREADS"] = before
    rows = []
    for r, run, reference in zip(ratios, runs, references):
        row = scene.finish(out, r, "default", run, reference)
        report = os.path.join(out, f"p{r:g}", "report.json")
        symmetry = None
        if os.path.isfile(report):
            with open(report) as fh:
                symmetry = json.load(fh)["results"]["accuracy"].get("symmetry")
        rows.append(scene_row(row, symmetry))
    return rows


def cost(row: dict) -> tuple[float, str]:
    """A row's seconds against the aim and their unit: a scene's CPU seconds, else the wall seconds."""
    if isinstance(row.get("cpu_seconds"), float):
        return row["cpu_seconds"], "CPU s"
    return row["seconds"], "s"


def verdict(rows: list[dict], tolerance: float, seconds: float) -> str:
    """Of ``rows`` (one load's, with a relative error), the fastest meeting the aim, its cell, size, error,
    cost and own estimate (whether that estimate alone would certify the tolerance); where none does in time,
    the fastest within the tolerance; or that none is within it."""
    close = [r for r in rows if abs(r["relative_error"]) <= tolerance]
    if not close:
        return f"not met (no row within {100.0 * tolerance:g} %)"
    ok = [r for r in close if cost(r)[0] <= seconds]
    best = min(ok or close, key=lambda r: cost(r)[0])
    spent, unit = cost(best)
    text = (f"{'met' if ok else f'within {100.0 * tolerance:g} % but not in {seconds:g} s'} by `{best['solver']}` "
            f"on the {best.get('cell') or 'period'} (size {best['size']}), {100.0 * best['relative_error']:+.2f} % "
            f"in {spent:.0f} {unit}")
    if isinstance(best.get("estimate"), float):
        own = best["estimate"] <= tolerance
        text += (f", its own estimate {100.0 * best['estimate']:.2f} % ({'within' if own else 'above'} "
                 f"{100.0 * tolerance:g} %: {'certified' if own else 'not certified'} without the converged value)")
    return text


def aim_status(rows: list[dict], tolerance: float = 0.01, seconds: float = 60.0) -> str:
    """Whether issue 38's aim (within ``tolerance`` of the converged contact fraction in at most ``seconds``
    per load) is met, per load, in Markdown: as a scene (part ``scene``: what ``ngcontact run`` gives, its CPU
    seconds) and by the fastest row part 4 assembles (:func:`verdict` of each)."""
    scored = [r for r in rows if r.get("part") in ("scene", "accuracy") and isinstance(r.get("relative_error"), float)]
    loads = []
    for ratio in sorted({r["pressure"] for r in scored}):
        kinds = []
        for part, name in (("scene", "as a scene"), ("accuracy", "by the solves part `accuracy` assembles")):
            sel = [r for r in scored if r["part"] == part and r["pressure"] == ratio]
            if sel:
                kinds.append(f"{name}, {verdict(sel, tolerance, seconds)}")
        loads.append(f"p/p* = {ratio:g}: " + "; ".join(kinds) + ".")
    return ("Aim (issue 38: within %g %% of the converged contact fraction in at most %g s per load; a scene's "
            "seconds are its run's CPU seconds on one thread, the others wall seconds, an extrapolation's the "
            "sum of its solves'). " % (100.0 * tolerance, seconds)
            + (" ".join(loads) if loads else "No accuracy rows."))


def plot_aim(ax, rows: list[dict], tolerance: float = 0.01, seconds: float = 60.0) -> bool:
    """The aim's panel: |relative error| against the seconds of :func:`cost`, per load and kind of row (the
    scene's filled squares, part 4's solves open circles, its extrapolations open diamonds), the aim's box
    dashed; whether any row was drawn."""
    scored = [r for r in rows if r.get("part") in ("scene", "accuracy") and isinstance(r.get("relative_error"), float)]
    kinds = (("solves of part accuracy (s)", "o", False), ("their extrapolations (s)", "D", False),
             ("scene (CPU s)", "s", True))

    def kind(r):
        return 2 if r["part"] == "scene" else 1 if str(r["solver"]).endswith(", extrapolated") else 0
    for k, ratio in enumerate(sorted({r["pressure"] for r in scored})):
        for j, (name, marker, filled) in enumerate(kinds):
            sel = [r for r in scored if kind(r) == j and r["pressure"] == ratio]
            if sel:
                ax.loglog([cost(r)[0] for r in sel], [max(abs(r["relative_error"]), 1e-5) for r in sel], marker,
                          color=f"C{k}", mfc=f"C{k}" if filled else "none", ls="none",
                          label=f"p/p* = {ratio:g}, {name}")
    ax.axhline(tolerance, color="k", lw=0.8, ls="--")
    ax.axvline(seconds, color="k", lw=0.8, ls="--")
    ax.set_xlabel("seconds (a scene's: CPU)")
    ax.set_ylabel("|contact fraction error|, relative")
    ax.set_title("bisinusoid aim: 1 % in 60 s")
    ax.grid(True, which="both", alpha=0.3)
    if scored:
        ax.legend(fontsize=7)
    return bool(scored)
