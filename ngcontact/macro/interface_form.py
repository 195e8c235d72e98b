"""The interface energy of a homogenized law on a mesh built in the caller's own NGSolve script.

The term of the macro energy (paper eq. 44, the Winkler form of eqs. 69-71)
that the interface ``S_0`` contributes::

    Pi_S0(u) = int_S0 W(a) w ds,    a = (J . n0, J . t...),    J = u_rough - u_counter,

``W`` the law's energy density (:mod:`ngcontact.laws.interface_energy`),
``a`` the jump in the interface's local frame
(:mod:`ngcontact.laws.local_frame`; ``n0`` points from ``rough`` into
``counter``, so ``a_n > 0`` closes the interface), ``w`` the measure weight
(``2 pi r`` in axisymmetry, else 1).  The traction ``tau = dW/da`` is what
the rough body transmits to the counter body, its normal component the
pressure ``p = tau_n`` (compression positive).

What the mesh must be
---------------------
* Two regions, ``rough`` and ``counter`` (the names of ``mesh.GetMaterials()``);
* an internal boundary ``interface`` between them: every boundary element of
  that name is a facet with one element of ``rough`` on one side and one of
  ``counter`` on the other (a conforming mesh, as ``netgen.occ.Glue`` of two
  solids or a ``SplineGeometry`` segment with ``leftdomain`` and
  ``rightdomain`` give).  The two sides are kept apart by the spaces, not by
  the mesh: each body's displacement is its own ``VectorH1`` defined on its
  region only (``definedon=mesh.Materials(rough)``), so its trace on
  ``S_0`` is that body's side and the jump is the difference of the traces.

A mesh whose bodies meet along two boundaries with separate (doubled) nodes
is refused (:func:`check_interface`): there every interface element has one
neighbouring element only; glue the bodies into one mesh instead.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ng

from ngcontact.errors import ModelError
from ngcontact.fem import elasticity
from ngcontact.fem.two_body import boundary_labels, interface_normal
from ngcontact.laws import interface_energy as ie
from ngcontact.laws.homogenized import InterfaceLaw, NormalLaw
from ngcontact.laws.local_frame import local_frame
from ngcontact.macro.macro_energy import gap_cf, local_jump


def refuse(name: str, value, allowed: str) -> ModelError:
    """The error of an argument: ``name = value: what is allowed``."""
    shown = repr(value) if isinstance(value, (str, int, float, tuple, list)) else f"a {type(value).__name__}"
    return ModelError(f"{name} = {shown}: {allowed}")


def interface_law(law, dim: int | None = None) -> InterfaceLaw:
    """``law`` as an :class:`~ngcontact.laws.homogenized.InterfaceLaw`: a normal law alone is wrapped
    (no friction); a bundle must have ``dim`` components per direction.

    Raises
    ------
    ModelError
        Neither an interface law nor a normal law, or a bundle of another dimension.
    """
    if isinstance(law, NormalLaw):
        law = InterfaceLaw(normal=law)
    if not isinstance(law, InterfaceLaw):
        raise refuse("law", law, "an InterfaceLaw (ngcontact.cell_law(...), or "
                     "ngcontact.laws.homogenized.InterfaceLaw) or a normal law (LinearLaw, BundleLaw, TabulatedLaw)")
    directions = getattr(law.normal, "directions", None)
    if dim is not None and directions and len(directions[0]) != dim:
        raise refuse("law", law, f"a bundle with {len(directions[0])} components per direction; this mesh "
                     f"needs {dim} (compute the law with the setting of the mesh)")
    return law


def setting_of(mesh, setting: str | None) -> str:
    """The setting of ``mesh``: ``setting`` checked against its dimension, default plane strain in 2D, 3d in 3D."""
    if setting is None:
        return "3d" if mesh.dim == 3 else "plane_strain"
    if setting not in elasticity.SETTINGS:
        raise refuse("setting", setting, "one of " + ", ".join(elasticity.SETTINGS))
    if elasticity.dimension(setting) != mesh.dim:
        raise refuse("setting", setting, f"the mesh is {mesh.dim}D; "
                     + ("use '3d'" if mesh.dim == 3 else "use 'plane_strain' or 'axisymmetric'"))
    return setting


def check_interface(mesh, rough: str, counter: str, interface: str) -> None:
    """Refuse region and interface names the mesh does not have, and an interface that is not an internal
    boundary between ``rough`` and ``counter`` (see the module's docstring).

    Raises
    ------
    ModelError
        Naming the argument, its value and what the mesh offers.
    """
    if not isinstance(mesh, ng.Mesh):
        raise refuse("mesh", mesh, "an ngsolve.Mesh with the two bodies' regions and the interface boundary")
    regions = sorted(set(mesh.GetMaterials()))
    for name, value in (("rough", rough), ("counter", counter)):
        if value not in regions:
            raise refuse(name, value, "no such region in the mesh; its regions are " + ", ".join(map(repr, regions)))
    if rough == counter:
        raise refuse("counter", counter, "the region of the other body (not the rough body's)")
    labels = boundary_labels(mesh)
    if interface not in labels:
        raise refuse("interface", interface, "no such boundary in the mesh; its boundaries are "
                     + ", ".join(map(repr, labels)))
    for k, el in enumerate(e for e in mesh.Elements(ng.BND) if e.mat == interface):
        facet = el.faces[0] if mesh.dim == 3 else el.edges[0]
        sides = sorted(mesh[e].mat for e in mesh[facet].elements)
        if len(sides) == 1:
            raise refuse("interface", interface, f"its element {k} borders one element only (of {sides[0]!r}): "
                         "an outer boundary, or two bodies meshed with separate (doubled) nodes; the interface "
                         "must be an internal boundary that both bodies share node for node (glue them into one "
                         "mesh, e.g. netgen.occ.Glue)")
        if sides != sorted((rough, counter)):
            raise refuse("interface", interface, f"its element {k} separates {' and '.join(map(repr, sides))}; "
                         f"an interface between rough = {rough!r} and counter = {counter!r} is needed")


def _trace(u):
    """A trial or test function's trace (its values on a boundary); a grid function evaluates there as it is."""
    return u.Trace() if isinstance(u, ng.comp.ProxyFunction) else u


@dataclass(frozen=True)
class InterfaceForm:
    """The interface term of a law for two bodies' displacements.

    Attributes
    ----------
    law
        The interface law.
    frame
        ``[n0, t0]`` (2D) or ``[n0, t1, t2]`` (3D) on the interface.
    jump
        The local jump ``a`` of the two displacements given.
    gap
        The macro normal gap ``g0`` (CoefficientFunction).
    weight
        The measure weight ``w``.
    measure
        ``ds`` on the interface.
    threshold
        The friction threshold field ``G`` held fixed in the friction energy (paper eqs. 38-44); ``None``:
        ``threshold(friction, 0) = G0``, the Tresca energy.  Coulomb's ``G = mu0 [p]_+ + G0`` is not the
        derivative of an energy: freeze it at an earlier state (``ie.threshold(law.friction, p_old)``), as
        the package's fixed point does, or let :func:`ngcontact.runner.solve_mesh` solve.
    """

    law: InterfaceLaw
    frame: list
    jump: list
    gap: ng.CoefficientFunction
    weight: ng.CoefficientFunction
    measure: ng.comp.DifferentialSymbol
    threshold: ng.CoefficientFunction | None = None

    @property
    def density(self) -> ng.CoefficientFunction:
        """``W(a) w``, the integrand (the friction energy at the fixed ``threshold``)."""
        return ie.energy(self.law, self.jump, self.gap, self.threshold) * self.weight

    @property
    def energy(self):
        """``int_S0 W(a) w ds``: ``Integrate`` it at grid functions, or wrap it in ``Variation``."""
        return self.density * self.measure

    @property
    def variation(self):
        """``Variation(int_S0 W(a) w ds)``, the term to add to a ``BilinearForm`` of trial functions."""
        return ng.Variation(self.energy)

    @property
    def traction(self) -> list:
        """``tau = dW/da`` in the local frame (the same ``threshold``)."""
        return ie.traction(self.law, self.jump, self.gap, self.threshold)

    @property
    def pressure(self) -> ng.CoefficientFunction:
        """The contact pressure ``p = tau_n`` (compression positive)."""
        return ie.pressure(self.law.normal, self.jump, self.gap)


def interface_form(law, mesh, u_rough, u_counter, *, rough: str, counter: str, interface: str = "interface",
                   setting: str | None = None, gap=0.0, threshold=None) -> InterfaceForm:
    """The interface term of ``law`` on the caller's mesh (paper eqs. 44, 69-71).

    Parameters
    ----------
    law
        An :class:`~ngcontact.laws.homogenized.InterfaceLaw` (e.g. :func:`ngcontact.cell_law`) or a
        normal law alone.
    mesh
        The ``ngsolve.Mesh`` (see the module's docstring for what it must be).
    u_rough, u_counter
        The bodies' displacements: trial functions (for a form) or grid functions (to evaluate), each of a
        ``VectorH1`` defined on its own region.
    rough, counter
        Region names of the rough body (paper ``D``) and the counter body.
    interface
        Boundary name of ``S_0``.
    setting
        ``plane_strain`` (2D default), ``axisymmetric`` (mesh ``(x, y)`` = ``(r, z)``) or ``3d``.
    gap
        The macro normal gap ``g0`` (number or CoefficientFunction); ``< 0`` an interference.
    threshold
        The friction threshold field ``G`` (see :class:`InterfaceForm`); default ``G0``.

    Raises
    ------
    ModelError
        A region or boundary the mesh does not have, an interface that is not an internal boundary
        between the two regions, a law of the wrong type or dimension, a setting of another dimension.
    """
    check_interface(mesh, rough, counter, interface)
    setting = setting_of(mesh, setting)
    law = interface_law(law, mesh.dim)
    frame = local_frame(interface_normal(mesh, rough, interface), mesh.dim)
    jump = local_jump(frame, _trace(u_rough) - _trace(u_counter))
    return InterfaceForm(law=law, frame=frame, jump=jump, gap=gap_cf(gap), weight=elasticity.weight(setting),
                         measure=ng.ds(definedon=mesh.Boundaries(interface)), threshold=threshold)
