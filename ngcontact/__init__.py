"""ngcontact: contact of elastic bodies with periodically rough interfaces.

Two-scale asymptotic homogenization (Orlik 2004) on NGSolve: periodic cell
problems give a homogenized interface law for a macro problem.  See the
README for the Python API and the scene-file reference.
"""
from ngcontact._version import __version__
from ngcontact.errors import ConvergenceError, ModelError, NgcontactError, SceneError
from ngcontact.scene.loader import load
from ngcontact.runner import solve

__all__ = ["ConvergenceError", "ModelError", "NgcontactError", "SceneError", "load", "solve", "__version__"]
