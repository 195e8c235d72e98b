"""The micro (cell) contact problem in the interface layer (paper Sec. 3.4).

A periodic cell holds two elastic bodies, ``rough`` below and ``counter``
above, meeting along the potential contact surface ``S_C`` (mesh naming
contract of :mod:`ngcontact.geometry`).  The cell problem of paper eqs.
49-51 (variational inequality 57; with the macro strain, eq. 63; with the
penalized contact condition, eq. 65) is solved for the periodic displacement
fluctuation of each body as the minimum of

    Pi(u_r, u_c, U) = sum_B int_B 1/2 (eps(u_B) + E) : C_B : (eps(u_B) + E) dx
                      + int_{S_C} psi(J) ds  -  |T| tbar . U

with

* ``u_r`` the fluctuation of ``rough``, periodic, zero on ``bottom``;
* ``u_c + U`` the displacement of ``counter``: a periodic fluctuation ``u_c``
  vanishing on ``top`` plus a rigid translation ``U`` of the far face (one
  ``NumberSpace`` per component);
* ``J = u_r - u_c - U`` the jump (the affine macro part ``E x`` is the same on
  both sides and does not jump), ``psi`` the interface energy of
  :mod:`ngcontact.laws.penalty`: the penalty ``k_n/2 [J.n - g]_+^2`` whose
  derivative is the contact term ``k_n [J.n - g]_+ n`` of eq. 65, and the
  friction term ``G |J_t|`` of eqs. 57 and 65 (Huber-regularized);
* ``E`` an optional in-plane macro strain (2D: ``e_xx``; 3D: ``e_xx, e_yy,
  e_xy``), the ``du^0/dx`` of eq. 63;
* per component ``i`` of the mesh axes a prescribed mean traction ``tbar_i``
  on the counter's far face or a prescribed jump ``Delta_i = -U_i`` across
  the layer (:mod:`ngcontact.cell.cell_load`).

Solve.  Newton's method (:func:`ngcontact.solvers.newton.minimize`), the
step minimizing the convex energy along the Newton direction
(``line_search="exact"``, Armijo test kept as a guard).  The first load
under a prescribed pressure starts from the rigid predictor of
:mod:`ngcontact.cell.fe.predictor`, moved onto the contact set of the spectral
twin where the cell has one (penalty, small slope:
:mod:`ngcontact.cell.spectral_start`), later loads from the previous
solution (a frictionless sweep with a twin: each pressure afresh from the
twin; the rules: :mod:`ngcontact.cell.fe.load_start`).  A
frictionless flat ``S_C`` leaves ``U_t`` free of energy: it is fixed at 0
and a nonzero shear is rejected.  Coulomb friction: Newton on the
coupled equations with the threshold ``mu p(u)`` differentiated (the
consistent, non-symmetric tangent), or the fixed point of Tresca problems
``G_k = mu p_{k-1}`` until ``max |p_k - p_{k-1}| <= coulomb_rtol * max p_k``
on ``S_C``: the same solution (:mod:`ngcontact.cell.fe.coulomb_friction`).

Exact non-penetration (``CellModel.enforcement = "exact"``, 2D, and 3D at order 1 or on a linear trace;
the rigid limit ``k_n -> infinity`` of the Winkler layer): the normal
energy is the augmented Lagrangian
``(1/(2 k_n)) ([lambda + k_n (J.n - g)]_+^2 - lambda^2)``, integrated with a
nodal rule on ``S_C`` (Gauss-Lobatto on segments, the vertices with their
areas on order-1 triangles) so that the constraints sit at the nodes of the
trace space, with a multiplier
``lambda`` per point held fixed in each Newton solve and updated by Uzawa's
iteration (:mod:`ngcontact.cell.fe.contact_multiplier`); the pressure of the
results is the multiplier, and ``k_n`` only sets the speed.  Tresca
friction adds its energy at the same points.  Coulomb friction takes the
threshold ``mu lambda`` from the multiplier held fixed in each Newton solve
(a Tresca problem), so Uzawa's iteration is the Coulomb fixed point too: it
stops when neither the multiplier nor, with it, the threshold changes.

Results of a load: :mod:`ngcontact.cell.fe.measures` (contact fraction, means,
stresses, eq. 34 on the real contact set); effective stiffness (beyond the
paper): :mod:`ngcontact.cell.fe.stiffness`.
"""
from __future__ import annotations

import logging

import ngsolve as ng
import numpy as np

