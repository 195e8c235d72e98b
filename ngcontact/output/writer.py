"""Writing a run's files into the user's output directory without harming anything else in it.

The contract, for ``ngcontact run SCENE --out DIR`` and every study:

* Only the package's own files are written: ``report.json``, its page
  ``report.html`` (:mod:`ngcontact.output.report_html`: the report, the
  PNGs embedded and the CSV tables, one self-contained file), the CSV
  tables, the VTK files and the PNG plots of the outcome, and the manifest
  ``.ngcontact-manifest.json`` that lists them.  ``DIR`` is created when
  missing (with the user's umask); an existing ``DIR`` keeps its mode, its
  owner and every file the package did not write.  A symbolic link ``DIR``
  is followed, never replaced; a path whose links loop is refused before
  any work.
* A rerun replaces the files the manifest of the previous run lists (and
  removes those of them the new run does not write); a file of the same
  name that no manifest lists is the user's, and the run is refused before
  anything is written.
* Only names of the kind the package writes (:func:`is_own_name`) are ever
  written, replaced or removed: a manifest entry of any other name (one
  edited in by hand: ``thesis.tex``, a path, ``..``) is ignored with a
  warning, never deleted, and no longer listed.
* ``DIR`` must not contain the scene or any file the scene reads (the
  directory ``.``, a parent, a data folder): refused before any work.
* Atomic as a whole: every file is first written into a staging directory
  ``.ngcontact-partial-<pid>-<host>-<random>`` beside or inside ``DIR``, on
  the same file system (``<host>``: :func:`host_tag`); the files are then
  moved into place by renames, with SIGINT and SIGTERM held back, and the
  manifest last.  A failure or an interruption before that leaves ``DIR`` as
  it was and removes the staging directory; one left behind by a killed run
  of this machine (its process no longer exists) is removed by the next run
  that stages there.  Another machine's (a file system shared by a
  cluster's nodes) is never removed: its process number means nothing here.

Errors are :class:`~ngcontact.errors.OutputError` with one line naming
``--out`` and the reason.
"""
from __future__ import annotations

import csv
import errno
import glob
import hashlib
import json
import logging
import os
import re
import shutil
import signal
import socket
import tempfile
from contextlib import contextmanager
from typing import TYPE_CHECKING, Iterable

import numpy as np

from ngcontact.errors import OutputError
from ngcontact.output.report import Outcome, file_names, to_plain
from ngcontact.output.report_html import write_html

if TYPE_CHECKING:
    from ngcontact.output.report import VtkField

log = logging.getLogger(__name__)

MANIFEST = ".ngcontact-manifest.json"
#: the files every run writes besides those of its outcome
REPORT_FILES = ("report.json", "report.html")
STAGING_PREFIX = ".ngcontact-partial-"
#: Every file name the package writes into an output directory, and so the only names it ever replaces or
#: removes: the reports, an outcome's tables, VTK files, plots and arrays (lower-case stems,
#: :func:`ngcontact.output.report.file_names`) and the law files of ``ngcontact export``
#: (:data:`ngcontact.export.export_law.FORMATS`) and the scene an accuracy study recommends.  The manifest is
#: handled apart.
OWN_NAMES = re.compile(r"report\.json|report\.html|[a-z][a-z0-9_]*\.(?:csv|vtu|pvtu|png|npy)"
                       r"|interface_law(?:_[a-z]+)?\.(?:inp|mac|json)|recommended\.toml")


def is_own_name(name: str) -> bool:
    """Whether ``name`` is a file name the package writes (:data:`OWN_NAMES`; no path, not the manifest)."""
    return OWN_NAMES.fullmatch(name) is not None


# ---------------------------------------------------------------- the files
def write_csv(path: str, header, rows) -> None:
    """One CSV table: a header row, then the rows (finite numbers only)."""
    rows = to_plain([list(r) for r in rows], os.path.basename(path))
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows(rows)


def write_vtk(path_noext: str, item: VtkField) -> None:
    """One ``.vtu`` file of the fields of ``item`` (NGSolve appends the extension); on a mesh distributed
    over MPI ranks a ``.pvtu`` file and its pieces (``item.pieces``)."""
    if item.pieces is not None:
        item.pieces.write(path_noext, item)
        return
    import ngsolve as ng
    names = list(item.fields)
    ng.VTKOutput(ma=item.mesh, coefs=[item.fields[n] for n in names], names=names,
                 filename=path_noext, subdivision=item.subdivision, legacy=False).Do()


# ---------------------------------------------------------------- the checks
def _inside(path: str, directory: str) -> bool:
    try:
        return os.path.commonpath([path, directory]) == directory
    except ValueError:  # different drives
        return False


