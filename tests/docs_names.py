#!/usr/bin/env python3
"""Every file and symbol that README.md, docs/*.md and docs/log/*.md name in backticks exists.

    python3 tests/docs_names.py SOURCE

Outside fenced code blocks, a backticked span is checked when it is
* a repository path: its first folder is one of the repository's (or it
  starts with ../shared/, resolved against SOURCE's parent), and it names a
  file (its last part has an extension), a folder (it ends in /) or a
  pattern (a * or a <name> part, as in scenes/<name>.scn): the file or
  folder must exist, the pattern match something.
  Scene names without .scn (`bench/glass`) are not paths;
* a source file by its bare name (`ShaderObject.h`, `trace.comp`): some file
  of the repository must have that name;
* `FILE:NUMBER`: the file must have that many lines; `FILE:name` or
  `FILE::name`: name must occur in the file as a word;
* `Type::name` (C++ scope): name must occur as a word in the sources;
* a file followed by (`name`) or , `name`: name must occur in that file;
* in a table row that names files, a `name()`: it must occur in one of the
  row's files (those of its own cell, if its cell names any).
Prints one line a missing name, "DOC:LINE: ...", and a count; exits 1 if any.
"""
import glob
import os
import re
import sys

SOURCE_EXTENSIONS = ("cpp", "h", "hpp", "comp", "glsl", "sh", "py", "cmake")
IDENTIFIER = r"[A-Za-z_][A-Za-z0-9_]*"
NAME = re.compile(rf"^(?:{IDENTIFIER}::)*({IDENTIFIER})(?:\(\))?$")
SCOPED = re.compile(rf"^(?:{IDENTIFIER}::)+({IDENTIFIER})(?:\(\))?$")
FUNCTION = re.compile(rf"^(?:{IDENTIFIER}::)*({IDENTIFIER})\(\)$")
SPAN = re.compile(r"`([^`]+)`")

source = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
shared_parent = os.path.dirname(source)
top_folders = {e for e in os.listdir(source) if os.path.isdir(os.path.join(source, e)) and not e.startswith(".")}
top_folders.discard("build")

# Every file of the repository by its name (build trees and git's own left out).
by_name = {}
for root, dirs, files in os.walk(source):
    dirs[:] = [d for d in dirs if not d.startswith(".") and not d.startswith("build")]
    for f in files:
        by_name.setdefault(f, []).append(os.path.join(root, f))
code_files = [p for ps in by_name.values() for p in ps
              if p.rsplit(".", 1)[-1] in SOURCE_EXTENSIONS
              and os.path.relpath(p, source).split(os.sep)[0] in ("host", "shaders", "tests", "bench", "scripts")]

_texts = {}


def text_of(path):
    if path not in _texts:
        try:
            with open(path, encoding="utf-8", errors="replace") as f:
                _texts[path] = f.read()
        except OSError:
            _texts[path] = ""
    return _texts[path]


def has_word(paths, name):
    word = re.compile(rf"(?<![A-Za-z0-9_]){re.escape(name)}(?![A-Za-z0-9_])")
    return any(word.search(text_of(p)) for p in paths)


problems = []
checked = {"paths": 0, "names": 0}
shared_missing = not os.path.isdir(os.path.join(shared_parent, "shared"))


def resolve(span):
    """The files a span names: (kind, [paths]) or None when it names none.
    kind: 'file', 'folder', 'glob', 'bare'; paths empty when missing."""
    if re.search(r"\s", span) or span.startswith(("-", "~", "/", "$")):
        return None
    if span.startswith("../shared/"):
        if shared_missing:
            return None
        base, rest = shared_parent, span[len("../"):]
    elif "/" in span and span.split("/", 1)[0] in top_folders:
        base, rest = source, span
    elif "/" not in span and re.fullmatch(r"[A-Za-z0-9_.+-]+\.(%s)" % "|".join(SOURCE_EXTENSIONS), span):
        return "bare", by_name.get(span, [])
    else:
        return None
    full = os.path.join(base, re.sub(r"<[^<>/]*>", "*", rest))  # host/cli/<Name>Command.cpp: a pattern
    if "*" in full:
        return "glob", glob.glob(full)
    if rest.endswith("/"):
        return "folder", [full] if os.path.isdir(full) else []
    if re.search(r"\.[A-Za-z0-9]+$", rest.rsplit("/", 1)[-1]):
        return "file", [full] if os.path.isfile(full) else []
    return None


