"""Periodic cell geometries: naming contract, periodicity, shifts and input validation."""
import math

import numpy as np
import ngsolve as ng
import pytest

from ngcontact.errors import GeometryError
from ngcontact.geometry import profiles as pr
from ngcontact.geometry.cell3d import (flat_cell3d, height_map_gap, square_hills_cell)
from ngcontact.geometry.tabulated import check_height_map, read_height_map, read_profile_csv

DATA = __import__("pathlib").Path(__file__).resolve().parents[2] / "geometries" / "cells" / "data"

PROFILES = {
    "flat": lambda: pr.flat(),
    "rectangular": lambda: pr.rectangular_valley(0.4, 0.3),
    "triangular": lambda: pr.triangular_valley(30, 60, width=0.5),
    "sawtooth": lambda: pr.triangular_valley(30, 60),
    "semicircular": lambda: pr.semicircular_valley(0.3),
    "sinusoid": lambda: pr.sinusoid(0.05),
    "tabulated": lambda: read_profile_csv(DATA / "profile_example.csv"),
}
NO_PLATEAU = {"sawtooth", "sinusoid"}


def _identified_pairs_shift(mesh, shifts):
    """Max distance of each identified vertex pair from the closest shift by a period."""
    ngm = mesh.ngmesh
    pts = ngm.Points()
    worst = 0.0
    pairs = ngm.GetIdentifications()
    assert len(pairs) > 0
    for a, b, _ in pairs:
        pa, pb = np.array(pts[a].p), np.array(pts[b].p)
        d = pb - pa
        worst = max(worst, min(np.linalg.norm(np.abs(d) - s) for s in shifts))
    return worst


def _length(mesh, bc):
    return ng.Integrate(ng.CF(1), mesh, definedon=mesh.Boundaries(bc), order=8)


@pytest.mark.parametrize("name", sorted(PROFILES))
@pytest.mark.parametrize("arrangement", ["conforming", "summit"])
def test_2d_cells_follow_the_naming_contract(name, arrangement):
    profile = PROFILES[name]()
    if arrangement == "summit" and name in NO_PLATEAU:
        with pytest.raises(GeometryError, match="no plane summit plateau"):
            pr.profile_cell(profile, arrangement=arrangement, h_rough=1, h_counter=1, maxh=0.3)
        return
    cell = pr.profile_cell(profile, arrangement=arrangement, h_rough=1.0, h_counter=0.5,
                           maxh=0.3, interface_maxh=0.1, order=2)
    mesh = cell.mesh
    assert set(mesh.GetMaterials()) == {"rough", "counter"}
    bcs = set(mesh.GetBoundaries())
    has_voids = arrangement == "summit" and name != "flat"
    assert bcs == {"contact", "bottom", "top", "periodic"} | ({"free"} if has_voids else set())
    assert _length(mesh, "bottom") == pytest.approx(1.0, rel=1e-12)
    assert _length(mesh, "top") == pytest.approx(1.0, rel=1e-12)
    # areas: both bodies fill the cell except the voids
    area = sum(ng.Integrate(ng.CF(1), mesh, definedon=mesh.Materials(m), order=6)
               for m in ("rough", "counter"))
    void = 0.0
    if has_voids:
        lo = profile.bounds[0]
        assert lo < 0
        void = ng.Integrate(ng.CF(1), mesh, definedon=mesh.Materials("rough"), order=6)
        void = 1.0 - void          # rough area = 1 * h_rough - valley area
        area += void               # the valley is void in the summit arrangement
    assert area == pytest.approx(1.5, rel=1e-6)
    assert _identified_pairs_shift(mesh, [np.array([1.0, 0.0, 0.0])]) < 1e-12


def test_summit_arrangement_contact_is_the_plateaus():
    cell = pr.profile_cell(pr.rectangular_valley(0.4, 0.3), arrangement="summit",
                           h_rough=1, h_counter=1, maxh=0.3, interface_maxh=0.1)
    assert _length(cell.mesh, "contact") == pytest.approx(0.6, rel=1e-12)
    # valley walls and bottom (0.3 + 0.4 + 0.3) plus the counter's face over the valley (0.4)
    assert _length(cell.mesh, "free") == pytest.approx(1.4, rel=1e-12)


def test_tabulated_profile_is_the_polyline_through_the_points():
    profile = read_profile_csv(DATA / "profile_example.csv")
    data = np.loadtxt(DATA / "profile_example.csv", delimiter=",", skiprows=1)
    expected = np.sum(np.hypot(np.diff(data[:, 0]), np.diff(data[:, 1])))
    cell = pr.profile_cell(profile, h_rough=1, h_counter=1, maxh=0.3, interface_maxh=0.1)
    assert _length(cell.mesh, "contact") == pytest.approx(expected, rel=1e-12)
    assert profile.bounds == (data[:, 1].min(), data[:, 1].max())


