"""The tabulated cell shear law (CellShear): it interpolates its rows, and its energy, traction and tangent
agree by central differences (pressure frozen), alone and assembled in a macro problem."""
import numpy as np
import pytest

from ngcontact.errors import ModelError
from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie

RNG = np.random.default_rng(11)


def shear_law(scale=1.0):
    """Three rows of a stick-then-slide shear, the plateau 0.7 p reached at a jump growing with p."""
    rows = [(0.0, 1.0, 2.0), (0.0, 0.5, 1.0, 3.0), (0.0, 1.0, 2.5, 4.0, 6.0)]
    pressures = (0.0, 1.0, 2.0)
    shears = [tuple(0.7 * p * min(1.0, s / (1.0 + p)) for s in row) for p, row in zip(pressures, rows)]
    return il.CellShear(pressure=pressures, jumps=tuple(tuple(scale * s for s in r) for r in rows),
                        shears=tuple(shears))


def test_cell_shear_hits_its_rows_interpolates_in_pressure_and_is_odd():
    law = shear_law()
    for p, row_s, row_t in zip(law.pressure, law.jumps, law.shears):
        for s, t in zip(row_s, row_t):
            assert abs(ie.friction_traction(law, [0.0, s], p)[1] - t) <= 1e-12
            assert abs(ie.friction_traction(law, [0.0, -s], p)[1] + t) <= 1e-12
    # halfway between the rows 1 and 2, at s = 1: the mean of the two rows carried along s / p = const
    t1 = 1.5 * np.interp(1.0 / 1.5, law.jumps[1], law.shears[1])
    t2 = 0.75 * np.interp(1.0 / 0.75, law.jumps[2], law.shears[2])
    assert abs(ie.friction_traction(law, [0.0, 1.0], 1.5)[1] - 0.5 * (t1 + t2)) <= 1e-12
    # held beyond the last jump, scaled with p above the last pressure; nothing at p <= 0
    assert abs(ie.friction_traction(law, [0.0, 50.0], 9.0)[1] - 4.5 * law.shears[2][-1]) <= 1e-12
    assert ie.friction_traction(law, [0.0, 2.0], -1.0)[1] == 0.0
    # a response homogeneous in the load, T(p, s) = p f(s / p), is reproduced between the rows
    f = (0.0, 0.2, 0.5, 0.7)
    x = (0.0, 0.1, 0.3, 1.0)
    homog = il.CellShear(pressure=(0.0, 1.0, 3.0), jumps=((0.0, 1.0), x, tuple(3 * v for v in x)),
                         shears=((0.0, 0.0), f, tuple(3 * v for v in f)))
    for p, s in ((1.7, 0.25), (2.4, 1.9), (2.9, 0.05)):
        assert abs(ie.friction_traction(homog, [0.0, s], p)[1] - p * np.interp(s / p, x, f)) <= 1e-12
    with pytest.raises(ModelError):
        ie.friction_traction(law, [0.0, 1.0, 0.0], 1.0)


@pytest.mark.parametrize("bad", [dict(pressure=(0.5, 1.0)), dict(pressure=(0.0, 2.0, 1.0)),
                                 dict(jumps=((0.0, 1.0), (0.0, 0.0))), dict(shears=((0.0, 1.0), (1.0, 2.0)))])
def test_cell_shear_rejects_bad_tables(bad):
    data = dict(pressure=(0.0, 1.0), jumps=((0.0, 1.0), (0.0, 1.0)), shears=((0.0, 0.0), (0.0, 0.5)))
    with pytest.raises(ModelError):
        il.CellShear(**{**data, **bad})


def test_cell_shear_traction_is_the_derivative_of_its_energy():
    """Central differences of W_t reproduce tau_t, and of tau_t its tangent, at random states (p frozen)."""
    law = il.InterfaceLaw(normal=il.TabulatedLaw(closure=(-0.1, 0.0, 0.2, 0.5), pressure=(0.0, 0.3, 1.0, 1.2)),
                          friction=shear_law())
    h = 1e-6
    for _ in range(30):
        a = np.array([RNG.normal(scale=0.3), RNG.normal(scale=3.0)])
        p = RNG.uniform(-0.5, 2.5)
        tau = np.array([float(t) for t in ie.traction(law, list(a), 0.0, p)])
        fd = [(ie.energy(law, list(a + e), 0.0, p) - ie.energy(law, list(a - e), 0.0, p)) / (2 * h)
              for e in h * np.eye(2)]
        np.testing.assert_allclose(tau, np.array(fd, float), rtol=1e-6, atol=1e-8)


