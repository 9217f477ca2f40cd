"""libhairis inside Blender uses its own Embree, OpenEXR and OpenImageIO, and computes what it
computes in a plain Python process.

Blender 4.5 and 5.0 bundle Embree 4, OpenEXR 3.3, OpenImageIO 3.0 and oneTBB 2021.13;
libhairis links Debian's Embree 3, OpenEXR 3.1, OpenImageIO 2.4 and oneTBB 2021.8. The add-on
loads libhairis with RTLD_DEEPBIND (native.load_mode) so that where Blender's libraries sit
in the global symbol scope (the Blender executable) the same-named C functions of Embree 3 and
OpenEXRCore still bind to libhairis's own copies.

Checks, against a reference computed by library_probe.py in a plain Python process (no bpy):
  * a bake gives the same EXR bytes, tables loaded from the file and from memory give the same
    samples and densities, and renders with the analytic and table strategies the same pixels;
  * every Embree/OpenEXR/OpenImageIO/Imath file the plain process maps is mapped here too;
  * oneTBB: libhairis binds to the TBB already in the process (the dynamic linker reuses a
    loaded libtbb.so.12 by its soname); its runtime version must be at least the one it was
    built against (oneTBB keeps binary compatibility with older builds);
  * bpy module only: the same in a process that imports bpy into the global scope first, as
    the Blender executable has its libraries (this is where the clash shows: without
    RTLD_DEEPBIND the hair is missing from the render).
"""

import json
import os
import shutil
import subprocess
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402
import library_probe  # noqa: E402

ARGS, PACKAGE = helpers.setup()
LIBRARY = helpers.require_library(PACKAGE)
helpers.use_library(None)
native = helpers.module("native")
NATIVE_SOURCE = native.__file__
PROBE = os.path.abspath(library_probe.__file__)
DEPENDENCY_KEYS = ("libembree", "libOpenEXR", "libOpenImageIO", "libImath", "libIex")
DIGESTS = ("exr", "sample_file", "sample_memory", "render_ANALYTIC", "render_TABLE")
MODULE_MODE = os.path.basename(sys.executable).startswith("python") and \
    "site-packages" in os.path.dirname(bpy.__file__)


def plain_python():
    """A Python without bpy that has numpy: the bpy venv's own (module mode), else Debian's."""
    if MODULE_MODE:
        return sys.executable
    return shutil.which("python3", path="/usr/bin:/bin") or "python3"


def run_probe(python, *extra, env=None):
    """library_probe.py in a new process; returns its result dict."""
    command = [python, PROBE, "--native", NATIVE_SOURCE, "--library", LIBRARY,
               "--workdir", ARGS.workdir] + list(extra)
    environment = dict(os.environ)
    environment.pop("PYTHONPATH", None)
    environment.update(env or {})
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True, env=environment, timeout=300)
    lines = [line for line in done.stdout.splitlines() if line.startswith("PROBE ")]
    # Judged by its output: some bpy builds crash at interpreter exit after the probe.
    assert lines, "the probe printed nothing (exit code %d):\n%s" % (done.returncode, done.stdout)
    return json.loads(lines[-1][len("PROBE "):])


REFERENCE = {}
"""The plain process's probe (test_reference fills it)."""


def same_numbers(result, where):
    """Every digest equals the reference's."""
    differing = [key for key in DIGESTS if result[key] != REFERENCE[key]]
    assert not differing, "%s: %s differ from the plain process (means %s vs %s)" % (
        where, differing, [result["mean_ANALYTIC"], result["mean_TABLE"]],
        [REFERENCE["mean_ANALYTIC"], REFERENCE["mean_TABLE"]])


def own_dependencies_mapped(result, where):
    """The plain process's Embree/OpenEXR/OIIO/Imath files are all mapped in ``result``."""
    wanted = [path for path in REFERENCE["maps"]
              if any(key in os.path.basename(path) for key in DEPENDENCY_KEYS)]
    assert any("embree" in path for path in wanted), REFERENCE["maps"]
    missing = [path for path in wanted if path not in result["maps"]]
    assert not missing, "%s: libhairis's own %s are not loaded" % (where, missing)


def version_tuple(text):
    return tuple(int(part) for part in text.split(".")[:2])


def test_reference():
    """The plain process's probe: it loaded with RTLD_DEEPBIND and its renders show hair (the
    sky alone averages 0.3: the world colour's mean)."""
    REFERENCE.update(run_probe(plain_python()))
    print("reference (plain Python %s): TBB %s, %s" % (
        plain_python(), REFERENCE["tbb_runtime_version"], ", ".join(REFERENCE["maps"])))
    assert REFERENCE["mode"] & getattr(os, "RTLD_DEEPBIND", 0), REFERENCE["mode"]
    for strategy in ("ANALYTIC", "TABLE"):
        assert abs(REFERENCE["mean_" + strategy] - 0.3) > 1e-3, REFERENCE


def test_in_blender_same_numbers_and_libraries():
    """The add-on's loaded library, inside this Blender: the reference's numbers and files."""
    result = library_probe.probe(native, LIBRARY, ARGS.workdir)
    print("in Blender %s: TBB %s, maps %s" % (bpy.app.version_string,
                                              result["tbb_runtime_version"],
                                              ", ".join(result["maps"])))
    same_numbers(result, "Blender %s" % bpy.app.version_string)
    own_dependencies_mapped(result, "Blender %s" % bpy.app.version_string)
    tbb = [path for path in result["maps"] if "libtbb.so" in os.path.basename(path)]
    print("TBB copies mapped: %s" % tbb)
    assert result["tbb_runtime_version"], "libhairis is bound to no TBB"
    assert version_tuple(result["tbb_runtime_version"]) >= \
        version_tuple(REFERENCE["tbb_runtime_version"]), \
        "Blender's TBB %s is older than the %s libhairis was built with" % (
            result["tbb_runtime_version"], REFERENCE["tbb_runtime_version"])


def test_global_scope_like_the_blender_executable():
    """bpy imported into the global scope first: still the reference's numbers (DEEPBIND).

    The same without RTLD_DEEPBIND is printed as the control (it loses the hair in bpy 4.5 and
    5.0: Embree 3's calls bind to Embree 4).
    """
    if not MODULE_MODE:
        print("not a bpy module: Blender %s's libraries are the system's, nothing to clash"
              % bpy.app.version_string)
        return
    result = run_probe(sys.executable, "--bpy-global")
    same_numbers(result, "bpy in the global scope")
    own_dependencies_mapped(result, "bpy in the global scope")
    control = run_probe(sys.executable, "--bpy-global", env={native.DEEPBIND_ENV: "0"})
    differing = [key for key in DIGESTS if control[key] != REFERENCE[key]]
    print("control without RTLD_DEEPBIND: %s differ (means %.6f, %.6f against %.6f, %.6f)"
          % (differing or "none", control["mean_ANALYTIC"], control["mean_TABLE"],
             REFERENCE["mean_ANALYTIC"], REFERENCE["mean_TABLE"]))


helpers.run([
    test_reference,
    test_in_blender_same_numbers_and_libraries,
    test_global_scope_like_the_blender_executable,
])
