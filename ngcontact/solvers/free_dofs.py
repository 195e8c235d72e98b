"""The free dofs of a solve as a NumPy mask: vectors restricted to them without NGSolve's BitArray per entry."""
from __future__ import annotations

import numpy as np


def fixed_mask(freedofs):
    """Boolean NumPy array, True where a dof is not free."""
    return ~np.array([freedofs[i] for i in range(len(freedofs))], dtype=bool)


def mask_fixed(vec, fixed) -> None:
    """Zero the entries of ``vec`` that are not free."""
    vec.FV().NumPy()[fixed] = 0.0
