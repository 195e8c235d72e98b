"""The package's version: that of the installed distribution, or the source tree's own.

A leaf: it imports nothing of the package, so that the package face
(``ngcontact/__init__.py``), the runner, the command line and the exporters
stamp their reports and files with it without importing one another.
"""
from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("ngcontact")
except PackageNotFoundError:  # running from a source tree
    __version__ = "0.1.0"
