"""Bake, load, sample and render through the add-on's native binding; report what was loaded.

Used by test_library_isolation.py in three places: inside Blender (with the add-on's own
``native`` module), in a plain Python process without bpy (the reference), and in a Python
that imports bpy into the global symbol scope first, as the Blender executable has its
libraries (``--bpy-global``):

    python3 library_probe.py --native .../hairis/native.py --library .../libhairis.so
                             --workdir DIR [--bpy-global]

prints one JSON line: SHA-1s of the baked EXR bytes, of samples and densities drawn from the
tables loaded from the file and from memory, of two renders (analytic and table strategies),
and the shared objects of interest mapped into the process.
"""

import argparse
import ctypes
import hashlib
import importlib.util
import json
import os
import sys

FIBER = {"roughness": 0.35, "melanin": 0.6}
"""hairis_principled_hair fields of the probe's fiber (the rest: the node's defaults)."""

LIBRARY_KEYS = ("libtbb", "libembree", "libOpenEXR", "libOpenImageIO", "libImath", "libIex",
                "libhairis")
"""Shared objects whose copies matter: libhairis's dependencies and Blender's namesakes."""


def mapped_libraries():
    """The files of interest mapped into this process (from /proc/self/maps)."""
    found = set()
    with open("/proc/self/maps") as handle:
        for line in handle:
            parts = line.split()
            if len(parts) >= 6 and any(key in os.path.basename(parts[5]) for key in LIBRARY_KEYS):
                found.add(os.path.realpath(parts[5]))
    return sorted(found)


def tbb_runtime_version(library):
    """TBB_runtime_version() of the TBB libhairis is bound to (looked up through its handle)."""
    try:
        function = library.raw.TBB_runtime_version
    except AttributeError:
        return ""
    function.restype = ctypes.c_char_p
    function.argtypes = []
    return function().decode()


def _digest(*arrays):
    sha = hashlib.sha1()
    for array in arrays:
        sha.update(array.tobytes())
    return sha.hexdigest()


def _scene(native, library, tables=None):
    """A small hair scene: a comb of 48 strands in front of the camera, a sun and a sky."""
    import numpy as np
    scene = library.scene()
    material = scene.add_hair_material(FIBER, tables)
    strands, keys = 48, 5
    points = np.zeros((strands, keys, 3), np.float32)
    points[:, :, 0] = np.linspace(-0.6, 0.6, strands)[:, None]
    points[:, :, 1] = 0.05 * np.sin(np.linspace(0.0, 3.0, keys))[None, :]
    points[:, :, 2] = np.linspace(-0.5, 0.5, keys)[None, :]
    first = np.arange(strands + 1, dtype=np.uint32) * keys
    scene.add_curves(material, first, points.reshape(-1, 3),
                     np.full(strands * keys, 0.012, np.float32))
    scene.add_sun((0.3, -1.0, 0.5), (1.0, 0.95, 0.9), 3.0, 0.05)
    scene.set_world((0.2, 0.3, 0.4), 1.0)
    scene.set_camera({"matrix": [1, 0, 0, 0, 0, 0, -1, -3, 0, 1, 0, 0, 0, 0, 0, 1],
                      "frame": [0.5, 0.4, -1.5, 0.5, -0.4, -1.5, -0.5, -0.4, -1.5, -0.5, 0.4, -1.5],
                      "width": 32, "height": 24})
    return scene


def probe(native, library_path, workdir):
    """Runs the bake/load/sample/render sequence; returns a dict of digests and mappings."""
    import numpy as np
    library = native.load_library(library_path)
    result = {"mode": library.mode}
    exr = os.path.join(workdir, "probe_%d.exr" % os.getpid())
    with library.fiber_principled(FIBER) as fiber:
        options = {"theta_r": 9, "theta_i": 16, "phi": 16, "n_h": "1,2", "threads": 2}
        with library.bake_tables(fiber, options) as baked:
            baked.write(exr)
        with open(exr, "rb") as handle:
            data = handle.read()
        os.remove(exr)
        result["exr"] = hashlib.sha1(data).hexdigest()
        rng = np.random.default_rng(3)
        wo = rng.normal(size=(4096, 3))
        wo /= np.linalg.norm(wo, axis=1)[:, None]
        u = rng.uniform(size=(4096, 3))
        with open(exr + ".copy", "wb") as handle:
            handle.write(data)
        for source in ("file", "memory"):
            tables = (library.load_tables_file(exr + ".copy") if source == "file"
                      else library.load_tables_memory(data))
            with tables, library.sampler("TABLE", fiber, tables, 0.0, 2) as sampler:
                wi, pdf = sampler.sample(wo, u)
                result["sample_" + source] = _digest(wi, pdf, sampler.pdf(wi, wo))
        os.remove(exr + ".copy")
        with library.load_tables_memory(data) as tables:
            for strategy in ("ANALYTIC", "TABLE"):
                settings = {"samples": 8, "strategy": strategy.lower(), "threads": 2, "seed": 5}
                with _scene(native, library, tables if strategy == "TABLE" else None) as scene:
                    rgba, _stats = scene.render(settings)
                result["render_" + strategy] = _digest(rgba)
                result["mean_" + strategy] = float(rgba[..., :3].mean())
    result["tbb_runtime_version"] = tbb_runtime_version(library)
    result["maps"] = mapped_libraries()
    return result


def main():
    """The command-line form: loads native.py by path, prints the probe as one JSON line."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--native", required=True)
    parser.add_argument("--library", required=True)
    parser.add_argument("--workdir", required=True)
    parser.add_argument("--bpy-global", action="store_true",
                        help="import bpy into the global symbol scope first")
    args = parser.parse_args()
    if args.bpy_global:
        flags = sys.getdlopenflags()
        sys.setdlopenflags(os.RTLD_NOW | os.RTLD_GLOBAL)
        import bpy  # noqa: F401
        sys.setdlopenflags(flags)
    spec = importlib.util.spec_from_file_location("hairis_probe_native", args.native)
    native = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(native)
    print("PROBE " + json.dumps(probe(native, args.library, args.workdir)), flush=True)


if __name__ == "__main__":
    main()
