"""The cell's building blocks: under shear one valley wall lets go, and the tangential stiffness drops.

Paper eq. 34 integrates the micro penalty over the *whole* contact surface;
for the rectangular valley of ``examples/ex27_coefficients.py`` that gives
``k_t0 = 0.6 k_n/|T|``, both valley walls holding the interface against
sliding.  That is only true while everything stays closed.  Push the counter
body sideways and it presses one wall harder and pulls away from most of
the other: the real contact set shrinks, and the coefficients on it (the same integral
over the closed part only) fall.  The linear law of the whole surface
overestimates the stiffness exactly where the interface is loaded in shear,
which is why the package's default macro law is the cell's bundle of
unilateral directions instead.

This example uses the building blocks directly: a cell from a profile
(:mod:`ngcontact.geometry.profiles`), its whole-surface coefficients
(:mod:`ngcontact.cell.coefficients`), and the cell contact problem
(:mod:`ngcontact.cell.fe.cell_problem`: both bodies elastic, ``E = 1``,
penalty ``k_n = 1e3``, periodic sides) solved for two loads, a mean
pressure alone and the same pressure with a shear of a fifth of it.  The key
number is ``k_t0`` on the real contact set under shear, in units of ``k_n/|T|``.

    python examples/cell_under_shear.py
"""
from ngcontact.cell.fe.cell_problem import CellModel, CellProblem, cell_load
from ngcontact.cell.coefficients import coefficients
from ngcontact.fem.materials import isotropic
from ngcontact.geometry.profiles import profile_cell, rectangular_valley

K_N = 1e3            # micro penalty [stress/length], 1000 x E per unit length: nearly rigid contact


def main() -> float:
    """Solve the valley cell under pressure and under pressure plus shear; return ``k_t0 / k_n`` under shear."""
    cell = profile_cell(rectangular_valley(width=0.4, depth=0.3), h_rough=0.8, h_counter=0.6,
                        maxh=0.1, order=2)
    whole = coefficients(cell, kn=K_N)            # eq. 34 over the whole surface S_C
    print(f"whole surface:        contact fraction {whole.contact_fraction:.3f}, "
          f"k_t0 = {whole.k_t / K_N:.3f} k_n/|T|")

    law = isotropic(E=1.0, nu=0.3)
    problem = CellProblem(cell, CellModel(rough=law, counter=law, k_n=K_N, order=2))
    # Loads in the mesh axes (x along S_0, y = n0): mean pressure 0.01 (compression positive),
    # then the same with a mean shear 0.002 on the counter body's far face.
    pressed, sheared = problem.sweep([cell_load(2, pressure=0.01),
                                      cell_load(2, pressure=0.01, shear=(0.002,))])

    for name, sol in (("pressure only", pressed), ("pressure and shear", sheared)):
        r = sol.results
        k_t = r["coefficients"]["k_t"] / K_N      # eq. 34 over the real contact set {p > 0}
        # effective stiffness: asperity compliance included, finite however large k_n is
        eff = r["effective_stiffness"]["matrix"]
        print(f"{name + ':':21} contact fraction {r['contact_fraction']:.3f}, k_t0 = {k_t:.3f} k_n/|T|, "
              f"effective tangential stiffness {eff[1][1]:.1f}")
    k_t_sheared = sheared.results["coefficients"]["k_t"] / K_N
    print(f"k_t0 under shear {k_t_sheared:.4f} k_n/|T| (whole surface: {whole.k_t / K_N:.1f})")
    return k_t_sheared


if __name__ == "__main__":
    main()
