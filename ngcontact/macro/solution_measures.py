"""Where the measures of a macro solution are taken: one process's whole mesh, or a mesh over MPI ranks.

The report of a macro run (the equilibrium check, the field extrema, the
support reactions, the interface's samples, the figures' samples) asks the
same questions of every solution; :class:`Measures` is that seam.
:class:`WholeMesh` answers them on the mesh of one process
(:mod:`ngcontact.macro.macro_measures`).  The distributed answer
(:class:`ngcontact.distributed.reduced_measures.Reduced`) takes each rank's
part of the integrals, extrema and samples and reduces them over the ranks,
so that every rank holds the same numbers as one process would.
"""
from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Callable

from ngcontact.fem.reaction import support_reactions
from ngcontact.macro import macro_measures as MM
from ngcontact.macro.macro_problem import MacroSolution

#: the samples of a figure of the stress fields (``x``, ``y``, ``triangles``, ``values``, ``axisymmetric``)
Samples = Callable[[MacroSolution, dict], dict]


class Measures(ABC):
    """The measures of a macro solution that its report states (every rank the same numbers)."""

    #: whether this process draws the figures (their samples are whole only there)
    draws: bool = True

    @abstractmethod
    def equilibrium(self, sol: MacroSolution) -> dict:
        """:func:`ngcontact.macro.macro_measures.equilibrium` of the whole solution."""

    @abstractmethod
    def extrema(self, sol: MacroSolution, fields: dict) -> dict:
        """:func:`ngcontact.macro.macro_measures.field_extrema` over the whole mesh."""

    @abstractmethod
    def reactions(self, sol: MacroSolution) -> dict:
        """:func:`ngcontact.fem.reaction.support_reactions` of every supported boundary."""

    @abstractmethod
    def surface(self, sol: MacroSolution) -> dict:
        """:func:`ngcontact.macro.macro_measures.interface_surface` in the whole mesh's order (3D)."""

    @abstractmethod
    def profile(self, sol: MacroSolution, points_per_element: int) -> dict:
        """:func:`ngcontact.macro.macro_measures.interface_profile` along the whole interface (2D)."""

    @abstractmethod
    def samples(self, sample: Samples, sol: MacroSolution, fields: dict) -> dict:
        """``sample(sol, fields)``, a figure's samples, whole where :attr:`draws`."""


def reactions_of(sol: MacroSolution, centres: dict | None = None) -> dict:
    """The reactions of ``sol``'s supports (``centres``: label -> the centre of its moment, see
    :func:`ngcontact.fem.reaction.support_reactions`)."""
    p = sol.problem
    return support_reactions(p.mesh, p.setting, p.order, p.supports,
                             ((p.rough, p.materials[p.rough], sol.u_rough),
                              (p.counter, p.materials[p.counter], sol.u_counter)), p.body_forces, centres)


class WholeMesh(Measures):
    """The measures on the whole mesh of one process."""

    def equilibrium(self, sol: MacroSolution) -> dict:
        return MM.equilibrium(sol)

    def extrema(self, sol: MacroSolution, fields: dict) -> dict:
        return MM.field_extrema(sol, fields)

    def reactions(self, sol: MacroSolution) -> dict:
        return reactions_of(sol)

    def surface(self, sol: MacroSolution) -> dict:
        return MM.interface_surface(sol)

    def profile(self, sol: MacroSolution, points_per_element: int) -> dict:
        return MM.interface_profile(sol, points_per_element)

    def samples(self, sample: Samples, sol: MacroSolution, fields: dict) -> dict:
        return sample(sol, fields)


#: the measures of a run in one process
WHOLE_MESH = WholeMesh()
