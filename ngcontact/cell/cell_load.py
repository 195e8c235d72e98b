"""The load of the cell problem: far-face tractions or jumps and the macro strain.

The cell problem (paper eqs. 49-51) is driven by the macro state at a point
``x`` of the macro interface ``S_0``.  The macro stress ``sigma^0(x)`` loads
the cell through the contact conditions of eq. 50 and the far-field
condition of eq. 51 (in the variational form, the last term of eq. 65,
``-sigma^0_ij int_{S_C} H(J.n - g) n_j (v_i - u_i) ds``); here it is applied
as the mean traction it transmits across the layer, on the far face of
``counter``, which moves rigidly by ``U`` (:mod:`ngcontact.cell.fe.cell_problem`).
The macro strain ``du^0/dx`` is the volume term of eq. 63.  The load is, per
mesh axis ``i`` (``x, y`` in 2D, ``x, y, z`` in 3D; the last one is the macro
normal ``n0``), one of

* a prescribed mean traction ``tbar_i`` on the counter's far face (normal
  pressure ``p = -tbar_n >= 0``, compression positive; shear ``tbar_t``), or
* a prescribed far-face jump ``Delta_i = (u_bottom - u_top)_i = -U_i``
  (``Delta_n > 0`` closes the layer),

together with an optional in-plane macro strain ``E`` (2D ``(E_xx,)``, 3D
``(E_xx, E_yy, E_xy)``), the affine part ``E x`` of the displacement that is
the same in both bodies and does not jump across ``S_C``.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class CellLoad:
    """One load state of the cell, per mesh axis (the last axis is ``n0``).

    ``traction[i]`` is the prescribed mean traction on the counter's far face
    or ``None`` where ``jump[i]`` (far-face jump, rough minus counter) is
    prescribed instead; ``macro_strain`` holds the in-plane macro strain
    (2D ``(e_xx,)``, 3D ``(e_xx, e_yy, e_xy)``) or is empty.
    """

    traction: tuple[float | None, ...]
    jump: tuple[float | None, ...]
    macro_strain: tuple[float, ...] = ()


def cell_load(dim: int, *, pressure=None, normal_jump=None, shear=None,
              tangential_jump=None, macro_strain=None) -> CellLoad:
    """Build a :class:`CellLoad` from the quantities of the interface.

    Parameters
    ----------
    dim
        Spatial dimension of the cell (2 or 3).
    pressure
        Mean normal pressure transmitted across the layer (compression
        positive); give this or ``normal_jump``.
    normal_jump
        Prescribed normal jump of the far faces (positive closes the layer).
    shear
        Mean tangential traction on the counter's far face, one value per
        tangential axis (``None`` entries: the jump is prescribed); default 0.
    tangential_jump
        Prescribed tangential far-face jump per tangential axis, or ``None``.
    macro_strain
        In-plane macro strain, 2D ``(e_xx,)``, 3D ``(e_xx, e_yy, e_xy)``.
    """
    nt = dim - 1
    if (pressure is None) == (normal_jump is None):
        raise ValueError("give exactly one of pressure and normal_jump")
    shear = tuple(shear) if shear is not None else (None,) * nt
    tj = tuple(tangential_jump) if tangential_jump is not None else (None,) * nt
    if len(shear) != nt or len(tj) != nt:
        raise ValueError(f"shear and tangential_jump need {nt} entries in {dim}D")
    traction, jump = [], []
    for s, j in zip(shear, tj):
        if s is not None and j is not None:
            raise ValueError("a tangential component takes a shear or a jump, not both")
        traction.append(None if j is not None else float(s or 0.0))
        jump.append(None if j is None else float(j))
    traction.append(None if pressure is None else -float(pressure))
    jump.append(None if normal_jump is None else float(normal_jump))
    ms = tuple(float(v) for v in (macro_strain or ()))
    if ms and len(ms) != (1 if dim == 2 else 3):
        raise ValueError(f"macro_strain needs {1 if dim == 2 else 3} entries in {dim}D")
    return CellLoad(traction=tuple(traction), jump=tuple(jump), macro_strain=ms)
