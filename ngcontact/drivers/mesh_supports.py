"""A scene's ``[[supports]]`` (:mod:`ngcontact.scene.supports`) as the problems' supports on a mesh.

Shared by the ``macro`` and ``direct`` kinds (and the epsilon study's
homogenized runs, which take the ``direct`` scene's supports onto the flat
bodies): what the scene could not know before meshing is read off the mesh
here,

* a symmetry plane's normal axis (:func:`ngcontact.fem.two_body.plane_normal_axis`):
  the support fixes that one component at zero;
* a slope's direction along the boundary: given by the shape (the ``direct``
  kind's horizontal boundaries) or, on any other mesh, the boundary's own
  direction when it is a straight horizontal or vertical 2D boundary
  (:func:`ngcontact.fem.two_body.boundary_along`);
* an affine support ``u = u0 + G x`` passes through unchanged.
"""
from __future__ import annotations

from collections.abc import Callable

from ngcontact.errors import SceneError
from ngcontact.fem.elasticity import COMPONENTS
from ngcontact.fem.two_body import Support, boundary_along, plane_normal_axis


def supports_on(specs, mesh, setting: str, along: Callable[[str], str] | None = None) -> tuple[Support, ...]:
    """The supports ``specs`` (``SupportSpec``) on ``mesh``.

    ``along``: label -> the coordinate a slope runs along (default: read
    off the mesh).

    Raises
    ------
    SceneError
        ``supports[i].symmetry`` on a boundary that is no plane normal to a
        coordinate axis; ``supports[i].slope`` on a boundary that is neither
        horizontal nor vertical (its direction is then not defined).
    """
    comps = COMPONENTS[setting]
    out = []
    for i, s in enumerate(specs):
        if s.symmetry:
            axis = plane_normal_axis(mesh, s.boundary)
            if axis is None:
                raise SceneError(f"supports[{i}].symmetry", True, f"boundary {s.boundary!r} is not a plane normal "
                                 f"to a coordinate axis ({', '.join(comps)}), so its normal component is none of "
                                 "them; fix the components you mean with components = [...]")
            out.append(Support(label=s.boundary, components=(comps[axis],)))
        elif s.affine():
            n = len(s.components or comps)
            out.append(Support(label=s.boundary, components=s.components, value=s.u0 or (0.0,) * n,
                               gradient=s.G or ((0.0,) * mesh.dim,) * n))
        else:
            direction = along(s.boundary) if along is not None else boundary_along(mesh, s.boundary)
            if any(s.slope) and direction is None:
                raise SceneError(f"supports[{i}].slope", s.slope, f"boundary {s.boundary!r} is neither a horizontal "
                                 "nor a vertical straight line, so 'along the boundary' is not one coordinate; give "
                                 "the tilt as u0 and G (u = u0 + G x)")
            out.append(Support(label=s.boundary, components=s.components, value=s.displacement, slope=s.slope,
                               along=direction or "x"))
    return tuple(out)
