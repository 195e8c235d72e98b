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


@pytest.mark.parametrize("stiffness", [1.0, 1e4])
def test_the_bubble_term_acts_on_the_edge_bubbles_alone_and_is_definite_there(stiffness):
    """On a flat face the surface Hessian vanishes on the (linear) vertex functions: the term leaves BDDC's
    coarse problem alone and makes the face's edge block positive definite, for any contact stiffness."""
    import numpy as np
    import scipy.sparse as sp

    from ngcontact.fem.elasticity import bubble_term
    mesh = _mesh(3)
    V = vector_h1(mesh, order=2, definedon=mesh.Materials("body"))
    u, v = V.TnT()
    form = ng.BilinearForm(V)
    form += bubble_term(u, v, 1.3, stiffness, "bottom")
    form.Assemble()
    rows, cols, vals = form.mat.COO()
    B = sp.csr_matrix((np.asarray(vals), (np.asarray(rows), np.asarray(cols))), shape=(V.ndof, V.ndof))
    vertex = sorted({d for vx in mesh.vertices for d in V.GetDofNrs(vx) if d >= 0})
    face = mesh.Boundaries("bottom")
    edges = sorted({d for el in face.Elements() for e in el.edges for d in V.GetDofNrs(e) if d >= 0})
    assert abs(B[vertex, :]).max() <= 1e-12 * abs(B).max()
    block = B[edges][:, edges].toarray()
    eig = np.linalg.eigvalsh(0.5 * (block + block.T))
    assert eig.min() > 1e-3 * eig.max() > 0
    off = sorted(set(range(V.ndof)) - set(edges))
    assert abs(B[off, :]).max() == 0.0
