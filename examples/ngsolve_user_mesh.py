"""A rough interface in your own NGSolve script: a cell's homogenized law on a mesh you built.

A steel block (20 x 5 mm) lies on a steel base of the same size, plane
strain; the base is held at its bottom, the block's top face is pressed
with 10 MPa and sheared with 2 MPa.  The two faces that meet are rough: an
asymmetric sawtooth of period 0.1 mm (the cell scene
``geometries/macro/sawtooth_cell.toml``), whose homogenized law is the
Winkler law of paper eq. 34 with the cell's stiffness matrix ``K0``.

The script builds its own mesh with ``netgen.occ`` (the two bodies glued,
so the interface is one internal boundary both share node for node) and
uses the package twice: ``ngcontact.interface_form`` adds the law's
interface energy to the script's own ``BilinearForm`` of two ``VectorH1``
spaces, one per body, solved by NGSolve's Newton; ``ngcontact.solve_mesh``
solves the same problem on the same mesh and reports it as ``ngcontact
run`` reports a macro scene.  The key number is the vertical force the
block transmits to the base through the interface: all of the load on its
top face, ``-p L``, by equilibrium.

    python examples/ngsolve_user_mesh.py
"""
import ngsolve as ng
from netgen.occ import Glue, OCCGeometry, WorkPlane, Y

import ngcontact


def main() -> tuple[float, float]:
    """Solve by both routes; return the vertical interface force of each [N per metre of depth]."""
    L, H = 0.02, 0.005                 # length and thickness of block and base [m]
    E, NU = 210e9, 0.3                 # steel
    P, T = 10e6, 2e6                   # pressure and shear on the block's top face [Pa]

    # Your mesh: two faces glued, so that the interface is one internal boundary.
    block = WorkPlane().MoveTo(0, 0).Rectangle(L, H).Face()
    base = WorkPlane().MoveTo(0, -H).Rectangle(L, H).Face()
    block.faces.name, base.faces.name = "block", "base"
    block.edges.Max(Y).name, base.edges.Min(Y).name = "top", "bottom"
    block.edges.Min(Y).name = base.edges.Max(Y).name = "interface"
    mesh = ng.Mesh(OCCGeometry(Glue([block, base]), dim=2).GenerateMesh(maxh=H / 2))

    # The law of a shipped cell scene (one cell unit = 0.1 mm): K0 of paper eq. 34 [Pa/m].
    law = ngcontact.cell_law("geometries/macro/sawtooth_cell.toml", form="linear", length_unit=1e-4)
    print("K0 =", law.coefficients["K0"])

    # Your forms: each body its own VectorH1 on its region, plus the law's interface energy.
    fes = (ng.VectorH1(mesh, order=2, definedon=mesh.Materials("block"))
           * ng.VectorH1(mesh, order=2, definedon=mesh.Materials("base"), dirichlet="bottom"))
    u_block, u_base = fes.TrialFunction()
    mu, lam = E / (2 + 2 * NU), E * NU / ((1 + NU) * (1 - 2 * NU))

    def elastic(u):
        eps = ng.Sym(ng.Grad(u))
        return mu * ng.InnerProduct(eps, eps) + lam / 2 * ng.Trace(eps) ** 2

    a = ng.BilinearForm(fes, symmetric=True)
    a += ng.Variation(elastic(u_block) * ng.dx("block") + elastic(u_base) * ng.dx("base"))
    a += ng.Variation(-(T * u_block[0] - P * u_block[1]) * ng.ds("top"))
    a += ngcontact.interface_form(law, mesh, u_block, u_base, rough="block", counter="base").variation
    gfu = ng.GridFunction(fes)
    ng.solvers.Newton(a, gfu, inverse="sparsecholesky", printing=False)
    form = ngcontact.interface_form(law, mesh, *gfu.components, rough="block", counter="base")
    own = -ng.Integrate(form.pressure * form.measure, mesh)     # n0 points down, from block into base

    # The package's solve on the same mesh, with the report of `ngcontact run` (out="dir" writes its files).
    report, _ = ngcontact.solve_mesh(
        mesh, law, rough="block", counter="base", materials={"block": {"E": E, "nu": NU}, "base": {"E": E, "nu": NU}},
        supports=[{"boundary": "bottom"}], loads=[{"boundary": "top", "pressure": P, "traction": [T, 0.0]}])
    force = report["results"]["resultant"]
    peak = report["results"]["maxima"]["pressure"]
    print(f"force through the interface, block on base: ({force['x']:.6g}, {force['y']:.6g}) N per metre of "
          f"depth; the load on the top face is ({T * L:.6g}, {-P * L:.6g})")
    print(f"the same from your own forms: {own:.6g} N/m vertically")
    print(f"peak pressure {peak['pressure'] / 1e6:.3f} MPa at x = {peak['x'] * 1e3:.1f} mm (mean {P / 1e6:g} MPa)")
    return force["y"], own


if __name__ == "__main__":
    main()
