"""Interface laws: consistency of energy and traction, bundle vs linear law, tables, friction.

These are evaluated on NumPy arrays (the same code builds the NGSolve
CoefficientFunctions); one test checks that the CoefficientFunction path
gives the same numbers.
"""
import numpy as np
import pytest

from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie
from ngcontact.laws.local_frame import local_frame

RNG = np.random.default_rng(7)


def _bundle(dim=2, n=7, gaps=True):
    """A random bundle of unit directions with a positive normal component."""
    d = RNG.normal(size=(n, dim))
    d[:, 0] = np.abs(d[:, 0]) + 0.2
    d /= np.linalg.norm(d, axis=1)[:, None]
    w = RNG.uniform(0.5, 2.0, n)
    g = RNG.uniform(0.0, 0.1, n) if gaps else np.zeros(n)
    return il.BundleLaw(weights=tuple(w), directions=tuple(map(tuple, d)), gaps=tuple(g))


def _cell_response_law():
    """The two-scale law: a cell's response closure c(p) = 0.3 p^0.6 (a stiffening contact) tabulated."""
    from ngcontact.coupling.pressure_table import CellTable, response_law
    table = CellTable(lambda p: {"contact_fraction": p ** 0.5, "k_n0": 1.0, "g_n0": 0.0, "closure": 0.3 * p ** 0.6},
                      tol=1e-3)
    table.cover(0.01, 3.0)
    return response_law(table)


LAWS = {
    "linear": il.InterfaceLaw(normal=il.LinearLaw(kn=3.0, kt=1.5, knt=0.7, gap_force=(0.2, -0.1))),
    "bundle": il.InterfaceLaw(normal=_bundle()),
    "tabulated": il.InterfaceLaw(normal=il.TabulatedLaw(closure=(-0.1, 0.0, 0.2, 0.5),
                                                         pressure=(0.0, 0.3, 1.0, 1.2), kt=0.4)),
    "tabulated_cubic": il.InterfaceLaw(normal=il.TabulatedLaw(closure=(-0.1, 0.0, 0.2, 0.5),
                                                               pressure=(0.0, 0.3, 1.0, 1.2), kt=0.4,
                                                               interpolation="monotone_cubic")),
    "bundle+friction": il.InterfaceLaw(normal=_bundle(), friction=il.Friction(mu=0.3, threshold=0.05,
                                                                              width=0.05)),
    "cell_response": il.InterfaceLaw(normal=_cell_response_law()),
    "cell_response+friction": il.InterfaceLaw(normal=_cell_response_law(),
                                              friction=il.Friction(mu=0.3, threshold=0.05, width=0.05)),
}


@pytest.mark.parametrize("name", sorted(LAWS))
def test_traction_is_the_derivative_of_the_energy(name):
    """Central differences of W reproduce tau = dW/da at random jumps (G frozen)."""
    law = LAWS[name]
    h = 1e-6
    for _ in range(20):
        a = RNG.normal(scale=0.4, size=2)
        g0 = RNG.normal(scale=0.05)
        G = 0.8
        tau = np.array([float(t) for t in ie.traction(law, list(a), g0, G)])
        fd = []
        for i in range(2):
            e = np.zeros(2)
            e[i] = h
            fd.append((ie.energy(law, list(a + e), g0, G) - ie.energy(law, list(a - e), g0, G)) / (2 * h))
        np.testing.assert_allclose(tau, np.array(fd, float), rtol=1e-6, atol=1e-8,
                                   err_msg=f"{name}: traction vs energy at a = {a}")


@pytest.mark.parametrize("dim", [2, 3])
def test_bundle_equals_linearized_law_when_every_direction_is_closed(dim):
    """With every ``n_q . a - g_q > 0`` the bundle energy and traction are those of K0 (eq. 34)."""
    bundle = _bundle(dim=dim, n=9)
    K = bundle.matrix()
    gf = np.einsum("q,q,qi->i", np.array(bundle.weights), bundle.g, np.array(bundle.directions))
    for _ in range(10):
        a = RNG.normal(scale=0.02, size=dim)
        a[0] = 5.0                      # deep closure: every direction is pressed
        g0 = -0.1 * RNG.uniform()
        assert min(np.dot(n, a) - g - n[0] * g0 for n, g in zip(bundle.directions, bundle.g)) > 0
        tau = np.array([float(t) for t in ie.normal_traction(bundle, list(a), g0)])
        e = a - g0 * np.eye(dim)[0]
        expected = K @ e - gf
        np.testing.assert_allclose(tau, expected, rtol=1e-13, atol=1e-13 * np.abs(expected).max())
        # energies agree up to the constant of the gaps
        W = ie.normal_energy(bundle, list(a), g0)
        Wlin = 0.5 * e @ K @ e - gf @ e + 0.5 * np.sum(np.array(bundle.weights) * bundle.g ** 2)
        assert abs(W - Wlin) <= 1e-12 * abs(W)
    if dim == 2:
        lin = il.linearized(bundle)
        a = [5.0, 0.03]
        np.testing.assert_allclose([float(t) for t in ie.normal_traction(lin, a, -0.02)],
                                   [float(t) for t in ie.normal_traction(bundle, a, -0.02)], rtol=1e-13)


