"""The discrete cell: what a state of the FE cell problem lives on and is measured with (no state).

The cell problem of paper eqs. 49-51 (penalized, eq. 65) discretized on a meshed cell: the space ``X = (u_r,
u_c, U_1 .. U_d)`` of the two bodies' periodic fluctuations (``u_r`` zero on ``bottom``, ``u_c`` zero on
``top``; on a symmetric quarter cell, :mod:`ngcontact.geometry.cell3d`, not periodic but with the displacement
normal to each mirror plane zero on it, :func:`mirror_flags`) and the far face's rigid translation ``U`` (one
``NumberSpace`` per component, defined only where it enters: on ``S_C`` and on the far face), the micro normal
``n`` on ``S_C``, the gap ``g`` (for the penalty its interpolant of the displacement order on ``S_C``: the
penetration ``J.n - g_h`` is then a polynomial per element, its sign not polluted by the interpolation error
of a transcendental gap), the load's parameters (far-face tractions ``tbar``, macro strain ``E`` of eq. 63),
and, for exact enforcement, the multiplier on ``S_C``'s nodes and the augmentation ``k_n``.

:func:`discretize` builds it once; the energy (:mod:`ngcontact.cell.fe.cell_energy`) and the cell problem
(:class:`~ngcontact.cell.fe.cell_problem.CellProblem`, which adds the state and the solvers) read it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import ngsolve as ng

from ngcontact.cell.coefficients import contact_normal
from ngcontact.cell.fe.cell_model import CellModel
from ngcontact.cell.fe.contact_multiplier import ContactMultiplier
from ngcontact.cell.fe.linear_trace import lower_trace, trace_order
from ngcontact.fem import elasticity as _el
from ngcontact.fem.quadrature import sampling_order
from ngcontact.geometry.cell3d import SYMMETRY_FACES


@dataclass(frozen=True)
class DiscreteCell:
    """The frozen description of a discretized cell (module docstring).

    ``traction``, ``strain_params`` and ``augmentation`` are NGSolve ``Parameter`` objects: the forms built on
    this description read their current values, which a load sets.
    """

    cell: Any
    model: CellModel
    X: ng.FESpace
    n: Any
    gap: Any
    u_dofs: tuple[int, ...]
    traction: tuple[ng.Parameter, ...]
    strain_params: tuple[ng.Parameter, ...]
    augmentation: ng.Parameter
    multiplier: ContactMultiplier | None
    tangential_free: bool
    inverse: str

    @property
    def mesh(self):
        return self.cell.mesh

    @property
    def dim(self) -> int:
        return self.cell.dim

    @property
    def setting(self) -> str:
        return "3d" if self.dim == 3 else "plane_strain"

    @property
    def area(self) -> float:
        """``|T|``: the projected area (3D) or length (2D) of one period."""
        return self.cell.area

    @property
    def contact_order(self) -> int:
        """Integration order of the contact energy (that of the ``Variation`` term)."""
        return 2 * self.model.order + self.model.contact_bonus_order

    def body_strain(self, u):
        """Total strain of a body: fluctuation plus the macro strain (if assembled)."""
        eps = _el.strain(u, self.setting)
        return eps + macro_strain_cf(self.strain_params, self.dim) if self.model.macro_strain else eps


def discretize(cell, model: CellModel, *, normal=None, inverse: str = "sparsecholesky") -> DiscreteCell:
    """The discrete cell of a meshed ``cell`` and its physics ``model`` (module docstring); ``normal``: the
    micro normal on ``S_C`` (default :func:`ngcontact.cell.coefficients.contact_normal`); ``inverse``: the
    sparse direct solver the forms' storage is chosen for."""
    mesh, dim = cell.mesh, cell.dim
    n = normal if normal is not None else contact_normal(cell)
    mirror = mirror_flags(cell)
    bodies = [_el.body_space(mesh, name, model.order, dirichlet=far, components=mirror)
              for name, far in (("rough", "bottom"), ("counter", "top"))]
    trace = trace_order(model, dim)
    if trace < model.order:          # exact contact in 3D on a linear trace (ngcontact.cell.fe.linear_trace)
        for V in bodies:
            lower_trace(V, mesh, "contact", trace)
    Vr, Vc = bodies if getattr(cell, "symmetric", False) else (ng.Periodic(V) for V in bodies)
    # U lives only where it enters (S_C and the far face): a NumberSpace on every element would couple all
    # dofs and make the factorization much slower
    N = ng.NumberSpace(mesh, definedon=mesh.Boundaries("contact|top"))
    X = ng.FESpace([Vr, Vc] + [N] * dim)
    # exact: the gap itself at the Lobatto nodes (an interpolant on S_C, not periodic, would give the two
    # copies of a periodic vertex different gaps: contradictory constraints on one node)
    gap = model.gap if model.enforcement == "exact" else discrete_gap(mesh, model)
    return DiscreteCell(
        cell=cell, model=model, X=X, n=n, gap=gap, u_dofs=tuple(X.Range(2 + i).start for i in range(dim)),
        traction=tuple(ng.Parameter(0.0) for _ in range(dim)),
        strain_params=tuple(ng.Parameter(0.0) for _ in range(1 if dim == 2 else 3)),
        # exact: the augmentation k_n as a Parameter (the constrained tangent extrapolates in it)
        augmentation=ng.Parameter(model.k_n),
        multiplier=ContactMultiplier(mesh, trace) if model.enforcement == "exact" else None,
        tangential_free=tangential_determinate(mesh, n, dim, model), inverse=inverse)