@pytest.mark.parametrize("name", ["rectangular", "sawtooth", "semicircular", "tabulated"])
@pytest.mark.parametrize("fraction", [0.13, 0.37, 0.81])
def test_shifted_profile_is_the_same_surface(name, fraction):
    profile = PROFILES[name]()
    moved = pr.shifted(profile, fraction)
    assert moved.pieces[0].start[0] == pytest.approx(0.0, abs=1e-14)
    assert moved.pieces[-1].end[0] == pytest.approx(moved.period, abs=1e-14)
    def length(p):
        return sum(_piece_length(q) for q in p.pieces)

    assert length(moved) == pytest.approx(length(profile), rel=1e-12)
    assert moved.bounds == pytest.approx(profile.bounds, abs=1e-14)
    # the first point of the moved chain is the original surface at x = fraction * period
    s = fraction * profile.period
    x0, y0 = moved.pieces[0].start
    assert y0 == pytest.approx(_height(profile, s), abs=1e-12)


def _piece_length(p):
    if isinstance(p, pr.Arc):
        return p.radius * (p.t1 - p.t0)
    return math.dist(p.start, p.end)


def _height(profile, x):
    for p in profile.pieces:
        if p.start[0] <= x <= p.end[0] and p.start[0] != p.end[0]:
            if isinstance(p, pr.Arc):
                cx, cy = p.center
                return cy - math.sqrt(p.radius ** 2 - (x - cx) ** 2)
            (xa, ya), (xb, yb) = p.start, p.end
            return ya + (x - xa) / (xb - xa) * (yb - ya)
    raise AssertionError("x outside the profile")


def test_3d_square_hills_follow_the_naming_contract_and_are_periodic():
    for arrangement, free in (("summit", True), ("conforming", False)):
        cell = square_hills_cell(0.4, 0.2, arrangement=arrangement, h_rough=0.5, h_counter=0.4,
                                 maxh=0.3)
        mesh = cell.mesh
        assert cell.dim == 3 and cell.area == 1.0
        assert set(mesh.GetMaterials()) == {"rough", "counter"}
        bcs = set(mesh.GetBoundaries())
        assert bcs == {"contact", "bottom", "top", "periodic"} | ({"free"} if free else set())
        contact = ng.Integrate(ng.CF(1), mesh, definedon=mesh.Boundaries("contact"))
        assert contact == pytest.approx(0.16 if free else 1.0 + 4 * 0.4 * 0.2, rel=1e-12)
        shifts = [np.array(v) for v in ((1.0, 0, 0), (0, 1.0, 0), (1.0, 1.0, 0))]
        assert _identified_pairs_shift(mesh, shifts) < 1e-12
        # periodic identification is usable by a finite element space
        fes = ng.H1(mesh, order=1)
        assert ng.Periodic(fes).FreeDofs().NumSet() < fes.ndof


def test_3d_flat_cell():
    cell = flat_cell3d(1.0, 0.5, 0.5, maxh=0.4)
    mesh = cell.mesh
    assert set(mesh.GetBoundaries()) == {"contact", "bottom", "top", "periodic"}
    assert ng.Integrate(ng.CF(1), mesh, definedon=mesh.Boundaries("contact")) == pytest.approx(1.0)


def test_height_map_sample_and_gap():
    H = read_height_map(DATA / "height_map_example.npy")
    assert H.shape[0] >= 3 and H.shape[1] >= 3
    cell = flat_cell3d(1.0, 0.5, 0.5, maxh=0.5)
    gap = height_map_gap(H)
    n = H.shape[0] - 1
    for i, j in ((0, 0), (2, 5), (7, 3), (n, n)):
        x, y = j / (H.shape[1] - 1), i / n
        x, y = min(max(x, 1e-9), 1 - 1e-9), min(max(y, 1e-9), 1 - 1e-9)
        assert gap(cell.mesh(x, y, -0.25)) == pytest.approx(H.max() - H[i, j], abs=1e-7)


# ------------------------------------------------------------- bad input
def _csv(tmp_path, text):
    f = tmp_path / "p.csv"
    f.write_text(text)
    return f


