"""VTK fields of a mesh distributed over MPI ranks, written in parallel: a ``.vtu`` piece per rank and a ``.pvtu``.

NGSolve's ``VTKOutput`` on a distributed mesh writes, on every rank that
holds elements (ranks ``1 .. N-1``: rank 0 keeps none), the piece
``NAME_proc<R>.vtu`` of its own elements; no rank gathers the fields.  Rank
0 then writes ``NAME.pvtu``, the parallel file that names the pieces and
their arrays (the points and one point array per field), which ParaView
opens as one data set.

Rank 0 alone runs the writer of the output directory
(:mod:`ngcontact.output.writer`: staged in a temporary directory, moved into
place).  The other ranks wait in :func:`written` for the path of each field
set, which rank 0 sends when its writer reaches it, write their pieces
there, and are released when rank 0's writer ends; they sleep while they
wait (:func:`ngcontact.distributed.world.broadcast`).

A write that fails never leaves a rank waiting for a collective call the
others do not make (MPI matches a blocking barrier only with a blocking
one).  Every rank makes the same calls whatever happens: after writing its
piece each rank sends the others its outcome, nothing or its error (an
``allgather`` where a barrier stood), and all raise the error of the
lowest failing rank; rank 0's writer, ended by it or by any other error,
sends that error instead of the closing ``None``, and every rank raises it
as itself (pickled: :func:`ngcontact.distributed.world.sent_error`), so
that the run ends on every rank with the same error and exit status.
"""
from __future__ import annotations

import os
from typing import Callable

from ngcontact.distributed.world import World, broadcast, launched_rank, raise_sent, sent_error


class RankPieces:
    """The :class:`~ngcontact.output.report.Pieces` of ``world``: one piece per rank ``1 .. N-1``."""

    def __init__(self, world: World):
        self.world = world

    def files(self, name: str) -> list[str]:
        return [f"{name}.pvtu"] + [piece(name, r) for r in range(1, self.world.size)]

    def write(self, path_noext: str, item) -> None:
        """On rank 0: send the path, write together with the other ranks, then the ``.pvtu`` file."""
        broadcast(self.world, path_noext)
        write_piece(path_noext, item, self.world)
        with open(path_noext + ".pvtu", "w", encoding="utf-8") as fh:
            fh.write(pvtu(os.path.basename(path_noext), item, self.world.size))


def piece(name: str, rank: int) -> str:
    """The file name of rank ``rank``'s piece (NGSolve's naming)."""
    return f"{name}_proc{rank}.vtu"


def write_piece(path_noext: str, item, world: World) -> None:
    """Every rank's part of ``item``'s fields (together on all ranks; rank 0's is empty), then every rank's
    outcome to all (module docstring): the error of the lowest failing rank is raised on every rank."""
    try:
        import ngsolve as ng
        names = list(item.fields)
        ng.VTKOutput(ma=item.mesh, coefs=[item.fields[n] for n in names], names=names, filename=path_noext,
                     subdivision=item.subdivision, legacy=False).Do()
        mine = None
    except Exception as exc:  # noqa: BLE001  (sent to every rank, raised there alike)
        mine = sent_error(exc, world.rank)
    failed = [sent for sent in world.comm.allgather(mine) if sent is not None]
    if failed:
        raise_sent(failed[0])
    stray = path_noext + ".pvd"           # NGSolve's collection file: the .pvtu replaces it
    if world.root and os.path.exists(stray):
        os.remove(stray)


def pvtu(name: str, item, ranks: int) -> str:
    """The ``.pvtu`` text of the pieces ``1 .. ranks-1`` of ``name`` with ``item``'s point arrays."""
    arrays = "".join(f'      <PDataArray type="Float64" Name="{n}" NumberOfComponents="{cf.dim}"/>\n'
                     for n, cf in item.fields.items())
    pieces = "".join(f'    <Piece Source="{piece(name, r)}"/>\n' for r in range(1, ranks))
    return ('<?xml version="1.0"?>\n'
            '<VTKFile type="PUnstructuredGrid" version="1.0" byte_order="LittleEndian">\n'
            '  <PUnstructuredGrid GhostLevel="0">\n'
            '    <PPoints>\n      <PDataArray type="Float64" Name="Points" NumberOfComponents="3"/>\n'
            '    </PPoints>\n'
            f'    <PPointData>\n{arrays}    </PPointData>\n'
            f'{pieces}'
            '  </PUnstructuredGrid>\n</VTKFile>\n')


def written(outcome, write: Callable[[], object]) -> None:
    """``write()`` (the output directory's writer) on rank 0, with the other ranks writing their pieces of
    ``outcome``'s distributed fields as rank 0 reaches them; without such fields just ``write()`` on rank 0."""
    pieces = [v.pieces for v in outcome.vtk.values() if isinstance(v.pieces, RankPieces)]
    if not pieces:
        if launched_rank() == 0:
            write()
        return
    world = pieces[0].world
    if world.root:
        try:
            write()
        except BaseException as exc:
            broadcast(world, sent_error(exc))   # the other ranks stop waiting and raise it
            raise
        broadcast(world)     # the other ranks stop waiting
        return
    while isinstance(message := broadcast(world), str):
        try:
            write_piece(message, outcome.vtk.get(os.path.basename(message)), world)
        except Exception:  # noqa: BLE001  (raised on rank 0 too: the message that ends its writer says how)
            pass
    if message is not None:
        raise_sent(message)
