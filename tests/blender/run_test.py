#!/usr/bin/env python3
"""Runs one headless Blender test script of the hairis add-on; CTest calls this.

    run_test.py [--blender EXE] [--zip hairis-addon.zip] [--fake-library libhairis_fake.so]
                [--timeout SECONDS] tests/blender/test_x.py

It makes a temporary user scripts folder (BLENDER_USER_SCRIPTS) and a temporary work folder,
runs ``blender -b --factory-startup --python-exit-code 1 --python test_x.py -- --zip ...
--fake-library ... --workdir ...`` and returns Blender's exit code. Exit code 77 means
"skipped" (CTest's SKIP_RETURN_CODE): Blender is not installed, or the test needs something
that is not built yet.

Standalone use (no CMake build): without --zip the add-on zip is made from addon/hairis (no
native library inside); without --fake-library the fake library is compiled from
fake_hairis.c with ``cc`` when a compiler is there.
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SKIP = 77


def build_zip(folder, library=None):
    """Zips addon/hairis (and ``library`` as hairis/lib/libhairis.so) into ``folder``."""
    source = os.path.join(ROOT, "addon", "hairis")
    path = os.path.join(folder, "hairis-addon.zip")
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name in sorted(os.listdir(source)):
            if name.endswith(".py"):
                archive.write(os.path.join(source, name), "hairis/" + name)
        if library:
            archive.write(library, "hairis/lib/libhairis.so")
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


def blender_environment():
    """This environment minus what the runner's own Python put in it.

    Blender's embedded Python finds its standard library through PATH; a runner started from
    pyenv or a virtualenv would hand it that Python's library (without numpy). So PYTHON*/
    PYENV_* variables and PATH entries inside this interpreter's prefix or pyenv go.
    """
    env = dict(os.environ)
    for key in list(env):
        if key in ("PYTHONHOME", "PYTHONPATH", "VIRTUAL_ENV") or key.startswith("PYENV"):
            del env[key]
    system = {"/", "/usr", "/usr/local"}
    prefixes = {os.path.realpath(p) for p in (sys.prefix, sys.base_prefix, sys.exec_prefix)}
    prefixes = [p for p in prefixes if p not in system]

    def keep(folder):
        real = os.path.realpath(folder)
        if "pyenv" in real.split(os.sep) or ".pyenv" in real.split(os.sep):
            return False
        return not any(real == p or real.startswith(p + os.sep) for p in prefixes)
    env["PATH"] = os.pathsep.join(d for d in env.get("PATH", "").split(os.pathsep)
                                  if d and keep(d))
    return env


def main():
    """Parses arguments, prepares the folders, runs Blender, returns its exit code."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--blender", default=os.environ.get("BLENDER", "blender"))
    parser.add_argument("--zip", default=None)
    parser.add_argument("--fake-library", default=None)
    parser.add_argument("--timeout", type=float, default=300.0)
    parser.add_argument("--keep", action="store_true", help="keep the temporary folders")
    parser.add_argument("script")
    args = parser.parse_args()

    blender = shutil.which(args.blender)
    if blender is None:
        print("SKIP: Blender is not installed (%r not found); install it with "
              "scripts/setup --with-blender" % args.blender)
        return SKIP

    temporary = tempfile.mkdtemp(prefix="hairis-blender-test-")
    try:
        user_scripts = os.path.join(temporary, "user_scripts")
        workdir = os.path.join(temporary, "work")
        os.makedirs(user_scripts)
        os.makedirs(workdir)
        zip_path = args.zip or build_zip(temporary)
        fake = args.fake_library or build_fake(temporary) or ""
        env = blender_environment()
        env.pop("HAIRIS_LIBRARY", None)
        env.pop("HAIRIS_EXPORT_DUMP", None)
        env["BLENDER_USER_SCRIPTS"] = user_scripts
        env["TMPDIR"] = os.path.join(temporary, "tmp")
        os.makedirs(env["TMPDIR"])
        command = [blender, "-b", "--factory-startup", "--python-exit-code", "1",
                   "--python", os.path.abspath(args.script), "--",
                   "--zip", os.path.abspath(zip_path), "--fake-library", fake,
                   "--workdir", workdir]
        print("run_test: " + " ".join(command), flush=True)
        try:
            result = subprocess.run(command, env=env, timeout=args.timeout)
        except subprocess.TimeoutExpired:
            print("FAIL: %s did not finish within %.0f s" % (args.script, args.timeout))
            return 1
        return result.returncode
    finally:
        if args.keep:
            print("run_test: kept " + temporary)
        else:
            shutil.rmtree(temporary, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
