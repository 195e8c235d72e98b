"""What a spectral cell's grid costs, and how large a grid a scene may ask for.

The small-slope cell (paper eqs. 49-51 on two periodic layers) is solved on a uniform grid of its
interface with FFTs; its memory grows with the points and its time with the points times the number of
constrained CG steps, which grows with the square root of the compliance's condition number.  The bounds
here are checked when a scene is read, before any work.
"""
from __future__ import annotations

import math

from ngcontact.errors import SceneError


#: Bytes of a spectral solve per grid point: the constrained CG's fields, the FFTs' and the friction's
#: buffers (about 25 arrays of doubles).
SPECTRAL_BYTES_PER_POINT = 200
#: Seconds of one constrained CG step per ``n log2 n`` (``n`` grid points): two real FFT pairs on one core.
SPECTRAL_STEP_SECONDS = 2e-8
#: Constrained CG steps per square root of the compliance's condition number (:func:`spectral_cost`).
STEPS_PER_ROOT = 3.0
#: Largest number of spectral grid points of a cell by dimension (2D: points, 3D: points squared): where the
#: estimate of :func:`spectral_cost` reaches about a quarter of an hour per load (2D) or 1 GB (3D).
MAX_SPECTRAL_POINTS = {2: 2 ** 20, 3: 2 ** 22}
#: Largest number of grid points refinement to the default tolerance may reach (a scene that states no
#: ``discretization.tolerance``): where :func:`spectral_cost` is of the order of seconds per load.  Beyond
#: it the finest grid is the answer, marked as not meeting the default tolerance.
DEFAULT_REFINEMENT_POINTS = {2: 2 ** 16, 3: 2 ** 18}
#: Largest ``discretization.tolerance`` of a spectral cell relative to ``solver.rtol``: two grids' answers,
#: each only within ``rtol`` of the gap's scale, cannot show a smaller change.
TOLERANCE_OVER_RTOL = 10.0


def spectral_cost(dim: int, grid: int) -> tuple[float, float]:
    """Memory (bytes) and time (seconds per load, the order of magnitude) of a spectral cell of ``grid`` points
    per direction.

    The layers' compliance falls like ``1/|k|``, so its condition number on the grid is the ratio of the
    largest wave number to the smallest, ``kappa = N/2`` (2D) or ``N/sqrt(2)`` (3D), and conjugate gradients
    take about ``STEPS_PER_ROOT sqrt(kappa)`` steps, each ``SPECTRAL_STEP_SECONDS n log2 n`` for ``n`` points.
    A guard against sizes that run for hours, not a prediction.
    """
    points = float(grid) ** (dim - 1)
    kappa = grid / 2.0 if dim == 2 else grid / math.sqrt(2.0)
    steps = STEPS_PER_ROOT * math.sqrt(kappa)
    return SPECTRAL_BYTES_PER_POINT * points, steps * SPECTRAL_STEP_SECONDS * points * math.log2(max(points, 2.0))


def check_spectral_size(dim: int, grid: int, key: str = "discretization.grid", value=None) -> None:
    """Refuse a spectral grid beyond :data:`MAX_SPECTRAL_POINTS`, with its estimated cost (:func:`spectral_cost`)."""
    points, bound = grid ** (dim - 1), MAX_SPECTRAL_POINTS[dim]
    if points > bound:
        memory, seconds = spectral_cost(dim, grid)
        raise SceneError(key, grid if value is None else value,
                         f"makes {points} grid points, more than {bound}: about {memory / 2 ** 30:.2g} GB of fields "
                         f"and of the order of {seconds:.2g} s per load; at most "
                         f"{round(bound ** (1 / (dim - 1)))} points per direction in {dim}D")
