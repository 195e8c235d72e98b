"""Linear elasticity on NGSolve in plane strain, axisymmetry and 3D.

The equilibrium problem ``div sigma = f``, ``sigma = C : eps(u)`` (paper
eqs. 1 and 46) is written as the minimum of the stored energy

    Pi(u) = sum over bodies B of  int_B  1/2 sigma(u) : eps(u)  w dx  - (loads),

with the measure weight ``w = 1`` (plane strain, 3D; per unit thickness in
plane strain) or ``w = 2 pi r`` (axisymmetric, per full revolution).

All settings use the 3x3 strain tensor:

* plane strain, coordinates ``(x, y)``: ``eps = [[e_xx, e_xy, 0], [e_xy, e_yy, 0], [0, 0, 0]]``;
* axisymmetric, coordinates ``(r, z)`` = mesh ``(x, y)``, displacement
  ``(u_r, u_z)``: as plane strain plus the hoop strain ``eps_tt = u_r / r``;
* 3D: the symmetric gradient.

Several bodies, each with its own law, each get their own ``VectorH1``
defined on their region only (``definedon``), so that displacements may jump
across an interface between them; on periodic meshes each space is wrapped
in ``Periodic``.
"""
from __future__ import annotations

from math import pi

import ngsolve as ng

from ngcontact.fem.materials import ElasticLaw
from ngcontact.errors import ModelError
from ngcontact.quiet import quiet

SETTINGS = ("plane_strain", "axisymmetric", "3d")
#: displacement components per setting, in the order of the mesh axes
COMPONENTS = {"plane_strain": ("x", "y"), "axisymmetric": ("r", "z"), "3d": ("x", "y", "z")}


def dimension(setting: str) -> int:
    """Spatial dimension of the mesh for ``setting``."""
    _check_setting(setting)
    return 3 if setting == "3d" else 2


def _check_setting(setting: str) -> None:
    if setting not in SETTINGS:
        raise ModelError(f"setting = {setting!r}: must be one of {', '.join(SETTINGS)}")


def strain(u, setting: str):
    """3x3 small-strain tensor of the displacement ``u`` (trial, test or grid function)."""
    _check_setting(setting)
    return strain_of_gradient(ng.Grad(u), u, setting)


def strain_of_gradient(G, u, setting: str):
    """3x3 strain tensor from a displacement gradient ``G`` (dim x dim) and ``u``.

    The same embedding as :func:`strain`, for fields whose gradient is known
    otherwise, e.g. a symbolic ``CoefficientFunction`` differentiated with
    ``.Diff``; ``u`` enters only through the hoop strain ``u_r / r``.
    """
    _check_setting(setting)
    if setting == "3d":
        return ng.Sym(G)
    hoop = u[0] / radius() if setting == "axisymmetric" else 0
    exy = 0.5 * (G[0, 1] + G[1, 0])
    return ng.CF((G[0, 0], exy, 0, exy, G[1, 1], 0, 0, 0, hoop), dims=(3, 3))


#: Floor of the radius in the hoop strain ``u_r / r``.  Quadrature rules may
#: sample points on the axis (e.g. edge midpoints at order 2), where ``u_r = 0``
#: makes ``u_r / r`` a 0/0.  With ``r`` floored there, ``u_r / r = 0`` and, the
#: measure weight ``2 pi r`` being 0, every derivative of the energy stays
#: finite (``1/R_FLOOR^2`` is still representable).
R_FLOOR = 1e-100


def radius():
    """``r = x`` floored at :data:`R_FLOOR` (points exactly on the axis)."""
    return ng.IfPos(ng.x - R_FLOOR, ng.x, R_FLOOR)


def weight(setting: str):
    """Measure weight: ``2 pi r`` in axisymmetry, else 1."""
    _check_setting(setting)
    return 2 * pi * ng.x if setting == "axisymmetric" else ng.CF(1.0)


def stress(law: ElasticLaw, u, setting: str):
    """3x3 stress tensor ``C : eps(u)``."""
    return law.stress(strain(u, setting))


def energy_density(law: ElasticLaw, u, setting: str):
    """Stored energy density ``1/2 sigma : eps`` (without the measure weight)."""
    eps = strain(u, setting)
    return 0.5 * ng.InnerProduct(law.stress(eps), eps)


def bilinear_integrand(law: ElasticLaw, u, v, setting: str):
    """``sigma(u) : eps(v) w``, the integrand of the elastic bilinear form."""
    return ng.InnerProduct(stress(law, u, setting), strain(v, setting)) * weight(setting)


