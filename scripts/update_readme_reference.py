"""Regenerate the scene-file reference in README.md from the scene schema.

The tables between the markers ``<!-- scene-reference:begin -->`` and
``<!-- scene-reference:end -->`` are written from the same field metadata that
validates scenes, so documentation and validation cannot drift apart.
``tests/test_readme.py`` fails when the README is out of date.

Usage: python scripts/update_readme_reference.py [--check]
"""
from __future__ import annotations

import argparse
import os
import sys

from ngcontact.geometry.tabulated import MAX_DATA_BYTES
from ngcontact.scene import law_file
from ngcontact.scene.kinds import KINDS
from ngcontact.scene.schema import MAX_SCENE_BYTES, MAX_STRING, describe

BEGIN = "<!-- scene-reference:begin -->"
END = "<!-- scene-reference:end -->"
README = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "README.md")


def reference() -> str:
    """Markdown tables, one per scene kind, after the limits every scene obeys."""
    out = [f"A scene file is UTF-8 text (a byte-order mark is skipped) of at most {MAX_SCENE_BYTES // 2 ** 20} MiB; "
           f"every string and every table name in it has at most {MAX_STRING} characters; the data files it names "
           f"(profiles, gaps, height maps: {MAX_DATA_BYTES // 2 ** 20} MiB; law files: "
           f"{law_file.MAX_BYTES // 2 ** 20} MiB) and the cell scenes it names must be regular files.\n"]
    for name in sorted(KINDS):
        cls = KINDS[name].scene
        doc = (cls.__module__ and sys.modules[cls.__module__].__doc__ or "").strip().splitlines()
        out.append(f"### kind = \"{name}\"\n")
        if doc:
            out.append(doc[0].split(": ", 1)[-1] + "\n")
        out.append("| key | type | default | units | allowed | meaning |")
        out.append("|---|---|---|---|---|---|")
        for row in describe(cls):
            cells = [f"`{row['key']}`", row["type"], row["default"], row["units"] or "-",
                     row["allowed"], row["doc"]]
            out.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
        out.append("")
        docs = getattr(sys.modules[cls.__module__], "BOUNDARY_DOCS", None)
        if docs:
            out.append(f"Boundary labels of kind `{name}` (for `[[supports]]` and `[[loads]]`; a support without "
                       "`components` fixes all of them):\n")
            out.append("| geometry | label | what it is |")
            out.append("|---|---|---|")
            for key, labels in docs.items():
                where = " / ".join(key) if isinstance(key, tuple) else key
                for label, text in labels.items():
                    out.append(f"| {where} | `{label}` | {text} |")
            out.append("")
    return "\n".join(out)


def updated(text: str) -> str:
    if BEGIN not in text or END not in text:
        raise SystemExit(f"README.md lacks the markers {BEGIN} ... {END}")
    head, rest = text.split(BEGIN, 1)
    _, tail = rest.split(END, 1)
    return f"{head}{BEGIN}\n{reference()}\n{END}{tail}"


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="exit 1 if README.md is out of date")
    args = p.parse_args()
    with open(README) as fh:
        text = fh.read()
    new = updated(text)
    if args.check:
        return 0 if new == text else 1
    with open(README, "w") as fh:
        fh.write(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
