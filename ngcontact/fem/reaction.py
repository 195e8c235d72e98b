"""The consistent reaction force and moment of a Dirichlet boundary.

The reaction is the derivative of the body's elastic energy (the first
integral of paper eq. 8, the bilinear form of the bodies) in the direction of a test field that
equals a rigid motion on the boundary's dofs and vanishes on every other
dof:

    R_i = - int_B sigma(u) : eps(v_i) w dx,   v_i = e_i (force) or the rigid rotation (moment)

At equilibrium with no load on the boundary's neighbours this is the force
the support transmits, with the sign of the force the body exerts on the
support.  The same function measures the resolved and the homogenized
solutions, so their reactions are compared alike.
"""
from __future__ import annotations

import ngsolve as ng

from ngcontact.fem import elasticity
from ngcontact.fem.elasticity import COMPONENTS


def boundary_reaction(mesh, setting: str, law, u, region: str, label: str, order: int,
                      about=(0.0, 0.0), force=()) -> dict:
    """Reaction force and moment that a Dirichlet boundary exerts on its body.

    The consistent reaction: the derivative of the body's elastic energy in
    the direction of a test field ``v`` equal to ``e_i`` (force component
    ``i``) or to the rigid rotation about ``about`` (moment, plane strain)
    on the dofs of ``label`` and zero on all other dofs.  At an equilibrium
    state with no load on the boundary's neighbours this is the force the
    support transmits; the sign is that of the force the body *exerts on
    the support* (e.g. positive ``y`` when the body presses upwards).

    Parameters
    ----------
    mesh, setting
        Mesh and setting.
    law
        The body's :class:`~ngcontact.fem.materials.ElasticLaw`.
    u
        The body's displacement (GridFunction or component).
    region, label
        The body's region and the boundary.
    order
        Order of the test field (that of ``u``).
    about
        Centre of the moment (plane strain).
    force
        The body's constant force density, if any: its work on the test
        field is a load on the boundary's neighbours, so the reaction is
        ``R_i = - int_B (sigma(u) : eps(v_i) - f . v_i) w dx``.

    Returns
    -------
    dict
        Force components by name (``x, y``, ``x, y, z`` or ``r, z``;
        axisymmetric: per full revolution, ``r`` omitted) and ``moment``
        (plane strain).
    """
    comps = COMPONENTS[setting]
    V = ng.VectorH1(mesh, order=order, definedon=mesh.Materials(region))
    v = ng.GridFunction(V)
    sigma = elasticity.stress(law, u, setting)
    w = elasticity.weight(setting)
    fields = {c: ng.CF(tuple(1.0 if j == i else 0.0 for j in range(mesh.dim))) for i, c in enumerate(comps)}
    if setting == "plane_strain":
        fields["moment"] = ng.CF((-(ng.y - about[1]), ng.x - about[0]))
    elif setting == "axisymmetric":
        fields.pop("r")
    out = {}
    for name, cf in fields.items():
        v.vec[:] = 0.0
        v.Set(cf, definedon=mesh.Boundaries(label))
        work = ng.InnerProduct(sigma, elasticity.strain(v, setting)) * w
        if any(force):
            work = work - ng.InnerProduct(ng.CF(tuple(float(f) for f in force)), v) * w
        out[name] = -float(ng.Integrate(work, mesh, definedon=mesh.Materials(region)))
    return out


def support_reactions(mesh, setting: str, order: int, supports, bodies, forces=None, centres=None) -> dict:
    """Reaction force (and, in plane strain, moment) of every supported boundary, summed over the bodies.

    ``supports``: the problem's :class:`~ngcontact.fem.two_body.Support`
    tuple; ``bodies``: ``(region, law, u)`` of each body; ``forces``: region ->
    constant body force (see :func:`boundary_reaction`).  Only the fixed
    components are kept (a free component's "reaction" is the residual,
    zero); in axisymmetry the radial one is dropped (its net force over a
    revolution vanishes) and there is no moment; a support fixing every
    component in plane strain also reports its moment about the boundary's
    mid-point (:func:`boundary_reaction`).  A boundary fixed in no kept
    component has no entry.  ``centres``: label -> that mid-point, where
    ``mesh`` is one rank's part of a distributed mesh (see :func:`boundary_centre`).
    """
    comps = COMPONENTS[setting]
    out = {}
    for s in supports:
        label = s.label
        keep = [c for c in (s.components or comps) if not (setting == "axisymmetric" and c == "r")]
        if setting == "plane_strain" and not s.components:
            keep.append("moment")
        if not keep:
            continue
        about = (0.0,) * mesh.dim
        if "moment" in keep:
            about = (centres or {}).get(label) or boundary_centre(mesh, label)
        total: dict | None = None
        for region, law, u in bodies:
            r = boundary_reaction(mesh, setting, law, u, region, label, order, about=about,
                                  force=(forces or {}).get(region, ()))
            total = r if total is None else {k: total[k] + r[k] for k in r}
        assert total is not None  # every problem has two bodies
        out[label] = {k: total[k] for k in keep}
    return out


def boundary_centre(mesh, label: str) -> tuple[float, ...]:
    """The mid-point of the bounding box of boundary ``label``'s vertices (the centre of its moment)."""
    xs = [mesh[v].point for el in mesh.Elements(ng.BND) if el.mat == label for v in el.vertices]
    return tuple(0.5 * (min(p[i] for p in xs) + max(p[i] for p in xs)) for i in range(mesh.dim))
