"""Micro stresses in the interface layer and the strength check (paper eqs. 74-78).

Linear recovery (paper eqs. 72-75).  With the real contact set ``S_act`` of
the cell held fixed, the cell problem of :mod:`ngcontact.cell.fe.cell_problem` becomes
quadratic: the penalty acts on ``S_act`` in both directions,

    Pi_lin(u) = sum_B int_B 1/2 (eps(u_B) + E) : C_B : (eps(u_B) + E) dx
                + int_{S_act} k_n/2 (J.n - g)^2 + k_t/2 |J_t|^2 ds - |T| tbar . U,

(``k_t`` a tangential stiffness on ``S_act``: 0 for frictionless contact,
else the stick stiffness that lets the summits carry shear).  Its solution is
affine in the load vector ``l = (tau_1[, tau_2], p, E_1, ...)`` made of the
mean shear on the counter's far face, the mean pressure ``p = -tbar_n``
(compression positive) and the in-plane macro strain components, so the
micro stress is the superposition

    sigma(xi; l) = sigma_g(xi) + sum_k l_k Sigma_k(xi),                  (75)

``sigma_g`` the stress of the gap alone (zero load) and ``Sigma_k`` the
stress of the unit-load correctors: unit tractions play the part of the
paper's unit macro jumps ``Theta_p`` (a traction and a jump determine each
other through the fixed-contact-set stiffness) and unit strains that of
``N_pq``.  One factorization serves every corrector.

Nonlinear recovery: the contact cell problem itself
(:class:`ngcontact.cell.fe.cell_problem.CellProblem`) solved at the macro state.

Strength (eqs. 76-78): the equivalent stress ``sigma_eq`` (von Mises
``sqrt(3/2 s:s)`` or Tresca ``max |sigma_k - sigma_l|``, eq. 77,
:mod:`ngcontact.fem.materials`) is maximized over the cell (``xi``) and over the
macro interface points (``x``); each body is checked against its own
ultimate stress ``sigma_u`` and the safety factor is
``min_B sigma_u,B / max sigma_eq,B`` (eq. 78 holds when it exceeds 1).

Macro state at an interface point (:mod:`ngcontact.coupling.interface_state`):
the local traction of the homogenized law (compression positive) and the
strain of the layer tangential to ``S_0``, the mean of the two bodies'
strains next to the point, put on the cell's axes.  2D and axisymmetric
macro problems: the cell's axes are ``(t0, n0)`` (2D cell) or ``(t0, hoop,
n0)`` (3D cell), loads ``shear_x = -tau``, ``p``, ``E_xx = e_t0t0`` and for
a 3D cell ``E_yy = e_hoop``, ``E_xy = 0``.  3D macro problems: a 3D cell
with axes ``(t1, t2, n0)`` of the law's frame, loads ``shear_x = -tau_1``,
``shear_y = -tau_2``, ``p``, ``E_xx = e_t1t1``, ``E_yy = e_t2t2``,
``E_xy = e_t1t2``.
"""
from __future__ import annotations

import logging
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import ngsolve as ng
import numpy as np

from ngcontact.cell.cell_load import cell_load
from ngcontact.cell.fe.measures import body_stresses
from ngcontact.fem import materials as _mat
from ngcontact.laws import penalty as _contact
from ngcontact.errors import ModelError

if TYPE_CHECKING:
    from ngcontact.cell.cell_solution import CellSolution
    from ngcontact.cell.fe.cell_problem import CellProblem

log = logging.getLogger(__name__)

#: a load vector ``l`` (:func:`load_names`)
LoadVector = Sequence[float] | np.ndarray
#: ``{body: {"points": (n, dim), "stress": (n, 3, 3)}}``
BodySamples = dict[str, dict[str, np.ndarray]]

CRITERIA = ("von_mises", "tresca")
BODIES = ("rough", "counter")


# ------------------------------------------------------------ load vectors
def load_names(dim: int) -> tuple[str, ...]:
    """Names of the load components ``l_k`` of a ``dim``-D cell (see module docstring)."""
    if dim == 2:
        return ("shear_x", "pressure", "E_xx")
    return ("shear_x", "shear_y", "pressure", "E_xx", "E_yy", "E_xy")