def body_space(mesh, body: str, order: int, dirichlet: str = "", periodic: bool = False,
               components: dict[str, str] | None = None):
    """``VectorH1`` of order ``order`` on region ``body`` (optionally periodic); ``components``: component-wise
    Dirichlet flags beside ``dirichlet`` (``{"dirichletx": "symmetry_x"}``: ``u_x = 0`` there)."""
    if order < 1:
        raise ModelError(f"order = {order!r}: must be >= 1")
    V = vector_h1(mesh, order=order, definedon=mesh.Materials(body), dirichlet=dirichlet, **(components or {}))
    return ng.Periodic(V) if periodic else V


def surface_wirebasket(V, mesh, boundaries: str) -> None:
    """Put every dof of the boundary elements on ``boundaries`` on BDDC's wirebasket.

    BDDC eliminates each element's interface dofs with that element's own
    matrix; a contact term on a boundary element couples the two bodies'
    traces alone and is singular (zero where the contact is open), so its
    dofs must stay in the coarse problem, unless BDDC is built from a form
    that adds :func:`bubble_term` (the cell's energy does; the macro problem
    and Coulomb's non-symmetric residual call this)."""
    wirebasket = ng.COUPLING_TYPE.WIREBASKET_DOF
    for el in mesh.Boundaries(boundaries).Elements():
        for d in V.GetDofNrs(el):
            if d >= 0:
                V.SetCouplingType(d, wirebasket)


#: the factor ``gamma`` of :func:`bubble_term`, chosen on the converged 3D bisinusoid cell
#: (``scripts/scaling_3d.py --coarse 0.06 --k-n K``, CG to 1e-8): there CG's iterations stay nearly
#: independent of k_n and as few as with the contact surface on the wirebasket, whose iterations cost more;
#: a larger gamma lets them grow with k_n, a smaller one with a stiff penalty
BUBBLE_GAMMA = 1.1e-4


def bubble_term(u, v, modulus: float, stiffness, boundaries: str):
    """The contact surface's bubble term of a BDDC preconditioner (never of the tangent itself):

        b(u, v) = int_{S_C} gamma sqrt(M k h^3) h^2  D2_S u : D2_S v  ds,

    ``D2_S`` the Hessian along the surface (NGSolve's ``hesseboundary``),
    ``M`` the body's longitudinal modulus, ``k`` the contact stiffness
    (penalty or augmentation, a number or ``Parameter``), ``h`` the
    element size, ``gamma = BUBBLE_GAMMA``.

    BDDC eliminates each element's interface dofs with that element's own
    matrix, and the contact term of a boundary element is singular on them
    (it couples the two traces through the normal jump alone).  Putting the
    whole contact surface on the wirebasket (:func:`surface_wirebasket`)
    makes BDDC's coarse problem grow with the surface (a large part of a
    3D cell's dofs).  ``b`` instead makes each boundary element's
    edge block definite while leaving the coarse problem alone: the vertex
    functions are linear on a flat triangle, so ``D2_S`` vanishes on them and
    ``b`` acts on the edge bubbles only (tested).  Its size, the geometric
    mean of a bubble's elastic stiffness ``M h`` and its contact stiffness
    ``k h^2`` (``D2_S`` of a bubble is ``1/h^2``), keeps the iterations
    independent of ``k``; ``gamma`` is calibrated (``BUBBLE_GAMMA``).
    """
    h = ng.specialcf.mesh_size
    coefficient = BUBBLE_GAMMA * ng.sqrt(modulus * stiffness * h ** 3) * h ** 2
    return coefficient * ng.InnerProduct(u.Operator("hesseboundary"), v.Operator("hesseboundary")) \
        * ng.ds(boundaries)


def vector_h1(mesh, **flags) -> ng.FESpace:
    """``VectorH1(mesh, **flags)`` with only the vertex dofs on BDDC's wirebasket (its coarse problem).

    At order >= 2 the edge dofs become interface dofs (``wb_withedges=False``,
    :mod:`ngcontact.solvers.linear_solver`); sparse direct solves ignore
    coupling types.  ``VectorH1`` hands the flag to the ``H1`` space of each
    component, which honours it (the coupling types equal those set dof by
    dof, tested), but prints from C++ that the flag is not among its own:
    that line is kept off the user's terminal.  (Setting the types dof by
    dof in Python would cost a noticeable share of a 3D cell solve.)
    """
    with quiet("stderr"):
        return ng.VectorH1(mesh, wb_withedges=False, **flags)


def add_elastic_energy(form: ng.BilinearForm, mesh, bodies: dict, displacements: dict, setting: str):
    """Add ``int_B 1/2 sigma:eps w dx`` of every body to a ``Variation`` form.

    Parameters
    ----------
    form
        The (symmetric) ``BilinearForm`` collecting the total energy.
    bodies
        ``name -> ElasticLaw``.
    displacements
        ``name -> trial function`` of that body's space.
    """
    w = weight(setting)
    for name, law in bodies.items():
        u = displacements[name]
        form += ng.Variation(energy_density(law, u, setting) * w * ng.dx(definedon=mesh.Materials(name)))
    return form
