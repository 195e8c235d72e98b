"""A ``macro`` scene solved on a mesh distributed over MPI ranks (``mpiexec -n N ngcontact run SCENE``).

What is distributed: the mesh (made on rank 0, distributed by
:func:`ngcontact.distributed.macro_mesh.distribute`), the spaces, the
assembly of the energy (the bodies' elasticity and the interface law's
energy, paper eqs. 44, 46-48), its residual and tangent, and Newton's
tangent solves by BDDC-preconditioned CG (``solver.linear = "iterative"``,
also for ``"auto"``; a sparse direct factorization does not run
distributed, so ``"direct"`` is refused).  Coulomb friction is solved as in one process by the
coupled Newton; the fixed point of ``solver.coulomb = "fixed_point"``
compares sampled pressures between its passes and is refused here.

Post-processing is reduced over the ranks
(:class:`ngcontact.distributed.reduced_measures.Reduced`): every rank
measures its own elements and the parts are combined with MPI, so that the
report holds one process's numbers without a gathered solution; the stress
fields are written in pieces, a ``.vtu`` per rank and a ``.pvtu``
(:mod:`ngcontact.distributed.vtk_pieces`).

What is not: rank 0 makes the mesh with straight elements, checks the
model on it (labels, supports, rigid motions: none of them depends on
curving or refining) and reads the supports off it, then distributes it and
lets it go (:func:`ngcontact.distributed.macro_mesh.distribute`); with
``discretization.refinements`` it makes the coarse mesh only, and the ranks
refine their parts, so that no rank holds the fine mesh whole.  A tilted
support's mid-point, taken over the ranks' parts, becomes the equivalent
affine field ``u0 + G x``.  Rank 0 orders the interface's samples by the
whole mesh's numbering (:mod:`ngcontact.distributed.boundary_numbers`),
draws the figures and alone writes the report.  The strength check samples
the whole stress field: with ``[strength]`` rank 0 keeps its whole mesh and
the solution is gathered onto it (:func:`ngcontact.distributed.macro_mesh.gather`)
for the check alone (refinements on the ranks are refused then).  A
two-scale scene's cells and their batches stay on the executor of one
process and are refused under MPI.
"""
from __future__ import annotations

import pickle
from dataclasses import replace
from functools import partial

import ngsolve as ng
import numpy as np

from ngcontact.distributed.macro_mesh import distribute, gather
from ngcontact.distributed.reduced_measures import Reduced, boundary_mid
from ngcontact.distributed.vtk_pieces import RankPieces
from ngcontact.distributed.world import World, broadcast, sent_error
from ngcontact.drivers import run_macro as R
from ngcontact.errors import SceneError
from ngcontact.fem.two_body import Support
from ngcontact.fem.two_body import boundary_mid as whole_mid
from ngcontact.laws import interface_energy as ie
from ngcontact.macro import macro_problem as M
from ngcontact.macro.macro_energy import gap_cf, local_jump
from ngcontact.output.report import Outcome

#: the fields of a macro problem rank 0 sends to the others (the mesh is each rank's; the gap is rebuilt)
SENT = ("setting", "rough", "counter", "materials", "law", "supports", "loads", "body_forces", "order", "interface")


def refuse(scene, world: World) -> None:
    """What does not run distributed ends here with the scene key, its value and what is allowed."""
    s = scene.solver
    if scene.two_scale is not None:
        raise SceneError("two_scale", "[two_scale]", f"a two-scale scene runs in one process, not on {world.size} "
                         "MPI ranks (its cells' batches go to the executor: --workers / --scheduler)")
    if s.linear == "direct":
        raise SceneError("solver.linear", s.linear, "'iterative' or 'auto' under mpiexec (both: BDDC-"
                         "preconditioned CG, which runs distributed; a sparse direct factorization does not)")
    if s.coulomb == "fixed_point":
        raise SceneError("solver.coulomb", s.coulomb, "'newton' under mpiexec (the coupled Newton runs "
                         "distributed; the fixed point does not)")
    if scene.strength is not None and scene.discretization.refinements:
        raise SceneError("discretization.refinements", scene.discretization.refinements, "0 with [strength] under "
                         "mpiexec (the strength check gathers the solution onto rank 0's whole mesh, which a mesh "
                         "refined on the ranks never is): refine by maxh instead, or run in one process")


