"""Run a validated scene: dispatch to its kind's driver and assemble the report.

The one code path behind ``ngcontact run`` and the Python API::

    report, outcome = ngcontact.solve(ngcontact.load("geometries/femur_stem.toml"))

``report`` is the JSON-ready dictionary (see the README's report reference);
``outcome`` keeps the NGSolve objects (meshes, fields) for further work.
Nothing is written to disk; :func:`ngcontact.report.write_outputs` does that.
"""
from __future__ import annotations

import importlib

from . import __version__
from . import scene as scene_mod
from .report import Clock, Outcome, build_report


def solve(scene, progress=None) -> tuple[dict, Outcome]:
    """Solve ``scene`` (a validated scene or a path to a scene file).

    Parameters
    ----------
    scene
        The result of :func:`ngcontact.load`, or a file path.
    progress
        Optional callable receiving one line per stage (e.g. ``print``).

    Returns
    -------
    (report, outcome)
    """
    if not hasattr(scene, "kind"):
        scene = scene_mod.load(scene)
    clock = Clock(progress)
    module, func = scene_mod.KINDS[scene.kind].runner.split(":")
    outcome = getattr(importlib.import_module(module), func)(scene, clock)
    report = build_report(kind=scene.kind, title=getattr(scene, "title", ""),
                          scene=scene_mod.as_dict(scene), effects=scene_mod.effects(scene),
                          outcome=outcome, timings=clock.total(), version=__version__)
    return report, outcome
