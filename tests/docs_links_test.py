#!/usr/bin/env python3
"""Checks the documentation: every relative link and image in README.md, CONTRIBUTING.md,
addon/README.md and docs/**/*.md names an existing file (and, for a Markdown target, an existing
heading when it has an anchor), and README.md is at most 15360 bytes.

Usage: docs_links_test.py [REPOSITORY_ROOT]. Before checking the repository it checks itself on
a small tree with one broken link, one broken anchor and an oversized README, which it must
report.
"""

import os
import re
import sys
import tempfile

README_LIMIT = 15360
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
FENCE = re.compile(r"^\s*(```|~~~)")
INLINE_CODE = re.compile(r"`[^`]*`")
HEADING = re.compile(r"^\s{0,3}(#{1,6})\s+(.*?)\s*#*\s*$")


def documents(root):
    """The Markdown files whose links are checked, relative to ``root``."""
    names = ("README.md", "CONTRIBUTING.md", os.path.join("addon", "README.md"))
    found = [name for name in names if os.path.isfile(os.path.join(root, name))]
    for folder, _, files in os.walk(os.path.join(root, "docs")):
        found += [os.path.relpath(os.path.join(folder, name), root)
                  for name in files if name.endswith(".md")]
    return sorted(found)


def prose_lines(text):
    """The lines outside fenced code blocks, with inline code removed, numbered from 1."""
    fenced = False
    for number, line in enumerate(text.split("\n"), 1):
        if FENCE.match(line):
            fenced = not fenced
            continue
        if not fenced:
            yield number, INLINE_CODE.sub("", line)


def slug(heading):
    """GitHub's anchor for a heading: lower case, punctuation dropped, spaces as hyphens."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading).strip().lower()
    text = "".join(c for c in text if c.isalnum() or c in " -_")
    return text.replace(" ", "-")


def anchors(path):
    """Every anchor the headings of a Markdown file define (repeats get -1, -2, ...)."""
    seen, result = {}, set()
    with open(path, encoding="utf-8") as handle:
        for _, line in prose_lines(handle.read()):
            match = HEADING.match(line)
            if match:
                base = slug(match.group(2))
                count = seen.get(base, 0)
                seen[base] = count + 1
                result.add(base if count == 0 else "%s-%d" % (base, count))
    return result


def problems(root):
    """Every broken link and size violation under ``root``, as messages."""
    found = []
    readme = os.path.join(root, "README.md")
    if os.path.isfile(readme) and os.path.getsize(readme) > README_LIMIT:
        found.append("README.md: %d bytes, more than the %d allowed"
                     % (os.path.getsize(readme), README_LIMIT))
    for document in documents(root):
        source = os.path.join(root, document)
        with open(source, encoding="utf-8") as handle:
            text = handle.read()
        for number, line in prose_lines(text):
            for match in LINK.finditer(line):
                target = match.group(1)
                if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
                    continue  # http:, https:, mailto:
                path, _, anchor = target.partition("#")
                resolved = source if not path else os.path.normpath(
                    os.path.join(os.path.dirname(source), path))
                where = "%s:%d: %s" % (document, number, target)
                if not os.path.exists(resolved):
                    found.append(where + ": no such file")
                elif anchor and resolved.endswith(".md") and anchor not in anchors(resolved):
                    found.append(where + ": no heading with anchor #" + anchor)
    return found


def self_test():
    """The checker reports a missing file, a missing anchor and an oversized README."""
    with tempfile.TemporaryDirectory() as root:
        os.makedirs(os.path.join(root, "docs"))
        with open(os.path.join(root, "docs", "a.md"), "w", encoding="utf-8") as handle:
            handle.write("# A page\n\n## The seed's slips\n\n"
                         "[ok](#the-seeds-slips) [up](../README.md)\n"
                         "```\n[ignored](missing-in-code.md)\n```\n")
        with open(os.path.join(root, "README.md"), "w", encoding="utf-8") as handle:
            handle.write("[fine](docs/a.md#the-seeds-slips) ![img](docs/missing.png) "
                         "[bad anchor](docs/a.md#nowhere) `[code](nope.md)`\n")
            handle.write("x" * README_LIMIT)
        found = problems(root)
        expected = ("more than the", "docs/missing.png: no such file",
                    "no heading with anchor #nowhere")
        missing = [e for e in expected if not any(e in p for p in found)]
        if missing or len(found) != len(expected):
            print("docs_links_test: the checker itself is wrong: expected %s, got %s"
                  % (expected, found))
            return False
    return True


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else
                           os.path.join(os.path.dirname(__file__), ".."))
    if not self_test():
        return 1
    found = problems(root)
    for message in found:
        print(message)
    print("docs_links_test: %d documents, %d problems" % (len(documents(root)), len(found)))
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
