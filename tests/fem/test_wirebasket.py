"""BDDC's coarse problem: only vertex dofs on the wirebasket of the body spaces, contact dofs added.

``vector_h1`` sets ``wb_withedges=False`` through NGSolve's flags; the test
holds its coupling types against the definition, dof by dof: vertex dofs
on the wirebasket, every dof of an edge (order >= 2) an interface dof, and
prints nothing (NGSolve warns from C++ that the flag is not among
VectorH1's own).
"""
import ngsolve as ng
import pytest
from netgen.csg import unit_cube
from netgen.geom2d import unit_square

from ngcontact.fem.elasticity import surface_wirebasket, vector_h1

WB, IF = ng.COUPLING_TYPE.WIREBASKET_DOF, ng.COUPLING_TYPE.INTERFACE_DOF


def _mesh(dim):
    mesh = ng.Mesh(unit_cube.GenerateMesh(maxh=0.3) if dim == 3 else unit_square.GenerateMesh(maxh=0.2))
    mesh.ngmesh.SetMaterial(1, "body")
    return mesh


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("order", [1, 2, 3])
def test_only_vertex_dofs_are_on_the_wirebasket_and_nothing_is_printed(dim, order, capfd):
    mesh = _mesh(dim)
    V = vector_h1(mesh, order=order, definedon=mesh.Materials("body"))
    assert "WARNING" not in capfd.readouterr().err
    vertex = {d for v in mesh.vertices for d in V.GetDofNrs(v) if d >= 0}
    edge = {d for e in mesh.edges for d in V.GetDofNrs(e) if d >= 0}
    assert len(vertex) == dim * mesh.nv and len(edge) == dim * len(mesh.edges) * (order - 1)
    assert all(V.CouplingType(d) == WB for d in vertex)
    assert all(V.CouplingType(d) == IF for d in edge)


def test_the_contact_surface_dofs_join_the_wirebasket():
    mesh = _mesh(3)
    V = vector_h1(mesh, order=2, definedon=mesh.Materials("body"))
    surface_wirebasket(V, mesh, "bottom|left")
    region = mesh.Boundaries("bottom|left")
    on = {d for el in mesh.Elements(ng.BND) if region.Mask()[el.index] for d in V.GetDofNrs(el) if d >= 0}
    assert on and all(V.CouplingType(d) == WB for d in on)
    off = {d for e in mesh.edges for d in V.GetDofNrs(e) if d >= 0} - on
    assert off and all(V.CouplingType(d) == IF for d in off)