def apply_load_vector(problem: CellProblem, l: LoadVector) -> None:
    """Put the load vector ``l`` (:func:`load_names`) into the traction and strain parameters of ``problem``.

    Only the parameters of the energy are set; the state ``problem.gfu`` is
    left as it is (see :meth:`Correctors.state`).
    """
    d = problem.dim
    for i in range(d - 1):
        problem.traction[i].Set(float(l[i]))
    problem.traction[d - 1].Set(-float(l[d - 1]))
    for k, par in enumerate(problem.strain_params):
        par.Set(float(l[d + k]))


def sample_stresses(problem: CellProblem) -> BodySamples:
    """Stress tensors of the current state of ``problem`` per body at element points.

    Returns ``{body: {"points": (n, dim), "stress": (n, 3, 3)}}``
    (:func:`ngcontact.cell.fe.measures.body_stresses`).
    """
    return body_stresses(problem)


# ------------------------------------------------------------ correctors
@dataclass
class Correctors:
    """Stress of the gap state and of the unit-load correctors, per body.

    Attributes
    ----------
    names
        Load component names (:func:`load_names`).
    points
        ``{body: (n, dim)}`` sample points.
    base
        ``{body: (n, 3, 3)}`` stress at zero load (the gap alone).
    unit
        ``{body: (K, n, 3, 3)}`` stress of the unit load ``k``.
    states
        Displacement vectors: the gap state, then the unit-load correctors
        (differences to the gap state).
    """

    names: tuple[str, ...]
    points: dict[str, np.ndarray]
    base: dict[str, np.ndarray]
    unit: dict[str, np.ndarray]
    states: list[ng.BaseVector] | None = None

    def state(self, load: LoadVector) -> ng.BaseVector:
        """Displacement vector of the superposed state (``states[0]`` the gap state)."""
        # set: linear_correctors, the only constructor of Correctors, always passes its states
        assert self.states is not None
        v = self.states[0].CreateVector()
        v.data = self.states[0]
        for lk, sk in zip(np.asarray(load, float), self.states[1:]):
            if lk != 0.0:
                v.data += float(lk) * sk
        return v

    def stress(self, load: LoadVector) -> dict[str, np.ndarray]:
        """Superposed stress ``sigma_g + sum_k l_k Sigma_k`` (eq. 75) per body."""
        l = np.asarray(load, float)
        return {b: self.base[b] + np.einsum("k,knij->nij", l, self.unit[b]) for b in self.base}


def linear_correctors(problem: CellProblem, *, contact_set: ng.CoefficientFunction | None = None,
                      tangential_stiffness: float = 0.0) -> Correctors:
    """Unit-load correctors of the cell with a fixed contact set (module docstring): the states of
    :func:`corrector_states` sampled by :func:`sampled_correctors`.

    Parameters
    ----------
    problem
        A :class:`ngcontact.cell.fe.cell_problem.CellProblem` built with ``macro_strain=True``
        (its spaces, normal, gap and parameters are reused; its state is
        overwritten).
    contact_set
        Indicator (CoefficientFunction, 1 in contact) of ``S_act`` on ``S_C``;
        default the whole contact surface.
    tangential_stiffness
        ``k_t`` on ``S_act`` [stress/length]; 0 leaves the tangential jump
        free (a flat frictionless surface then carries no shear).

    Raises
    ------
    ModelError
        The cell problem lacks the macro strain term.
    """
    states = corrector_states(problem, contact_set=contact_set, tangential_stiffness=tangential_stiffness)
    return sampled_correctors(problem, states, tangential_stiffness=tangential_stiffness)


def _carries_shear(problem: CellProblem, tangential_stiffness: float) -> bool:
    """Whether the fixed-set cell carries a mean shear: a stick stiffness ``k_t > 0`` or a free tangential jump
    (else a unit shear gets a zero corrector)."""
    return tangential_stiffness > 0 or problem.tangential_free


