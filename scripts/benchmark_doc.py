"""Measured figures into ``docs/benchmarks.md``: one section per script, rewritten from the script's own CSV.

The figures of the project's studies (timings, Newton steps, errors against
reference solutions) live in ``docs/benchmarks.md``, not in docstrings: they
belong to one machine, one commit and one day.  Each section of that file is
delimited by the HTML comments ``<!-- section: NAME -->`` and
``<!-- end: NAME -->`` and is written only by :func:`publish`, called by the
script that measured the figures (its ``--publish`` flag) right after it has
written its CSV.  :func:`publish` replaces that one section (other sections
and the text between them are kept byte for byte) with

* a heading (the section's title),
* a stamp line: the command that produced the figures, the git commit
  (``git rev-parse --short HEAD``, ``+dirty`` when tracked files outside the
  benchmark document differ from it), the machine (CPU model, core count,
  total memory, load average when published) and the date,
* the script's note (what the columns mean, how to read them),
* the CSV as a Markdown table (the chosen columns; numbers to ``DIGITS``
  significant digits),
* a link to the script's PNG, if it wrote one: the PNG is copied to
  ``docs/benchmarks/NAME.png``, because the scripts' output directories
  (``results/`` by default) are not under version control, so a link into
  them would be dead in any other clone.

A section missing from the document is appended at its end.  A CSV that
cannot be a table (missing, empty, ragged rows, unknown columns) is refused
with :class:`BenchmarkDocError` and the document is left as it was.

Usage from a script (``scripts/`` is on ``sys.path`` when a script runs)::

    import benchmark_doc
    benchmark_doc.add_flag(parser)
    ...
    if args.publish:
        benchmark_doc.publish("scaling_3d", "3D at scale", csv_path, columns=[...], note="...",
                              png=png_path)
"""
from __future__ import annotations

import argparse
import csv
import datetime
import os
import re
import shlex
import shutil
import subprocess
import sys
from collections.abc import Sequence

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
#: the benchmark document and the folder of its figures' PNG copies
DOC = os.path.join(ROOT, "docs", "benchmarks.md")
#: significant digits of the numbers in a table
DIGITS = 4

_NAME = re.compile(r"^[A-Za-z0-9_]+$")


class BenchmarkDocError(ValueError):
    """A CSV, section name or document that :func:`publish` cannot turn into a section."""


def begin_marker(section: str) -> str:
    return f"<!-- section: {section} -->"


def end_marker(section: str) -> str:
    return f"<!-- end: {section} -->"


def add_flag(parser: argparse.ArgumentParser) -> None:
    """The scripts' ``--publish`` flag."""
    parser.add_argument("--publish", action="store_true",
                        help="also rewrite this script's section of docs/benchmarks.md from the CSV just written "
                             "(stamped with commit, machine, date and this command)")