def _existing_ancestor(path: str) -> str:
    probe = path
    while not os.path.exists(probe):
        probe = os.path.dirname(probe)
    return probe


def _resolved(out_dir: str) -> str:
    """The real path ``DIR`` stands for, its symbolic links followed; a loop among them is refused here,
    before any work (it would fail only when the files are moved into place)."""
    path = os.path.abspath(out_dir)
    try:
        os.path.realpath(path, strict=True)
    except (FileNotFoundError, NotADirectoryError):  # the missing part is created; a file on the way is refused below
        pass
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise OutputError(f"--out {out_dir}: a symbolic link on the path ({exc.filename}) leads into a loop; "
                              "fix or remove the link, or choose another directory") from None
        raise OutputError(f"--out {out_dir}: cannot be resolved ({exc.strerror}: {exc.filename})") from None
    return os.path.realpath(path)


def own_files(out_dir: str, *, warn: bool = False) -> set[str] | None:
    """The files the package's manifest in ``out_dir`` lists; ``None`` when there is no manifest.

    Entries that are not names the package writes (:func:`is_own_name`) are
    left out (``warn``: with one warning line naming them): they are never
    replaced or removed.

    Raises
    ------
    OutputError
        A file of the manifest's name that is not a manifest of this package.
    """
    path = os.path.join(out_dir, MANIFEST)
    if not os.path.lexists(path):
        return None
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        data = None
    files = data.get("files") if isinstance(data, dict) and data.get("written_by") == "ngcontact" else None
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        raise OutputError(f"--out {out_dir}: {MANIFEST} exists and is not a manifest of ngcontact; "
                          "move it or choose another directory")
    foreign = sorted({f for f in files if not is_own_name(f)})
    if warn and foreign:
        log.warning("ngcontact: %s in %s lists %s, which ngcontact never writes; ignored (kept, not deleted, no "
                    "longer listed)", MANIFEST, out_dir, ", ".join(map(repr, foreign)))
    return {f for f in files if is_own_name(f)}


def check_output_dir(out_dir: str, inputs: Iterable[str] = (), names: Iterable[str] = REPORT_FILES) -> str:
    """Refuse, before any work, an output directory the run may not write; returns its real path.

    Parameters
    ----------
    out_dir
        The ``--out`` directory (need not exist).
    inputs
        The scene file and every file it reads.
    names
        File names the run will write; one that exists and is not the
        package's (no manifest lists it) is refused.
    """
    real = _resolved(out_dir)
    if os.path.exists(real) and not os.path.isdir(real):
        raise OutputError(f"--out {out_dir}: exists and is not a directory")
    for p in inputs:
        if _inside(os.path.realpath(os.path.abspath(p)), real):
            raise OutputError(f"--out {out_dir}: contains {p}, which the scene reads; choose a directory "
                              "that holds no input (the default is results/<scene name>)")
    probe = _existing_ancestor(real)
    if not os.path.isdir(probe) or not os.access(probe, os.W_OK | os.X_OK):
        raise OutputError(f"--out {out_dir}: cannot write in {probe}")
    if os.path.isdir(real):
        ours = own_files(real) or set()
        for name in names:
            if name not in ours and os.path.lexists(os.path.join(real, name)):
                raise OutputError(f"--out {out_dir}: {name} exists and was not written by ngcontact; "
                                  "move it or choose another directory")
    return real


# ---------------------------------------------------------------- staging
def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists (one of another user counts)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        pass
    return True


def host_tag() -> str:
    """Eight hex digits of this machine's name, in its staging directories' names (no ``-``)."""
    return hashlib.sha256(socket.gethostname().encode()).hexdigest()[:8]


def remove_stale_staging(directory: str) -> list[str]:
    """Remove staging directories of this machine's runs whose process no longer exists (a name without a
    machine's tag counts as this machine's); returns their paths."""
    removed = []
    for path in glob.glob(os.path.join(directory, STAGING_PREFIX + "*")):
        parts = os.path.basename(path)[len(STAGING_PREFIX):].split("-")
        pid, elsewhere = parts[0], len(parts) > 2 and parts[1] != host_tag()
        if pid.isdigit() and not elsewhere and os.path.isdir(path) and not os.path.islink(path) \
                and not _alive(int(pid)):
            shutil.rmtree(path, ignore_errors=True)
            removed.append(path)
    return removed