def corrector_states(problem: CellProblem, *, contact_set: ng.CoefficientFunction | None = None,
                     tangential_stiffness: float = 0.0) -> np.ndarray:
    """``(K + 1, ndof)``: the displacement of the fixed-set cell (:func:`linear_correctors`) at the zero load
    (the gap alone), then at each unit load ``e_k`` (:func:`load_names`), whole states, not differences; a
    unit shear the cell does not carry (:func:`_carries_shear`) repeats the zero load's row.  One
    factorization serves every row."""
    m = problem.model
    if not m.macro_strain:
        raise ModelError("linear correctors need a cell problem built with macro_strain = True")
    X, d = problem.X, problem.dim
    form = _fixed_set_form(problem, contact_set, tangential_stiffness)
    free = ng.BitArray(X.FreeDofs())
    carried = _carries_shear(problem, tangential_stiffness)
    if not carried:
        for i in range(d - 1):
            free.Clear(problem.u_dofs[i])
    K = len(load_names(d))
    zero = problem.gfu.vec.CreateVector()
    zero[:] = 0.0
    apply_load_vector(problem, np.zeros(K))
    form.AssembleLinearization(zero)
    inv = form.mat.Inverse(free, inverse=problem.inverse)
    res = zero.CreateVector()
    rows = np.zeros((K + 1, len(zero)))
    for k in range(-1, K):
        if not carried and 0 <= k < d - 1:
            rows[k + 1] = rows[0]
            continue
        apply_load_vector(problem, np.eye(K)[k] if k >= 0 else np.zeros(K))
        form.Apply(zero, res)
        problem.gfu.vec.data = -(inv * res)
        rows[k + 1] = problem.gfu.vec.FV().NumPy()
    apply_load_vector(problem, np.zeros(K))
    log.info("linear correctors: %d unit loads, one factorization", K)
    return rows


def sampled_correctors(problem: CellProblem, states: np.ndarray, *, tangential_stiffness: float = 0.0
                       ) -> Correctors:
    """The :class:`Correctors` of the rows of :func:`corrector_states` on ``problem``: the stresses at the
    element points (:func:`sample_stresses`) of the zero load and the differences the unit loads add (eq. 75),
    zero for a shear the cell does not carry.  The state of ``problem`` is overwritten.

    Raises
    ------
    ValueError
        ``states`` is not ``(K + 1, ndof)`` for this problem.
    """
    d, K = problem.dim, len(load_names(problem.dim))
    states = np.asarray(states, float)
    if states.shape != (K + 1, problem.ndof):
        raise ValueError(f"corrector states of shape {states.shape}, the cell needs {(K + 1, problem.ndof)}")
    carried = _carries_shear(problem, tangential_stiffness)

    def vector(row: np.ndarray) -> ng.BaseVector:
        v = problem.gfu.vec.CreateVector()
        v.FV().NumPy()[:] = row
        return v

    def sampled(l: np.ndarray, row: np.ndarray) -> BodySamples:
        apply_load_vector(problem, l)
        problem.gfu.vec.FV().NumPy()[:] = row
        return sample_stresses(problem)

    base = sampled(np.zeros(K), states[0])
    vectors = [vector(states[0])]
    unit: dict[str, list[np.ndarray]] = {b: [] for b in BODIES}
    for k in range(K):
        if not carried and k < d - 1:
            for b in BODIES:  # a free tangential jump carries no shear: zero corrector
                unit[b].append(np.zeros_like(base[b]["stress"]))
            vectors.append(vector(np.zeros(problem.ndof)))
            continue
        s = sampled(np.eye(K)[k], states[k + 1])
        vectors.append(vector(states[k + 1] - states[0]))
        for b in BODIES:
            unit[b].append(s[b]["stress"] - base[b]["stress"])
    apply_load_vector(problem, np.zeros(K))
    return Correctors(names=load_names(d), points={b: base[b]["points"] for b in BODIES},
                      base={b: base[b]["stress"] for b in BODIES},
                      unit={b: np.array(unit[b]) for b in BODIES}, states=vectors)


