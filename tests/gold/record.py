"""The gold record of the shipped scenes: which numbers characterise a report, and how two of them compare.

Used by ``scripts/gold_record.py`` (which writes ``tests/gold/scenes.json``) and by
``tests/drivers/test_gold.py`` (which compares a fresh run of every recorded scene with it); both load
this file by its path.

Extraction.  A report's ``results`` is flattened to ``dotted.key -> number`` (list indices become key
components: ``loads.2.contact_fraction``), and only the leaves matching :data:`HEADLINE` are kept, in
its order, at most :data:`MAX_KEYS` per scene: the cell's coefficients of the whole contact surface
(paper eqs. 34, 42-43) and per load the contact fraction, mean pressure and closure, peak pressure,
slip, the coefficients on the real contact set, the diagonal of the effective stiffness and the
bodies' peak von Mises stress; an ensemble's mean and band half-width per load and the shrinkage rate
of its standard error; a macro run's resultant, support reactions, peak pressure and shear, stress
extrema, contact area, detachment points, the strength check's safety factors (paper eqs. 74-78) and
the two-scale loop's peak pressures and table error; a resolved run's reactions, contact force,
contact fraction and probe displacements; a verification's convergence rates and finest errors.  The
report's ``ndof`` is kept as an integer.  Timings, iteration counts, file lists, locations of extrema
and the long arrays along the interface are not part of the record; nor is a value that is not finite.

Comparison.  A float key passes when ``|new - gold| <= max(RTOL * |gold|, ZERO * scale)``; an integer key
(``ndof``) must be equal.  ``RTOL = 1e-6`` is chosen from the run-to-run spread: NGSolve's threaded
assembly sums in a varying order, so two runs of a scene on the same commit are not bit-identical.  Two
records of every shipped scene on one commit (and a third run of the Westergaard cells) differed by at
most 5.2e-8 relative, in the effective stiffness of the graded Westergaard cell's loads (the inverse of a
difference of two nearly equal compliances, see the README's ``effective_stiffness``), by at most 1.3e-9
in any key of the other scenes, and not at all for the spectral, ensemble, verification and
whole-surface scenes.  1e-6 leaves a factor of about 20 above that spread, while a change of
discretization, law, or solver tolerance moves these numbers by far more.

``scale`` is the largest ``|gold|`` among the scene's keys of the same quantity (the same last name
component; the stiffnesses ``k_*`` pooled, the stresses ``g_*``, ``G_*`` pooled), or the scene's largest
value where that quantity is zero throughout: a coefficient that is zero up to round-off (``k_nt`` of a
symmetric valley) then compares against ``ZERO = 1e-9`` of its own quantity's size, not of a quantity in
other units (the scenes are in SI units, where pressures of 1e6 Pa sit beside closures of 1e-6 m).  A key
of the record that the new report lacks is a failure; keys the new report adds are ignored.

A key that is a difference of larger numbers of the record (:data:`DIFFERENCES`: ``max_rate_deviation``,
an observed convergence rate less its expected one) carries their round-off, not its own: its
``RTOL`` is taken of the largest of those numbers (the rates), not of the small difference.
"""
from __future__ import annotations

import math
import re
from typing import Any, Iterator

#: relative tolerance of a comparison (see the module docstring)
RTOL = 1e-6
#: absolute floor of a comparison, relative to the size of the key's quantity in its scene
ZERO = 1e-9
#: largest number of keys kept per scene
MAX_KEYS = 60
#: a scene whose run takes longer than this many seconds is marked ``expensive`` in the record
EXPENSIVE_SECONDS = 60.0

