#!/usr/bin/env python3
"""Fails when CTest skipped a test that the allow-list does not name with its reason.

    check_skips.py JUNIT.xml [--allow tests/allowed_skips.txt]

JUNIT.xml is what ``ctest --output-junit`` wrote. A skipped test (exit code 77 under
SKIP_RETURN_CODE, or a disabled one) is allowed only when a line of the allow-list matches it:

    # comment
    NAME_REGEX   REASON

NAME_REGEX must match the whole CTest name, and REASON (the rest of the line) must occur in
one of the test's ``SKIP: ...`` output lines: a test allowed to skip for one reason (Blender
3.4 has no Huang model) fails the check when it skips for another (the add-on zip lost its
library). Exit code 0 when every skip is allowed, 1 otherwise (each offender named), 2 when
the inputs cannot be read.
"""

import argparse
import os
import re
import sys
import xml.etree.ElementTree as ElementTree

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_ALLOW = os.path.join(ROOT, "tests", "allowed_skips.txt")
SKIP_LINE = "SKIP: "
"""The prefix every skipping test prints its reason with (helpers.skip, run_test.py, CMake)."""


class InputError(Exception):
    """The allow-list or the JUnit file cannot be read."""


def read_allow_list(path):
    """[(compiled name regex, reason)] from the allow-list at ``path``."""
    entries = []
    with open(path, encoding="utf-8") as stream:
        for number, raw in enumerate(stream, 1):
            line = raw.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.split(None, 1)
            if len(parts) != 2:
                raise InputError("%s:%d: a name regex needs a reason after it: %r"
                                 % (path, number, line))
            try:
                pattern = re.compile(parts[0])
            except re.error as error:
                raise InputError("%s:%d: bad regex %r: %s" % (path, number, parts[0], error))
            entries.append((pattern, parts[1].strip()))
    return entries


def skipped_tests(junit_path):
    """[(name, [reason printed after 'SKIP: ', ...])] of every skipped test in the JUnit file."""
    try:
        root = ElementTree.parse(junit_path).getroot()
    except (OSError, ElementTree.ParseError) as error:
        raise InputError("cannot read %s: %s" % (junit_path, error))
    skipped = []
    for case in root.iter("testcase"):
        if case.find("skipped") is None and case.get("status") not in ("notrun", "disabled"):
            continue
        output = case.findtext("system-out") or ""
        reasons = [line.split(SKIP_LINE, 1)[1].strip()
                   for line in output.splitlines() if SKIP_LINE in line]
        skipped.append((case.get("name", "?"), reasons))
    return skipped


def unallowed(skipped, allow):
    """[(name, why)] of the skipped tests that no allow-list entry covers."""
    offenders = []
    for name, reasons in skipped:
        entries = [reason for pattern, reason in allow if pattern.fullmatch(name)]
        if not entries:
            offenders.append((name, "not on the allow-list (it printed: %s)"
                              % ("; ".join(reasons) or "no SKIP line")))
        elif not any(entry in printed for entry in entries for printed in reasons):
            offenders.append((name, "allowed only for %s, but it printed: %s"
                              % (" or ".join(repr(e) for e in entries),
                                 "; ".join(reasons) or "no SKIP line")))
    return offenders


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("junit", help="the file ctest --output-junit wrote")
    parser.add_argument("--allow", default=DEFAULT_ALLOW, help="the allow-list")
    args = parser.parse_args(argv)
    try:
        allow = read_allow_list(args.allow)
        skipped = skipped_tests(args.junit)
    except (OSError, InputError) as error:
        print("check_skips: %s" % error)
        return 2
    offenders = unallowed(skipped, allow)
    for name, why in offenders:
        print("check_skips: FAIL: %s skipped, %s" % (name, why))
    allowed = len(skipped) - len(offenders)
    print("check_skips: %d skipped test(s), %d allowed by %s, %d not allowed"
          % (len(skipped), allowed, os.path.relpath(args.allow), len(offenders)))
    return 1 if offenders else 0


if __name__ == "__main__":
    sys.exit(main())