def test_bundle_opens_direction_by_direction():
    """Directions open one at a time; the tangent loses exactly their ``w n n^T``."""
    d = [(np.cos(b), np.sin(b)) for b in (-0.6, -0.2, 0.0, 0.3, 0.7)]
    w = (1.0, 2.0, 1.5, 0.5, 1.2)
    bundle = il.BundleLaw(weights=w, directions=tuple(d), gaps=(0.0,) * 5)
    # a pure tangential jump closes the directions with n . t0 > 0 and opens the others
    a = np.array([0.0, 0.1])
    closed = [np.dot(n, a) > 0 for n in d]
    tau = np.array([float(t) for t in ie.normal_traction(bundle, list(a))])
    expected = sum(wq * np.outer(n, n) @ a for wq, n, c in zip(w, np.array(d), closed) if c)
    np.testing.assert_allclose(tau, expected, rtol=1e-14)
    assert 0 < sum(closed) < len(d)
    # sweep the closure: the number of active directions grows monotonically
    active = []
    for an in np.linspace(-0.2, 0.2, 41):
        a = np.array([an, 0.05])
        active.append(sum(np.dot(n, a) > 0 for n in d))
    assert active[0] == 0 and active[-1] == len(d)
    assert all(x <= y for x, y in zip(active, active[1:]))
    assert len(set(active)) > 3, "directions should open at different closures"


def test_tabulated_law_interpolates_the_table_and_integrates_it():
    """p(c) hits every table point, is 0 before the first, extends the last slope; W' = p."""
    c = (0.0, 1e-6, 3e-6, 6e-6)
    p = (0.0, 1e4, 5e4, 6e4)
    law = il.TabulatedLaw(closure=c, pressure=p)
    for ci, pi in zip(c, p):
        assert abs(ie.pressure(law, [ci, 0.0]) - pi) <= 1e-9 * max(p)
    assert ie.pressure(law, [-1e-6, 0.0]) == 0.0
    slope = (p[-1] - p[-2]) / (c[-1] - c[-2])
    assert abs(ie.pressure(law, [8e-6, 0.0]) - (p[-1] + slope * 2e-6)) <= 1e-9 * max(p)
    # energy at c_last equals the trapezoidal integral of the table (exact for a polyline)
    W = ie.normal_energy(law, [c[-1], 0.0])
    assert abs(W - np.trapezoid(p, c)) <= 1e-12 * W
    # a gap shifts the law: g0 = -1e-6 means contact already at c = -1e-6
    assert abs(ie.pressure(law, [0.0, 0.0], g0=-1e-6) - p[1]) <= 1e-9 * max(p)


def test_monotone_cubic_table_interpolates_is_c1_and_continues_with_its_last_slope():
    """The two-scale law's interpolation: through every node, zero before the first, W' = p, a
    continuous tangent at the nodes (the polyline's jumps), the last node slope beyond the table."""
    c = (0.0, 1e-6, 3e-6, 6e-6)
    p = (0.0, 1e4, 5e4, 6e4)
    law = il.TabulatedLaw(closure=c, pressure=p, interpolation="monotone_cubic")
    poly = il.TabulatedLaw(closure=c, pressure=p)
    for ci, pi in zip(c, p):
        assert abs(ie.pressure(law, [ci, 0.0]) - pi) <= 1e-9 * max(p)
    assert ie.pressure(law, [-1e-6, 0.0]) == 0.0
    m = law.node_slopes()
    assert abs(ie.pressure(law, [8e-6, 0.0]) - (p[-1] + m[-1] * 2e-6)) <= 1e-9 * max(p)
    h = 1e-12
    for ci in c[1:-1]:
        jumps = []
        for L in (law, poly):
            left = (ie.pressure(L, [ci, 0.0]) - ie.pressure(L, [ci - h, 0.0])) / h
            right = (ie.pressure(L, [ci + h, 0.0]) - ie.pressure(L, [ci, 0.0])) / h
            jumps.append(abs(right - left) / law.stiffness)
        assert jumps[0] < 1e-3 < jumps[1], jumps
    x = np.linspace(-1e-6, 8e-6, 37)
    W = np.array([float(ie.normal_energy(law, [xi, 0.0])) for xi in x])
    fd = np.array([(ie.normal_energy(law, [xi + 1e-11, 0.0]) - ie.normal_energy(law, [xi - 1e-11, 0.0])) / 2e-11
                   for xi in x])
    np.testing.assert_allclose(fd, [float(ie.pressure(law, [xi, 0.0])) for xi in x], rtol=1e-5, atol=1e-6 * max(p))
    assert W[0] == 0.0 and np.all(np.diff(W) >= 0)


