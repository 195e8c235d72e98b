"""ANSYS APDL commands of an exported law: absolute contact stiffnesses and the friction coefficient.

ANSYS contact elements (CONTA17x) take a constant normal stiffness: real
constant 3, ``FKN``, read as an absolute value [force / length^3 = Pa/m] when
negative, and the sticking stiffness, real constant 12, ``FKT``, likewise;
the macro gap enters as the contact offset, real constant 10, ``CNOF``
(positive closes: ``CNOF = -g0``).  Written:

    FKN = -k_n0    (the slope beyond the last kink: exact for p >= p_full)
    FKT = -k_t0    (the stick slope, paper eqs. 34, 42-43; not written when k_t0 = 0:
                    ANSYS would read 0 as its default factor)
    CNOF = -g0 - c_full + p_full / k_n0   (the straight line through the curve's last segment)
    MU = mu0       (MP,MU; TB,FRIC with TBDATA,1,mu0 in newer versions)

A linear stiffness holds only where the curve is straight: for pressures
at or above ``p_full`` (every direction closed); below it the file lists
the table as comments (ANSYS's own nonlinear normal stiffness input is not
written).  The real-constant set and material numbers are parameters
(``NGC_REAL``, ``NGC_MAT``, set to 2 at the top of the file: edit them).
"""
from __future__ import annotations

from ngcontact.export.abaqus import header
from ngcontact.export.law_table import ExportedLaw, number


def offset(law: ExportedLaw) -> float:
    """``CNOF`` [m]: the overclosure shift that puts the line ``k_n0 (d + CNOF)`` on the curve's last segment."""
    c_full = float(law.kinks.max())
    return -law.gap - c_full + law.full_contact_pressure() / law.k_n0


def text(law: ExportedLaw) -> str:
    lines = header(law, "!", "ANSYS Mechanical APDL (CONTA17x)")
    p_full = law.full_contact_pressure()
    lines += [f"! FKN and CNOF reproduce the law exactly for contact pressures p >= {p_full:.6g} Pa "
              f"(up to the table's {law.p_max:.6g} Pa and beyond); below, the law is the table:",
              "!   pressure [Pa], closure [m]"] + [f"!   {p:.10g}, {c:.10g}" for c, p in zip(law.closure, law.pressure)]
    lines += ["NGC_REAL = 2   ! real-constant set of the contact pair: edit", "NGC_MAT = 2   ! its material: edit",
              f"NGC_FKN = {number(-law.k_n0, '.17g')}   ! absolute normal stiffness [N/m^3] (negative: absolute)"]
    if law.stick_slope > 0:
        lines.append(f"NGC_FKT = {number(-law.stick_slope, '.17g')}   ! absolute sticking stiffness [N/m^3]")
    lines += [f"NGC_CNOF = {number(offset(law), '.17g')}   ! contact offset [m], positive closes",
              f"NGC_MU = {number(law.mu, '.17g')}   ! friction coefficient ({law.mu_source})",
              "R,NGC_REAL", "RMODIF,NGC_REAL,3,NGC_FKN", "RMODIF,NGC_REAL,10,NGC_CNOF"]
    # FKT = 0 would read as ANSYS's default factor, not as an absolute stiffness: no zero is written
    lines += (["RMODIF,NGC_REAL,12,NGC_FKT"] if law.stick_slope > 0 else
              ["! no FKT: the law has no tangential stiffness (k_t0 = 0); ANSYS takes its default sticking stiffness"])
    lines.append("MP,MU,NGC_MAT,NGC_MU")
    return "\n".join(lines) + "\n"
