"""The two-body layer shared by the macro and the resolved problems.

Two elastic bodies (two mesh regions) meet along an interface boundary; each
body's displacement lives in its own ``VectorH1`` defined on its region
(``definedon``), so ``u.Trace()`` on the interface is that body's side and the
jump ``J = u_rough - u_counter`` is the difference of the two traces.  This
module holds what both problems set up the same way:

* supports (:class:`Support`: prescribed components, constant, tilted or a
  general affine field ``u0 + G x``) and surface loads (:class:`Load`), with
  the Dirichlet flags of the compound space (:func:`spaces`) and the
  prescribed values (:func:`set_dirichlet`); a boundary's plane normal and
  its direction of largest extent (:func:`plane_normal_axis`,
  :func:`boundary_along`), which turn a symmetry plane and a slope into
  components;
* the load potential ``-int t . u w ds`` (:func:`add_load_potential`),
  ``t = -p n + traction``, and the body forces' ``-int f . u w dx``
  (:func:`add_body_force_potential`);
* the interface normal oriented from ``rough`` into the other body
  (:func:`interface_normal`), the paper's ``n`` on ``S_C`` and ``n0`` on
  ``S_0``;
* the label checks (:func:`check_labels`).

The interface energy itself (a homogenized law on ``S_0``, paper eqs. 69-71,
or the micro penalty law on a resolved ``S_C``, eq. 13) is each problem's own.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ng
import numpy as np

from ngcontact.fem.elasticity import COMPONENTS, vector_h1
from ngcontact.errors import ModelError


@dataclass(frozen=True, kw_only=True)
class Support:
    """Prescribed displacement components on a boundary.

    ``value[i]`` is prescribed for ``components[i]`` (names of
    :data:`ngcontact.fem.elasticity.COMPONENTS`; all components when empty;
    default zeros), plus ``slope[i] * (s - s_mid)`` where ``s`` is the coordinate
    along ``along`` (``"x"``, ``"y"`` or ``"z"``) and ``s_mid`` the mid-point of the
    boundary in that coordinate: a linear variation (a tilt of a face).

    With ``gradient`` (one row per listed component, one entry per
    coordinate) the prescribed field is the general affine one
    ``u_c(x) = value[c] + sum_j gradient[c][j] x_j`` in absolute
    coordinates (``value`` is then ``u0``, the value at the origin) and
    ``slope`` is not used.
    """

    label: str
    components: tuple[str, ...] = ()
    value: tuple[float, ...] = ()
    slope: tuple[float, ...] = ()
    along: str = "x"
    gradient: tuple[tuple[float, ...], ...] = ()


@dataclass(frozen=True, kw_only=True)
class Load:
    """Surface load on a boundary: ``pressure`` (positive pushes into the body) plus ``traction``."""

    label: str
    pressure: float = 0.0
    traction: tuple[float, ...] = ()


def boundary_labels(mesh) -> list:
    """Boundary labels present in ``mesh`` (sorted)."""
    return sorted(set(mesh.GetBoundaries()) - {""})


def check_labels(mesh, setting: str, interface: str, supports, loads, regions=()) -> None:
    """Reject regions, boundaries and components that do not exist (``ValueError`` naming them)."""
    labels = boundary_labels(mesh)
    present = set(mesh.GetMaterials())
    for role, name in regions:
        if name not in present:
            raise ModelError(f"{role} = {name!r}: no such region; regions are {', '.join(sorted(present))}")
    if interface not in labels:
        raise ModelError(f"interface = {interface!r}: no such boundary; labels are {', '.join(labels)}")
    comps = COMPONENTS[setting]
    for item in tuple(supports) + tuple(loads):
        if item.label not in labels:
            raise ModelError(f"boundary {item.label!r} does not exist; labels are {', '.join(labels)}")
    for s in supports:
        bad = [c for c in s.components if c not in comps]
        if bad:
            raise ModelError(f"support on {s.label!r}: component {bad[0]!r}; allowed {', '.join(comps)}")
        if s.value and len(s.value) != len(s.components or comps):
            raise ModelError(f"support on {s.label!r}: give one displacement per component")
        if s.gradient and (len(s.gradient) != len(s.components or comps)
                           or any(len(row) != mesh.dim for row in s.gradient)):
            raise ModelError(f"support on {s.label!r}: the gradient needs one row per component, "
                             f"{mesh.dim} entries each")


def spaces(mesh, setting: str, regions: tuple[str, str], supports, order: int, periodic: bool = False):
    """Compound space of the two bodies with the Dirichlet flags of the supports.

    Labels fixed in every component use ``dirichlet``, the others the
    component-wise flags; ``Periodic`` keeps only the former (NGSolve drops
    component-wise flags when it wraps the space), so a periodic problem
    accepts only supports that fix every component.
    """
    comps = COMPONENTS[setting]
    full: list[str] = []
    partial: dict[str, list[str]] = {c: [] for c in comps}
    for s in supports:
        if not s.components or set(s.components) == set(comps):
            full.append(s.label)
        else:
            if periodic:
                raise ModelError(f"support on {s.label!r}: a periodic problem takes supports that fix "
                                 "every component")
            for c in s.components:
                partial[c].append(s.label)
    kw = {f"dirichlet{'xyz'[i]}": "|".join(partial[c] + full) for i, c in enumerate(comps) if partial[c]}
    if full:
        kw["dirichlet"] = "|".join(full)
    spaces = []
    for name in regions:
        V = vector_h1(mesh, order=order, definedon=mesh.Materials(name), **kw)
        spaces.append(ng.Periodic(V) if periodic else V)
    return ng.FESpace(spaces)


def boundary_mid(mesh, label: str, axis: int) -> float:
    """Mid-point of a boundary's extent along a coordinate axis."""
    coords = [mesh[v].point[axis] for el in mesh.Elements(ng.BND) if el.mat == label for v in el.vertices]
    return 0.5 * (min(coords) + max(coords))


