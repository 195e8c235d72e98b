"""ngcontact: contact of elastic bodies with periodically rough interfaces.

Two-scale asymptotic homogenization (Orlik 2004) on NGSolve: periodic cell
problems give a homogenized interface law for a macro problem.  See the
README for the Python API and the scene-file reference.
"""
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("ngcontact")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0.1.0"

from ngcontact.errors import ConvergenceError, ModelError, NgcontactError, SceneError  # noqa: E402
from ngcontact.scene.loader import load  # noqa: E402
from ngcontact.runner import solve  # noqa: E402

__all__ = ["ConvergenceError", "ModelError", "NgcontactError", "SceneError", "load", "solve", "__version__"]