def absolute(support: Support, mesh, mid=whole_mid) -> Support:
    """A tilted support as the same affine field ``u0 + G x``; ``mid(mesh, label, axis)``: its boundary's
    mid-point along the axis of its slope (of the whole mesh; under MPI reduced over the ranks' parts)."""
    if support.gradient or not any(support.slope):
        return support
    axis = "xyz".index(support.along)
    mid = mid(mesh, support.label, axis)
    value = tuple(support.value) or (0.0,) * len(support.slope)
    rows = tuple(tuple(float(s) if j == axis else 0.0 for j in range(mesh.dim)) for s in support.slope)
    return replace(support, value=tuple(float(v) - float(s) * mid for v, s in zip(value, support.slope)),
                   slope=(), gradient=rows)


def _on_root(world: World, make):
    """``make()`` on rank 0, its value (or its exception) on every rank, which sleep meanwhile
    (:func:`~ngcontact.distributed.world.broadcast`)."""
    if world.root:
        try:
            value = ("value", make())
            sent = pickle.dumps(value)
        except Exception as exc:  # noqa: BLE001  (sent on, raised on every rank alike)
            value = ("error", exc)
            sent = sent_error(exc)
        broadcast(world, sent)
    else:
        value = pickle.loads(broadcast(world))
    if value[0] == "error":
        raise value[1]
    return value[1]


def run(scene, clock, world: World) -> Outcome:
    """Solve ``scene`` distributed over ``world``; rank 0's outcome is the report's, the others' are empty."""
    refuse(scene, world)
    scene = replace(scene, solver=replace(scene.solver, linear="iterative"))     # 'auto' chooses by size: CG here
    order, keep = scene.discretization.order, scene.strength is not None
    whole = serial = None
    with clock.stage("mesh"):
        if world.root:
            whole = R.build_geometry(scene, order=1, refinements=0)
    with clock.stage("interface law"):
        def checked():
            nonlocal serial
            assert whole is not None
            problem, info = R.problem_of(scene, whole)
            M.check_problem(problem)
            serial = problem if keep else None
            return {k: getattr(problem, k) for k in SENT}, info, M.start_stiffness(problem)
        fields, info, stiffness = _on_root(world, checked)
    with clock.stage("mesh"):
        geo, numbers = distribute(whole, order, scene.discretization.refinements, world, keep=keep)
        if keep and world.root and order > 1:
            assert whole is not None
            whole.mesh.Curve(order)
        whole = None                    # rank 0's whole mesh lives on in ``serial`` only for the strength check
        mid = partial(boundary_mid, world)
        fields["supports"] = tuple(absolute(s, geo.mesh, mid) for s in fields["supports"])
    with clock.stage("interface law"):
        problem = M.MacroProblem(mesh=geo.mesh, gap=R.gap_of(scene), **fields)
        problem.parts.update(checked=True, start_stiffness=stiffness)
    with clock.stage("solve"):
        sol = R.solve_scene(scene, problem)
    with clock.stage("post-processing"):
        outcome = R.measured(sol, geo, info, scene.output, Reduced(world, numbers))
        outcome.ndof = global_ndof(sol, world)
        outcome.vtk["stress"].pieces = RankPieces(world)
        outcome.results["accuracy"] = accuracy_not_estimated(scene, sol, outcome.results["equilibrium"],
                                                                  world)
    outcome.solver["mpi"] = {"ranks": world.size, "distributed": "mesh, assembly, Newton with BDDC-CG, "
                             "post-processing reduced over the ranks, VTK in pieces",
                             "rank_0": "meshes (coarse where the ranks refine), checks, orders the interface's "
                             "samples, figures, files",
                             "elements": [int(n) for n in world.comm.allgather(geo.mesh.ne)],
                             "refined_on_ranks": scene.discretization.refinements}
    if scene.strength is not None:
        with clock.stage("strength check"):
            strength(scene, world, sol, serial, outcome)
    if not world.root:
        return Outcome(results={}, ndof=outcome.ndof, solver={}, vtk=outcome.vtk)
    return outcome