def mirror_flags(cell) -> dict[str, str]:
    """The component-wise Dirichlet flags of a symmetric quarter cell (:mod:`ngcontact.geometry.cell3d`): the
    displacement normal to each mirror plane held at zero on it (``u_x`` on ``symmetry_x``, ``u_y`` on
    ``symmetry_y``), the shear traction there left natural (zero); none on a periodic cell."""
    if not getattr(cell, "symmetric", False):
        return {}
    return {f"dirichlet{axis}": face for axis, face in zip("xy", SYMMETRY_FACES)}


def discrete_gap(mesh, model: CellModel):
    """The gap interpolated into polynomials of the displacement order on ``S_C`` (module docstring);
    ``model.gap`` itself without gap or with ``interpolate_gap = False``."""
    g = model.gap
    if g is None or not model.interpolate_gap:
        return g
    Vg = ng.H1(mesh, order=model.order, definedon=mesh.Boundaries("contact"))
    gh = ng.GridFunction(Vg)
    gh.Set(g, definedon=mesh.Boundaries("contact"))
    return gh


def tangential_determinate(mesh, n, d: int, model: CellModel) -> bool:
    """False when the far-face translation ``U_t`` costs no energy: frictionless and a flat ``S_C``."""
    if model.friction is not None:
        return True
    nt2 = ng.InnerProduct(n, n) - n[d - 1] * n[d - 1]
    tilt = ng.Integrate(nt2, mesh, definedon=mesh.Boundaries("contact"), order=sampling_order(model.order))
    size = ng.Integrate(ng.CF(1.0), mesh, definedon=mesh.Boundaries("contact"))
    return tilt > 1e-12 * size


def macro_strain_cf(params, dim: int):
    """The in-plane macro strain ``E`` of eq. 63 as a 3x3 CoefficientFunction.

    ``params``: 2D ``(e_xx,)``, 3D ``(e_xx, e_yy, e_xy)`` (``Parameter`` objects or numbers).
    """
    e = params
    if dim == 2:
        return ng.CF((e[0], 0, 0, 0, 0, 0, 0, 0, 0), dims=(3, 3))
    return ng.CF((e[0], e[2], 0, e[2], e[1], 0, 0, 0, 0), dims=(3, 3))
