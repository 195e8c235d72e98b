"""A CalculiX (ccx) model of two blocks meeting through an exported interface law: the ccx side of the client check.

The macro ``block`` geometry of :func:`ngcontact.geometry.bodies.block_on_plane`
(a block ``[0, L] x [0, h_block]`` on a base ``[0, L] x [-h_base, 0]``) in
plane strain, written as a slab one element thick of 8-node hexahedra with
incompatible modes (``C3D8I``) and ``u_z = 0`` at every node.  The two bodies
have their own nodes on ``y = 0``; the block's bottom faces (slave) meet the
base's top faces (master) by node-to-face penalty contact
(``*CONTACT PAIR, TYPE=NODE TO SURFACE, SMALL SLIDING``) with the interaction
of :mod:`ngcontact.export.calculix`: each slave node carries the pressure
times its share of the slave faces (a quarter of each adjacent face).  The base's bottom is clamped; the block's
top is moved by ``(shear, -press)`` [m].

:func:`run` writes the deck, runs ``ccx`` and reads from its ``.dat`` file
the reaction force on the block's top (per metre of thickness: the slab is
``thickness`` thick) and the contact stresses at the slave nodes (the two
nodes of the slab's thickness averaged).

:class:`PressFit` is the second model: the quarter of two coaxial tubes
(``a < r < b`` inner, rough; ``b < r < c`` outer) of the macro ``coaxial``
geometry in plane strain, a C3D8I slab structured in radius and angle, the
cuts ``x = 0`` and ``y = 0`` held normally, pressed together only by the
exported law's interference (its table shifted by ``g0 < 0``);
:func:`run_press_fit` reads the hoop force of the outer tube on its cut
``x = 0``, the radial displacements of mantle and bore at 45 degrees and the
contact pressure along the arc.
"""
from __future__ import annotations

import os
import re
import shutil
import subprocess
import time
from dataclasses import dataclass

import numpy as np

#: C3D8 face numbers: y = y_j (bottom of an element) and y = y_{j+1} (top) with the node order used here.
FACE_BOTTOM, FACE_TOP = 3, 5


@dataclass(frozen=True)
class Blocks:
    """Dimensions [m], elastic constants [Pa] of both bodies, mesh divisions and the top's displacement [m]."""

    length: float
    h_block: float
    h_base: float
    E: float
    nu: float
    nx: int
    ny_block: int
    ny_base: int
    press: float
    shear: float = 0.0
    thickness: float = 1e-3


#: The base reaches this fraction of the length beyond both ends of the block, so that the end nodes of the
#: block's bottom project inside a master face (exactly on its edge ccx finds no face and drops the node).
OVERHANG = 1e-5


def _grid(b: Blocks, y0: float, y1: float, ny: int, first: int, overhang: float = 0.0):
    """Node numbers ``[j, i, k]`` and coordinates of a structured slab of ``nx x ny x 1`` cells."""
    d = overhang * b.length
    xs, ys, zs = np.linspace(-d, b.length + d, b.nx + 1), np.linspace(y0, y1, ny + 1), (0.0, b.thickness)
    ids = first + np.arange((ny + 1) * (b.nx + 1) * 2).reshape(ny + 1, b.nx + 1, 2)
    lines = [f"{ids[j, i, k]}, {xs[i]:.12g}, {ys[j]:.12g}, {zs[k]:.12g}" for j in range(ny + 1) for i in range(b.nx + 1)
             for k in range(2)]
    return ids, lines


def _elements(ids, first: int) -> list[tuple[int, list[int]]]:
    out: list[tuple[int, list[int]]] = []
    for j in range(ids.shape[0] - 1):
        for i in range(ids.shape[1] - 1):
            n = [ids[j, i, 0], ids[j, i + 1, 0], ids[j + 1, i + 1, 0], ids[j + 1, i, 0],
                 ids[j, i, 1], ids[j, i + 1, 1], ids[j + 1, i + 1, 1], ids[j + 1, i, 1]]
            out.append((first + len(out), n))
    return out


def slave_nodes(b: Blocks) -> np.ndarray:
    """Node numbers ``[i, k]`` of the block's bottom (``x_i = i L / nx``, ``k`` through the thickness)."""
    first = (b.ny_base + 1) * (b.nx + 1) * 2 + 1
    return first + np.arange((b.nx + 1) * 2).reshape(b.nx + 1, 2)


