#!/usr/bin/env python3
"""Fails when a function, lambda or class body in the run session's ring (src/wheelins/run,
src/wheelins/study, python, app) is longer than 80 lines (issue "One run session...").

Counts every top-level brace block of each .cpp (namespaces and extern "C" are not blocks),
from the line of its opening brace to the line of its closing one, after taking out comments
and the contents of string and character literals. A class with its members written inside
counts as one block: define long members outside the class body.

Usage: scripts/check-function-length.py [SOURCE_DIR] [--max N]
"""
import pathlib
import re
import sys

FOLDERS = ["src/wheelins/run", "src/wheelins/study", "python", "app"]
STRING = re.compile(r'"(\\.|[^"\\])*"')
CHAR = re.compile(r"'(\\.|[^'\\])*'")
NAMESPACE = re.compile(r'^\s*(inline\s+)?namespace\b[^;{]*\{|^\s*extern\s+"C"\s*\{')


def code_lines(text):
    """The file's lines with comments and literal contents blanked (braces in them do not count)."""
    out, in_comment = [], False
    for line in text.split("\n"):
        line = STRING.sub('""', CHAR.sub("''", line))
        kept = ""
        k = 0
        while k < len(line):
            if in_comment:
                end = line.find("*/", k)
                if end < 0:
                    k = len(line)
                else:
                    in_comment, k = False, end + 2
            elif line.startswith("//", k):
                break
            elif line.startswith("/*", k):
                in_comment, k = True, k + 2
            else:
                kept += line[k]
                k += 1
        out.append(kept)
    return out


def long_blocks(path, limit):
    lines = code_lines(path.read_text(encoding="utf-8"))
    found, depth, opened, namespaces = [], 0, None, []
    for i, line in enumerate(lines):
        if NAMESPACE.match(line):  # its brace opens no block; its closing brace is skipped below
            namespaces.append(depth)
            line = line[line.index("{") + 1:]
        for ch in line:
            if ch == "{":
                if depth == 0:
                    opened = i
                depth += 1
            elif ch == "}":
                if depth == 0 and namespaces:
                    namespaces.pop()
                    continue
                depth -= 1
                if depth == 0 and opened is not None:
                    if i - opened + 1 > limit:
                        found.append((i - opened + 1, opened + 1))
                    opened = None
    return found


def main(argv):
    limit = 80
    if "--max" in argv:
        k = argv.index("--max")
        limit = int(argv[k + 1])
        del argv[k:k + 2]
    root = pathlib.Path(argv[1] if len(argv) > 1 else ".")
    bad, files = [], 0
    for folder in FOLDERS:
        for path in sorted((root / folder).rglob("*.cpp")):
            files += 1
            for n, line in long_blocks(path, limit):
                bad.append(f"{path.relative_to(root)}:{line}: a block of {n} lines (at most {limit})")
    if files == 0:
        print(f"check-function-length: no .cpp files under {root} in {', '.join(FOLDERS)}", file=sys.stderr)
        return 2
    for b in bad:
        print(b, file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
