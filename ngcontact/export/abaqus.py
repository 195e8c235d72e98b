"""Abaqus keywords of an exported law: ``*SURFACE INTERACTION``, tabular ``*SURFACE BEHAVIOR``, ``*FRICTION``.

Normal: ``PRESSURE-OVERCLOSURE=TABULAR`` with one data line per table node,
``pressure, overclosure``, overclosures strictly increasing and the first
pressure zero.  The overclosure ``d`` of the code is measured between the
surfaces as meshed (both on ``S_0``): ``d = a_n = c + g0`` with ``c`` the
closure of the law and ``g0`` the macro gap, so an interference ``g0 < 0``
shifts the table to negative overclosures (pressure at zero overclosure).
Abaqus extrapolates beyond the last node with the last slope (here
``k_n0``, exact for the bundle) and transmits nothing below the first.

Tangential: ``*FRICTION, ELASTIC SLIP=gamma`` with the Coulomb coefficient
``mu0`` on the data line.  Abaqus's stick stiffness is ``mu0 p / gamma``;
with ``gamma = mu0 p_ref / k_t0`` it equals the law's stick slope ``k_t0``
(paper eqs. 34, 42-43) at the reference pressure ``p_ref``, half the table's
largest pressure, and scales with ``p`` elsewhere (stated in the file).
"""
from __future__ import annotations

from ngcontact.errors import ModelError
from ngcontact.export.law_table import ExportedLaw, number

NAME = "NGCONTACT_LAW"


def header(law: ExportedLaw, comment: str, code: str) -> list[str]:
    """Comment lines naming the source, the units, the table's range and what is not carried."""
    s = law.source
    lines = [f"ngcontact homogenized interface law for {code} (Orlik 2004; units: m, Pa, Pa/m = N/m^3)",
             f"source: {s['kind']} scene {s['scene']} (SHA-256 {s['scene_sha256']})"]
    if "cell_sha256" in s:
        lines.append(f"cell content hash {s['cell_sha256']}, cell length unit {s.get('length_unit', 1.0):g} m")
    kinks = f"{len(law.kinks)} kink" + ("s" if len(law.kinks) != 1 else "")
    lines += [f"normal law: p(c) = sum_i s_i [c - c_i]_+ with {kinks}; k_n0 = {law.k_n0:.10g} Pa/m "
              f"beyond the last kink (p >= {law.full_contact_pressure():.6g} Pa)",
              f"table: {len(law.closure)} nodes, exact at the nodes, within {law.tolerance:g} * p_max between; "
              f"pressure range 0 .. {law.p_max:.6g} Pa, closure {law.closure[0]:.6g} .. {law.closure[-1]:.6g} m",
              f"macro gap g0 = {law.gap:.6g} m (overclosure d = closure + g0; negative g0 = interference)",
              f"friction: mu0 = {law.mu:.6g} ({law.mu_source}), stick slope k_t0 = {law.stick_slope:.10g} Pa/m"]
    lines += [f"NOT CARRIED: {n}" for n in law.notes]
    return [f"{comment} {line}" for line in lines]


def table_rows(law: ExportedLaw) -> list[str]:
    """``pressure, overclosure`` data lines (13 significant digits)."""
    return [f"{number(p)}, {number(c + law.gap)}" for c, p in zip(law.closure, law.pressure)]


def text(law: ExportedLaw) -> str:
    """The Abaqus keyword block (include it with ``*INCLUDE``; name it in ``*CONTACT PAIR, INTERACTION=``)."""
    lines = header(law, "**", "Abaqus/Standard")
    lines += ["** beyond the last node Abaqus continues with the last slope; below the first, no pressure",
              f"*SURFACE INTERACTION, NAME={NAME}",
              "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR"] + table_rows(law)
    if law.mu > 0 and law.stick_slope > 0:
        p_ref = 0.5 * law.p_max
        gamma = law.mu * p_ref / law.stick_slope
        if not (1e-300 < gamma < 1e300):
            who = "--mu" if law.mu_source == "given" else f"mu0 (from {law.mu_source})"
            raise ModelError(f"{who} {law.mu!r}: the elastic slip mu0 p_ref / k_t0 = {gamma:g} m it gives (p_ref = "
                             f"{p_ref:.6g} Pa, k_t0 = {law.stick_slope:.6g} Pa/m) must be a positive finite number")
        lines += [f"** elastic slip gamma = mu0 p_ref / k_t0 with p_ref = {p_ref:.6g} Pa: the stick stiffness "
                  "mu0 p / gamma equals k_t0 at p = p_ref only (Abaqus scales it with the pressure)",
                  f"*FRICTION, ELASTIC SLIP={number(gamma)}", number(law.mu)]
    elif law.mu > 0:
        lines += ["** the law has no tangential stiffness (k_t0 = 0): elastic slip 1e-3 of the table's closure range",
                  f"*FRICTION, ELASTIC SLIP={number(1e-3 * (law.closure[-1] - law.closure[0]))}", number(law.mu)]
    else:
        lines.append("** no *FRICTION: the friction coefficient is 0 (give one with --mu to carry the stick slope)")
    return "\n".join(lines) + "\n"