def strength(scene, world: World, sol: M.MacroSolution, serial: M.MacroProblem | None, outcome: Outcome) -> None:
    """The strength check (:mod:`ngcontact.drivers.run_strength`) on rank 0: its stress recovery samples
    the whole field, so the solution is gathered for it (and only for it)."""
    from ngcontact.drivers.run_strength import evaluate
    whole_sol = gathered(world, sol, serial)
    if whole_sol is None:
        return
    st = evaluate(scene, whole_sol)
    outcome.results["strength"] = st["results"]
    outcome.tables["strength_map"] = st["table"]
    outcome.vtk["worst_cell"] = st["vtk"]
    outcome.plots.update(st["plots"])


def global_ndof(sol: M.MacroSolution, world: World) -> int:
    """The free dofs of the distributed solution, each counted once (on the rank that is its master)."""
    fes = sol.gfu.space
    free = np.array(list(fes.FreeDofs()), dtype=bool)
    master = np.array(list(fes.ParallelDofs().MasterDofs()), dtype=bool)
    return int(world.comm.allreduce(int(np.count_nonzero(free & master))))


def accuracy_not_estimated(scene, sol: M.MacroSolution, balance: dict, world: World) -> dict:
    """The verdict of a distributed run: the equilibrium and law-closure checks and the modelling-error estimate
    (:mod:`ngcontact.drivers.macro_accuracy`); the neighbouring-order solves of the discretization estimate
    would run on rank 0 alone, so they are not made, and the verdict says so."""
    from ngcontact.drivers.macro_accuracy import modelling, verdict
    from ngcontact.macro import law_closure as LC
    mine = LC.law_closure(sol, scene.solver.coulomb_rtol)      # this rank's samples; the largest over the ranks
    closure = LC.closure_of(max(world.comm.allgather(mine["difference"])), max(world.comm.allgather(mine["scale"])),
                            mine["tolerance"], int(world.comm.allreduce(mine["samples"])))
    out = verdict([], scene.discretization.tolerance, balance, closure=closure)
    out.update(estimated=False, how="not estimated under MPI: the discretization estimate's solves at the "
                                    "neighbouring orders run in one process (ngcontact run without mpiexec)")
    out["modelling"] = modelling(scene, sol)
    return out


def gathered(world: World, sol: M.MacroSolution, serial: M.MacroProblem | None) -> M.MacroSolution | None:
    """The distributed solution ``sol`` as a solution of ``serial`` (rank 0's whole problem) on rank 0."""
    fes = frame = gfu = old = None
    if world.root:
        assert serial is not None
        fes, frame = M.space_and_frame(serial)
        gfu, old = ng.GridFunction(fes), ng.GridFunction(fes)
    gather(world, sol.gfu, gfu)
    if sol.previous is not None:
        gather(world, sol.previous, old)
    if not world.root:
        return None
    assert serial is not None and gfu is not None and old is not None and frame is not None
    law = serial.law
    G = None
    if law.friction is not None and law.friction.coulomb:
        a_old = local_jump(frame, old.components[0] - old.components[1])
        G = ie.threshold(law.friction, ie.pressure(law.normal, a_old, gap_cf(serial.gap)))
    elif law.friction is not None:
        G = ng.CF(ie.threshold(law.friction, 0.0))
    ur, uc = gfu.components
    return M.MacroSolution(problem=serial, gfu=gfu, u_rough=ur, u_counter=uc, frame=frame,
                           local_jump=local_jump(frame, ur - uc), threshold=G, history=sol.history, previous=old)