def _central_differences(form, u, v, free, energy: bool):
    """Relative errors (energy vs residual, residual vs tangent) of ``form`` at ``u`` along ``v``."""
    import ngsolve as ng
    h = 1e-9
    up, um, r, rp, rm, Kv = (u.CreateVector() for _ in range(6))
    up.data = u + h * v
    um.data = u - h * v
    form.Apply(u, r)
    rv = ng.InnerProduct(r, v)
    e_res = abs((form.Energy(up) - form.Energy(um)) / (2 * h) - rv) / abs(rv) if energy else 0.0
    form.Apply(up, rp)
    form.Apply(um, rm)
    form.AssembleLinearization(u)
    Kv.data = form.mat * v
    fd = (rp.FV().NumPy() - rm.FV().NumPy())[free] / (2 * h)
    kv = Kv.FV().NumPy()[free]
    return e_res, float(np.linalg.norm(fd - kv) / np.linalg.norm(kv))


def test_cell_shear_is_consistent_in_the_assembled_macro_problem():
    """Energy -> residual -> tangent of the macro problem with a tabulated normal law and the cell shear,
    pressure frozen at another state, and residual -> tangent of the coupled equations (pressure of the
    current state), by central differences to 1e-7 at random states where part of the interface is open."""
    import ngsolve as ng
    from ngcontact.fem import two_body
    from ngcontact.fem.materials import isotropic
    from ngcontact.geometry import bodies as gm
    from ngcontact.laws.local_frame import local_frame
    from ngcontact.macro import macro_energy as ME
    from ngcontact.macro import macro_problem as M
    normal = il.TabulatedLaw(closure=(-1e-4, 0.0, 2e-4, 5e-4), pressure=(0.0, 30.0, 100.0, 120.0))
    law = il.InterfaceLaw(normal=normal, friction=shear_law(scale=1e-4))
    g = gm.coaxial_plane_strain(0.5, 1.0, 2.0, maxh=0.4, order=2)
    sup = (M.Support(label="sym_x", components=("x",)), M.Support(label="sym_y", components=("y",)))
    problem = M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="inner", counter="outer",
                             materials={"inner": isotropic(2e5, 0.3), "outer": isotropic(7e4, 0.25)},
                             law=law, gap=-0.5e-4 * ng.x, supports=sup, order=2)
    fes = two_body.spaces(problem.mesh, problem.setting, (problem.rough, problem.counter), problem.supports, 2)
    frame = local_frame(two_body.interface_normal(problem.mesh, "inner", "interface"), 2)
    rng = np.random.default_rng(5)
    free = np.array(list(fes.FreeDofs()), dtype=bool)
    old = ng.GridFunction(fes)
    old.vec.FV().NumPy()[free] = 2e-4 * rng.standard_normal(free.sum())
    p_old = ie.pressure(normal, ME.local_jump(frame, old.components[0] - old.components[1]), -0.5e-4 * ng.x)
    frozen = ME.macro_energy(problem, fes, frame, G=ie.threshold(law.friction, p_old))
    coupled = ME.macro_energy(problem, fes, frame, coupled=True)
    u = ng.GridFunction(fes).vec
    for _ in range(3):
        u.FV().NumPy()[:] = 0.0
        u.FV().NumPy()[free] = 2e-4 * rng.standard_normal(free.sum())
        v = u.CreateVector()
        v.FV().NumPy()[:] = 0.0
        v.FV().NumPy()[free] = rng.standard_normal(free.sum())
        e_res, e_tan = _central_differences(frozen, u, v, free, energy=True)
        assert e_res <= 1e-7 and e_tan <= 1e-7, (e_res, e_tan)
        _, e_tan = _central_differences(coupled, u, v, free, energy=False)
        assert e_tan <= 1e-7, f"coupled residual vs tangent: {e_tan:.2e}"


def test_the_coefficient_function_path_gives_the_numbers_of_the_numpy_path():
    """The B-spline rows of the assembled law against the ramps, energy and traction, at mesh points."""
    import ngsolve as ng
    from netgen.geom2d import unit_square
    mesh = ng.Mesh(unit_square.GenerateMesh(maxh=0.5))
    law = shear_law()
    s_cf, p_cf = 16.0 * (ng.x - 0.5), 3.0 * ng.y - 0.4      # jumps beyond both ends, pressures below 0 and above 2
    W = ie.friction_energy(law, [0.0 * ng.x, s_cf], p_cf)
    T = ie.friction_traction(law, [0.0 * ng.x, s_cf], p_cf)[1]
    for x, y in ((0.1, 0.3), (0.45, 0.5), (0.52, 0.75), (0.9, 0.95), (0.7, 0.05)):
        s, p = 16.0 * (x - 0.5), 3.0 * y - 0.4
        mp = mesh(x, y)
        assert abs(T(mp) - ie.friction_traction(law, [0.0, s], p)[1]) <= 1e-10, (x, y)
        assert abs(W(mp) - ie.friction_energy(law, [0.0, s], p)) <= 1e-9 * max(1.0, abs(W(mp))), (x, y)