def git_commit(root: str = ROOT) -> str:
    """``git rev-parse --short HEAD``, plus ``+dirty`` when tracked files differ from it.

    The benchmark document itself and its PNG folder are left out of the
    check: publishing one section must not mark the next one dirty.
    """
    try:
        head = subprocess.run(["git", "-C", root, "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, check=True).stdout.strip()
        status = subprocess.run(["git", "-C", root, "status", "--porcelain", "--untracked-files=no", "--", ".",
                                 ":(exclude)docs/benchmarks.md", ":(exclude)docs/benchmarks"],
                                capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown commit"
    return head + ("+dirty" if status else "")


def _read_field(path: str, key: str) -> str | None:
    try:
        with open(path) as fh:
            for line in fh:
                name, sep, value = line.partition(":")
                if sep and name.strip() == key:
                    return value.strip()
    except OSError:
        return None
    return None


def machine() -> str:
    """CPU model, core count, total memory (from ``/proc`` where it exists) and the load average of the last minute.

    The load tells a reader of a timing whether the machine was shared while it ran.
    """
    import platform
    cpu = _read_field("/proc/cpuinfo", "model name") or platform.processor() or platform.machine() or "unknown CPU"
    cores = os.cpu_count() or 0
    mem = _read_field("/proc/meminfo", "MemTotal")
    memory = "memory unknown"
    if mem and mem.split()[0].isdigit():
        memory = f"{int(mem.split()[0]) / 2 ** 20:.1f} GiB memory"
    load = f", load average {os.getloadavg()[0]:.1f}" if hasattr(os, "getloadavg") else ""
    return f"{cpu}, {cores} cores, {memory}{load}"


def command_line(argv: Sequence[str] | None = None) -> str:
    """The command that ran this process: ``python`` and the script relative to the repository, its arguments."""
    argv = list(sys.argv if argv is None else argv)
    script = argv[0] if argv else ""
    if script and os.path.isabs(script) and os.path.commonpath([ROOT, os.path.abspath(script)]) == ROOT:
        script = os.path.relpath(script, ROOT)
    return shlex.join(["python", script] + argv[1:])


def _cell(value: str) -> str:
    text = value.strip()
    try:
        number = float(text)
    except ValueError:
        return text.replace("|", "\\|").replace("\n", " ")
    if re.fullmatch(r"[+-]?\d+", text) or text.lower() in ("nan", "inf", "-inf"):
        return text
    return f"{number:.{DIGITS}g}"


def read_table(csv_path: str, columns: Sequence[str] | None = None) -> tuple[list[str], list[list[str]]]:
    """Header and rows of ``csv_path``, restricted to ``columns`` (all when ``None``); refused when malformed."""
    try:
        with open(csv_path, newline="") as fh:
            rows = list(csv.reader(fh))
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise BenchmarkDocError(f"{csv_path}: cannot read the CSV ({err})") from None
    if not rows or not any(h.strip() for h in rows[0]):
        raise BenchmarkDocError(f"{csv_path}: no header")
    header = [h.strip() for h in rows[0]]
    if any(not h for h in header) or len(set(header)) != len(header):
        raise BenchmarkDocError(f"{csv_path}: empty or repeated column names in the header {header}")
    body = [r for r in rows[1:] if r]
    if not body:
        raise BenchmarkDocError(f"{csv_path}: no rows")
    ragged = [k + 2 for k, r in enumerate(body) if len(r) != len(header)]
    if ragged:
        raise BenchmarkDocError(f"{csv_path}: rows {ragged[:5]} do not have the header's {len(header)} fields")
    wanted = list(header if columns is None else columns)
    unknown = [c for c in wanted if c not in header]
    if unknown or not wanted:
        raise BenchmarkDocError(f"{csv_path}: columns {unknown or wanted} not in the header {header}")
    index = [header.index(c) for c in wanted]
    return wanted, [[r[i] for i in index] for r in body]


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(_cell(v) for v in row) + " |" for row in rows]
    return "\n".join(lines)


def _span(text: str, section: str) -> tuple[int, int] | None:
    """Start of the begin marker and end of the end marker of ``section`` in ``text``; ``None`` if absent."""
    begin, end = begin_marker(section), end_marker(section)
    nb, ne = text.count(begin), text.count(end)
    if nb == ne == 0:
        return None
    if nb != 1 or ne != 1 or text.index(begin) > text.index(end):
        raise BenchmarkDocError(f"section {section!r}: expected one {begin} followed by one {end}")
    return text.index(begin), text.index(end) + len(end)


def render(section: str, title: str, body: str) -> str:
    """The whole section, markers included."""
    return f"{begin_marker(section)}\n## {title}\n\n{body.strip()}\n{end_marker(section)}"


def replace_section(text: str, section: str, block: str) -> str:
    """``text`` with ``section`` (markers included) replaced by ``block``, or ``block`` appended."""
    span = _span(text, section)
    if span is None:
        return text.rstrip("\n") + "\n\n" + block + "\n"
    return text[:span[0]] + block + text[span[1]:]


def publish(section: str, title: str, csv_path: str, columns: Sequence[str] | None = None, note: str = "",
            png: str | None = None, command: str | None = None, doc: str = DOC) -> str:
    """Rewrite section ``section`` of ``doc`` from ``csv_path`` (module docstring); returns the new section.

    ``columns``: the CSV's columns to show, in order (default all); ``note``:
    Markdown shown above the table; ``png``: the script's plot, copied to
    ``docs/benchmarks/SECTION.png`` beside ``doc`` and linked (skipped with a
    line in the section when the file is missing); ``command``: the command
    in the stamp (default: this process's, :func:`command_line`).
    """
    if not _NAME.match(section):
        raise BenchmarkDocError(f"section name {section!r}: letters, digits and underscores only")
    header, rows = read_table(csv_path, columns)
    try:
        with open(doc) as fh:
            text = fh.read()
    except FileNotFoundError:
        text = "# Benchmarks\n"
    _span(text, section)   # a malformed section is refused before anything is written
    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    parts = [f"Generated by `{command or command_line()}` at commit `{git_commit()}` on {machine()}, {date}."]
    if note.strip():
        parts.append(note.strip())
    parts.append(markdown_table(header, rows))
    if png is not None:
        if os.path.isfile(png):
            folder = os.path.join(os.path.dirname(os.path.abspath(doc)), "benchmarks")
            os.makedirs(folder, exist_ok=True)
            shutil.copyfile(png, os.path.join(folder, f"{section}.png"))
            parts.append(f"![{title}](benchmarks/{section}.png)")
        else:
            parts.append(f"(no plot: {os.path.basename(png)} was not written)")
    block = render(section, title, "\n\n".join(parts))
    tmp = doc + ".tmp"
    os.makedirs(os.path.dirname(os.path.abspath(doc)), exist_ok=True)
    with open(tmp, "w") as fh:
        fh.write(replace_section(text, section, block))
    os.replace(tmp, doc)
    print(f"published section {section} of {os.path.relpath(doc)}")
    return block