def plane_normal_axis(mesh, label: str, tol: float = 1e-8) -> int | None:
    """Index of the coordinate axis along which the boundary ``label``'s normal lies everywhere, or ``None``.

    The normal at the mid-point of every boundary element must be ``+-e_k``
    for one ``k`` (to ``tol``): the boundary is then made of planes (3D) or
    straight lines (2D) normal to that axis, on which the normal
    displacement is that one component.  A curved or slanted boundary gives
    ``None``.
    """
    dim = mesh.dim
    rule = ng.IntegrationRule([(1 / 3, 1 / 3)] if dim == 3 else [(0.5,)], [1.0])
    normals = np.abs(np.asarray(ng.specialcf.normal(dim)(mesh.MapToAllElements(rule, mesh.Boundaries(label))))
                     ).reshape(-1, dim)
    if not len(normals):
        return None
    axes = [k for k in range(dim) if np.all(normals[:, k] >= 1.0 - tol)]
    return axes[0] if axes else None


def boundary_along(mesh, label: str, tol: float = 1e-8) -> str | None:
    """The coordinate along a straight 2D boundary normal to an axis (``"x"`` on a horizontal one, ``"y"``
    on a vertical one); ``None`` for a slanted or curved boundary and in 3D (a face has two directions)."""
    axis = plane_normal_axis(mesh, label, tol) if mesh.dim == 2 else None
    return None if axis is None else "xy"[1 - axis]


def affine_field(mesh, support: Support, comps: tuple[str, ...]):
    """The prescribed field of ``support`` in all ``comps`` (zero in the components it does not fix).

    Constant ``value``; plus ``slope * (s - s_mid)`` along ``along``; or,
    with a ``gradient``, ``u0 + G x`` (see :class:`Support`).
    """
    listed = support.components or comps
    value = tuple(support.value) or (0.0,) * len(listed)
    xyz = (ng.x, ng.y, ng.z)[:mesh.dim]
    rows: list
    if support.gradient:
        rows = [float(value[k]) + sum(float(g) * x for g, x in zip(support.gradient[k], xyz))
                for k in range(len(listed))]
    elif any(support.slope):
        axis = "xyz".index(support.along)
        coord = xyz[axis] - boundary_mid(mesh, support.label, axis)
        rows = [float(value[k]) + float(support.slope[k]) * coord for k in range(len(listed))]
    else:
        rows = [float(v) for v in value]
    return ng.CF(tuple(rows[listed.index(c)] if c in listed else 0.0 for c in comps))