_IDX = r"\d+"
#: regular expressions over the dotted keys of ``results``, in the order the keys are kept
HEADLINE: tuple[str, ...] = (
    # cell: the coefficients of the whole contact surface (paper eqs. 34, 42-43)
    r"whole_surface\.contact_fraction",
    r"whole_surface\.(k_n|k_t|k_nt|g_n|g_t|G_n|G_t)(\.\d+)?",
    # cell: per load
    rf"loads\.{_IDX}\.contact_fraction",
    rf"loads\.{_IDX}\.mean_pressure",
    rf"loads\.{_IDX}\.mean_closure",
    rf"loads\.{_IDX}\.max_pressure",
    rf"loads\.{_IDX}\.(slip_fraction|max_slip)",
    rf"loads\.{_IDX}\.coefficients\.(k_n|g_n)",
    rf"loads\.{_IDX}\.effective_stiffness\.matrix\.(\d+)\.\1",
    rf"loads\.{_IDX}\.max_von_mises_(rough|counter)\.value",
    rf"loads\.{_IDX}\.coefficients\.(k_t|k_nt|G_n|G_t)(\.\d+)?",
    # ensemble: mean and band per load, and how the band shrinks with the members
    rf"loads\.{_IDX}\.(contact_fraction|k_n0|effective_stiffness|mean_closure|transmitted_pressure)\.mean",
    rf"loads\.{_IDX}\.(contact_fraction|k_n0|effective_stiffness|mean_closure)\.half_width",
    r"shrinkage\.\w+\.rate",
    # macro
    r"resultant\.\w+",
    r"strength\.safety_factor",
    r"strength\.bodies\.\w+\.(safety_factor|max_sigma_eq)",
    r"maxima\.pressure\.pressure",
    r"maxima\.shear\.shear",
    r"contact_area",
    r"maxima\.von_mises\.max\.value",
    r"two_scale\.history\.\d+\.max_pressure",
    r"two_scale\.table\.error_estimate",
    r"equilibrium\.bodies\.\w+\.\w+\.supports",
    r"detachment\.\d+\.(s|z)",
    r"maxima\.sigma_\w+\.(max|min)\.value",
    # direct (resolved)
    r"reactions\.\w+\.\w+",
    r"contact_force\.\d+",
    r"contact_fraction",
    r"probes\.\d+\.\d+",
    # manufactured
    r"max_rate_deviation",
    r"rates\.\w+\.(l2|h1)",
)
_HEADLINE = tuple(re.compile(p) for p in HEADLINE)

#: keys that are differences of larger numbers of the record, and the prefix of those numbers' keys: compared at
#: ``RTOL`` of the largest of them (module docstring)
DIFFERENCES = {"max_rate_deviation": "rates."}

#: last key components that share one scale in the comparison
_FAMILY = {"k_n": "k_*", "k_t": "k_*", "k_nt": "k_*", "g_n": "g_*", "g_t": "g_*", "G_n": "g_*", "G_t": "g_*"}


def flatten(tree: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """Every leaf of a JSON tree as ``(dotted.key, value)``; list indices are key components."""
    if isinstance(tree, dict):
        for k, v in tree.items():
            yield from flatten(v, f"{prefix}.{k}" if prefix else str(k))
    elif isinstance(tree, list):
        for i, v in enumerate(tree):
            yield from flatten(v, f"{prefix}.{i}" if prefix else str(i))
    else:
        yield prefix, tree


def _finest_errors(results: dict) -> dict[str, float]:
    """A verification's errors on its finest level, per order: ``finest.p<order>.l2`` and ``.h1``."""
    rows = results.get("rows")
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) and "order" in r for r in rows):
        return {}
    out: dict[str, float] = {}
    for order in sorted({r["order"] for r in rows}):
        finest = max((r for r in rows if r["order"] == order), key=lambda r: r.get("level", 0))
        for norm in ("l2", "h1"):
            if isinstance(finest.get(norm), (int, float)):
                out[f"finest.p{order}.{norm}"] = float(finest[norm])
    return out


