"""Run a validated scene: dispatch to its kind's driver and assemble the report.

The one code path behind ``ngcontact run`` and the Python API::

    report, outcome = ngcontact.solve(ngcontact.load("geometries/femur_stem.toml"))

``report`` is the JSON-ready dictionary (see the README's report reference);
``outcome`` keeps the NGSolve objects (meshes, fields) for further work.
Nothing is written to disk; :func:`ngcontact.output.report.write_outputs` does that.
"""
from __future__ import annotations

import importlib
from typing import Callable

from ngcontact import __version__
from ngcontact.output.report import Clock, Outcome, build_report
from ngcontact.scene import loader

#: kind -> the driver module whose ``run(scene, clock)`` solves it; imported
#: on first use, so that ``ngcontact check`` stays light.
DRIVERS = {
    "manufactured": "ngcontact.drivers.run_manufactured",
    "cell": "ngcontact.drivers.run_cell",
    "macro": "ngcontact.drivers.run_macro",
    "direct": "ngcontact.drivers.run_resolved",
}


def solve(scene, progress: Callable[[str], None] | None = None) -> tuple[dict, Outcome]:
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
        scene = loader.load(scene)
    clock = Clock(progress)
    outcome = importlib.import_module(DRIVERS[scene.kind]).run(scene, clock)
    report = build_report(kind=scene.kind, title=getattr(scene, "title", ""),
                          scene=loader.as_dict(scene), effects=loader.effects(scene),
                          outcome=outcome, timings=clock.total(), version=__version__)
    return report, outcome