from ngcontact.cell.fe import measures
from ngcontact.cell.fe.contact_multiplier import TRIANGLE_MAX_ORDER, solve_exact
from ngcontact.cell.cell_load import CellLoad, cell_load  # noqa: F401 (cell_load: re-exported)
from ngcontact.cell.cell_solution import CellSolution
from ngcontact.cell.fe.cell_model import CellModel
from ngcontact.cell.fe.cell_energy import cell_energy, interface_tangent, jump, preconditioning_form
from ngcontact.cell.fe.discrete_cell import discretize
from ngcontact.cell.fe.contact_quadrature import ContactQuadrature
from ngcontact.cell.fe.linear_trace import trace_order
from ngcontact.cell.fe.contact_quadrature import applies as quadrature_applies
from ngcontact.cell.fe.coulomb_friction import METHODS, solve_coulomb
from ngcontact.cell.fe.load_start import Predictor, check_start, start_load, starts_afresh, tangential_load
from ngcontact.cell.fe.predictor import max_gap
from ngcontact.errors import ModelError
from ngcontact.laws import penalty as _contact
from ngcontact.solvers.linear_solver import LinearSolver
from ngcontact.solvers.newton import minimize
from ngcontact.solvers.split_energy import SplitEnergy

log = logging.getLogger(__name__)