def deck(b: Blocks, interaction: str) -> str:
    """The ccx input deck of the two blocks with the ``*SURFACE INTERACTION`` block ``interaction``."""
    base_ids, base_nodes = _grid(b, -b.h_base, 0.0, b.ny_base, 1, OVERHANG)
    block_ids, block_nodes = _grid(b, 0.0, b.h_block, b.ny_block, int(base_ids.max()) + 1)
    assert np.array_equal(block_ids[0], slave_nodes(b))  # the numbering results() relies on
    base_el = _elements(base_ids, 1)
    block_el = _elements(block_ids, len(base_el) + 1)
    nx = b.nx
    L = ["** two blocks pressed (and sheared) through an ngcontact interface law; plane strain slab",
         "*NODE"] + base_nodes + block_nodes
    L += ["*ELEMENT, TYPE=C3D8I, ELSET=BASE"] + [f"{e}, " + ", ".join(map(str, n)) for e, n in base_el]
    L += ["*ELEMENT, TYPE=C3D8I, ELSET=BLOCK"] + [f"{e}, " + ", ".join(map(str, n)) for e, n in block_el]
    L += ["*ELSET, ELSET=SLAVE_EL"] + [str(e) for e, _ in block_el[:nx]]
    L += ["*ELSET, ELSET=MASTER_EL"] + [str(e) for e, _ in base_el[-nx:]]
    L += ["*SURFACE, NAME=SLAVE", f"SLAVE_EL, S{FACE_BOTTOM}", "*SURFACE, NAME=MASTER", f"MASTER_EL, S{FACE_TOP}"]
    L += ["*NSET, NSET=ALLN"] + [str(n) for n in np.concatenate([base_ids.ravel(), block_ids.ravel()])]
    L += ["*NSET, NSET=BOTTOM"] + [str(n) for n in base_ids[0].ravel()]
    L += ["*NSET, NSET=TOP"] + [str(n) for n in block_ids[-1].ravel()]
    L += ["*MATERIAL, NAME=SOLID", "*ELASTIC", f"{b.E:.12g}, {b.nu:.12g}",
          "*SOLID SECTION, ELSET=BASE, MATERIAL=SOLID", "*SOLID SECTION, ELSET=BLOCK, MATERIAL=SOLID"]
    L += [interaction.rstrip("\n")]
    name = re.search(r"\*SURFACE INTERACTION,\s*NAME=(\S+)", interaction)
    pair = name.group(1) if name else "NGCONTACT_LAW"
    L += [f"*CONTACT PAIR, INTERACTION={pair}, TYPE=NODE TO SURFACE, SMALL SLIDING",
          "SLAVE, MASTER",
          "*BOUNDARY", "ALLN, 3, 3, 0.0", "BOTTOM, 1, 2, 0.0",
          "*STEP, INC=200", "*STATIC", "0.1, 1.0, 1e-6, 0.2",
          "*BOUNDARY", f"TOP, 1, 1, {b.shear:.12g}", f"TOP, 2, 2, {-b.press:.12g}",
          "*NODE PRINT, NSET=TOP, TOTALS=ONLY", "RF",
          "*CONTACT PRINT", "CSTR",
          "*END STEP"]
    return "\n".join(L) + "\n"


def _last_block(text: str, title: str) -> list[list[str]]:
    """Rows of the last block of the ``.dat`` file whose title line contains ``title``."""
    blocks: list[list[list[str]]] = []
    rows: list[list[str]] = []
    inside = False
    for line in text.splitlines():
        if title in line:
            if inside:
                blocks.append(rows)
            rows, inside = [], True
        elif inside and line.strip() and line.lstrip()[0].isalpha():
            blocks.append(rows)
            rows, inside = [], False
        elif inside and line.strip():
            rows.append(line.split())
    if inside:
        blocks.append(rows)
    if not blocks:
        raise RuntimeError(f"ccx wrote no '{title}' block")
    return blocks[-1]


def results(dat: str, b: Blocks) -> dict:
    """Reaction on the block's top per metre (``rf_x, rf_y`` [N/m]) and the contact stresses at the slave nodes.

    ``x`` [m]: the slave nodes' abscissae; ``pressure`` and ``shear`` [Pa]:
    ccx's normal and first tangential contact stress there (0 where a node
    has no contact element).
    """
    rf = _last_block(dat, "total force (fx,fy,fz)")
    fx, fy = float(rf[0][0]), float(rf[0][1])
    stress = {int(r[0]): (float(r[1]), float(r[2])) for r in _last_block(dat, "contact stress")}
    ids = slave_nodes(b)
    vals = np.array([[stress.get(int(n), (0.0, 0.0)) for n in row] for row in ids]).mean(axis=1)
    return {"rf_x": fx / b.thickness, "rf_y": fy / b.thickness, "x": np.linspace(0, b.length, b.nx + 1),
            "pressure": vals[:, 0], "shear": vals[:, 1]}