def _fixed_set_form(problem: CellProblem, contact_set, tangential_stiffness: float) -> ng.BilinearForm:
    """The quadratic energy of the cell with a fixed contact set: the bodies (with the macro strain), the
    penalty ``k_n/2 chi [J.n - g]^2`` and ``k_t/2 chi |J_t|^2`` on ``S_C``, the far-face load potential."""
    m, mesh = problem.model, problem.mesh
    trial = problem.X.TrialFunction()
    ur, uc, U = trial[0], trial[1], ng.CF(tuple(trial[2:]))
    form = ng.BilinearForm(problem.X, symmetric=True)
    for name, law, u in (("rough", m.rough, ur), ("counter", m.counter, uc)):
        eps = problem.body_strain(u)
        form += ng.Variation(0.5 * ng.InnerProduct(law.stress(eps), eps) * ng.dx(definedon=mesh.Materials(name)))
    J = ur - uc - U
    chi = ng.CF(1.0) if contact_set is None else contact_set
    pen = _contact.penetration(J, problem.n, problem.gap)
    psi = 0.5 * m.k_n * chi * pen * pen
    if tangential_stiffness > 0:
        Jt = _contact.tangential_slip(J, problem.n)
        psi = psi + 0.5 * tangential_stiffness * chi * ng.InnerProduct(Jt, Jt)
    form += ng.Variation(psi * ng.ds("contact", bonus_intorder=m.contact_bonus_order))
    form += ng.Variation(-ng.InnerProduct(ng.CF(tuple(problem.traction)), U) * ng.ds("top"))
    return form


def nonlinear_stress(problem: CellProblem, load_vector: LoadVector) -> tuple[BodySamples, CellSolution]:
    """The contact cell problem solved at the load vector (rigid-predictor start).

    Returns the sampled stresses per body (:func:`sample_stresses`) and the
    :class:`ngcontact.cell.cell_solution.CellSolution`.  A flat frictionless cell carries
    no shear: its shear components must be 0.
    """
    d = problem.dim
    l = np.asarray(load_vector, float)
    shear = tuple(float(v) for v in l[:d - 1])
    ms = tuple(float(v) for v in l[d:]) if problem.model.macro_strain else None
    sol = problem.solve(cell_load(d, pressure=float(l[d - 1]), shear=shear, macro_strain=ms),
                        first=True, measure=False)
    return sample_stresses(problem), sol


# ------------------------------------------------------------ criteria
def equivalent(stress: np.ndarray, criterion: str) -> np.ndarray:
    """``sigma_eq`` of eq. 77 for an array of 3x3 tensors."""
    if criterion == "von_mises":
        return _mat.von_mises(stress)
    if criterion == "tresca":
        return _mat.tresca(stress)
    raise ModelError(f"criterion = {criterion!r}: must be one of {', '.join(CRITERIA)}")


@dataclass
class StrengthMap:
    """Largest ``sigma_eq`` over the cell at each macro point, per body.

    ``values[body]`` has one entry per macro point, ``cell_point[body]`` the
    cell point (cell coordinates) where it is reached.
    """

    criterion: str
    values: dict[str, np.ndarray]
    cell_point: dict[str, np.ndarray]


#: stress entries superposed at once by :func:`strength_map` (macro points x cell points x 9): 16 MB
CHUNK_ENTRIES = 2_000_000


