"""``ngcontact export``: a scene's interface law written in one format into an output directory.

Formats and files: ``abaqus`` -> ``interface_law_abaqus.inp``, ``calculix`` ->
``interface_law_calculix.inp``, ``ansys`` -> ``interface_law_ansys.mac``,
``json`` -> ``interface_law.json`` (:mod:`ngcontact.export.abaqus`,
:mod:`~ngcontact.export.calculix`, :mod:`~ngcontact.export.ansys`,
:mod:`~ngcontact.export.json_law`).  The directory obeys the rules of
``run --out`` (:mod:`ngcontact.output.writer`): only the package's own files
are written, atomically; an export adds its file to those of earlier runs
and exports in the directory.
"""
from __future__ import annotations

from ngcontact._version import __version__
from ngcontact.errors import ModelError
from ngcontact.export import abaqus, ansys, calculix, json_law
from ngcontact.export.law_source import exported_law
from ngcontact.export.law_table import ExportedLaw
from ngcontact.output.writer import check_output_dir, write_text_files
from ngcontact.scene import loader

FORMATS = {"abaqus": ("interface_law_abaqus.inp", abaqus.text),
           "calculix": ("interface_law_calculix.inp", calculix.text),
           "ansys": ("interface_law_ansys.mac", ansys.text),
           "json": ("interface_law.json", json_law.text)}


def warnings(law: ExportedLaw, fmt: str) -> tuple[str, ...]:
    """What format ``fmt`` cannot carry of ``law`` (empty for JSON)."""
    if fmt == "json":
        return ()
    return calculix.notes(law) if fmt == "calculix" else law.notes


def check(path: str, fmt: str, out: str) -> list[str]:
    """Refuse an unknown format, an invalid scene or a forbidden ``out`` before any work; the scene's inputs."""
    if fmt not in FORMATS:
        raise ModelError(f"--format {fmt!r}: must be one of " + ", ".join(FORMATS))
    inputs = loader.inputs(loader.load(path), path)
    check_output_dir(out, inputs, [FORMATS[fmt][0]])
    return inputs


def export(path: str, fmt: str, out: str, **options) -> tuple[str, ExportedLaw]:
    """Write the law of scene ``path`` in format ``fmt`` into ``out``; the file's path and the law.

    ``options``: ``length_unit``, ``p_max``, ``tolerance``, ``mu`` of
    :func:`ngcontact.export.law_source.exported_law`.
    """
    inputs = check(path, fmt, out)
    law = exported_law(path, **options)
    name, render = FORMATS[fmt]
    real = write_text_files(out, {name: render(law)}, inputs, version=__version__)
    return f"{real}/{name}", law
