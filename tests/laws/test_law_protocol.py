"""Every homogenized law is one class of the protocol (laws/law_protocol.py): the built-in laws implement it,
their export rows are their own pressure curve, and a new law defined here, in the test, solves a macro
problem through the unchanged macro energy (laws/interface_energy.py knows no law by name)."""
import math

import numpy as np
import pytest

from ngcontact.errors import ModelError
from ngcontact.export import law_table as lt
from ngcontact.fem.materials import isotropic
from ngcontact.geometry import bodies as gm
from ngcontact.laws import homogenized as il
from ngcontact.laws import interface_energy as ie
from ngcontact.laws.law_evaluation import ramp
from ngcontact.macro import macro_measures as MM
from ngcontact.macro import macro_problem as M

NORMAL = [il.LinearLaw(kn=5e11, kt=2e11, knt=1e10, gap_force=(1e3, 2e2)),
          il.BundleLaw(weights=(3e11, 2e11, 1e11), directions=((1.0, 0.0), (0.8, 0.6), (0.6, -0.8)),
                       gaps=(0.0, 1e-7, 2e-7)),
          il.TabulatedLaw(closure=(0.0, 2e-6, 5e-6), pressure=(0.0, 1e6, 4e6), kt=1e11),
          il.TabulatedLaw(closure=(0.0, 2e-6, 5e-6), pressure=(0.0, 1e6, 4e6), interpolation="monotone_cubic")]
TANGENTIAL = [il.Friction(mu=0.3, threshold=1e4, width=1e-7),
              il.CellShear(pressure=(0.0, 1.0), jumps=((0.0, 1.0), (0.0, 1.0)), shears=((0.0, 0.0), (0.0, 0.5)))]


@pytest.mark.parametrize("law", NORMAL + TANGENTIAL, ids=lambda law: type(law).__name__)
def test_every_law_class_implements_the_protocol(law):
    base = il.NormalLaw if law in NORMAL else il.TangentialLaw
    assert isinstance(law, base) and not type(law).__abstractmethods__


@pytest.mark.parametrize("law", NORMAL[:3], ids=lambda law: type(law).__name__)
def test_export_rows_are_the_laws_own_pressure_under_a_normal_closure(law):
    """p(c) = sum_i s_i [c - c_i]_+ of the rows is the law's p at a = (c, 0), above the first kink (the linear
    law is bilateral: below its kink it pulls, which the rows leave out and say so)."""
    rows = law.export_rows()
    c = np.linspace(float(np.min(rows.kinks)), 8e-6, 41)
    p = np.asarray(ie.pressure(law, [c, np.zeros_like(c)]), float)
    np.testing.assert_allclose(lt.curve(rows.kinks, rows.slopes, c), p, rtol=1e-12, atol=1e-9 * p.max())
    assert rows.bilateral == law.quadratic
    assert rows.stick_slope == pytest.approx(law.kt if rows.K0 is None else np.mean(np.diag(rows.K0)[1:]))


def test_a_cubic_table_has_no_exact_curve_to_export():
    with pytest.raises(ModelError, match="cannot be exported"):
        NORMAL[3].export_rows()


def test_a_class_that_leaves_out_a_method_is_not_a_law():
    class NoTraction(il.NormalLaw):
        def energy(self, a, g0=0.0, closed=False):
            return 0.0 * a[0]

        @property
        def stiffness(self):
            return 1.0

    with pytest.raises(TypeError, match="traction"):
        NoTraction()


# ------------------------------------------------------------- a new law, defined here
class UnilateralSpring(il.NormalLaw):
    """``W(a) = k/2 [a_n - g0]_+^2 + k_t/2 |a_t|^2``: a one-kink table, written as a new class."""

    def __init__(self, k: float, kt: float = 0.0):
        self.k, self.kt = k, kt

    def energy(self, a, g0=0.0, closed=False):
        c = a[0] - g0
        closure = c if closed else ramp(c)
        return 0.5 * self.k * closure * closure + 0.5 * self.kt * sum(t * t for t in a[1:])

    def traction(self, a, g0=0.0):
        return [self.k * ramp(a[0] - g0)] + [self.kt * t for t in a[1:]]

    @property
    def stiffness(self):
        return self.k

    @property
    def holds_tangentially(self):
        return self.kt > 0


class TangentialSpring(il.TangentialLaw):
    """``W_f(a) = k_t/2 |a_t|^2`` whatever the threshold: an elastic bond that never slips."""

    def __init__(self, kt: float):
        self.kt = kt

    @property
    def width(self):
        return math.inf

    @property
    def coulomb(self):
        return False

    def threshold_at(self, p):
        return 0.0

    def energy(self, a, G):
        return 0.5 * self.kt * sum(t * t for t in a[1:])

    def traction(self, a, G):
        return [0.0 * a[0]] + [self.kt * t for t in a[1:]]


K_N, K_T, P, T = 5e11, 2e11, 2e6, 3e5


def _block(law):
    """A block pressed (P) and sheared (T) on a base (paper setting of a rough block on a plane)."""
    g = gm.block_on_plane(0.1, 0.01, 0.02, maxh=0.01)
    prob = M.MacroProblem(mesh=g.mesh, setting="plane_strain", rough="block", counter="base",
                          materials={"block": isotropic(10e9, 0.3), "base": isotropic(70e9, 0.2)},
                          law=law, order=2, supports=(M.Support(label="bottom"),),
                          loads=(M.Load(label="top", pressure=P, traction=(T, 0.0)),))
    return M.solve(prob)


def test_a_new_law_class_solves_the_macro_problem_like_the_built_in_law_it_equals():
    """The new normal law (and, apart, the new tangential law) against the one-kink table with k_t."""
    a = [np.array([-1e-6, 0.0, 2e-6]), np.array([1e-6, -3e-6, 0.0])]
    table = il.TabulatedLaw(closure=(0.0, 1.0), pressure=(0.0, K_N), kt=K_T)
    for law in (il.InterfaceLaw(normal=UnilateralSpring(K_N, K_T)),
                il.InterfaceLaw(normal=UnilateralSpring(K_N), friction=TangentialSpring(K_T))):
        np.testing.assert_allclose(ie.energy(law, a), ie.energy(il.InterfaceLaw(normal=table), a), rtol=1e-14)
        np.testing.assert_allclose(ie.traction(law, a), ie.traction(il.InterfaceLaw(normal=table), a), rtol=1e-14)
        assert law.holds_tangentially and not law.quadratic
    reference = MM.interface_profile(_block(il.InterfaceLaw(normal=table)))
    for law in (il.InterfaceLaw(normal=UnilateralSpring(K_N, K_T)),
                il.InterfaceLaw(normal=UnilateralSpring(K_N), friction=TangentialSpring(K_T))):
        sol = _block(law)
        assert sol.history["converged"]
        prof = MM.interface_profile(sol)
        for key in ("pressure", "shear", "jump_n", "jump_t"):
            scale = np.max(np.abs(reference[key]))
            assert np.max(np.abs(prof[key] - reference[key])) <= 1e-8 * scale, key
        R = MM.resultant(sol)
        assert abs(R["x"] - T * 0.1) < 1e-8 * T * 0.1 and abs(R["y"] + P * 0.1) < 1e-8 * P * 0.1
        assert set(prof["status"]) <= {"stick", "open"}


def test_a_new_law_is_refused_by_the_exporters_unless_it_gives_its_rows():
    with pytest.raises(ModelError, match="a UnilateralSpring cannot be exported"):
        UnilateralSpring(K_N).export_rows()
