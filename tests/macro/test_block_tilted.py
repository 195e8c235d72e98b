"""The homogenized block as a macro scene against its resolved counterpart under the same tilted load.

``geometries/macro/block_tilted.toml`` is ``geometries/direct/block_rect_valleys.toml`` homogenized and
mirrored in ``y`` (the macro block has its rough body on top): its reaction on ``bottom`` is the resolved
reaction on ``top`` with ``y`` and the moment mirrored.
"""
from pathlib import Path

import numpy as np
import pytest

from ngcontact.drivers import run_macro as RM
from ngcontact.drivers import run_resolved as drv
from ngcontact.drivers import study_epsilon as S
from ngcontact.laws import homogenized as il
from ngcontact.scene.loader import load

ROOT = Path(__file__).resolve().parents[2]


def _mirrored(r: dict) -> np.ndarray:
    return np.array([r["x"], -r["y"], -r["moment"]])


def _vector(r: dict) -> np.ndarray:
    return np.array([r["x"], r["y"], r["moment"]])


def _relative(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Relative error of the force vector and of the moment of ``a`` against ``b``."""
    return (float(np.linalg.norm(a[:2] - b[:2]) / np.linalg.norm(b[:2])), abs(a[2] - b[2]) / abs(b[2]))


@pytest.mark.slow
def test_the_homogenized_block_scene_has_the_resolved_reaction_within_O_eps(tmp_path, monkeypatch):
    """The macro scene's reaction: within 0.1 eps of the resolved one (force and moment), and within 1e-3 of
    the epsilon study's own homogenized run on the direct scene's flat bodies (the same problem on another
    mesh)."""
    monkeypatch.setenv("NGCONTACT_CACHE", str(tmp_path))
    direct = load(ROOT / "geometries" / "direct" / "block_rect_valleys.toml")
    macro = load(ROOT / "geometries" / "macro" / "block_tilted.toml")
    geo = RM.build_geometry(macro)
    problem, info = RM.problem_of(macro, geo)
    assert info["type"] == "bundle"
    homogenized = _mirrored(RM.reactions(RM.solve_scene(macro, problem))["bottom"])
    resolved = _vector(drv.reactions(direct, drv.solve_scene(direct, drv.problem_of(direct,
                                                                                      drv.build_resolved(direct))))["top"])
    flat = drv.build_flat(direct, direct.study.interface_maxh)
    study = _vector(drv.reactions(direct, S.solve_homogenized(direct, flat, il.InterfaceLaw(
        normal=S.cell_bundle(direct))))["top"])
    eps = drv.eps_of(direct, direct.geometry.periods)
    force, moment = _relative(homogenized, resolved)
    assert max(force, moment) <= 0.1 * eps, (force, moment)
    assert max(_relative(homogenized, study)) <= 1e-3
