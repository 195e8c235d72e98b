"""An energy whose bodies are linear: the quadratic part assembled once, only the interface each step.

The energies minimized here (cell: paper eqs. 57, 63, 65; macro: eq. 85
with the homogenized interface law) are a sum

    Pi(u) = Q(u) + Psi(u),      Q(u) = c + g . u + 1/2 u . K u,

of the bodies' linear elasticity with the load potentials (``Q``:
quadratic, ``K`` the bodies' stiffness, ``g`` minus the load vector, ``c``
a constant such as the macro strain's energy) and the nonlinear interface
energy ``Psi`` (contact, friction), which lives on the interface elements
only.  NGSolve's ``Variation`` forms re-evaluate every element at every
residual, energy and tangent; yet ``Q`` never changes within a solve.
:class:`SplitEnergy` holds

* ``K`` assembled once (``Q''`` at any state) and ``g = Q'(0)``,
  ``c = Q(0)``, refreshed only when the parameters of the load change
  (``key()``: the traction and macro strain ``Parameter`` values);
* the interface form ``Psi``, assembled at every state on the interface
  elements alone;

and answers the questions Newton's method asks of a form
(:func:`ngcontact.solvers.newton.minimize`):

* ``Apply(u, r)``: ``r = K u + g + Psi'(u)``;
* ``Energy(u)``: ``c + g . u + 1/2 u . K u + Psi(u)``;
* ``AssembleLinearization(u)``: ``mat = K + Psi''(u)``, written into the
  matrix of the whole form (the sparsity of every term's matrix is part of
  the whole form's, whose matrix is allocated once; the positions are
  found once), so that the factorization of one Newton step is refreshed
  in place at the next (``LinearSolver``).

The same numbers as the whole form to round-off (tested), at a fraction of
its cost: the bodies' part, most of the dofs, is not assembled again.  The first tangent is
the whole form's assembly (it allocates the matrix), and so is
:meth:`SplitEnergy.rebuild`: a preconditioner registered with the whole form
(BDDC, built from element matrices) is built there and kept by the later
steps' tangents, until the linear solver finds it stale
(:class:`ngcontact.solvers.linear_solver.LinearSolver`).

A split energy may carry a *preconditioning* form
(:class:`StateForm`): the tangent written as a
bilinear form of the state, plus terms meant for the preconditioner alone
(the contact surface's bubble term,
:func:`ngcontact.fem.elasticity.bubble_term`).  Once a preconditioner is
registered with it (:meth:`SplitEnergy.preconditioner_form`), a rebuild
assembles that form at the state, which builds the preconditioner, and
writes the tangent ``K + Psi''`` into the whole form's matrix from its
parts: the tangent never holds the extra terms.
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ng
import numpy as np

from ngcontact.solvers.roundoff import local_matrix, ranks_sum


@dataclass
class StateForm:
    """A bilinear form whose coefficients read a state: the linearization of an energy, written out.

        a_u(du, v) = d2 Pi(u)[du, v],

    assembled at a vector ``u`` by copying ``u`` into ``state``, the
    GridFunction the coefficients of ``form`` (bilinear in trial and test
    functions) read, and calling ``Assemble``.  NGSolve linearizes a
    ``Variation`` by automatic differentiation at every quadrature point; a
    bilinear form of the same Hessian, written out, assembles faster (a
    preconditioner rebuilt from it:
    :func:`ngcontact.cell.fe.cell_energy.preconditioning_form`).  It answers the
    one question a split energy asks of its preconditioning form and of its
    interface tangent (:class:`SplitEnergy`).
    """

    form: ng.BilinearForm
    state: ng.GridFunction

    @property
    def mat(self):
        """The matrix of the last assembly."""
        return self.form.mat

    def AssembleLinearization(self, vec) -> None:  # noqa: N802 (NGSolve's name)
        """Assemble ``form`` at the state ``vec`` (a preconditioner registered with it is built)."""
        self.state.vec.data = vec
        self.form.Assemble()


_UNSET = object()   # no load parameters seen yet


class SplitEnergy:
    """``Pi = Q + Psi`` with ``Q`` quadratic (module docstring), a drop-in for the whole form in Newton.

    Parameters
    ----------
    whole
        The form of ``Pi`` (all terms); its matrix receives the tangent.
    quadratic
        The form of ``Q`` (same space and storage): the bodies and the load potentials.
    interface
        The form of ``Psi`` (same space and storage), or an object answering the same
        ``Apply``, ``Energy``, ``AssembleLinearization`` and ``mat`` (e.g.
        :class:`ngcontact.cell.fe.contact_quadrature.ContactQuadrature`).
    key
        ``key() -> hashable``: the values of the parameters ``g`` and ``c``
        depend on (e.g. the load's ``Parameter`` values); ``K`` must not
        depend on them.
    assembled
        ``quadratic`` is assembled already (``K`` shared with another split
        energy of the same bodies, e.g. with another interface law).
    preconditioning
        The form, linearized at a state, a preconditioner is built from instead
        of ``whole`` (module docstring); ``None``: ``whole``.
    interface_tangent
        ``Psi''`` written out as a form of the state (same matrix as the
        linearization of ``interface``, faster to assemble); ``None``: the
        linearization of ``interface``.
    """

    def __init__(self, whole: ng.BilinearForm, quadratic: ng.BilinearForm, interface: ng.BilinearForm, key,
                 assembled: bool = False, preconditioning: StateForm | None = None,
                 interface_tangent: StateForm | None = None):
        self.whole, self.quadratic, self.interface, self.key = whole, quadratic, interface, key
        self._psi = interface if interface_tangent is None else interface_tangent      # assembles Psi''
        self.preconditioning = preconditioning
        self._precondition = False      # a preconditioner is registered with ``preconditioning``
        self.space = whole.space
        self._state = ng.GridFunction(whole.space)      # owns the zero vector
        zero = self._zero = self._state.vec
        if not assembled:
            quadratic.AssembleLinearization(zero)       # Q'' is the same at every state
        self.K = quadratic.mat
        # after the whole form's first assembly: where the interface's entries go, K in the whole storage
        self._slots_psi: np.ndarray | None = None
        self._K_whole: np.ndarray | None = None
        self._matrix = None     # the tangent's own matrix, when the whole form is never assembled
        self._loads: object = _UNSET
        self._g = zero.CreateVector()
        self._c = 0.0
        self._work = zero.CreateVector()
        self._at = zero.CreateVector()
        #: whether the last :meth:`AssembleLinearization` assembled the whole form (and with it a
        #: preconditioner registered with it) rather than only the interface
        self.assembled_whole = False
        self._renew = False

    @property
    def mat(self):
        """The tangent ``K + Psi''`` of the last :meth:`AssembleLinearization`: the whole form's matrix, or a
        matrix of the preconditioning form's sparsity (:meth:`rebuild`)."""
        return self.whole.mat if self._matrix is None else self._matrix

    def _linear_part(self) -> None:
        loads = self.key()
        if loads != self._loads:
            self.quadratic.Apply(self._zero, self._g)
            self._c = ranks_sum(self._zero, self.quadratic.Energy(self._zero))
            self._loads = loads

    def Apply(self, vec, out) -> None:  # noqa: N802 (NGSolve's name)
        """``out = Pi'(vec)``."""
        self._linear_part()
        self.interface.Apply(vec, self._work)
        out.data = self.K * vec
        out.data += self._g
        out.data += self._work

    def Energy(self, vec) -> float:  # noqa: N802
        """``Pi(vec)`` (over every MPI rank of a distributed space: NGSolve's ``Energy`` of a form sums
        the rank's own elements, the inner products of distributed vectors are global already)."""
        self._linear_part()
        self._work.data = self.K * vec
        quad = 0.5 * ng.InnerProduct(vec, self._work) + ng.InnerProduct(self._g, vec) + self._c
        return quad + ranks_sum(vec, self.interface.Energy(vec))     # a form's energy is its rank's elements'


    def AssembleLinearization(self, vec) -> None:  # noqa: N802
        """``mat = K + Psi''(vec)``: the first time by the whole form's assembly, which allocates its
        matrix (or, with a registered preconditioning form, by that form's assembly, whose matrix has the
        same sparsity), then from ``K`` and the interface's assembly alone."""
        self._at.data = vec
        self._psi.AssembleLinearization(vec)
        if self._K_whole is None:
            self.rebuild()
            return
        if self._renew:
            self.rebuild()
            return
        self._sum_parts()
        self.assembled_whole = False

    def interface_product(self, vec, x, out) -> None:
        """``out = Psi''(vec) x``: the interface's tangent alone, assembled at ``vec`` (the tangent of the next
        :meth:`AssembleLinearization` assembles it again, at its own state)."""
        self._psi.AssembleLinearization(vec)
        out.data = self._psi.mat * x

    def _sum_parts(self) -> None:
        """``whole.mat = K + Psi''`` from ``K`` and the interface's last assembly."""
        vals = local_matrix(self.mat).AsVector().FV().NumPy()
        vals[:] = self._K_whole
        vals[self._slots_psi] += local_matrix(self._psi.mat).AsVector().FV().NumPy()

    def preconditioner_form(self) -> ng.BilinearForm:
        """The form to register a preconditioner with: the preconditioning form if there is one (from then on
        every rebuild assembles it), else the whole form."""
        if self.preconditioning is None:
            return self.whole
        self._precondition = True
        return self.preconditioning.form

    def renew_preconditioner(self) -> None:
        """The whole form was assembled elsewhere (e.g. on other free dofs, for a measurement): the next
        tangent assembles it again, and with it a preconditioner registered with it."""
        self._renew = True

    def rebuild(self) -> None:
        """Assemble the whole form at the state of the last :meth:`AssembleLinearization`: the same
        tangent to round-off, and a preconditioner registered with the whole form (BDDC) built from it.
        With a registered preconditioning form: that form is assembled instead (building the
        preconditioner), and the tangent is summed from its parts into a matrix of that form's sparsity,
        allocated at the first rebuild (the bodies and the contact surface couple the same dofs in both
        forms, so the whole form, whose assembly costs as much again, is never assembled)."""
        if not self._precondition or self.preconditioning is None:
            self.whole.AssembleLinearization(self._at)
            if self._K_whole is None:
                self._locate(self.whole.mat)
        else:
            self.preconditioning.AssembleLinearization(self._at)
            if self._K_whole is None:
                self._matrix = self.preconditioning.form.mat.CreateMatrix()
                self._locate(self._matrix)
            self._sum_parts()
        self.assembled_whole = True
        self._renew = False

    def _locate(self, matrix) -> None:
        """Where ``K``'s and the interface's entries sit in the tangent's ``matrix`` (once).  Matrices
        distributed over MPI ranks: each rank's own part (its elements' entries, added up by NGSolve)."""
        matrix, psi, K = local_matrix(matrix), local_matrix(self._psi.mat), local_matrix(self.K)
        keys = _keys(matrix)
        self._slots_psi = _positions(matrix, psi, keys)
        self._K_whole = np.zeros(matrix.nze)
        self._K_whole[_positions(matrix, K, keys)] = K.AsVector().FV().NumPy()


def add_matrix(whole, part) -> None:
    """``whole += part`` in place: two matrices of one space and storage, ``part`` storing a subset of the
    entries ``whole`` stores (a term's matrix into the whole form's)."""
    whole, part = local_matrix(whole), local_matrix(part)
    whole.AsVector().FV().NumPy()[_positions(whole, part)] += part.AsVector().FV().NumPy()

def _positions(whole, part, whole_keys: np.ndarray | None = None) -> np.ndarray:
    """Where each stored entry of the sparse matrix ``part`` sits among the stored entries of ``whole``.

    Both in NGSolve's CSR storage with sorted columns per row (the same
    storage, full or lower triangle); raises when ``part`` has an entry that
    ``whole`` does not store.  ``whole_keys``: :func:`_keys` of ``whole``, if at hand.
    """
    big = _keys(whole) if whole_keys is None else whole_keys
    small = _keys(part)
    at = np.searchsorted(big, small)
    if not (np.all(at < len(big)) and np.array_equal(big[np.minimum(at, len(big) - 1)], small)):
        raise ValueError("a term's matrix stores an entry the whole form's matrix does not: "
                         "the forms differ in space or storage")
    return at


def _keys(mat) -> np.ndarray:
    """``row * width + column`` of each stored entry, in storage order (ascending)."""
    _, cols, ptr = mat.CSR()
    cols = np.asarray(cols).astype(np.int64)
    ptr = np.asarray(ptr).astype(np.int64)
    rows = np.repeat(np.arange(len(ptr) - 1, dtype=np.int64), np.diff(ptr))
    return rows * mat.width + cols
