"""ngcontact: contact of elastic bodies with periodically rough interfaces.

Two-scale asymptotic homogenization (Orlik 2004) on NGSolve: periodic cell
problems give a homogenized interface law for a macro problem.  See the
README for the Python API (a scene's solve; the law of a cell on a mesh of
one's own NGSolve script: ``cell_law``, ``interface_form``, ``solve_mesh``)
and the scene-file reference.
"""
from ngcontact._version import __version__
from ngcontact.errors import ConvergenceError, ModelError, NgcontactError, SceneError
# the runner first: it opens the window in which the run's first look reads the free cores
# (ngcontact.parallel.free_cores.OPENING) before NGSolve and the scene's modules load
from ngcontact.runner import solve, solve_mesh
from ngcontact.scene.loader import load

__all__ = ["ConvergenceError", "ModelError", "NgcontactError", "SceneError", "cell_law", "interface_form", "load",
           "solve", "solve_mesh", "__version__"]



def __getattr__(name: str):
    """``cell_law`` (a homogenized law from a cell scene) and ``interface_form`` (its energy on the caller's
    mesh), imported when first asked for (the face imports the runner, not the model code)."""
    if name == "cell_law":
        from ngcontact.drivers.cell_scene_law import cell_law
        return cell_law
    if name == "interface_form":
        from ngcontact.macro.interface_form import interface_form
        return interface_form
    raise AttributeError(f"module 'ngcontact' has no attribute {name!r}")