def set_dirichlet(mesh, setting: str, supports, gfu) -> None:
    """Prescribed support values (constant, tilted or affine: :func:`affine_field`) into every body's
    component of ``gfu``."""
    comps = COMPONENTS[setting]
    for s in supports:
        if not any(s.value) and not any(s.slope) and not any(any(row) for row in s.gradient):
            continue
        vec = affine_field(mesh, s, comps)
        for gf in gfu.components:
            gf.Set(vec, definedon=mesh.Boundaries(s.label))


def add_body_force_potential(form, mesh, forces: dict, displacements: dict, weight):
    """Add ``-int_B f_B . u_B w dx`` of every body's constant force density ``f_B`` to a ``Variation`` form.

    ``forces``: region -> force per unit volume (global components; in
    axisymmetry ``(f_r, f_z)``); ``displacements``: region -> that body's
    trial function.
    """
    for region, f in forces.items():
        if not any(f):
            continue
        work = ng.InnerProduct(ng.CF(tuple(float(c) for c in f)), displacements[region])
        form += ng.Variation(-work * weight * ng.dx(definedon=mesh.Materials(region)))
    return form


def add_load_potential(form, mesh, loads, displacements, weight):
    """Add ``-int t . u w ds`` of every surface load to a ``Variation`` form.

    ``t = -p n + traction`` with ``n`` the outer normal of the loaded
    boundary (a pressure ``p > 0`` pushes into the body).  Each body's
    displacement is defined on its own region only, so summing over
    ``displacements`` picks the body that owns the boundary.
    """
    n = ng.specialcf.normal(mesh.dim)
    for load in loads:
        t = -float(load.pressure) * n
        if load.traction:
            t = t + ng.CF(tuple(float(c) for c in load.traction))
        work = sum(ng.InnerProduct(t, u.Trace()) for u in displacements)
        form += ng.Variation(-work * weight * ng.ds(definedon=mesh.Boundaries(load.label)))
    return form


def interface_normal(mesh, rough: str, label: str = "interface"):
    """Unit normal ``n0`` on ``label``, pointing out of the region ``rough``.

    The mesh normal ``specialcf.normal`` of each boundary element is flipped
    where it points towards the adjacent ``rough`` element's centroid; the
    signs live in a piecewise constant ``SurfaceL2`` function.
    """
    dim = mesh.dim
    region = mesh.Boundaries(label)
    mid_rule = ng.IntegrationRule([(1 / 3, 1 / 3)] if dim == 3 else [(0.5,)], [1.0])
    mips = mesh.MapToAllElements(mid_rule, region)
    xyz = ng.CF((ng.x, ng.y, ng.z)[:dim])
    mids = np.asarray(xyz(mips)).reshape(-1, dim)
    normals = np.asarray(ng.specialcf.normal(dim)(mips)).reshape(-1, dim)
    space = ng.SurfaceL2(mesh, order=0, definedon=region)
    sign = ng.GridFunction(space)
    values = sign.vec.FV().NumPy()
    elements = [el for el in mesh.Elements(ng.BND) if el.mat == label]
    if len(elements) != len(mids):
        raise RuntimeError("interface elements and mapped points do not match")
    for k, el in enumerate(elements):
        facet = el.faces[0] if dim == 3 else el.edges[0]
        vols = [mesh[e] for e in mesh[facet].elements]
        side = [v for v in vols if v.mat == rough]
        if len(side) != 1 or len(vols) != 2:
            raise ModelError(f"interface element {k} does not separate {rough!r} from another region")
        centroid = np.mean([mesh[v].point for v in side[0].vertices], axis=0)[:dim]
        away = mids[k] - centroid
        values[space.GetDofNrs(el)[0]] = 1.0 if np.dot(normals[k], away) > 0 else -1.0
    n = ng.specialcf.normal(dim)
    return sign * n
