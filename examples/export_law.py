"""Hand a cell's interface law to CalculiX, Abaqus or ANSYS: the table, the friction card, and what is lost.

A conforming sinusoidal interface (amplitude 0.05, period 1 in cell units
of 0.1 mm) with a sinusoidal initial gap closes face by face: its direction
bundle (paper eqs. 31-33) answers a normal closure ``c`` with the pressure
``p(c) = sum_q w_q beta_q [beta_q c - g_q]_+``, a kink wherever one more
face touches, straight with slope ``k_n0`` (eq. 34) once all do.  That curve
is the ``*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=TABULAR`` card of Abaqus and
CalculiX, thinned to a stated tolerance; the homogenized tangential stiffness
``k_t0`` becomes the friction card's stick slope.

The same as on the command line::

    ngcontact export geometries/macro/sinusoid_gap_cell.toml --format calculix \\
        --length-unit 1e-4 --max-pressure 1e8 --mu 0.3

Run it as ``python examples/export_law.py``; it writes no file.  The key
number is ``k_n0`` [Pa/m]: for a sinusoid ``y(x)`` the whole surface gives
``k_n0 = k_n / P * integral over a period of dx / sqrt(1 + y'(x)^2)``.
"""
from ngcontact.export import calculix, json_law
from ngcontact.export.law_source import exported_law

CELL = "geometries/macro/sinusoid_gap_cell.toml"


def main() -> float:
    """Export the sinusoidal cell's law; print its numbers and its CalculiX card; return ``k_n0`` [Pa/m]."""
    law = exported_law(CELL, length_unit=1e-4, p_max=1e8, tolerance=1e-3, mu=0.3)
    print(f"k_n0 = {law.k_n0:.6e} Pa/m (the slope once every face touches, at p >= "
          f"{law.full_contact_pressure() / 1e6:.3f} MPa)")
    print(f"k_t0 = {law.stick_slope:.6e} Pa/m (the stick slope), mu0 = {law.mu} ({law.mu_source})")
    print(f"the exact curve has {len(law.kinks)} kinks; the table keeps {len(law.closure)} nodes "
          f"within {law.tolerance:g} x {law.p_max / 1e6:g} MPa")
    print(calculix.text(law))
    print(f"the JSON law file (ngcontact export --format json) holds {len(json_law.text(law))} characters: the "
          "bundle, K0, the table and the friction, read back by a macro scene with interface.law = \"file\"")
    return law.k_n0


if __name__ == "__main__":
    main()