@contextmanager
def _signals_held():
    """Hold SIGINT and SIGTERM back (they arrive after the block) where the platform allows."""
    held = {signal.SIGINT, signal.SIGTERM}
    try:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    except (AttributeError, ValueError, OSError):  # no POSIX signal masks here
        yield
        return
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _move(src: str, dst: str) -> None:
    try:
        os.replace(src, dst)
    except OSError as exc:
        if exc.errno != errno.EXDEV:
            raise
        # the staging directory lies on another file system (DIR was created below a mount point)
        shutil.copy2(src, dst + ".ngcontact-tmp")
        os.replace(dst + ".ngcontact-tmp", dst)


# ---------------------------------------------------------------- the write
def _staged(out_dir: str, names: list[str], inputs: Iterable[str], fill, version, *, keep_previous: bool) -> str:
    """Stage ``fill(tmp)``'s files, then move ``names`` and the manifest into place (the module's contract).

    ``keep_previous``: the manifest also lists the files of earlier runs
    (none is removed); otherwise those the new run does not write are removed.
    """
    foreign = [n for n in names if not is_own_name(n)]
    if foreign:  # a programming error: the package may delete what it writes, so it writes only its own names
        raise ValueError(f"not a file name ngcontact writes: {', '.join(foreign)} (see writer.OWN_NAMES)")
    real = check_output_dir(out_dir, inputs, names)
    stage_in = real if os.path.isdir(real) else _existing_ancestor(real)
    remove_stale_staging(stage_in)
    try:
        tmp = tempfile.mkdtemp(prefix=f"{STAGING_PREFIX}{os.getpid()}-{host_tag()}-", dir=stage_in)
    except OSError as exc:
        raise OutputError(f"--out {out_dir}: cannot write in {stage_in} ({exc.strerror})") from None
    try:
        fill(tmp)
        with _signals_held():
            old = (own_files(real, warn=True) or set()) if os.path.isdir(real) else set()
            listed = sorted(set(names) | ({n for n in old if os.path.lexists(os.path.join(real, n))}
                                          if keep_previous else set()))
            with open(os.path.join(tmp, MANIFEST), "w", encoding="utf-8") as fh:
                json.dump({"written_by": "ngcontact", "version": version, "files": listed}, fh, indent=1)
                fh.write("\n")
            os.makedirs(real, exist_ok=True)
            for name in names:
                _move(os.path.join(tmp, name), os.path.join(real, name))
            for name in sorted(old - set(listed)):
                target = os.path.join(real, name)
                if os.path.isfile(target) or os.path.islink(target):
                    os.remove(target)
            _move(os.path.join(tmp, MANIFEST), os.path.join(real, MANIFEST))
    except OSError as exc:  # e.g. a full disk: an output problem, reported as such
        raise OutputError(f"--out {out_dir}: writing failed ({exc}); the previous output, if any, "
                          "is unchanged") from exc
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return real


def write_outputs(out_dir: str, report: dict, outcome: Outcome, inputs: Iterable[str] = ()) -> str:
    """Write ``report.json``, ``report.html`` and the outcome's files into ``out_dir`` under the contract of this
    module.

    Returns the directory's real path.
    """
    names = file_names(outcome) + list(REPORT_FILES)

    def fill(tmp: str) -> None:
        for name, (header, rows) in outcome.tables.items():
            write_csv(os.path.join(tmp, f"{name}.csv"), header, rows)
        for name, item in outcome.vtk.items():
            write_vtk(os.path.join(tmp, name), item)
        for name, draw in outcome.plots.items():
            draw(os.path.join(tmp, f"{name}.png"))
        for name, array in outcome.arrays.items():
            np.save(os.path.join(tmp, f"{name}.npy"), array, allow_pickle=False)
        for name, text in outcome.texts.items():
            with open(os.path.join(tmp, name), "w", encoding="utf-8") as fh:
                fh.write(text)
        with open(os.path.join(tmp, "report.json"), "w") as fh:
            json.dump(report, fh, indent=2, allow_nan=False)
            fh.write("\n")
        write_html(os.path.join(tmp, "report.html"), report, tmp, file_names(outcome))

    return _staged(out_dir, names, inputs, fill, report.get("version"), keep_previous=False)


def write_text_files(out_dir: str, files: dict[str, str], inputs: Iterable[str] = (), *, version=None) -> str:
    """Write text files ``{name: content}`` into ``out_dir`` under the contract of this module.

    Unlike :func:`write_outputs`, the files of earlier runs stay (an export
    adds its file beside a run's report).  Returns the directory's real path.
    """
    def fill(tmp: str) -> None:
        for name, content in files.items():
            with open(os.path.join(tmp, name), "w", encoding="utf-8") as fh:
                fh.write(content)

    return _staged(out_dir, sorted(files), inputs, fill, version, keep_previous=True)