def check_doc(doc):
    rel = os.path.relpath(doc, source)
    lines = text_of(doc).split("\n")
    fenced = False
    for i, line in enumerate(lines):  # blank the fenced blocks, keeping the line numbers
        if line.lstrip().startswith("```"):
            fenced = not fenced
            lines[i] = ""
        elif fenced:
            lines[i] = ""
    text = "\n".join(lines)
    starts = [0]
    for line in lines:
        starts.append(starts[-1] + len(line) + 1)

    def line_of(offset):
        lo, hi = 0, len(starts) - 1
        while lo < hi - 1:
            mid = (lo + hi) // 2
            lo, hi = (mid, hi) if starts[mid] <= offset else (lo, mid)
        return lo + 1

    def report(offset, span, why):
        problems.append(f"{rel}:{line_of(offset)}: `{span}`: {why}")

    def check_name(offset, span, name, files, where):
        checked["names"] += 1
        if not has_word(files, name):
            report(offset, span, f"no '{name}' in {where}")

    for m in SPAN.finditer(text):
        span = m.group(1).strip()
        # FILE:NUMBER, FILE:name, FILE::name
        target, suffix = span, None
        parts = re.match(r"^([^:\s]+?)(::?)([^:\s].*)$", span)
        if parts and resolve(parts.group(1)) is not None:
            target, suffix = parts.group(1), parts.group(3)
        resolved = resolve(target)
        if resolved is None:
            scoped = SCOPED.match(span)
            if scoped:
                check_name(m.start(), span, scoped.group(1), code_files, "the sources")
            continue
        kind, files = resolved
        checked["paths"] += 1
        if not files:
            report(m.start(), span, {"glob": "matches no file", "folder": "no such folder",
                                     "bare": "no file of that name in the repository"}.get(kind, "no such file"))
            continue
        if kind in ("folder", "glob"):
            continue
        if suffix is not None:
            if suffix.isdigit():
                checked["names"] += 1
                if len(text_of(files[0]).split("\n")) < int(suffix):
                    report(m.start(), span, f"{target} has fewer than {suffix} lines")
            elif NAME.match(suffix):
                check_name(m.start(), span, NAME.match(suffix).group(1), files, target)
            continue
        # FILE (`name`) or FILE, `name`
        after = re.match(r"\s*(?:\(\s*|,\s*)`([^`]+)`", text[m.end():m.end() + 200])
        if after and NAME.match(after.group(1).strip()):
            check_name(m.end(), after.group(1), NAME.match(after.group(1).strip()).group(1), files, target)

    # Table rows: a function named in a row that names files.
    for number, line in enumerate(lines, 1):
        if not line.lstrip().startswith("|"):
            continue
        cells = re.split(r"(?<!\\)\|", line)
        cell_files = []
        for cell in cells:
            found = []
            for span in SPAN.findall(cell):
                resolved = resolve(span.strip())
                if resolved and resolved[0] in ("file", "bare"):
                    found += resolved[1]
            cell_files.append(found)
        row_files = [p for found in cell_files for p in found]
        if not row_files:
            continue
        for cell, found in zip(cells, cell_files):
            for span in SPAN.findall(cell):
                function = FUNCTION.match(span.strip())
                if function:
                    files = found or row_files
                    checked["names"] += 1
                    if not has_word(files, function.group(1)):
                        problems.append(f"{rel}:{number}: `{span}`: no '{function.group(1)}' in "
                                        + ", ".join(os.path.relpath(p, source) for p in files))


docs = [os.path.join(source, "README.md")] + sorted(glob.glob(os.path.join(source, "docs", "*.md"))) + sorted(
    glob.glob(os.path.join(source, "docs", "log", "*.md")))
for doc in docs:
    check_doc(doc)
for p in problems:
    print(p)
note = " (../shared is absent: its paths were not checked)" if shared_missing else ""
print(f"docs names: {len(docs)} docs, {checked['paths']} paths and {checked['names']} names checked, "
      f"{len(problems)} missing{note}")
sys.exit(1 if problems else 0)
