"""Netgen's mesher run with NGSolve's task manager asleep.

A run computes inside NGSolve's task manager (:func:`ngcontact.runner.threads`):
its worker threads wait for the next parallel loop by spinning, each on a
core.  Netgen's mesher (constructive solid geometry, OCC, 2D geometries) is
serial and gives them none, so while it runs they only take the cores it
needs: on a machine with other work (or fewer free cores than threads) the
mesher then waits for the spinning workers (the 3D cell of the femur's
strength check, ``geometries/cells/hip_hills.toml``: its stage in
``docs/benchmarks.md``, section ``main_job_first_run``).  Asleep
(``pyngcore.SuspendTaskManager``: a worker sleeps between checks for work)
they leave the cores to the mesher; the mesh is the same, point for point.
Outside a task manager nothing changes.
"""
from __future__ import annotations

import contextlib

#: microseconds a worker sleeps between two checks for work while the mesher runs
SLEEP_USECS = 1000


def asleep():
    """Context in which the task manager's idle workers sleep (a no-op without ``pyngcore``)."""
    try:
        from pyngcore import SuspendTaskManager
    except ImportError:          # an NGSolve without it: the workers spin as before
        return contextlib.nullcontext()
    return SuspendTaskManager(SLEEP_USECS)


def generate(geometry, **kwargs):
    """``geometry.GenerateMesh(**kwargs)`` (a Netgen mesh) with the task manager's workers asleep."""
    with asleep():
        return geometry.GenerateMesh(**kwargs)
