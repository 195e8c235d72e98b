"""CalculiX (ccx 2.20) keywords of an exported law: tabular ``*SURFACE BEHAVIOR`` and ``*FRICTION``.

The same data lines as Abaqus (``pressure, overclosure``,
:mod:`ngcontact.export.abaqus`), with two differences of ccx documented in its
manual: outside the table the pressure stays *constant* (no extrapolation:
the table must cover every pressure of the model, so its range is stated and
should be chosen with ``--max-pressure``), nodes closer than ``1e-10``
(length units) are moved apart, and a table of more than 200 nodes is
resampled at 200 equidistant closures (``plcopy.f``).  Use it with node-to-face
penalty contact (``*CONTACT PAIR, TYPE=NODE TO SURFACE``), which multiplies
the pressure by each slave node's share of the slave faces: with
face-to-face contact ccx 2.20 transmits no pressure through a tabular law
(``springforc_f2f.f`` reads the table's length from ``plconloc(81)`` instead
of ``plconloc(801)``; seen here as zero contact stress everywhere).

Friction: ``*FRICTION`` with ``mu0, lambda``, the stick slope ``lambda`` in
force per volume, here the law's ``k_t0`` [Pa/m] exactly (paper eqs. 34,
42-43; ccx requires ``mu0 > 0``).
"""
from __future__ import annotations

import numpy as np

from ngcontact.export.abaqus import NAME, header, table_rows
from ngcontact.export.law_table import ExportedLaw, number

#: ccx moves table nodes closer than this apart (surfacebehaviors.f).
CCX_MIN_SPACING = 1e-10


def notes(law: ExportedLaw) -> tuple[str, ...]:
    """What ccx loses beyond :attr:`ExportedLaw.notes`."""
    out = list(law.notes)
    if len(law.closure) > 1 and np.min(np.diff(law.closure)) < CCX_MIN_SPACING:
        out.append(f"table nodes closer than {CCX_MIN_SPACING:g} m are moved apart by ccx (smallest spacing "
                   f"{np.min(np.diff(law.closure)):.3g} m): choose a coarser --table-tol or another length unit")
    if len(law.closure) > 200:
        out.append(f"the table has {len(law.closure)} nodes; ccx resamples more than 200 at 200 equidistant "
                   "closures: choose a coarser --table-tol")
    if law.mu > 0 and law.stick_slope == 0:
        out.append("the law has no tangential stiffness (k_t0 = 0); ccx takes its default stick slope")
    if law.mu == 0:
        out.append(f"the stick slope k_t0 = {law.stick_slope:.6g} Pa/m is not carried: ccx's *FRICTION needs mu0 > 0 "
                   "(give one with --mu)")
    return tuple(out)


def text(law: ExportedLaw) -> str:
    """The ccx keyword block (``*INCLUDE`` it before the first ``*STEP``)."""
    lines = header(law, "**", "CalculiX ccx 2.20")
    lines += [f"** NOT CARRIED: {n}" for n in notes(law) if n not in law.notes]
    lines += [f"** ccx holds the pressure constant beyond the last node ({law.p_max:.6g} Pa): keep the model's "
              "pressures below it; below the first node the pressure is 0",
              "** use with *CONTACT PAIR, INTERACTION=" + NAME + ", TYPE=NODE TO SURFACE (ccx 2.20's face-to-face "
              "contact transmits no pressure through a tabular law)",
              f"*SURFACE INTERACTION, NAME={NAME}",
              "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR"] + table_rows(law)
    if law.mu > 0:
        lines += ["** mu0, stick slope lambda = k_t0 [N/m^3]",
                  "*FRICTION", f"{number(law.mu)}, {number(law.stick_slope)}" if law.stick_slope > 0
                  else number(law.mu)]
    return "\n".join(lines) + "\n"
