"""The far-face strain of a cell solution against the small-strain model.

The cell problem (paper eqs. 49-51) is linear elasticity: its answer holds
while the strains are small.  The far-face jump ``U`` (rough minus counter
far face, :mod:`ngcontact.cell.cell_load`) spread over the cell's height
``h_rough + h_counter`` is the mean strain of the cell,

    far_face_strain = |U| / (h_rough + h_counter),

and beyond :data:`SMALL_STRAIN` the linear model, and with it the answer,
no longer describes the bodies (a soft penalty layer or a load far above
the bodies' modulus: jumps of 14867 in a cell 2 high).  Every cell method's
results pass here (:func:`check`, called by the cell driver for each load).
"""
from __future__ import annotations

import logging
import math
from typing import Any

log = logging.getLogger(__name__)

#: Largest mean strain of the cell taken as small: the linear theory's error is of the order of the strain.
SMALL_STRAIN = 0.05


def far_face_strain(results: dict[str, Any], height: float) -> float:
    """``|U| / height`` of one load's results (module docstring); ``|U|`` by ``hypot``, which does not overflow
    where the squares of the components would."""
    return math.hypot(*(float(u) for u in results["far_face_jump"])) / height


def check(results: dict[str, Any], height: float, label: str) -> float:
    """Record ``far_face_strain`` in a load's ``results`` and warn once when it is beyond :data:`SMALL_STRAIN`.

    ``label`` names the load in the warning (e.g. ``"load 2"``).
    """
    strain = far_face_strain(results, height)
    results["far_face_strain"] = strain
    if strain > SMALL_STRAIN:
        log.warning("%s: the far-face strain %.3g (far-face jump %.3g over the cell height %g) is beyond small "
                    "strain (%g): the linear cell model does not hold; lower the load, or raise contact.k_n or "
                    "the bodies' E", label, strain, strain * height, height, SMALL_STRAIN)
    return strain