def test_an_unknown_table_interpolation_is_refused():
    with pytest.raises(ValueError, match="interpolation = 'spline'"):
        il.TabulatedLaw(closure=(0.0, 1.0), pressure=(0.0, 1.0), interpolation="spline")


@pytest.mark.parametrize("bad", [dict(closure=(0.0, 1.0), pressure=(1.0, 2.0)),
                                 dict(closure=(0.0, 0.0, 1.0), pressure=(0.0, 1.0, 2.0)),
                                 dict(closure=(0.0, 1.0, 2.0), pressure=(0.0, 2.0, 1.0))])
def test_tabulated_law_rejects_non_monotone_tables(bad):
    with pytest.raises(ValueError):
        il.TabulatedLaw(**bad)


def test_friction_sticks_within_the_width_and_slides_at_the_threshold():
    """Huber friction: traction G s / w below the width, exactly G beyond it."""
    fr = il.Friction(mu=0.3, width=1e-3)
    G = 2.0
    for s in (1e-4, 5e-4, 9.99e-4):
        t = ie.friction_traction(fr, [0.0, s], G)[1]
        assert abs(t - G * s / fr.width) <= 1e-12 * G
    for s in (1.001e-3, 0.1, -0.1):
        t = ie.friction_traction(fr, [0.0, s], G)[1]
        assert abs(abs(t) - G) <= 1e-12 * G and np.sign(t) == np.sign(s)
    assert ie.threshold(fr, -5.0) == 0.0 and abs(ie.threshold(fr, 10.0) - 3.0) < 1e-15


def test_coefficient_function_path_matches_numpy():
    """The NGSolve build of the energy and traction gives the NumPy numbers."""
    import ngsolve as ng
    from netgen.geom2d import unit_square
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=1.0))
    mip = mesh(0.3, 0.3)
    for name, law in LAWS.items():
        a = [0.13, -0.07]
        W = ie.energy(law, [ng.CF(a[0]), ng.CF(a[1])], ng.CF(-0.02), ng.CF(0.8))(mip)
        t = [tc(mip) for tc in ie.traction(law, [ng.CF(a[0]), ng.CF(a[1])], ng.CF(-0.02), ng.CF(0.8))]
        assert abs(W - ie.energy(law, a, -0.02, 0.8)) <= 1e-12 * max(1.0, abs(W)), name
        np.testing.assert_allclose(t, [float(x) for x in ie.traction(law, a, -0.02, 0.8)], rtol=1e-12,
                                   atol=1e-14, err_msg=name)


@pytest.mark.parametrize("interpolation", ["linear", "monotone_cubic"])
def test_tabulated_law_on_coefficient_functions_matches_numpy(interpolation):
    """The B-spline evaluation (CoefficientFunctions) equals the NumPy one (ramps of the polyline, the
    Hermite formulas of the cubic) at closures across the table and beyond both ends."""
    import dataclasses
    import ngsolve as ng
    from netgen.geom2d import unit_square
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=1.0))   # kept: a mesh point does not hold its mesh
    mip = mesh(0.3, 0.3)
    law = dataclasses.replace(_cell_response_law(), interpolation=interpolation)
    span = law.closure[-1] - law.closure[0]
    for c in np.linspace(law.closure[0] - 0.1, law.closure[-1] + 2.5 * span, 61):
        W = ie.normal_energy(law, [ng.CF(c), ng.CF(0.0)])(mip)
        p = ie.pressure(law, [ng.CF(c), ng.CF(0.0)])(mip)
        want_W, want_p = ie.normal_energy(law, [c, 0.0]), ie.pressure(law, [c, 0.0])
        assert abs(W - want_W) <= 1e-12 * max(1.0, want_W) and abs(p - want_p) <= 1e-12 * max(1.0, want_p), c