def strength_map(correctors: Correctors, loads: np.ndarray, criterion: str = "von_mises") -> StrengthMap:
    """Superpose the correctors at every row of ``loads`` (eq. 75) and take the cell maxima of eq. 77.

    The superposition of a block of rows is one matrix product ``loads @ unit``
    (the unit stresses flattened), the blocks sized to ``CHUNK_ENTRIES``.  Von
    Mises needs no superposed tensor: with ``s_0``, ``s_k`` the deviators of
    the base and unit stresses at a cell point, ``sigma_eq^2 = 3/2 |s_0 + l_k
    s_k|^2 = a + 2 b . l + l . C l`` with ``a = 3/2 s_0:s_0``, ``b_k = 3/2
    s_0:s_k``, ``C_kl = 3/2 s_k:s_l`` computed once per cell point, so a block
    costs two matrix products of ``K + K^2`` columns (``K`` load components)
    instead of ``9 K`` and the deviators.
    """
    loads = np.atleast_2d(np.asarray(loads, float))
    if criterion not in CRITERIA:
        raise ModelError(f"criterion = {criterion!r}: must be one of {', '.join(CRITERIA)}")
    values: dict[str, np.ndarray] = {}
    where: dict[str, np.ndarray] = {}
    for b in correctors.base:
        base, unit, points = correctors.base[b], correctors.unit[b], correctors.points[b]
        if criterion == "von_mises":
            quadratic = _von_mises_form(base, unit)
        else:
            flat = unit.reshape(len(unit), -1)
        v = np.empty(len(loads))
        w = np.empty((len(loads), points.shape[1]))
        rows = max(1, CHUNK_ENTRIES // max(base.size, 1))
        for start in range(0, len(loads), rows):
            block = loads[start:start + rows]
            if criterion == "von_mises":
                eq = np.sqrt(np.maximum(quadratic(block), 0.0))
            else:
                s = (base.reshape(1, -1) + block @ flat).reshape((len(block),) + base.shape)
                eq = equivalent(s, criterion)
            k = np.argmax(eq, axis=1)
            v[start:start + len(block)] = eq[np.arange(len(block)), k]
            w[start:start + len(block)] = points[k]
        values[b], where[b] = v, w
    return StrengthMap(criterion=criterion, values=values, cell_point=where)


def _von_mises_form(base: np.ndarray, unit: np.ndarray):
    """``block -> sigma_eq^2`` at every cell point for the load rows of ``block`` (:func:`strength_map`)."""
    def deviator(t):
        return (t - np.trace(t, axis1=-2, axis2=-1)[..., None, None] / 3.0 * np.eye(3)).reshape(t.shape[:-2] + (9,))
    s0, sk = deviator(base), deviator(unit)                      # (n, 9), (K, n, 9)
    a = 1.5 * np.einsum("nj,nj->n", s0, s0)
    b = 1.5 * np.einsum("nj,knj->nk", s0, sk)
    C = 1.5 * np.einsum("knj,lnj->nkl", sk, sk).reshape(len(s0), -1)
    K = len(sk)

    def form(block: np.ndarray) -> np.ndarray:
        pairs = (block[:, :, None] * block[:, None, :]).reshape(len(block), K * K)
        return a[None, :] + 2.0 * block @ b.T + pairs @ C.T
    return form


def check(smap: StrengthMap, sigma_u: Mapping[str, float], macro_points: np.ndarray) -> dict[str, Any]:
    """The check of eq. 78 per body and overall.

    Parameters
    ----------
    smap
        :func:`strength_map` result.
    sigma_u
        ``{body: ultimate stress}``.
    macro_points
        ``(m, dim)`` coordinates of the macro interface points (rows of the loads).

    Returns
    -------
    dict
        Per body ``max_sigma_eq``, ``sigma_u``, ``safety_factor``, the
        ``macro_point`` (index and coordinates) and ``cell_point``; overall
        ``safety_factor`` (the smallest), ``critical_body`` and ``holds``
        (``safety_factor > 1``).
    """
    bodies: dict[str, dict[str, Any]] = {}
    out: dict[str, Any] = {"criterion": smap.criterion, "bodies": bodies}
    for b, vals in smap.values.items():
        k = int(np.argmax(vals))
        bodies[b] = {"max_sigma_eq": float(vals[k]), "sigma_u": float(sigma_u[b]),
                     "safety_factor": float(sigma_u[b] / vals[k]) if vals[k] > 0 else None,
                     "macro_point": {"index": k, "coordinates": np.asarray(macro_points[k]).tolist()},
                     "cell_point": smap.cell_point[b][k].tolist()}
    finite: dict[str, float] = {b: e["safety_factor"] for b, e in bodies.items() if e["safety_factor"] is not None}
    crit = min(finite, key=finite.__getitem__)
    out["critical_body"] = crit
    out["safety_factor"] = finite[crit]
    out["holds"] = bool(finite[crit] > 1.0)
    return out