@dataclass(frozen=True)
class PressFit:
    """Quarter of two coaxial tubes in plane strain: radii ``a < b < c`` [m], elastic constants [Pa], divisions.

    The interference is the exported law's macro gap ``g0 < 0`` (its table
    shifted to negative overclosures), so the mesh has both tubes meeting on
    ``r = b`` and no load.
    """

    a: float
    b: float
    c: float
    E: float
    nu: float
    n_theta: int
    n_inner: int
    n_outer: int
    thickness: float = 1e-3


def _ring(f: PressFit, r0: float, r1: float, nr: int, first: int, overhang: float = 0.0):
    """Nodes ``[j, i, k]`` (radius ``j``, angle ``i``, thickness ``k``) of a quarter ring and their lines."""
    d = overhang * np.pi / 2
    rs, ts, zs = np.linspace(r0, r1, nr + 1), np.linspace(-d, np.pi / 2 + d, f.n_theta + 1), (0.0, f.thickness)
    ids = first + np.arange((nr + 1) * (f.n_theta + 1) * 2).reshape(nr + 1, f.n_theta + 1, 2)
    lines = [f"{ids[j, i, k]}, {rs[j] * np.cos(ts[i]):.12g}, {rs[j] * np.sin(ts[i]):.12g}, {zs[k]:.12g}"
             for j in range(nr + 1) for i in range(f.n_theta + 1) for k in range(2)]
    return ids, lines


def _ring_elements(ids, first: int) -> list[tuple[int, list[int]]]:
    """Hexahedra with the radial direction first (``e_r, e_theta, e_z`` right-handed): face 4 at the
    element's larger radius, face 6 at its smaller one."""
    out: list[tuple[int, list[int]]] = []
    for j in range(ids.shape[0] - 1):
        for i in range(ids.shape[1] - 1):
            n = [ids[j, i, 0], ids[j + 1, i, 0], ids[j + 1, i + 1, 0], ids[j, i + 1, 0],
                 ids[j, i, 1], ids[j + 1, i, 1], ids[j + 1, i + 1, 1], ids[j, i + 1, 1]]
            out.append((first + len(out), n))
    return out