class CellProblem:
    """A cell problem built on a meshed cell; solve loads with :meth:`sweep`.

    Parameters
    ----------
    cell
        A :class:`ngcontact.geometry.cell2d.Cell` (or 3D analogue) obeying the
        naming contract.
    model
        :class:`CellModel`.
    rtol, atol, max_iter, inverse
        Newton settings (see :func:`ngcontact.solvers.newton.minimize`).
    normal
        Micro normal on ``contact``; default
        :func:`ngcontact.cell.coefficients.contact_normal`.
    line_search
        ``"exact"`` (default: energy minimized along the Newton direction)
        or ``"armijo"`` (backtracking only).
    linear
        Tangent solves (:class:`~ngcontact.solvers.linear_solver.LinearSolver`);
        default: direct with ``inverse``.
    start
        Start of the first load under a prescribed pressure: ``"predictor"``
        (the default with a ``predictor``: the rigid predictor's state moved on
        by it), ``"rigid"`` (the default without: the rigid predictor of
        :mod:`ngcontact.cell.fe.predictor`) or ``"closed"`` (every point of
        ``S_C`` pushed into contact).
    predictor
        A :class:`~ngcontact.cell.fe.load_start.Predictor` of the first loads, penalty only (the
        spectral twin's contact set, :class:`ngcontact.cell.spectral_start.SpectralStart`, made by
        :func:`ngcontact.drivers.build.predictor_twin`); ``None``: none.
    coulomb
        Coulomb friction with the penalty: ``"newton"`` (default, the
        coupled Newton) or ``"fixed_point"``
        (:mod:`ngcontact.cell.fe.coulomb_friction`).

    Attributes
    ----------
    discrete
        The :class:`~ngcontact.cell.fe.discrete_cell.DiscreteCell` (space, normal, gap, load parameters,
        multiplier); its fields are also this object's attributes of the same names.
    gfu, form
        The state ``(u_r, u_c, U)`` and the energy ``Pi``.
    J, pressure, penetration, slip, augmented_pressure
        CoefficientFunctions of the state (exact enforcement: ``pressure`` is the multiplier, meaningful at
        its points only; ``augmented_pressure`` is ``[lambda + k_n (J.n - g)]_+``, else ``None``).
    coulomb_previous
        Coulomb with the penalty: the frozen state of the threshold ``mu p``.
    """

    def __init__(self, cell, model: CellModel, *, rtol: float = 1e-10, atol: float = 0.0,
                 max_iter: int = 40, inverse: str = "sparsecholesky", normal=None,
                 line_search: str = "exact", start: str | None = None, linear: LinearSolver | None = None,
                 coulomb: str = "newton", predictor: Predictor | None = None):
        if coulomb not in METHODS:
            raise ValueError(f"coulomb = {coulomb!r}: must be one of {METHODS}")
        if line_search not in ("exact", "armijo"):
            raise ValueError(f"line_search = {line_search!r}: must be 'exact' or 'armijo'")
        start = check_start(start, predictor, model.enforcement)
        if model.enforcement == "exact" and cell.dim == 3 and trace_order(model, 3) > TRIANGLE_MAX_ORDER:
            raise ModelError(f"order = {model.order} with enforcement = 'exact' in a 3D cell: exact contact on "
                             f"triangles is built for order <= {TRIANGLE_MAX_ORDER} (quadratic triangles leave corner "
                             "nodes open inside the contact patch); use order 1, a linear trace on S_C "
                             "(CellModel.linear_trace), the penalty, or the spectral cell")
        if predictor is not None:
            predictor.check(cell.mesh)
        self.line_search, self.start, self.coulomb, self.predictor = line_search, start, coulomb, predictor
        self.coulomb_residual = None      # Coulomb, coupled Newton: the residual form, built on first use
        self.rtol, self.atol, self.max_iter, self.inverse = rtol, atol, max_iter, inverse
        self.linear = linear if linear is not None else LinearSolver("direct", inverse=inverse)
        self.discrete = d = discretize(cell, model, normal=normal, inverse=inverse)
        self.cell, self.model, self.mesh, self.dim, self.setting, self.area = cell, model, d.mesh, d.dim, \
            d.setting, d.area
        self.X, self.n, self.gap, self.u_dofs, self.tangential_free = d.X, d.n, d.gap, d.u_dofs, d.tangential_free
        self.traction, self.strain_params, self.augmentation, self.multiplier = \
            d.traction, d.strain_params, d.augmentation, d.multiplier
        self.gfu = ng.GridFunction(self.X)
        self.form, self.coulomb_previous, self._parts = cell_energy(d)
        # the state the written-out tangent and the preconditioning form are assembled at
        self._linearized_at = ng.GridFunction(self.X)
        # the penalty's high quadrature on the contact edge's elements only, where that is exact
        self._quadrature = ContactQuadrature(d, self._linearized_at) if quadrature_applies(d) else None
        self._preconditioning = preconditioning_form(d, self._linearized_at, self._quadrature,
                                                     self.coulomb_previous)
        self._split: SplitEnergy | None = None
        self._largest_gap: float | None = None
        # the state as CoefficientFunctions (for results and tests)
        comps = self.gfu.components
        self.U = ng.CF(tuple(comps[2:]))
        self.J = jump(comps)
        if self.multiplier is None:
            self.pressure = _contact.pressure(self.J, self.n, model.k_n, self.gap)
            self.augmented_pressure = None
        else:
            self.pressure = self.multiplier.value
            self.augmented_pressure = _contact.augmented_pressure(self.J, self.n, self.augmentation,
                                                                  self.multiplier.value, self.gap)
        self.penetration = _contact.penetration(self.J, self.n, self.gap)
        self._active_points = None
        self.slip = _contact.tangential_slip(self.J, self.n)

    # -------------------------------------------------------------- energy
    def body_strain(self, u):
        """Total strain of a body: fluctuation plus the macro strain (if assembled)."""
        return self.discrete.body_strain(u)

    def largest_gap(self) -> float:
        """Largest initial gap on ``S_C`` (:func:`ngcontact.cell.fe.predictor.max_gap`), sampled once: the gap
        of a problem is fixed."""
        if self._largest_gap is None:
            self._largest_gap = max_gap(self)
        return self._largest_gap

    @property
    def ndof(self) -> int:
        return self.X.ndof

    @property
    def contact_order(self) -> int:
        """Integration order of the contact energy (that of the ``Variation`` term)."""
        return self.discrete.contact_order

    # --------------------------------------------------------------- solve
    def _freedofs(self, load: CellLoad):
        free = ng.BitArray(self.X.FreeDofs())
        for i, d in enumerate(self.u_dofs):
            if load.jump[i] is not None or (i < self.dim - 1 and not self.tangential_free):
                free.Clear(d)
        return free

    def _apply_load(self, load: CellLoad):
        d = self.dim
        if not self.tangential_free:
            for i in range(d - 1):
                if load.traction[i] not in (None, 0.0) or load.jump[i] not in (None, 0.0):
                    raise ValueError(
                        "a frictionless flat contact surface carries no shear and fixes no "
                        "tangential jump: give shear = 0 or add friction")
        if load.macro_strain and not self.model.macro_strain:
            raise ValueError("this cell problem was built without the macro strain term")
        for i, p in enumerate(self.strain_params):
            p.Set(load.macro_strain[i] if load.macro_strain else 0.0)
        vec = self.gfu.vec
        for i in range(d):
            t = load.traction[i]
            self.traction[i].Set(0.0 if t is None else t)
            jump = load.jump[i]
            if jump is not None:
                vec[self.u_dofs[i]] = -jump
            elif i < d - 1 and not self.tangential_free:
                vec[self.u_dofs[i]] = 0.0

    def solve(self, load: CellLoad, first: bool = False, measure: bool = True) -> CellSolution:
        """Solve one load, starting from the current state (continuation).

        With ``measure=False`` only ``contact_fraction`` and
        ``mean_pressure`` are evaluated (no stresses, coefficients or
        stiffness Schur complements) and ``surface`` is empty: for timing
        studies of the solve itself.
        """
        before = tangential_load(self)
        self._apply_load(load)
        free = self._freedofs(load)
        started, predicted = start_load(self, load, free, first, before)
        histories: list[dict] = [] if predicted is None else [predicted]
        fp = 0
        if self.coulomb_previous is not None:
            coulomb, fp = solve_coulomb(self, free, self._newton)
            histories += coulomb
        else:
            histories.append(self._newton(free, self.atol))
        if started is not None:
            histories[0]["start"] = started         # a first load: no rigid continuation before it
        if measure:
            results = self.measure(load)
            surface = measures.surface_distribution(self)
        else:
            results = {"contact_fraction": measures.contact_fraction(self),
                       "mean_pressure": measures.mean_pressure(self)}
            surface = {}
        return CellSolution(load=load, results=results, surface=surface, newton=histories,
                            coulomb_iterations=fp)

    def _newton(self, free, atol) -> dict:
        if self.multiplier is not None:
            return solve_exact(self, lambda a: self._newton_once(free, a), atol)
        return self._newton_once(free, atol)

    def energy(self) -> SplitEnergy:
        """The energy Newton minimizes: the whole form split into the bodies' quadratic part, assembled
        once, and the interface (:class:`~ngcontact.solvers.split_energy.SplitEnergy`)."""
        if self._split is None:
            loads = self.traction + self.strain_params
            quadratic, interface = self._parts
            tangent = None
            if self._quadrature is not None:
                interface = self._quadrature
            else:
                tangent = interface_tangent(self.discrete, self._linearized_at, self.coulomb_previous)
            self._split = SplitEnergy(self.form, quadratic, interface, key=lambda: tuple(p.Get() for p in loads),
                                      preconditioning=self._preconditioning, interface_tangent=tangent)
        return self._split

    def _newton_once(self, free, atol) -> dict:
        def run(rtol, atol):
            return minimize(self.energy(), self.gfu, freedofs=free, rtol=rtol, atol=atol,
                            max_iter=self.max_iter, linear=self.linear, line_search=self.line_search,
                            active_set=self.active_set).as_dict()
        if self._quadrature is None:
            return run(self.rtol, atol)
        return self._quadrature.newton(self.gfu.vec, run, self.rtol, atol)

    def active_set(self, gfu=None) -> bytes:
        """Signature of the contact state: which quadrature points of ``S_C`` penetrate.

        Exact enforcement: where the augmented pressure is positive, at the
        multiplier's points.
        """
        if self.multiplier is not None:
            aug = self.multiplier.at_points(self.multiplier.value + self.augmentation * self.penetration)
            return np.packbits(aug > 0.0).tobytes()
        if self._active_points is None:
            shape = ng.TRIG if self.dim == 3 else ng.SEGM
            rule = ng.IntegrationRule(shape, 2 * self.model.order)
            self._active_points = self.mesh.MapToAllElements(rule, self.mesh.Boundaries("contact"))
        pen = np.asarray(self.penetration(self._active_points)).ravel()
        return np.packbits(pen > 0.0).tobytes()

    def sweep(self, loads) -> list:
        """Solve a list of loads in order, each from the previous solution.

        A frictionless cell with a spectral twin starts every load under a prescribed pressure afresh from
        the twin's contact set instead: its energy is convex with one minimizer, so the start may forget the
        previous state, and the twin's contact set is nearer the solution's than the previous load's (fewer
        Newton steps on the Westergaard sweep and the tabulated gap).
        """
        self.gfu.vec[:] = 0.0
        out = []
        for k, load in enumerate(loads):
            sol = self.solve(load, first=k == 0 or starts_afresh(self, load))
            log.info("load %d: %d Newton steps, contact fraction %.6f", k, sol.iterations,
                     sol.results["contact_fraction"])
            out.append(sol)
        return out

    def measure(self, load: CellLoad) -> dict:
        """Results of the current state: :func:`ngcontact.cell.fe.measures.measure`."""
        return measures.measure(self, load)
