#!/usr/bin/env python3
"""Fails, naming each one, on a reference to a file that is not in the repository.

Scans the repository's text files (md, h, cc, json, py, sh, txt, cmake, CMakeLists.txt) for
  - markdown links [text](target) and [text](target#anchor): the target must exist relative to
    the linking file, and an anchor must be a heading of the target (GitHub's slugs);
  - paths rooted at a top-level folder (`station/daemon/judge.h`, `tests/data/x/`, `station/files`):
    the file or folder must exist;
  - bare markdown names (`NOTES.md`): some file of that name must exist in the repository;
  - references out of the checkout (`../shared/...`, `/work/...`): a user's clone has none.
Generated paths are not references: anything under build/ or node_modules/, and tokens with
placeholders (`<area>`, `*`, `{`, `$`).

Usage: check_references.py ROOT       exit 0 when every reference resolves, 1 otherwise
       check_references.py --self-test  checks the checker on a tree it writes (good and bad)
"""
import os
import re
import sys
import tempfile

TEXT_EXTENSIONS = (".md", ".h", ".cc", ".json", ".py", ".sh", ".txt", ".cmake")
SKIP_DIRS = {".git", "node_modules", "__pycache__", "corpus"}
TOP_LEVEL = ("analysis", "cmake", "db", "deploy", "drivers", "recipes", "station", "tests")

MD_LINK = re.compile(r"\[[^\]\n]*\]\(([^)\s]+)\)")
ROOTED = re.compile(r"(?<![\w./~@:-])((?:%s)/[\w./+*<>{}$-]*)" % "|".join(TOP_LEVEL))
BARE_MD = re.compile(r"(?<![\w./-])([A-Za-z][\w-]*\.md)\b")
OUTSIDE = re.compile(r"(\.\./shared\b[\w./-]*|/work/[\w./-]+)")
PLACEHOLDER = re.compile(r"[<>*{}$%]")
# Paths named but not references to files of the checkout: what the daemon looks for at run
# time when a build made it, and "tests/s" (a rate).
NOT_REFERENCES = {"station/web/dist", "tests/s"}


def text_files(root):
    for d, dirs, files in os.walk(root):
        rel = os.path.relpath(d, root)
        dirs[:] = sorted(x for x in dirs if x not in SKIP_DIRS and not
                         (rel == "." and x.startswith("build")))
        for f in sorted(files):
            if f.endswith(TEXT_EXTENSIONS) or f == "CMakeLists.txt":
                yield os.path.join(d, f)


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces to dashes."""
    s = heading.strip().lower()
    s = re.sub(r"[^\w\- ]", "", s)
    return s.replace(" ", "-")


def anchors_of(path, cache):
    if path not in cache:
        found, counts, fence = set(), {}, False
        with open(path, encoding="utf-8", errors="replace") as f:
            for line in f:
                if line.startswith("```"):
                    fence = not fence
                m = None if fence else re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
                if m:
                    base = slug(m.group(1))
                    n = counts.get(base, 0)
                    counts[base] = n + 1
                    found.add(base if n == 0 else "%s-%d" % (base, n))
        cache[path] = found
    return cache[path]


def clean(token):
    return token.rstrip(".,;:)'\"`")


def check_link(root, path, target, anchors):
    if re.match(r"^[a-z][a-z0-9+.-]*:", target) or PLACEHOLDER.search(target):
        return None  # a URL (http:, mailto:) or a placeholder
    file_part, _, anchor = target.partition("#")
    dest = path if not file_part else os.path.normpath(
        os.path.join(os.path.dirname(path), file_part))
    if not os.path.realpath(dest).startswith(os.path.realpath(root)):
        return "link out of the repository: %s" % target
    if not os.path.exists(dest):
        return "link to a missing file: %s" % target
    if anchor and dest.endswith(".md") and anchor not in anchors_of(dest, anchors):
        return "link to a missing heading: %s" % target
    return None


def check_rooted(root, token):
    token = clean(token)
    if PLACEHOLDER.search(token) or "//" in token or token.rstrip("/") in NOT_REFERENCES:
        return None
    first, _, rest = token.partition("/")
    if not rest:
        return None  # "tests/" alone: a folder named in prose
    return None if os.path.exists(os.path.join(root, token)) else "missing: %s" % token


def check_file(root, path, basenames, anchors):
    problems = []
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    for lineno, line in enumerate(text.splitlines(), 1):
        found = []
        if path.endswith(".md"):
            found += [check_link(root, path, m.group(1), anchors) for m in MD_LINK.finditer(line)]
            line = MD_LINK.sub("", line)  # checked as a link: not again as a path
        found += [check_rooted(root, m.group(1)) for m in ROOTED.finditer(line)]
        for m in BARE_MD.finditer(line):
            if m.group(1) not in basenames:
                found.append("no file of this name in the repository: %s" % m.group(1))
        for m in OUTSIDE.finditer(line):
            found.append("refers outside the repository: %s" % clean(m.group(1)))
        rel = os.path.relpath(path, root)
        problems += ["%s:%d: %s" % (rel, lineno, p) for p in found if p]
    return problems


def check_tree(root):
    root = os.path.abspath(root)
    files = list(text_files(root))
    basenames = set()
    for d, dirs, names in os.walk(root):
        dirs[:] = [x for x in dirs if x not in SKIP_DIRS]
        basenames.update(names)
    anchors, problems = {}, []
    for path in files:
        if os.path.samefile(path, __file__):
            continue  # its examples of bad references are not references
        problems += check_file(root, path, basenames, anchors)
    return files, problems


def self_test():
    """The checker must pass a clean tree and name every kind of bad reference."""
    with tempfile.TemporaryDirectory() as root:
        def write(rel, text):
            os.makedirs(os.path.dirname(os.path.join(root, rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w") as f:
                f.write(text)
        write("README.md", "# Top\n## Where to look\nSee [db](db/README.md#records), db/store.h.\n")
        write("db/README.md", "# db\n## Records\nThe [top](../README.md#where-to-look).\n")
        write("db/store.h", "// Contract in db/README.md; see README.md.\n")
        write("build/x.md", "[gone](nothing.md)\n")  # generated: never scanned
        _, clean_problems = check_tree(root)
        if clean_problems:
            print("self-test: a clean tree was refused:\n  " + "\n  ".join(clean_problems))
            return 1
        write("db/store.cc", "// From NOTES.md 3 and station/files/motor_json.h, ../shared/x.\n")
        write("db/CMakeLists.txt", "# see db/gone.h\n")
        write("deploy/OPS.md", "[a](../db/README.md#nope) [b](missing.md) [c](../../out.md)\n")
        _, problems = check_tree(root)
        expected = ["NOTES.md", "station/files/motor_json.h", "../shared/x", "db/gone.h",
                    "#nope", "missing.md", "../../out.md"]
        missed = [e for e in expected if not any(e in p for p in problems)]
        if missed or len(problems) != len(expected):
            print("self-test: expected one problem each for %s, got:\n  %s" %
                  (expected, "\n  ".join(problems)))
            return 1
    print("check_references self-test: a clean tree passes, %d bad references named" %
          len(expected))
    return 0


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    if len(argv) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    files, problems = check_tree(argv[1])
    for p in problems:
        print(p)
    if problems:
        print("check_references: %d references to files that are not in the repository "
              "(%d files scanned)" % (len(problems), len(files)))
        return 1
    print("check_references: every reference of %d files resolves" % len(files))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