def extract(report: dict) -> dict[str, float | int]:
    """The headline numbers of a report (see the module docstring), in :data:`HEADLINE` order."""
    leaves = {k: v for k, v in flatten(report.get("results", {}))
              if isinstance(v, (int, float)) and not isinstance(v, bool)}
    picked: dict[str, float | int] = {}
    if isinstance(report.get("ndof"), int) and not isinstance(report.get("ndof"), bool):
        picked["ndof"] = report["ndof"]
    for rx in _HEADLINE:
        for key, value in leaves.items():
            if key not in picked and rx.fullmatch(key) and math.isfinite(value):
                picked[key] = float(value)
    if report.get("kind") == "manufactured":
        picked.update({k: v for k, v in _finest_errors(report["results"]).items() if math.isfinite(v)})
    return dict(list(picked.items())[:MAX_KEYS])


def _family(key: str) -> str:
    last = next((p for p in reversed(key.split(".")) if not p.isdigit()), key)
    return _FAMILY.get(last, last)


def scales(gold: dict[str, float | int]) -> dict[str, float]:
    """Per key of a scene's record: the size of its quantity in that scene (see the module docstring)."""
    largest: dict[str, float] = {}
    for key, value in gold.items():
        fam = _family(key)
        largest[fam] = max(largest.get(fam, 0.0), abs(float(value)))
    overall = max((abs(v) for v in gold.values() if isinstance(v, float)), default=0.0)
    return {key: largest[_family(key)] or overall for key in gold}


def compare(gold: dict[str, float | int], new: dict[str, float | int], *,
            rtol: float = RTOL, zero: float = ZERO) -> list[tuple[str, Any, Any, float]]:
    """The keys of ``gold`` that ``new`` misses or does not reproduce: ``(key, gold, new, relative difference)``.

    ``new`` is ``None`` for a missing key (relative difference ``inf``).  Keys only in ``new`` are ignored.
    """
    size = scales(gold)
    bad: list[tuple[str, Any, Any, float]] = []
    for key, ref in gold.items():
        if key not in new:
            bad.append((key, ref, None, math.inf))
            continue
        val = new[key]
        diff = abs(float(val) - float(ref))
        rel = diff / abs(ref) if ref else (0.0 if diff == 0 else math.inf)
        if isinstance(ref, int) and not isinstance(ref, bool):
            ok = val == ref
        else:
            of = max((abs(float(v)) for k, v in gold.items() if k.startswith(DIFFERENCES[key])), default=0.0) \
                if key in DIFFERENCES else 0.0
            ok = math.isfinite(float(val)) and diff <= max(rtol * max(abs(ref), of), zero * size[key])
        if not ok:
            bad.append((key, ref, val, rel))
    return bad


def largest_difference(gold: dict[str, float | int], new: dict[str, float | int], *, zero: float = ZERO) -> float:
    """The largest ``|new - gold| / max(|gold|, zero * scale)`` over the keys of ``gold`` (``inf`` for a missing
    key): the relative spread of two records, each key measured as :func:`compare` measures it."""
    size = scales(gold)
    worst = 0.0
    for key, ref in gold.items():
        if key not in new:
            return math.inf
        diff = abs(float(new[key]) - float(ref))
        denom = max(abs(float(ref)), zero * size[key])
        worst = max(worst, diff / denom if denom > 0 else (0.0 if diff == 0 else math.inf))
    return worst


def table(rows: list[tuple[str, str, Any, Any, float]]) -> str:
    """A readable table of failures ``(scene, key, gold, new, relative difference)``."""
    head = ("scene", "key", "gold", "new", "rel. diff")
    cells = [head] + [(s, k, _num(g), "missing" if n is None else _num(n), f"{r:.3e}") for s, k, g, n, r in rows]
    widths = [max(len(c[i]) for c in cells) for i in range(len(head))]
    return "\n".join("  ".join(c[i].ljust(widths[i]) for i in range(len(head))).rstrip() for c in cells)


def _num(x: Any) -> str:
    return str(x) if isinstance(x, int) else f"{float(x):.12g}"
