"""The micro (cell) contact problem in the interface layer (paper Sec. 3.4).

A periodic cell holds two elastic bodies, ``rough`` below and ``counter``
above, meeting along the potential contact surface ``S_C`` (mesh naming
contract of :mod:`ngcontact.geometry`).  The cell problem (paper eqs. 49-51,
variational form 57 and 65) is solved for the periodic displacement
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
  :mod:`ngcontact.laws.penalty` (penalty, gap, friction as asked for);
* ``E`` an optional in-plane macro strain (2D: ``e_xx``; 3D: ``e_xx, e_yy,
  e_xy``);
* per component ``i`` of the mesh axes (``x, y`` in 2D, ``x, y, z`` in 3D; the
  last one is the macro normal ``n0``) either a prescribed mean traction
  ``tbar_i`` on the counter's far face (normal pressure ``p = -tbar_n >= 0``,
  compression positive) or a prescribed jump across the layer
  ``Delta_i = (u_bottom - u_top)_i = -U_i`` (``Delta_n > 0`` closes).

Start of a solve.  The tangent is singular in ``U_n`` while nothing is in
contact, and Newton's active-set updates converge slowly (each step halves
the distance of a contact edge) when they start with the whole surface
closed.  The first load of a sweep therefore starts from the *rigid
predictor*: fluctuations zero and the counter translated by the normal
approach ``d`` that minimizes the energy over rigid normal translations
alone, i.e. the root of

    R(d) = int_{S_C} k_n [d n.n0 - g]_+ (n.n0) ds - p |T| = 0

(the penalty layer alone carries the pressure; a Winkler foundation of
stiffness ``k_n``).  Because ``k_n`` is much stiffer than the bodies, this
under-estimates the contact set, and Newton approaches the contact edges
from the open side, where each step moves them most of the way.  The step
length is the minimizer of the (convex) energy along the Newton direction
(``line_search="exact"`` of :func:`ngcontact.newton.minimize`, Armijo test
kept as a guard); ``start="closed"`` restores the earlier start (counter
pushed down by the largest gap plus ``p/k_n``).  Later loads continue from
the previous solution.
When friction is absent and ``S_C`` is flat, a tangential translation of the
counter costs no energy: it is then fixed at 0 (any value solves the problem)
and a nonzero shear is rejected (a frictionless flat interface carries
none).

Coulomb friction is a fixed point of Tresca problems, ``G_k = mu p_{k-1}``
(see :mod:`ngcontact.laws.penalty`); it stops when
``max |p_k - p_{k-1}| <= coulomb_rtol * max p_k`` at the quadrature points
of ``S_C``.

Effective stiffness (beyond the paper, DESIGN Sec. 3): with ``S`` the Schur
complement of the tangent on ``U`` divided by ``|T|`` (the tangent of the
mean traction with respect to the far faces' relative displacement) and
``S_0`` the same for the flat bonded laminate of the same thickness
(analytic, :meth:`CellProblem.reference_stiffness`), the interface's
compliance is ``S^-1 - S_0^-1`` (penalty layer plus asperities) and the
effective stiffness its inverse.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

import ngsolve as ng
import numpy as np

from ngcontact.laws import penalty as _contact
from ngcontact.fem import elasticity as _el
from ngcontact.fem import materials as _mat
from ngcontact.errors import ConvergenceError
from ngcontact.solvers.newton import illinois_root, minimize

log = logging.getLogger(__name__)


# ------------------------------------------------------------ descriptions
@dataclass(frozen=True)
class Friction:
    """Friction law: ``"tresca"`` with threshold ``G`` or ``"coulomb"`` with ``mu``; Huber width ``w``."""

    law: str
    w: float
    G: float | None = None
    mu: float | None = None

    def __post_init__(self):
        if self.law not in ("tresca", "coulomb"):
            raise ValueError(f"friction law {self.law!r}: must be 'tresca' or 'coulomb'")
        if not self.w > 0:
            raise ValueError(f"friction width w = {self.w!r}: must be > 0")
        if self.law == "tresca" and (self.G is None or self.G < 0):
            raise ValueError(f"Tresca threshold G = {self.G!r}: must be >= 0")
        if self.law == "coulomb" and (self.mu is None or self.mu < 0):
            raise ValueError(f"Coulomb coefficient mu = {self.mu!r}: must be >= 0")


@dataclass(frozen=True)
class CellLoad:
    """One load state of the cell, per mesh axis (the last axis is ``n0``).

    ``traction[i]`` is the prescribed mean traction on the counter's far face
    or ``None`` where ``jump[i]`` (far-face jump, rough minus counter) is
    prescribed instead; ``macro_strain`` holds the in-plane macro strain
    (2D ``(e_xx,)``, 3D ``(e_xx, e_yy, e_xy)``) or is empty.
    """

    traction: tuple
    jump: tuple
    macro_strain: tuple = ()


def cell_load(dim: int, *, pressure=None, normal_jump=None, shear=None,
              tangential_jump=None, macro_strain=None) -> CellLoad:
    """Build a :class:`CellLoad` from the quantities of the interface.

    Parameters
    ----------
    dim
        Spatial dimension of the cell (2 or 3).
    pressure
        Mean normal pressure transmitted across the layer (compression
        positive); give this or ``normal_jump``.
    normal_jump
        Prescribed normal jump of the far faces (positive closes the layer).
    shear
        Mean tangential traction on the counter's far face, one value per
        tangential axis (``None`` entries: the jump is prescribed); default 0.
    tangential_jump
        Prescribed tangential far-face jump per tangential axis, or ``None``.
    macro_strain
        In-plane macro strain, 2D ``(e_xx,)``, 3D ``(e_xx, e_yy, e_xy)``.
    """
    nt = dim - 1
    if (pressure is None) == (normal_jump is None):
        raise ValueError("give exactly one of pressure and normal_jump")
    shear = tuple(shear) if shear is not None else (None,) * nt
    tj = tuple(tangential_jump) if tangential_jump is not None else (None,) * nt
    if len(shear) != nt or len(tj) != nt:
        raise ValueError(f"shear and tangential_jump need {nt} entries in {dim}D")
    traction, jump = [], []
    for s, j in zip(shear, tj):
        if s is not None and j is not None:
            raise ValueError("a tangential component takes a shear or a jump, not both")
        traction.append(None if j is not None else float(s or 0.0))
        jump.append(None if j is None else float(j))
    traction.append(None if pressure is None else -float(pressure))
    jump.append(None if normal_jump is None else float(normal_jump))
    ms = tuple(float(v) for v in (macro_strain or ()))
    if ms and len(ms) != (1 if dim == 2 else 3):
        raise ValueError(f"macro_strain needs {1 if dim == 2 else 3} entries in {dim}D")
    return CellLoad(traction=tuple(traction), jump=tuple(jump), macro_strain=ms)


@dataclass(frozen=True)
class CellModel:
    """Physics of a cell problem (no mesh).

    Attributes
    ----------
    rough, counter
        Elastic laws of the two bodies.
    k_n
        Penalty stiffness [stress/length].
    gap
        Initial gap as a CoefficientFunction of the coordinates, or ``None``.
    friction
        :class:`Friction` or ``None`` (frictionless).
    order
        Polynomial order of the displacements.
    macro_strain
        Assemble the macro strain term.
    interpolate_gap
        Replace the gap by its interpolant of the displacement order on ``S_C``.
    contact_bonus_order
        Extra integration order on ``S_C`` (the penalty has a kink).
    coulomb_rtol, coulomb_max_iter
        Stopping rule of the Coulomb fixed point.
    """

    rough: _mat.ElasticLaw
    counter: _mat.ElasticLaw
    k_n: float
    gap: object = None
    friction: Friction | None = None
    order: int = 2
    macro_strain: bool = False
    interpolate_gap: bool = True
    contact_bonus_order: int = 12
    coulomb_rtol: float = 1e-8
    coulomb_max_iter: int = 40


@dataclass
class CellSolution:
    """Results of one load (plain numbers and arrays)."""

    load: CellLoad
    results: dict
    surface: dict
    newton: list = field(default_factory=list)
    coulomb_iterations: int = 0

    @property
    def iterations(self) -> int:
        return sum(h["iterations"] for h in self.newton)


# ------------------------------------------------------------------ model
def contact_normal(cell):
    """Unit micro normal on ``contact``, from ``rough`` into ``counter``.

    Delegates to :func:`ngcontact.homogenize.contact_normal` (sign fixed per
    boundary element by the side of its ``rough`` neighbour).
    """
    from ngcontact.cell.coefficients import contact_normal as _normal
    return _normal(cell)


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
        Newton settings (see :func:`ngcontact.newton.minimize`).
    normal
        Micro normal on ``contact``; default :func:`contact_normal`.
    line_search
        ``"exact"`` (default: energy minimized along the Newton direction)
        or ``"armijo"`` (backtracking only).
    start
        Start of the first load under a prescribed pressure: ``"rigid"``
        (default, the rigid predictor of the module docstring) or
        ``"closed"`` (every point of ``S_C`` pushed into contact).
    """

    def __init__(self, cell, model: CellModel, *, rtol: float = 1e-10, atol: float = 0.0,
                 max_iter: int = 40, inverse: str = "sparsecholesky", normal=None,
                 line_search: str = "exact", start: str = "rigid"):
        if line_search not in ("exact", "armijo"):
            raise ValueError(f"line_search = {line_search!r}: must be 'exact' or 'armijo'")
        if start not in ("rigid", "closed"):
            raise ValueError(f"start = {start!r}: must be 'rigid' or 'closed'")
        self.line_search, self.start = line_search, start
        self.cell, self.model = cell, model
        self.mesh = mesh = cell.mesh
        self.dim = dim = cell.dim
        self.setting = "3d" if dim == 3 else "plane_strain"
        self.rtol, self.atol, self.max_iter, self.inverse = rtol, atol, max_iter, inverse
        self.area = cell.area
        self.n = normal if normal is not None else contact_normal(cell)
        Vr = _el.body_space(mesh, "rough", model.order, dirichlet="bottom", periodic=True)
        Vc = _el.body_space(mesh, "counter", model.order, dirichlet="top", periodic=True)
        # U lives only where it enters (S_C and the far face): a NumberSpace on
        # every element would couple all dofs and slow the factorization 5x
        N = ng.NumberSpace(mesh, definedon=mesh.Boundaries("contact|top"))
        self.X = ng.FESpace([Vr, Vc] + [N] * dim)
        self.gap = self._discrete_gap()
        self.gfu = ng.GridFunction(self.X)
        self.u_dofs = [self.X.Range(2 + i).start for i in range(dim)]
        self.traction = [ng.Parameter(0.0) for _ in range(dim)]
        nE = 1 if dim == 2 else 3
        self.strain_params = [ng.Parameter(0.0) for _ in range(nE)]
        self.tangential_free = self._tangential_determinate()
        self._previous = None
        trial = self.X.TrialFunction()
        ur, uc, U = trial[0], trial[1], ng.CF(tuple(trial[2:]))
        self.form = self._energy(ur, uc, U, trial)
        # the state as CoefficientFunctions (for results and tests)
        comps = self.gfu.components
        self.U = ng.CF(tuple(comps[2:]))
        self.J = comps[0] - comps[1] - self.U
        self.pressure = _contact.pressure(self.J, self.n, model.k_n, self.gap)
        self.penetration = _contact.penetration(self.J, self.n, self.gap)
        self._active_points = None
        self.slip = _contact.tangential_slip(self.J, self.n)

    # -------------------------------------------------------------- energy
    def _discrete_gap(self):
        """The gap interpolated into polynomials of the displacement order on ``S_C``.

        The penetration ``J_n - g_h`` is then a polynomial on each boundary
        element, so its sign (the contact set) is not polluted by the
        interpolation error of a transcendental gap against polynomial
        displacements, which for a stiff penalty exceeds the penetration.
        """
        g = self.model.gap
        if g is None or not self.model.interpolate_gap:
            return g
        mesh = self.mesh
        Vg = ng.H1(mesh, order=self.model.order, definedon=mesh.Boundaries("contact"))
        gh = ng.GridFunction(Vg)
        gh.Set(g, definedon=mesh.Boundaries("contact"))
        return gh

    def _macro_strain_cf(self):
        e = self.strain_params
        if self.dim == 2:
            return ng.CF((e[0], 0, 0, 0, 0, 0, 0, 0, 0), dims=(3, 3))
        return ng.CF((e[0], e[2], 0, e[2], e[1], 0, 0, 0, 0), dims=(3, 3))

    def body_strain(self, u):
        """Total strain of a body: fluctuation plus the macro strain (if assembled)."""
        eps = _el.strain(u, self.setting)
        return eps + self._macro_strain_cf() if self.model.macro_strain else eps

    def _energy(self, ur, uc, U, trial):
        m, mesh = self.model, self.mesh
        # UMFPACK reads only one triangle of a symmetric-storage matrix: full storage for it
        form = ng.BilinearForm(self.X, symmetric=True,
                               symmetric_storage=self.inverse == "sparsecholesky")
        for name, law, u in (("rough", m.rough, ur), ("counter", m.counter, uc)):
            eps = self.body_strain(u)
            form += ng.Variation(0.5 * ng.InnerProduct(law.stress(eps), eps)
                                 * ng.dx(definedon=mesh.Materials(name)))
        J = ur - uc - U
        friction = threshold = w = None
        if m.friction is not None:
            friction, w = m.friction.law, m.friction.w
            if friction == "tresca":
                threshold = m.friction.G
            else:
                self._previous = ng.GridFunction(self.X)
                pc = self._previous.components
                J_prev = pc[0] - pc[1] - ng.CF(tuple(pc[2:]))
                threshold = _contact.coulomb_threshold(J_prev, self.n, m.k_n, m.friction.mu, self.gap)
        psi = _contact.interface_energy(J, self.n, k_n=m.k_n, gap=self.gap, friction=friction,
                                        w=w, threshold=threshold)
        form += ng.Variation(psi * ng.ds("contact", bonus_intorder=m.contact_bonus_order))
        t = ng.CF(tuple(self.traction))
        form += ng.Variation(-ng.InnerProduct(t, U) * ng.ds("top"))
        return form

    def _tangential_determinate(self) -> bool:
        """False when ``U_t`` costs no energy: frictionless and a flat ``S_C``."""
        if self.model.friction is not None:
            return True
        mesh, n, d = self.mesh, self.n, self.dim
        nt2 = ng.InnerProduct(n, n) - n[d - 1] * n[d - 1]
        tilt = ng.Integrate(nt2, mesh, definedon=mesh.Boundaries("contact"), order=2 * self.model.order + 2)
        size = ng.Integrate(ng.CF(1.0), mesh, definedon=mesh.Boundaries("contact"))
        return tilt > 1e-12 * size

    @property
    def ndof(self) -> int:
        return self.X.ndof

    # --------------------------------------------------------------- solve
    def _freedofs(self, load: CellLoad):
        free = ng.BitArray(self.X.FreeDofs())
        for i, d in enumerate(self.u_dofs):
            if load.jump[i] is not None or (i < self.dim - 1 and not self.tangential_free):
                free.Clear(d)
        return free

    def _apply_load(self, load: CellLoad, first: bool):
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
            if load.jump[i] is not None:
                vec[self.u_dofs[i]] = -load.jump[i]
            elif i < d - 1 and not self.tangential_free:
                vec[self.u_dofs[i]] = 0.0
        if first and load.jump[d - 1] is None:
            p = -load.traction[d - 1]
            if not p > 0:
                raise ValueError(f"normal pressure {p!r}: must be > 0 (a free layer has no unique "
                                 "rigid position); prescribe a normal jump instead")
            if self.start == "closed":
                vec[self.u_dofs[d - 1]] = -(self.max_gap() + p / self.model.k_n)
            else:
                vec[:] = 0.0
                for i in range(d):
                    if load.jump[i] is not None:
                        vec[self.u_dofs[i]] = -load.jump[i]
                vec[self.u_dofs[d - 1]] = -self.rigid_approach(p)

    def _contact_order(self) -> int:
        """Integration order of the contact energy (that of the ``Variation`` term)."""
        return 2 * self.model.order + self.model.contact_bonus_order

    def rigid_approach(self, p: float) -> float:
        """Normal approach ``d`` of the rigid predictor: root of ``R(d)`` (module docstring).

        ``R`` is nondecreasing and piecewise linear in ``d`` at the
        quadrature points of the contact energy; the root is bracketed by
        doubling and found by the Illinois variant of regula falsi.  The
        predicted state has at least one quadrature point in contact, so
        the first tangent is regular in ``U_n``.
        """
        k_n, area = self.model.k_n, self.area
        n0 = self.n[self.dim - 1]
        dpar = ng.Parameter(0.0)
        pen = dpar * n0 if self.gap is None else dpar * n0 - self.gap
        force = k_n * _contact.positive_part(pen) * n0
        order = self._contact_order()

        def R(dv):
            dpar.Set(dv)
            return float(self._contact_integral(force, order=order)) - p * area

        lo, flo = 0.0, R(0.0)
        scale = self.max_gap() + p / k_n
        if flo >= 0.0:            # interference: already pressed at d = 0
            hi, fhi = lo, flo
            lo = -scale
            while (flo := R(lo)) >= 0.0:
                lo *= 2.0
        else:
            hi = scale
            while (fhi := R(hi)) <= 0.0:
                lo, flo, hi = hi, fhi, 2.0 * hi
        d = illinois_root(R, lo, flo, hi, fhi, ftol=1e-12 * p * area, xtol=1e-14 * abs(hi),
                          max_iter=200)
        log.debug("rigid predictor: approach %.6e for pressure %.6e", d, p)
        return d

    def max_gap(self) -> float:
        """Largest initial gap at the quadrature points of ``S_C`` (0 without gap)."""
        if self.gap is None:
            return 0.0
        vals = self.sample_surface({"g": self.gap})["g"]
        return float(max(vals.max(), 0.0))

    def solve(self, load: CellLoad, first: bool = False, measure: bool = True) -> CellSolution:
        """Solve one load, starting from the current state (continuation).

        With ``measure=False`` only ``contact_fraction`` and
        ``mean_pressure`` are evaluated (no stresses, coefficients or
        stiffness Schur complements) and ``surface`` is empty: for timing
        studies of the solve itself.
        """
        self._apply_load(load, first)
        free = self._freedofs(load)
        histories = []
        fp = 0
        if self.model.friction is not None and self.model.friction.law == "coulomb":
            p_old = self.sample_surface({"p": self.pressure})["p"]
            atol = self.atol
            for fp in range(1, self.model.coulomb_max_iter + 1):
                self._previous.vec.data = self.gfu.vec
                h = self._newton(free, atol)
                histories.append(h)
                if fp == 1:
                    atol = max(self.atol, self.rtol * h["residuals"][0])
                p_new = self.sample_surface({"p": self.pressure})["p"]
                change = float(np.max(np.abs(p_new - p_old))) if p_new.size else 0.0
                scale = float(np.max(np.abs(p_new))) if p_new.size else 0.0
                log.info("coulomb fixed point %d: max |dp| = %.3e (max p %.3e)", fp, change, scale)
                if change <= self.model.coulomb_rtol * max(scale, 1e-300):
                    break
                p_old = p_new
            else:
                raise ConvergenceError(
                    f"Coulomb fixed point did not converge in {self.model.coulomb_max_iter} "
                    f"iterations: max pressure change {change:.3e} > "
                    f"{self.model.coulomb_rtol:g} x max pressure {scale:.3e}",
                    {"newton": histories})
        else:
            histories.append(self._newton(free, self.atol))
        if measure:
            results = self.measure(load)
            surface = self.surface_distribution()
        else:
            results = {"contact_fraction": self.contact_fraction(),
                       "mean_pressure": float(self._contact_integral(self.pressure)) / self.area}
            surface = {}
        return CellSolution(load=load, results=results, surface=surface, newton=histories,
                            coulomb_iterations=fp)

    def _newton(self, free, atol) -> dict:
        h = minimize(self.form, self.gfu, freedofs=free, rtol=self.rtol, atol=atol,
                     max_iter=self.max_iter, inverse=self.inverse, line_search=self.line_search,
                     active_set=self.active_set)
        return h.as_dict()

    def active_set(self, gfu=None) -> bytes:
        """Signature of the contact state: which quadrature points of ``S_C`` penetrate."""
        if self._active_points is None:
            shape = ng.TRIG if self.dim == 3 else ng.SEGM
            rule = ng.IntegrationRule(shape, 2 * self.model.order)
            self._active_points = self.mesh.MapToAllElements(rule, self.mesh.Boundaries("contact"))
        pen = np.asarray(self.penetration(self._active_points)).ravel()
        return np.packbits(pen > 0.0).tobytes()

    def sweep(self, loads) -> list:
        """Solve a list of loads in order, each from the previous solution."""
        self.gfu.vec[:] = 0.0
        out = []
        for k, load in enumerate(loads):
            sol = self.solve(load, first=(k == 0))
            log.info("load %d: %d Newton steps, contact fraction %.6f", k, sol.iterations,
                     sol.results["contact_fraction"])
            out.append(sol)
        return out

    # ------------------------------------------------------------- results
    def _contact_integral(self, cf, order=None):
        o = order if order is not None else 4 * self.model.order + 24
        return ng.Integrate(cf, self.mesh, definedon=self.mesh.Boundaries("contact"), order=o)

    def contact_fraction(self, method: str = "auto") -> float:
        """Measure of the real contact set ``{J_n - g >= 0}`` on ``S_C`` divided by ``|T|``.

        Parameters
        ----------
        method
            ``"roots"`` (2D): on each boundary element the penetration
            ``J_n - g_h`` is a polynomial of the reference coordinate ``t``
            (degree ``order`` on straight elements with the interpolated
            gap); it is interpolated at ``order + 3`` Gauss points, its real
            roots in ``[0, 1]`` split the element, and the length
            ``int |dx/dt| dt`` of the pieces where it is nonnegative is
            summed.  The contact edge is thus located inside the element
            instead of at the nearest quadrature point.
            ``"quadrature"``: integral of the indicator at high order (3D,
            where the zero set is a curve on each face).  ``"auto"``: roots
            in 2D, quadrature in 3D.
        """
        if method == "auto":
            method = "roots" if self.dim == 2 else "quadrature"
        if method == "quadrature":
            ind = ng.IfPos(-self.penetration, 0.0, 1.0)
            return float(self._contact_integral(ind)) / self.area
        if method != "roots" or self.dim != 2:
            raise ValueError(f"method = {method!r}: must be 'auto', 'quadrature' or (2D) 'roots'")
        return self._contact_length_by_roots() / self.area

    def _contact_length_by_roots(self) -> float:
        P = np.polynomial.polynomial
        m = self.model.order + 3
        ir = ng.IntegrationRule(ng.SEGM, 2 * m - 1)
        t = np.array([q[0] for q in ir.points])
        mesh = self.mesh
        pts = mesh.MapToAllElements(ir, mesh.Boundaries("contact"))
        vals = np.asarray(ng.CF((self.penetration, ng.x, ng.y))(pts)).reshape(-1, m, 3)
        # monomial coefficients in t of penetration, x and y, per element
        coef = np.linalg.solve(P.polyvander(t, m - 1), vals.transpose(1, 0, 2).reshape(m, -1))
        coef = coef.reshape(m, -1, 3)
        tg, wg = np.polynomial.legendre.leggauss(m + 2)
        total = 0.0
        for e in range(vals.shape[0]):
            c_pen, c_x, c_y = coef[:, e, 0], coef[:, e, 1], coef[:, e, 2]
            pen = vals[e, :, 0]
            if np.all(pen > 0) or np.all(pen < 0):
                r = P.polyroots(c_pen) if np.any(c_pen[1:]) else np.empty(0)
                r = r[np.abs(r.imag) <= 1e-10].real
                if not np.any((r > 0.0) & (r < 1.0)):
                    if pen[0] > 0:
                        total += self._arc(c_x, c_y, 0.0, 1.0, tg, wg)
                    continue
            r = P.polyroots(c_pen) if np.any(c_pen[1:]) else np.empty(0)
            r = np.sort(r[(np.abs(r.imag) <= 1e-10) & (r.real > 0.0) & (r.real < 1.0)].real)
            cuts = np.concatenate(([0.0], r, [1.0]))
            for a, b in zip(cuts[:-1], cuts[1:]):
                if b > a and P.polyval(0.5 * (a + b), c_pen) >= 0.0:
                    total += self._arc(c_x, c_y, a, b, tg, wg)
        return total

    @staticmethod
    def _arc(c_x, c_y, a, b, tg, wg) -> float:
        """Length of the curve ``(x(t), y(t))`` (monomial coefficients) for ``t`` in ``[a, b]``."""
        P = np.polynomial.polynomial
        s = 0.5 * (b - a) * tg + 0.5 * (a + b)
        dx, dy = P.polyval(s, P.polyder(c_x)), P.polyval(s, P.polyder(c_y))
        return float(0.5 * (b - a) * np.sum(wg * np.hypot(dx, dy)))

    def mean_traction(self, load: CellLoad) -> np.ndarray:
        """Mean traction on the counter's far face per axis (prescribed or reaction)."""
        res = self.gfu.vec.CreateVector()
        self.form.Apply(self.gfu.vec, res)
        out = np.empty(self.dim)
        for i, d in enumerate(self.u_dofs):
            if load.traction[i] is not None and (i == self.dim - 1 or self.tangential_free):
                out[i] = load.traction[i]
            else:  # the load term of a controlled component is zero: residual = reaction
                out[i] = res[d] / self.area
        return out

    def mean_jump(self) -> np.ndarray:
        """Projected mean of the jump on ``S_C``: ``(1/|T|) int J |n.n0| ds``."""
        w = ng.IfPos(self.n[self.dim - 1], self.n[self.dim - 1], -self.n[self.dim - 1])
        return np.array(self._contact_integral(self.J * w, order=2 * self.model.order + 4)) / self.area

    def measure(self, load: CellLoad) -> dict:
        """Scalar results of the current state (see module docstring)."""
        d = self.dim
        t = self.mean_traction(load)
        jbar = self.mean_jump()
        Uv = np.array([self.gfu.vec[k] for k in self.u_dofs])
        res = {
            "contact_fraction": self.contact_fraction(),
            "mean_pressure": float(self._contact_integral(self.pressure)) / self.area,
            "mean_traction": t.tolist(),
            "transmitted_pressure": float(-t[d - 1]),
            "mean_jump": jbar.tolist(),
            "mean_closure": float(jbar[d - 1]),
            "far_face_jump": (-Uv).tolist(),
            "max_penetration": float(self.sample_surface({"pen": self.penetration})["pen"].max()),
        }
        res.update(self.stress_maxima())
        res["effective_stiffness"] = self.effective_stiffness()
        res["coefficients"] = self.real_contact_coefficients()
        return res

    def friction_threshold(self):
        """``G`` on ``S_C`` of the current state (``mu p`` for Coulomb), or ``None``."""
        f = self.model.friction
        if f is None:
            return None
        return f.G if f.law == "tresca" else f.mu * self.pressure

    def real_contact_coefficients(self) -> dict:
        """Paper eqs. 34, 42-43 on the real contact set ``{J_n - g >= 0}`` of the current state."""
        from ngcontact.cell.coefficients import coefficients
        ind = ng.IfPos(-self.penetration, 0.0, 1.0)
        c = coefficients(self.cell, kn=self.model.k_n, gap=self.gap, G=self.friction_threshold(),
                         weight=ind, normal=self.n, intorder=4 * self.model.order + 24)
        return c.as_dict()

    def sample_surface(self, fields: dict, order: int | None = None) -> dict:
        """Values of CoefficientFunctions at the quadrature points of ``S_C``.

        Evaluated on the boundary elements of ``contact`` themselves, so the
        traces of each body are unambiguous.  Returns arrays, with the
        coordinates under ``"x"``, ``"y"`` (and ``"z"``).
        """
        mesh = self.mesh
        o = order if order is not None else 2 * self.model.order + 2
        S = ng.comp.IntegrationRuleSpaceSurface(mesh, order=o, definedon=mesh.Boundaries("contact"))
        names = ["x", "y", "z"][: self.dim] + list(fields)
        cfs = [ng.x, ng.y, ng.z][: self.dim] + [fields[k] for k in fields]
        flat = []
        for cf in cfs:
            flat.extend(cf[i] for i in range(cf.dim)) if cf.dim > 1 else flat.append(cf)
        gf = ng.GridFunction(S ** len(flat)) if len(flat) > 1 else ng.GridFunction(S)
        gf.Set(ng.CF(tuple(flat)) if len(flat) > 1 else flat[0], definedon=mesh.Boundaries("contact"))
        arr = gf.vec.FV().NumPy().reshape(len(flat), -1)
        out, k = {}, 0
        for name, cf in zip(names, cfs):
            out[name] = arr[k:k + cf.dim].copy() if cf.dim > 1 else arr[k].copy()
            k += cf.dim
        return out

    def surface_distribution(self) -> dict:
        """Pressure and slip at the quadrature points of ``S_C`` (2D: sorted by ``x``)."""
        s = self.sample_surface({"pressure": self.pressure,
                                 "slip": _contact.slip_magnitude(self.J, self.n),
                                 "closure": _contact.normal_closure(self.J, self.n)})
        if self.dim == 2:
            idx = np.argsort(s["x"], kind="stable")
            s = {k: v[..., idx] for k, v in s.items()}
        return s

    def body_stresses(self) -> dict:
        """Stress tensors of the current state at the element integration points of each body.

        Returns ``{body: {"stress": (n, 3, 3), "points": (n, dim)}}``.  The
        points are those of the order-``2p`` rule mapped to every element of
        the body, so none lies on the interface (where point evaluation could
        pick the other body's element).
        """
        out = {}
        mesh, m = self.mesh, self.model
        comps = self.gfu.components
        shape = ng.TET if self.dim == 3 else ng.TRIG
        rule = ng.IntegrationRule(shape, 2 * max(m.order, 1))
        for name, law, u in (("rough", m.rough, comps[0]), ("counter", m.counter, comps[1])):
            sig = law.stress(self.body_strain(u))
            coords = (ng.x, ng.y, ng.z)[: self.dim]
            cf = ng.CF(tuple(sig[i, j] for i in range(3) for j in range(3)) + coords)
            vals = np.asarray(cf(mesh.MapToAllElements(rule, mesh.Materials(name))))
            out[name] = {"stress": vals[:, :9].reshape(-1, 3, 3).copy(), "points": vals[:, 9:].copy()}
        return out

    def stress_maxima(self) -> dict:
        """Largest von Mises and Tresca stress in each body and where (element points)."""
        out = {}
        for name, sample in self.body_stresses().items():
            S, X = sample["stress"], sample["points"]
            vm = _mat.von_mises(S)
            tr = _mat.tresca(S)
            i, j = int(np.argmax(vm)), int(np.argmax(tr))
            out[f"max_von_mises_{name}"] = {"value": float(vm[i]), "location": X[i].tolist()}
            out[f"max_tresca_{name}"] = {"value": float(tr[j]), "location": X[j].tolist()}
        return out

    # --------------------------------------------------- effective stiffness
    def _schur_on_U(self, form, X, u_dofs, state_vec):
        """Schur complement of the tangent of ``form`` on the dofs ``u_dofs``."""
        form.AssembleLinearization(state_vec)
        K = form.mat
        free = ng.BitArray(X.FreeDofs())
        for d in u_dofs:
            free.Clear(d)
        inv = K.Inverse(free, inverse=self.inverse)
        n = len(u_dofs)
        S = np.zeros((n, n))
        e, y, x, z = (state_vec.CreateVector() for _ in range(4))
        for j, dj in enumerate(u_dofs):
            e[:] = 0.0
            e[dj] = 1.0
            y.data = K * e
            x.data = inv * y
            z.data = K * x
            for i, di in enumerate(u_dofs):
                S[i, j] = y[di] - z[di]
        return 0.5 * (S + S.T)

    def reference_stiffness(self) -> np.ndarray:
        """``S_0``: far-face stiffness of the flat bonded laminate of the same thickness.

        Both bodies, each with its own law, stacked flat with the interface in
        the summit plane (``rough`` below it over ``h_rough``, ``counter``
        above over ``h_counter``) and bonded.  Under a mean traction each
        layer is in a uniform state ``eps = sym(a (x) n0)`` with
        ``t = A a``, ``A_ik = C_ijkl n0_j n0_l`` (the acoustic tensor), so
        the far-face jump is ``sum_L h_L A_L^-1 t`` and

            S_0 = (h_rough A_rough^-1 + h_counter A_counter^-1)^-1,

        in the components ``(t0[, t1], n0)`` (per ``|T|``).
        """
        d = self.dim
        idx = list(range(d))  # mesh axes; n0 is the last one
        C = 0.0
        for law, h in ((self.model.rough, self.cell.h_rough), (self.model.counter, self.cell.h_counter)):
            A = _acoustic_tensor(law, normal_axis=d - 1)[np.ix_(idx, idx)]
            C = C + h * np.linalg.inv(A)
        return np.linalg.inv(C)

    def tangent_stiffness(self) -> np.ndarray:
        """``S``: tangent of the mean far-face traction w.r.t. the far-face jump (per ``|T|``)."""
        return self._schur_on_U(self.form, self.X, self.u_dofs, self.gfu.vec) / self.area

    def effective_stiffness(self) -> dict:
        """Interface stiffness with asperity compliance: ``(S^-1 - S_0^-1)^-1``.

        ``S`` is the tangent far-face stiffness of the cell, ``S_0`` that of
        the flat bonded laminate (:meth:`reference_stiffness`); their
        compliance difference is the interface's share: penalty layer plus
        the compliance of the asperities (constriction), which stays finite
        as ``k_n -> infinity`` (DESIGN Sec. 3).  Restricted to the components
        that are determinate (all but the tangential ones of a frictionless
        flat interface).  ``matrix`` is ``None`` when the interface
        compliance is singular (e.g. a component the interface does not
        resist beyond the bulk).  An open interface transmits nothing
        (``S`` singular): its stiffness is the limit
        ``S (I - S_0^-1 S)^-1 = 0`` and ``compliance`` is ``None``.
        """
        keep = [i for i in range(self.dim) if i == self.dim - 1 or self.tangential_free]
        names = (["t0"] if self.dim == 2 else ["t1", "t2"]) + ["n0"]
        S = self.tangent_stiffness()[np.ix_(keep, keep)]
        S0 = self.reference_stiffness()[np.ix_(keep, keep)]
        if np.linalg.cond(S) > 1e12 * np.linalg.cond(S0):  # (partly) open: S^-1 does not exist
            compliance = None
            A = np.eye(len(keep)) - np.linalg.solve(S0, S)
            K = None if np.linalg.cond(A) > 1e12 else S @ np.linalg.inv(A)
        else:
            compliance = np.linalg.inv(S) - np.linalg.inv(S0)
            compliance = 0.5 * (compliance + compliance.T)
            K = None if np.linalg.cond(compliance) > 1e12 else np.linalg.inv(compliance)
        if K is not None:
            K = (0.5 * (K + K.T)).tolist()
        return {"components": [names[i] for i in keep], "matrix": K,
                "compliance": None if compliance is None else compliance.tolist(),
                "total": S.tolist(), "reference": S0.tolist()}


def _acoustic_tensor(law, normal_axis: int) -> np.ndarray:
    """``A_ik = C_ijkl n_j n_l`` for ``n = e_normal_axis`` (3x3, from the Voigt matrix)."""
    C = law.matrix
    voigt = {}
    for k, (i, j) in enumerate(_mat.VOIGT_PAIRS):
        voigt[i, j] = voigt[j, i] = k
    m = normal_axis
    return np.array([[C[voigt[i, m], voigt[k, m]] for k in range(3)] for i in range(3)])


def solve_cell(cell, model: CellModel, loads, **newton) -> list:
    """Build the cell problem and solve the sweep ``loads``; see :class:`CellProblem`."""
    return CellProblem(cell, model, **newton).sweep(loads)

