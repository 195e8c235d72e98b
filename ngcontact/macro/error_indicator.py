"""Where a macro solution's error lives: an element-wise indicator of its stress error, and the elements to refine.

The indicator of a volume element ``T`` of body ``B`` (stiffness ``C_B``, largest modulus ``E_B``) is

    eta_T^2 = 1/E_B int_T |sigma* - sigma_h|^2 w dx  +  sum_{F in S_0, F < T} h_F/E_F int_F |[sigma* n]|^2 w ds,

with ``sigma_h = C_B : eps(u_B)`` the discrete stress (discontinuous between elements), ``sigma*`` its
recovery: the stress interpolated into the continuous space of the same order on each body separately
(:func:`recovered_stress`, NGSolve's ``Set``: element-wise projection, averaged at shared vertices and
edges), ``[sigma* n] = (sigma*_rough - sigma*_counter) n`` the jump of the two bodies' recovered normal
stress across the interface ``S_0``, ``h_F`` the interface element's length (2D) or the square root of its
area (3D), ``E_F`` the larger modulus of the two bodies and ``w`` the measure weight (``2 pi r`` in
axisymmetry).  The interface term is added to the indicator of both elements that share ``F``.

Why this indicator
    * The volume term is the Zienkiewicz-Zhu estimate: where the exact stress is smooth, the recovered
      stress is closer to it than the discrete one (super-convergent averaging), so ``|sigma* - sigma_h|``
      measures the discrete stress's error element by element; divided by the modulus it is the error's
      complementary energy, comparable between a stiff and a soft body.  At a corner where the stress is
      singular (or has a singular derivative, as where a body's side meets the interface) the discrete
      stress jumps most between neighbouring elements, and so does the indicator: the refinement grades
      towards the corner.
    * The interface term is the residual of the interface's equilibrium: both bodies carry the law's
      traction on ``S_0`` (paper eq. 46), so their normal stresses must agree there; the discrete ones
      do only weakly.  Every headline quantity of the macro run is a traction on ``S_0`` (peak pressure,
      resultant) or a stress maximum, which sits on or next to it in every shipped scene; this term puts
      the interface's elements first where the bodies' stresses disagree across it.
    * It needs no second solve: one interpolation per body and element-wise integrals.

The elements to refine (:func:`marked`): the fewest with the largest indicators whose squares sum to at
least :data:`BULK` of the total (Doerfler's bulk criterion, which makes adaptive refinement converge at
the optimal rate for the energy error), and the elements that hold a quantity still beyond the tolerance
(:func:`holding`: a stress maximum or the peak pressure is sampled at points of its element, so its
sampling error and its local error shrink only with that element, wherever the energy error lies).
"""
from __future__ import annotations

import ngsolve as ng
import numpy as np

from ngcontact.fem import elasticity
from ngcontact.macro.macro_problem import MacroSolution

#: the share of the squared indicators the marked elements carry (Doerfler's bulk parameter)
BULK = 0.5


def _modulus(law) -> float:
    """The largest diagonal entry of a stiffness in Voigt form: the modulus the stress error is scaled by."""
    return float(max(law.voigt[i][i] for i in range(len(law.voigt))))


def recovered_stress(sol: MacroSolution, region: str, stress: ng.CoefficientFunction) -> ng.GridFunction:
    """The stress of body ``region`` interpolated into the continuous space of the solution's order on it
    (nine components, the 3x3 tensor row by row)."""
    p = sol.problem
    space = ng.H1(p.mesh, order=p.order, dim=9, definedon=p.mesh.Materials(region))
    out = ng.GridFunction(space)
    out.Set(stress, definedon=p.mesh.Materials(region))
    return out


def indicator(sol: MacroSolution) -> np.ndarray:
    """``eta_T`` (module docstring) of every volume element of ``sol``'s mesh, in element order."""
    p = sol.problem
    mesh, w = p.mesh, elasticity.weight(p.setting)
    flat: dict[str, ng.CoefficientFunction] = {}
    recovered: dict[str, ng.GridFunction] = {}
    eta2 = np.zeros(mesh.ne)
    for region, u in ((p.rough, sol.u_rough), (p.counter, sol.u_counter)):
        flat[region] = elasticity.stress(p.materials[region], u, p.setting).Reshape((9,))
        recovered[region] = recovered_stress(sol, region, flat[region])
        diff = recovered[region] - flat[region]
        part = ng.Integrate(ng.InnerProduct(diff, diff) * w / _modulus(p.materials[region]), mesh, ng.VOL,
                            definedon=mesh.Materials(region), order=2 * p.order + 2, element_wise=True)
        eta2 += np.asarray(part)
    eta2 += interface_share(sol, recovered)
    return np.sqrt(np.maximum(eta2, 0.0))


def interface_share(sol: MacroSolution, recovered: dict[str, ng.GridFunction]) -> np.ndarray:
    """The interface term of the indicator (module docstring) on the volume elements beside ``S_0``."""
    p = sol.problem
    mesh, dim = p.mesh, p.mesh.dim
    n = ng.specialcf.normal(dim)
    jump = (recovered[p.rough] - recovered[p.counter]).Reshape((3, 3))
    tn = ng.CF(tuple(sum(jump[i, j] * n[j] for j in range(dim)) for i in range(3)))
    size = ng.specialcf.mesh_size
    modulus = max(_modulus(law) for law in p.materials.values())
    on = mesh.Boundaries(p.interface)
    per_face = np.asarray(ng.Integrate(ng.InnerProduct(tn, tn) * size * elasticity.weight(p.setting) / modulus,
                                       mesh, ng.BND, definedon=on, order=2 * p.order + 2, element_wise=True))
    out = np.zeros(mesh.ne)
    for el in mesh.Elements(ng.BND):
        if el.mat != p.interface:
            continue
        facet = el.faces[0] if dim == 3 else el.edges[0]
        for vol in mesh[facet].elements:
            out[vol.nr] += per_face[el.nr]
    return out


def marked(eta: np.ndarray, bulk: float = BULK) -> np.ndarray:
    """The elements to refine: the fewest with the largest ``eta`` whose ``eta^2`` sum to ``bulk`` of the
    total (all elements whose ``eta`` ties the last one chosen are marked too), as a boolean array."""
    eta2 = np.asarray(eta, dtype=float) ** 2
    total = float(eta2.sum())
    out = np.zeros(len(eta2), dtype=bool)
    if total <= 0.0:
        return out
    order = np.argsort(-eta2, kind="stable")
    count = int(np.searchsorted(np.cumsum(eta2[order]), bulk * total) + 1)
    threshold = eta2[order[min(count, len(eta2)) - 1]]
    out[eta2 >= threshold] = True
    return out


def holding(mesh: ng.Mesh, points: list[tuple[float, ...]]) -> np.ndarray:
    """The volume elements holding ``points`` (a maximum's or a peak's location) as a boolean array."""
    out = np.zeros(mesh.ne, dtype=bool)
    for point in points:
        found = mesh(*point)
        if found.nr >= 0 and found.vb == ng.VOL:
            out[found.nr] = True
    return out


def refine_marked(mesh: ng.Mesh, flags: np.ndarray, curve_order: int) -> None:
    """Refine the flagged volume elements of ``mesh`` in place (Netgen's local refinement, with the closure
    that keeps the mesh conforming; new boundary vertices placed on the geometry where the mesh has one)
    and curve it again at ``curve_order``."""
    for el in mesh.Elements(ng.VOL):
        mesh.SetRefinementFlag(el, bool(flags[el.nr]))
    mesh.Refine()
    mesh.Curve(curve_order)
