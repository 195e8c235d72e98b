"""A bilinear form whose coefficients read a state: the linearization of an energy, written out.

    a_u(du, v) = d2 Pi(u)[du, v],

assembled at a vector ``u`` by copying ``u`` into the state GridFunction the
form's coefficients read and calling ``Assemble``.  NGSolve linearizes a
``Variation`` by automatic differentiation at every quadrature point; a
bilinear form of the same Hessian, written out, assembles in about half the
time (a preconditioner rebuilt from it:
:func:`ngcontact.cell.fe.cell_energy.preconditioning_form`).  It answers the
one question a split energy asks of a preconditioning form
(:class:`ngcontact.solvers.split_energy.SplitEnergy`).
"""
from __future__ import annotations

from dataclasses import dataclass

import ngsolve as ng


@dataclass
class StateForm:
    """``form`` (bilinear in trial and test functions) with coefficients that read ``state``."""

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
