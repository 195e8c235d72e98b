"""Exceptions raised by ngcontact.

Every error a user can cause names the offending key path, the value given and
what would have been allowed, so that a scene file can be fixed from the
message alone.
"""
from __future__ import annotations


class _Missing:
    """Stands for a key that is absent from the scene."""

    def __repr__(self) -> str:
        return "<missing>"


MISSING = _Missing()


class NgcontactError(Exception):
    """Base class of all errors raised by the package.

    The errors of this module pickle with the arguments they were made of (``__reduce__`` where these are not
    the message alone), so that one raised in a worker process or on MPI rank 0 is raised alike where it is
    received."""


class SceneError(NgcontactError):
    """An invalid scene: ``path = value: what is allowed``.

    Parameters
    ----------
    path
        Dotted key path in the scene, e.g. ``materials.bone.nu``.
    value
        The offending value (``repr`` goes into the message).
    allowed
        What would have been accepted.
    """

    def __init__(self, path: str, value, allowed: str):
        self.path = path
        self.value = value
        self.allowed = allowed
        super().__init__(f"{path} = {_show(value)}: {allowed}")

    def __reduce__(self):
        return type(self), (self.path, self.value, self.allowed)


class ConvergenceError(NgcontactError):
    """A nonlinear solve that did not converge; carries its iteration history."""

    def __init__(self, message: str, history: dict):
        self.history = history
        super().__init__(message)

    def __reduce__(self):
        return type(self), (str(self), self.history)


class ModelError(NgcontactError, ValueError):
    """Physically inadmissible input met by the model code (not a solver failure).

    Raised by the numerics (materials, laws, problems) with the name of the
    quantity, its value and what is allowed; a ``ValueError`` as well, so
    that the scene layer can translate it into a :class:`SceneError` with
    the key path.  The command line maps it to exit status 2.
    """


class GeometryError(ModelError):
    """An inadmissible geometry argument: ``name = value: what is allowed``.

    Raised by :mod:`ngcontact.geometry` with its own argument names (a
    profile's ``width``, a data file's name); the scene layer translates it
    into a :class:`SceneError` with the scene's key path, and a caller
    outside a scene sees the argument name.  A :class:`ModelError`, so the
    command line maps it to exit status 2.
    """

    def __init__(self, name: str, value, allowed: str):
        self.name = name
        self.value = value
        self.allowed = allowed
        super().__init__(f"{name} = {_show(value)}: {allowed}")

    def __reduce__(self):
        return type(self), (self.name, self.value, self.allowed)


class BatchError(NgcontactError):
    """A member of a batch of independent solves failed twice (its retry too): ``label: member: reason``.

    The batch returns nothing; the command line maps it to exit status 3.
    """

    def __init__(self, label: str, member: str, reason: str):
        self.label = label
        self.member = member
        self.reason = reason
        super().__init__(f"{label}: {member} failed twice: {reason}")

    def __reduce__(self):
        return type(self), (self.label, self.member, self.reason)


class OutputError(NgcontactError):
    """The output directory cannot be written."""


#: Strings longer than this are shown by their start and their length (a message is one line to read).
SHOW_CHARACTERS = 256


def _show(value) -> str:
    if isinstance(value, str):
        if len(value) > SHOW_CHARACTERS:
            head = repr(value[:40])
            return f"{head[:-1]}...{head[-1]} ({len(value)} characters)"
        return repr(value)
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, (list, tuple)):  # as the scene writes it: a TOML array
        if len(value) > 8:
            return f"[{', '.join(_show(v) for v in value[:8])}, ...] ({len(value)} entries)"
        return f"[{', '.join(_show(v) for v in value)}]"
    if isinstance(value, dict):
        return "{" + ", ".join(sorted(value)) + "}"
    return repr(value)