@pytest.mark.parametrize("text, match", [
    ("x,y\n0,0\n0.5,-0.1\n1,0.2\n", "must be periodic"),
    ("x,y\n0,0\n0.5,nan\n1,0\n", "must be finite"),
    ("x,y\n0,0\n0.5,-0.1,3\n1,0\n", "exactly two columns"),
    ("x,y\n0,0\n0.5,-0.1\n0.4,-0.1\n1,0\n", "increase strictly"),
    ("x,y\n0.1,0\n0.5,-0.1\n1,0\n", "start at x = 0"),
    ("x,y\n0,0\n1,0\n", "at least 3 points"),
])
def test_bad_csv_profiles_are_rejected(tmp_path, text, match):
    with pytest.raises(GeometryError, match=match) as err:
        read_profile_csv(_csv(tmp_path, text))
    assert "p.csv" in str(err.value)


def test_profile_reaching_the_cell_height_is_rejected():
    profile = pr.rectangular_valley(0.4, 0.3)
    with pytest.raises(GeometryError, match="h_rough.*must exceed the profile depth"):
        pr.profile_cell(profile, h_rough=0.3, h_counter=1, maxh=0.3)
    with pytest.raises(GeometryError, match="^height.*must be < h_rough"):
        square_hills_cell(0.4, 0.5, h_rough=0.5, h_counter=0.5, maxh=0.3)


@pytest.mark.parametrize("array, match", [
    (np.zeros(5), "2D array"),
    (np.zeros((3, 3, 3)), "2D array"),
    (np.array([[0, 1, 0], [1, np.inf, 1], [0, 1, 0.0]]), "finite"),
    (np.array([[0, 1, 0], [1, 2, 1], [0.5, 1, 0.5]]), "last row must repeat the first"),
    (np.array([[0, 1, 0.2], [1, 2, 1], [0, 1, 0.2]]), "last column must repeat the first"),
])
def test_bad_height_maps_are_rejected(tmp_path, array, match):
    f = tmp_path / "h.npy"
    np.save(f, array)
    with pytest.raises(GeometryError, match=match):
        read_height_map(f)
    with pytest.raises(GeometryError, match=match):
        check_height_map(array)


def test_bad_profile_parameters_are_rejected():
    with pytest.raises(GeometryError, match="^width.*must be < period"):
        pr.rectangular_valley(1.2, 0.3)
    with pytest.raises(GeometryError, match="^angle_left.*\\(0, 90\\)"):
        pr.triangular_valley(95, 30)
    with pytest.raises(GeometryError, match="^radius.*period / 2"):
        pr.semicircular_valley(0.6)
    with pytest.raises(GeometryError, match="arrangement.*lateral edges must cut a summit plateau"):
        pr.profile_cell(pr.shifted(pr.rectangular_valley(0.4, 0.3), 0.5), arrangement="summit",
                        h_rough=1, h_counter=1, maxh=0.3)
    with pytest.raises(GeometryError, match="arrangement.*conforming, summit"):
        pr.interface_segments(pr.flat(), "glued")


@pytest.mark.parametrize("dim", [2, 3])
def test_a_mesh_size_as_large_as_the_period_still_gives_a_solvable_cell(dim):
    """Regression: maxh >= period / 2 let one element touch both periodic sides, and the
    assembly of the identified space failed ('illegal dnums').  The size is now capped."""
    from ngcontact.cell.cell_load import cell_load
    from ngcontact.cell.fe.cell_problem import CellModel, CellProblem
    from ngcontact.geometry.cell2d import flat_cell
    from ngcontact.fem.materials import isotropic
    cell = flat_cell(maxh=1.0) if dim == 2 else flat_cell3d(maxh=1.0)
    law = isotropic(1.0, 0.3)
    P = CellProblem(cell, CellModel(rough=law, counter=law, k_n=1e3, order=1))
    sol = P.solve(cell_load(dim, pressure=0.01), first=True)
    assert sol.results["mean_pressure"] == pytest.approx(0.01, rel=1e-9)


def test_a_byte_order_mark_is_not_a_header(tmp_path):
    """Was: a CSV saved with a UTF-8 BOM and no header lost its first row (the BOM made it 'not numeric')."""
    from ngcontact.geometry.tabulated import read_gap_csv
    for name, reader in (("p.csv", read_profile_csv), ("g.csv", read_gap_csv)):
        f = tmp_path / name
        f.write_bytes(b"\xef\xbb\xbf0,0.1\n0.5,0\n1,0.1\n")
        points = reader(f)
        x = [p.start[0] for p in points.pieces] if name == "p.csv" else list(points[0])
        assert x[:2] == [0.0, 0.5], name
        f.write_bytes(b"\xef\xbb\xbfx,y\n0,0.1\n0.5,0\n1,0.1\n")   # a header after the BOM is still a header
        points = reader(f)
        x = [p.start[0] for p in points.pieces] if name == "p.csv" else list(points[0])
        assert x[:2] == [0.0, 0.5], name