def press_fit_deck(f: PressFit, interaction: str) -> tuple[str, dict]:
    """The ccx deck of the press fit and the node numbers :func:`press_fit_results` reads."""
    inner, inner_lines = _ring(f, f.a, f.b, f.n_inner, 1)
    outer, outer_lines = _ring(f, f.b, f.c, f.n_outer, int(inner.max()) + 1, OVERHANG)
    inner_el = _ring_elements(inner, 1)
    outer_el = _ring_elements(outer, len(inner_el) + 1)
    nt = f.n_theta
    name = re.search(r"\*SURFACE INTERACTION,\s*NAME=(\S+)", interaction)
    L = ["** quarter of two coaxial tubes pressed together by the interference of an ngcontact law; plane strain",
         "*NODE"] + inner_lines + outer_lines
    L += ["*ELEMENT, TYPE=C3D8I, ELSET=INNER"] + [f"{e}, " + ", ".join(map(str, n)) for e, n in inner_el]
    L += ["*ELEMENT, TYPE=C3D8I, ELSET=OUTER"] + [f"{e}, " + ", ".join(map(str, n)) for e, n in outer_el]
    L += ["*ELSET, ELSET=SLAVE_EL"] + [str(e) for e, _ in inner_el[-nt:]]
    L += ["*ELSET, ELSET=MASTER_EL"] + [str(e) for e, _ in outer_el[:nt]]
    L += ["*SURFACE, NAME=SLAVE", "SLAVE_EL, S4", "*SURFACE, NAME=MASTER", "MASTER_EL, S6"]
    L += ["*NSET, NSET=ALLN"] + [str(n) for n in np.concatenate([inner.ravel(), outer.ravel()])]
    L += ["*NSET, NSET=SYM_Y"] + [str(n) for n in np.concatenate([inner[:, 0].ravel(), outer[:, 0].ravel()])]
    L += ["*NSET, NSET=SYM_X"] + [str(n) for n in np.concatenate([inner[:, -1].ravel(), outer[:, -1].ravel()])]
    L += ["*NSET, NSET=OUTER_SYM_X"] + [str(n) for n in outer[:, -1].ravel()]
    L += ["*NSET, NSET=MANTLE_MID"] + [str(n) for n in outer[-1, nt // 2]]
    L += ["*NSET, NSET=BORE_MID"] + [str(n) for n in inner[0, nt // 2]]
    L += ["*MATERIAL, NAME=SOLID", "*ELASTIC", f"{f.E:.12g}, {f.nu:.12g}",
          "*SOLID SECTION, ELSET=INNER, MATERIAL=SOLID", "*SOLID SECTION, ELSET=OUTER, MATERIAL=SOLID",
          interaction.rstrip("\n"),
          f"*CONTACT PAIR, INTERACTION={name.group(1) if name else 'NGCONTACT_LAW'}, TYPE=NODE TO SURFACE, "
          "SMALL SLIDING", "SLAVE, MASTER",
          "*BOUNDARY", "ALLN, 3, 3, 0.0", "SYM_Y, 2, 2, 0.0", "SYM_X, 1, 1, 0.0",
          "*STEP, INC=200", "*STATIC", "0.1, 1.0, 1e-6, 0.2",
          "*NODE PRINT, NSET=OUTER_SYM_X, TOTALS=ONLY", "RF",
          "*NODE PRINT, NSET=MANTLE_MID", "U", "*NODE PRINT, NSET=BORE_MID", "U",
          "*CONTACT PRINT", "CSTR", "*END STEP"]
    return "\n".join(L) + "\n", {"slave": inner[-1], "mantle": outer[-1, nt // 2], "bore": inner[0, nt // 2]}


def press_fit_results(dat: str, f: PressFit, nodes: dict) -> dict:
    """Hoop force of the outer tube on ``x = 0`` [N/m], radial displacements at 45 degrees [m], pressures [Pa]."""
    hoop = float(_last_block(dat, "total force (fx,fy,fz) for set OUTER_SYM_X")[0][0]) / f.thickness
    disp = {}
    for key, nset in (("mantle", "MANTLE_MID"), ("bore", "BORE_MID")):
        rows = _last_block(dat, f"displacements (vx,vy,vz) for set {nset}")
        u = np.mean([[float(v) for v in r[1:3]] for r in rows], axis=0)
        disp[key] = float(u @ np.array([1.0, 1.0]) / np.sqrt(2.0))
    stress = {int(r[0]): float(r[1]) for r in _last_block(dat, "contact stress")}
    p = np.array([[stress.get(int(n), 0.0) for n in row] for row in nodes["slave"]]).mean(axis=1)
    return {"hoop": hoop, "u_mantle": disp["mantle"], "u_bore": disp["bore"], "pressure": p,
            "theta": np.linspace(0.0, np.pi / 2, f.n_theta + 1)}


def run_press_fit(f: PressFit, interaction: str, workdir: str, *, ccx: str = "ccx", timeout: float = 600.0) -> dict:
    """Like :func:`run`, for the press fit; :func:`press_fit_results` plus ``seconds``."""
    text, nodes = press_fit_deck(f, interaction)
    dat, seconds = _ccx(text, workdir, "pressfit", ccx, timeout)
    res = press_fit_results(dat, f, nodes)
    res["seconds"] = seconds
    return res


def ccx_path() -> str | None:
    """The ``ccx`` executable on ``PATH``, or ``None``."""
    return shutil.which("ccx")


def run(b: Blocks, interaction: str, workdir: str, *, ccx: str = "ccx", timeout: float = 600.0) -> dict:
    """Write the deck into ``workdir``, run ``ccx`` and return :func:`results` plus ``seconds`` and ``deck``.

    Raises
    ------
    RuntimeError
        ccx failed (its last output lines in the message) or wrote no results.
    """
    dat, seconds = _ccx(deck(b, interaction), workdir, "blocks", ccx, timeout)
    res = results(dat, b)
    res.update(seconds=seconds, deck=os.path.join(workdir, "blocks.inp"))
    return res


def _ccx(text: str, workdir: str, job: str, ccx: str, timeout: float) -> tuple[str, float]:
    """Write ``workdir/job.inp``, run ccx on one thread; its ``.dat`` text and the wall time [s]."""
    os.makedirs(workdir, exist_ok=True)
    with open(os.path.join(workdir, job + ".inp"), "w", encoding="utf-8") as fh:
        fh.write(text)
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    t0 = time.perf_counter()
    proc = subprocess.run([ccx, "-i", job], cwd=workdir, capture_output=True, text=True, timeout=timeout, env=env)
    seconds = time.perf_counter() - t0
    out = proc.stdout + proc.stderr
    dat = os.path.join(workdir, job + ".dat")
    if proc.returncode != 0 or "*ERROR" in out or not os.path.isfile(dat):
        raise RuntimeError("ccx failed:\n" + "\n".join(out.splitlines()[-15:]))
    with open(dat, encoding="utf-8") as fh:
        return fh.read(), seconds
