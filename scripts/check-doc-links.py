#!/usr/bin/env python3
"""Check the links of README.md, each top-level folder's README.md and docs/**/*.md.

Every relative link target must exist, and a #anchor into a markdown file must name one of
its headings (GitHub's rule: lower case, punctuation dropped, spaces as hyphens, -1, -2 ...
for repeats). Links inside code spans and fenced blocks are ignored.
Usage: check-doc-links.py [repository root]; exit status 1 when a link is broken.
"""
import pathlib
import re
import sys
import urllib.parse


def outside_code(text):
    """The lines of text with fenced blocks blanked and code spans removed."""
    lines, fence = [], False
    for line in text.split("\n"):
        if line.lstrip().startswith("```"):
            fence = not fence
            lines.append("")
            continue
        lines.append("" if fence else re.sub(r"`[^`]*`", "", line))
    return lines


def anchors(path):
    """The anchors GitHub makes for the headings of a markdown file."""
    seen, result, fence = {}, set(), False
    for line in path.read_text().split("\n"):
        if line.lstrip().startswith("```"):
            fence = not fence
            continue
        match = None if fence else re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not match:
            continue
        anchor = re.sub(r"[^\w\- ]", "", match.group(1).lower()).replace(" ", "-")
        repeat = seen.get(anchor, 0)
        seen[anchor] = repeat + 1
        result.add(anchor if repeat == 0 else f"{anchor}-{repeat}")
    return result


def main():
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".").resolve()
    # The README of each top-level folder (Filters/, Benchmarks/, measurements/, ...) too;
    # not the build tree's.
    folders = sorted(p for p in root.glob("*/README.md") if p.parent.name not in ("docs", "build"))
    files = [root / "README.md"] + folders + sorted((root / "docs").rglob("*.md"))
    bad = 0
    for md in files:
        for number, line in enumerate(outside_code(md.read_text()), 1):
            for match in re.finditer(r"\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)", line):
                target = match.group(1)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target):
                    continue  # http:, https:, mailto:
                path, _, fragment = target.partition("#")
                resolved = (md.parent / urllib.parse.unquote(path)).resolve() if path else md
                where = f"{md.relative_to(root)}:{number}"
                if not resolved.exists():
                    print(f"{where}: {target}: no such file")
                    bad += 1
                elif fragment and resolved.suffix == ".md" and fragment not in anchors(resolved):
                    print(f"{where}: {target}: no such heading")
                    bad += 1
    print(f"{len(files)} markdown files, {bad} broken links")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