def test_cell_response_law_is_consistent_in_the_assembled_macro_problem():
    """Energy -> residual -> tangent of the macro problem with the two-scale law, by central differences to
    1e-7, at random states where part of the interface is open."""
    import ngsolve as ng
    from ngcontact.fem import two_body
    from ngcontact.geometry import bodies as gm
    from ngcontact.macro import macro_energy as ME
    from ngcontact.macro import macro_problem as M
    from ngcontact.fem.materials import isotropic
    law = _cell_response_law()
    scale = 1e-3 / law.closure[-1]   # closures of the table in mm
    law = il.TabulatedLaw(closure=tuple(scale * c for c in law.closure), pressure=tuple(law.pressure),
                          interpolation=law.interpolation)
    g = gm.coaxial_plane_strain(0.5, 1.0, 2.0, maxh=0.4, order=2)
    sup = (M.Support(label="sym_x", components=("x",)), M.Support(label="sym_y", components=("y",)))
    problem = M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="inner", counter="outer",
                             materials={"inner": isotropic(200.0, 0.3), "outer": isotropic(70.0, 0.25)},
                             law=il.InterfaceLaw(normal=law, friction=il.Friction(mu=0.3, threshold=0.05, width=1e-4)),
                             gap=-0.5e-3 * ng.x, supports=sup, order=2)
    fes = two_body.spaces(problem.mesh, problem.setting, (problem.rough, problem.counter), problem.supports, 2)
    frame = local_frame(two_body.interface_normal(problem.mesh, "inner", "interface"), 2)
    rng = np.random.default_rng(5)
    free = np.array(list(fes.FreeDofs()), dtype=bool)
    old = ng.GridFunction(fes)      # a frozen Coulomb threshold mu p(old) + G0, as in the fixed point
    old.vec.FV().NumPy()[free] = 1e-3 * rng.standard_normal(free.sum())
    G = ie.threshold(problem.law.friction, ie.pressure(law, ME.local_jump(frame, old.components[0] - old.components[1]),
                                                        -0.5e-3 * ng.x))
    form = ME.macro_energy(problem, fes, frame, G=G)
    u = ng.GridFunction(fes).vec
    for trial in range(3):
        u.FV().NumPy()[:] = 0.0
        u.FV().NumPy()[free] = 1e-3 * rng.standard_normal(free.sum())
        v = u.CreateVector()
        v.FV().NumPy()[:] = 0.0
        v.FV().NumPy()[free] = rng.standard_normal(free.sum())
        h = 1e-9
        up, um, r, rp, rm, Kv = (u.CreateVector() for _ in range(6))
        up.data = u + h * v
        um.data = u - h * v
        form.Apply(u, r)
        dE = (form.Energy(up) - form.Energy(um)) / (2 * h)
        rv = ng.InnerProduct(r, v)
        assert abs(dE - rv) <= 1e-7 * abs(rv), f"energy vs residual: {dE} vs {rv}"
        form.Apply(up, rp)
        form.Apply(um, rm)
        form.AssembleLinearization(u)
        Kv.data = form.mat * v
        fd = (rp.FV().NumPy() - rm.FV().NumPy())[free] / (2 * h)
        kv = Kv.FV().NumPy()[free]
        err = np.linalg.norm(fd - kv) / np.linalg.norm(kv)
        assert err <= 1e-7, f"residual vs tangent: relative error {err:.2e}"


def test_local_frame_turns_with_the_normal():
    """2D: t0 = n0 turned clockwise (e_y -> e_x); 3D: orthonormal, right-handed."""
    import ngsolve as ng
    from netgen.geom2d import unit_square
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=1.0))
    n0, t0 = local_frame(ng.CF((0.0, 1.0)), 2)
    np.testing.assert_allclose(t0(mesh(0.5, 0.5)), (1.0, 0.0))
    ang = 0.4
    n0, t0 = local_frame(ng.CF((np.cos(ang), np.sin(ang))), 2)
    np.testing.assert_allclose(t0(mesh(0.5, 0.5)), (np.sin(ang), -np.cos(ang)), atol=1e-15)
    mesh3 = mesh  # the frame is pointwise: a 3-vector CF evaluates anywhere
    for n in [(0, 0, 1.0), (1.0, 0, 0), (0.6, 0.0, 0.8), (0.48, 0.6, 0.64)]:
        frame = local_frame(ng.CF(n), 3)
        E = np.array([np.asarray(e(mesh3(0.5, 0.5))) for e in frame])
        np.testing.assert_allclose(E @ E.T, np.eye(3), atol=1e-14)
        assert abs(np.linalg.det(E) - 1.0) < 1e-14
    E = np.array([np.asarray(e(mesh3(0.5, 0.5))) for e in local_frame(ng.CF((0, 0, 1.0)), 3)])
    np.testing.assert_allclose(E, np.eye(3)[[2, 0, 1]], atol=1e-15)
