#!/usr/bin/env python3
"""scripts/check_skips.py on fake CTest JUnit files: an allowed skip passes; a skip that is
not on the allow-list, or that printed another reason than the allowed one, fails."""

import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(ROOT, "scripts", "check_skips.py")

ALLOW = """# name regex     reason
blender34_cycles_huang   has no Huang model
capi_ctypes              numpy is not installed
"""


def case(name, status, output=""):
    """One <testcase> of ctest's JUnit output."""
    skipped = '<skipped message="SKIP_RETURN_CODE=77"/>' if status == "notrun" else ""
    failure = '<failure message="Failed"/>' if status == "fail" else ""
    return ('<testcase name="%s" classname="%s" time="0.1" status="%s">%s%s'
            '<system-out>%s</system-out></testcase>'
            % (name, name, status, skipped, failure, output))


def junit(*cases):
    return ('<?xml version="1.0" encoding="UTF-8"?>\n<testsuite name="hairis" tests="%d">%s'
            '</testsuite>\n' % (len(cases), "".join(cases)))


class CheckSkipsTest(unittest.TestCase):
    def setUp(self):
        self.folder = tempfile.TemporaryDirectory()
        self.allow = os.path.join(self.folder.name, "allowed_skips.txt")
        with open(self.allow, "w") as stream:
            stream.write(ALLOW)

    def tearDown(self):
        self.folder.cleanup()

    def check(self, text, allow=None):
        """(exit code, output) of check_skips.py on the JUnit ``text``."""
        path = os.path.join(self.folder.name, "junit.xml")
        with open(path, "w") as stream:
            stream.write(text)
        result = subprocess.run([sys.executable, SCRIPT, path, "--allow", allow or self.allow],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                universal_newlines=True)
        return result.returncode, result.stdout

    def test_allowed_skip_passes(self):
        code, output = self.check(junit(
            case("render_test.Furnace", "run", "ok"),
            case("blender34_cycles_huang", "notrun",
                 "installing\nSKIP: Blender 3.4.1 has no Huang model\n"),
            case("chi2_test.Fit", "fail", "a failure is ctest's business, not this check's")))
        self.assertEqual(code, 0, output)
        self.assertIn("1 skipped test(s), 1 allowed", output)

    def test_skip_off_the_list_fails_naming_it(self):
        code, output = self.check(junit(
            case("blender34_cycles_huang", "notrun", "SKIP: Blender 3.4.1 has no Huang model"),
            case("bpy45_native_render", "notrun",
                 "SKIP: libhairis.so is not built yet (looked for /x/lib/libhairis.so)")))
        self.assertEqual(code, 1, output)
        self.assertIn("FAIL: bpy45_native_render skipped, not on the allow-list", output)
        self.assertIn("libhairis.so is not built yet", output)
        self.assertNotIn("FAIL: blender34_cycles_huang", output)

    def test_listed_test_skipping_for_another_reason_fails(self):
        code, output = self.check(junit(case(
            "blender34_cycles_huang", "notrun", "SKIP: libhairis.so is not built yet")))
        self.assertEqual(code, 1, output)
        self.assertIn("allowed only for 'has no Huang model'", output)

    def test_name_regex_matches_the_whole_name(self):
        code, output = self.check(junit(case(
            "blender34_cycles_huang_legacy", "notrun", "SKIP: Blender 3.4 has no Huang model")))
        self.assertEqual(code, 1, output)

    def test_skip_without_reason_fails(self):
        code, output = self.check(junit(case("capi_ctypes", "notrun", "")))
        self.assertEqual(code, 1, output)
        self.assertIn("no SKIP line", output)

    def test_unreadable_inputs_are_errors(self):
        code, output = self.check("<testsuite><testcase")
        self.assertEqual(code, 2, output)
        bad = os.path.join(self.folder.name, "bad.txt")
        with open(bad, "w") as stream:
            stream.write("lonely_name_without_reason\n")
        code, output = self.check(junit(), allow=bad)
        self.assertEqual(code, 2, output)
        self.assertIn("needs a reason", output)

    def test_committed_allow_list_reads(self):
        code, output = self.check(junit(case("chi2_test.Fit", "run")),
                                  allow=os.path.join(ROOT, "tests", "allowed_skips.txt"))
        self.assertEqual(code, 0, output)


if __name__ == "__main__":
    unittest.main()
