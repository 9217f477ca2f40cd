#!/usr/bin/env python3
"""Runs one headless Blender test script of the hairis add-on; CTest calls this.

    run_test.py (--blender EXE | --bpy-python PYTHON) [--install legacy|extension]
                [--expect-version MAJOR.MINOR]
                [--zip hairis-addon.zip] [--extension-zip hairis-extension.zip]
                [--fake-library libhairis_fake.so] [--timeout SECONDS] tests/blender/test_x.py

Two ways to run Blender:

- ``--blender EXE``: ``EXE -b --factory-startup --python-exit-code 1 --python test_x.py -- ...``
  (Debian's Blender 3.4, or any Blender executable);
- ``--bpy-python PYTHON``: ``PYTHON test_x.py -- ...`` with the Python of a virtual environment
  holding a bpy wheel (Blender 4.5 and 5.0 as Python modules, scripts/setup --with-blender).
  ``import bpy`` starts Blender as ``-b --factory-startup`` does.

``--install`` says how the test installs the add-on: ``legacy`` (the bl_info zip through
``preferences.addon_install``, every version) or ``extension`` (the Extension zip through
``extensions.package_install_files``, Blender 4.2+). User scripts, extensions and configuration
go to temporary folders (BLENDER_USER_SCRIPTS, BLENDER_USER_RESOURCES, BLENDER_USER_CONFIG).

A test is judged by the result line helpers.run() prints last (``hairis-test-result: PASSED``,
``FAILED`` or ``SKIPPED``), not only by the exit code: some bpy 4.5 builds crash at interpreter
exit after the test has finished. Exit code 0 = passed, 77 = skipped (CTest's
SKIP_RETURN_CODE: that Blender is not installed, or the test needs something not built yet),
anything else = failed; a run that prints no result line has failed whatever its exit code.

Standalone use (no CMake build): without --zip / --extension-zip the zips are made from
addon/hairis (no native library inside); without --fake-library the fake library is compiled
from fake_hairis.c with ``cc`` when a compiler is there.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SKIP = 77
RESULT_PREFIX = "hairis-test-result: "
"""The line helpers.run() and helpers.skip() end every test with."""


def build_zip(folder, library=None, extension=False):
    """Zips addon/hairis (and ``library`` as lib/libhairis.so) into ``folder``.

    The legacy zip holds the ``hairis/`` package folder; the Extension zip holds the package's
    files at its root, with blender_manifest.toml.
    """
    source = os.path.join(ROOT, "addon", "hairis")
    name = "hairis-extension.zip" if extension else "hairis-addon.zip"
    prefix = "" if extension else "hairis/"
    path = os.path.join(folder, name)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for entry in sorted(os.listdir(source)):
            if entry.endswith(".py") or (extension and entry == "blender_manifest.toml"):
                archive.write(os.path.join(source, entry), prefix + entry)
        if library:
            archive.write(library, prefix + "lib/libhairis.so")
    return path


def build_fake(folder):
    """Compiles fake_hairis.c into ``folder``; None when no compiler works."""
    compiler = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    if not compiler:
        return None
    output = os.path.join(folder, "libhairis_fake.so")
    command = [compiler, "-std=c11", "-O1", "-fPIC", "-shared", "-fvisibility=hidden",
               "-I" + os.path.join(ROOT, "lib", "include"),
               os.path.join(HERE, "fake_hairis.c"), "-o", output, "-lm"]
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            universal_newlines=True)
    if result.returncode != 0:
        print("run_test: could not compile the fake library:\n" + result.stdout)
        return None
    return output


def blender_environment(keep_prefix=None):
    """This environment minus what the runner's own Python put in it.

    Blender's embedded Python finds its standard library through PATH; a runner started from
    pyenv or a virtualenv would hand it that Python's library (without numpy). So PYTHON*/
    PYENV_* variables and PATH entries inside this interpreter's prefix or pyenv go.
    ``keep_prefix`` (a bpy virtual environment) is never removed from PATH.
    """
    env = dict(os.environ)
    for key in list(env):
        if key in ("PYTHONHOME", "PYTHONPATH", "VIRTUAL_ENV") or key.startswith("PYENV"):
            del env[key]
    system = {"/", "/usr", "/usr/local"}
    prefixes = {os.path.realpath(p) for p in (sys.prefix, sys.base_prefix, sys.exec_prefix)}
    prefixes = [p for p in prefixes if p not in system]
    keep_prefix = os.path.realpath(keep_prefix) if keep_prefix else None

    def keep(folder):
        real = os.path.realpath(folder)
        if keep_prefix and (real == keep_prefix or real.startswith(keep_prefix + os.sep)):
            return True
        if "pyenv" in real.split(os.sep) or ".pyenv" in real.split(os.sep):
            return False
        return not any(real == p or real.startswith(p + os.sep) for p in prefixes)
    env["PATH"] = os.pathsep.join(d for d in env.get("PATH", "").split(os.pathsep)
                                  if d and keep(d))
    return env


def judge(returncode, results):
    """The runner's exit code from Blender's exit code and the result lines it printed."""
    if not results:
        print("run_test: FAIL: the test printed no %r line (exit code %d): it crashed or "
              "stopped before its end" % (RESULT_PREFIX.strip(), returncode))
        return returncode if returncode not in (0, SKIP) and returncode > 0 else 1
    result = results[-1]
    if result == "PASSED":
        if returncode != 0:
            print("run_test: the test passed, then the process exited with code %d (ignored: "
                  "some bpy builds crash at interpreter exit)" % returncode)
        return 0
    if result == "SKIPPED":
        return SKIP
    return 1


def run(command, env, timeout):
    """Runs ``command``, echoing its output; returns (exit code, result lines) or None."""
    process = subprocess.Popen(command, env=env, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, universal_newlines=True,
                               errors="replace")
    results = []

    def pump():
        for line in process.stdout:
            sys.stdout.write(line)
            sys.stdout.flush()
            if line.startswith(RESULT_PREFIX):
                results.append(line[len(RESULT_PREFIX):].strip())
    reader = threading.Thread(target=pump, daemon=True)
    reader.start()
    try:
        returncode = process.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        reader.join(5)
        return None
    reader.join()
    return returncode, results


def main():
    """Parses arguments, prepares the folders, runs Blender, returns the test's exit code."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    runner = parser.add_mutually_exclusive_group()
    runner.add_argument("--blender", help="a Blender executable")
    runner.add_argument("--bpy-python", help="the Python of a virtual environment with bpy")
    parser.add_argument("--install", choices=("legacy", "extension"), default="legacy")
    parser.add_argument("--expect-version", default="",
                        help="MAJOR.MINOR the Blender must be (the test fails otherwise)")
    parser.add_argument("--zip", default=None, help="the legacy add-on zip")
    parser.add_argument("--extension-zip", default=None, help="the Extension zip")
    parser.add_argument("--fake-library", default=None)
    parser.add_argument("--timeout", type=float, default=300.0)
    parser.add_argument("--keep", action="store_true", help="keep the temporary folders")
    parser.add_argument("script")
    args = parser.parse_args()

    bpy_prefix = None
    if args.bpy_python:
        if not os.path.isfile(args.bpy_python):
            print("SKIP: no bpy environment at %s; install it with scripts/setup --with-blender"
                  % os.path.dirname(os.path.dirname(args.bpy_python)))
            return SKIP
        program = os.path.abspath(args.bpy_python)
        bpy_prefix = os.path.dirname(os.path.dirname(program))
    else:
        name = args.blender or os.environ.get("BLENDER", "blender")
        program = shutil.which(name)
        if program is None:
            print("SKIP: Blender is not installed (%r not found); install it with "
                  "scripts/setup --with-blender" % name)
            return SKIP

    temporary = tempfile.mkdtemp(prefix="hairis-blender-test-")
    try:
        user_scripts = os.path.join(temporary, "user_scripts")
        resources = os.path.join(temporary, "user_resources")
        workdir = os.path.join(temporary, "work")
        for folder in (user_scripts, resources, workdir):
            os.makedirs(folder)
        if args.install == "extension":
            zip_path = args.extension_zip or build_zip(temporary, extension=True)
        else:
            zip_path = args.zip or build_zip(temporary)
        fake = args.fake_library or build_fake(temporary) or ""
        env = blender_environment(bpy_prefix)
        env.pop("HAIRIS_LIBRARY", None)
        env.pop("HAIRIS_EXPORT_DUMP", None)
        env["BLENDER_USER_SCRIPTS"] = user_scripts
        env["BLENDER_USER_RESOURCES"] = resources
        env["BLENDER_USER_CONFIG"] = os.path.join(resources, "config")
        env["TMPDIR"] = os.path.join(temporary, "tmp")
        os.makedirs(env["TMPDIR"])
        script_args = ["--", "--zip", os.path.abspath(zip_path), "--install", args.install,
                       "--fake-library", fake, "--workdir", workdir,
                       "--expect-version", args.expect_version]
        if args.bpy_python:
            command = [program, os.path.abspath(args.script)] + script_args
        else:
            command = [program, "-b", "--factory-startup", "--python-exit-code", "1",
                       "--python", os.path.abspath(args.script)] + script_args
        print("run_test: " + " ".join(command), flush=True)
        outcome = run(command, env, args.timeout)
        if outcome is None:
            print("run_test: FAIL: %s did not finish within %.0f s" % (args.script, args.timeout))
            return 1
        return judge(*outcome)
    finally:
        if args.keep:
            print("run_test: kept " + temporary)
        else:
            shutil.rmtree(temporary, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
