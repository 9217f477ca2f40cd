"""Render time per sample: this Hairis, an earlier Hairis and Cycles, side by side in one run.

Runs inside Blender through tests/blender/run_test.py (render_versions does it):

    HAIRIS_OLD_ADDON=<old checkout>/addon/hairis HAIRIS_OLD_LIBRARY=<old build>/lib/libhairis.so \
        /usr/bin/python3 tests/blender/run_test.py --blender blender \
        --zip build/hairis-addon.zip --timeout 3600 bench/studies/render_versions/render_versions.py

For each scene (the Cycles-comparison scene, the demo head, and "sphere": particle hair on a
sphere under a sun and a dim world at 8 bounces), the scene is exported once with this
add-on's exporter; then, interleaved and repeated REPEATS times:

- each library (old, new) renders the exported scene through its own binding with TABLE (its
  own freshly baked tables) and ANALYTIC, at LOW and HIGH samples per pixel;
- Cycles renders the Blender scene (set up as the README's comparison table says) at LOW and
  HIGH samples, timing bpy.ops.render.render().

Time per sample is the slope (t_HIGH − t_LOW)/(HIGH − LOW) of each repeat, so per-render costs
(scene sync, BVH build) drop out; the median over repeats is reported, with the ratios new/old
and new/Cycles. Times are the process's CPU time (time.process_time) around each render, which
other jobs on a shared machine inflate far less than wall time; every renderer runs on THREADS
threads (1 by default, so that no thread waits or spins). For the new library
the rays, shadow rays and path length per camera sample come from hairis_last_render_stats.
Agreement: each image's channel means against the other version's (same samples).

Writes HAIRIS_STUDY_OUT (default: this folder)/render_versions.{json,md}. Environment:
HAIRIS_VERSIONS_SCENES (compare,demo,sphere), _LOW (16), _HIGH (64), _REPEATS (3), _THREADS (1).
"""

import copy
import importlib.util
import json
import os
import statistics
import sys
import time

import bpy
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))  # the repository
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
OLD_ADDON = os.environ.get("HAIRIS_OLD_ADDON", "")
OLD_LIBRARY = os.environ.get("HAIRIS_OLD_LIBRARY", "")
SCENES = os.environ.get("HAIRIS_VERSIONS_SCENES", "compare,demo,sphere").split(",")
LOW = int(os.environ.get("HAIRIS_VERSIONS_LOW", "16"))
HIGH = int(os.environ.get("HAIRIS_VERSIONS_HIGH", "64"))
REPEATS = int(os.environ.get("HAIRIS_VERSIONS_REPEATS", "3"))
THREADS = int(os.environ.get("HAIRIS_VERSIONS_THREADS", "1"))
OUT = os.environ.get("HAIRIS_STUDY_OUT", HERE)
START = time.monotonic()


def log(message):
    """Prints with a timestamp, flushed."""
    print("[render_versions %7.1f s] %s" % (time.monotonic() - START, message), flush=True)


def import_package(path, name):
    """The add-on package at ``path`` imported as ``name`` (not registered)."""
    spec = importlib.util.spec_from_file_location(name, os.path.join(path, "__init__.py"),
                                                  submodule_search_locations=[path])
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


def make_scene(name):
    """The Blender scene and its bounce limit."""
    if name == "compare":
        scene = helpers.make_compare_scene(LOW, 4, "TABLE", resolution=(96, 72))
        return scene, 4
    if name == "demo":
        scene = helpers.make_demo_head(resolution=(240, 180))
        bounces = 8
    else:  # "sphere": particle hair on a sphere, a sun and a dim world, 8 bounces, 96 × 96
        scene = helpers.reset()
        helpers.make_camera(scene, location=(0.0, -6.0, 0.0), resolution=(96, 96),
                            percentage=100)
        helpers.make_world(scene, color=(0.2, 0.22, 0.25), strength=0.3)
        hair = helpers.make_hair_material("Hair", "MELANIN", **{"Melanin": 0.25,
                                                                "Roughness": 0.3})
        skin = helpers.make_diffuse_material("Skin", (0.6, 0.5, 0.45, 1.0))
        helpers.make_particle_hair(scene, count=1000, location=(0.0, 0.0, 0.0), scale=1.4,
                                   hair_material=hair, skin_material=skin)
        helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=0.05, rotation=(0.8, 0.2, 0.4))
        bounces = 8
    helpers.match_cycles(scene, LOW, bounces)
    scene.hairis.max_bounces = bounces
    scene.hairis.threads = THREADS
    if THREADS > 0:
        scene.render.threads_mode = "FIXED"
        scene.render.threads = THREADS
    bpy.context.view_layer.update()
    return scene, bounces


class OldHair:
    """HairParameters as the binding before ABI v2 knows them: without the Cycles version,
    which must be 3.4's (the only semantics it has)."""

    def __init__(self, hair):
        if hair.cycles != "3.4":
            raise RuntimeError("the old library has only Cycles 3.4's Chiang; this Blender's is %s"
                               % hair.cycles)
        self.hair = hair

    def as_dict(self):
        values = self.hair.as_dict()
        for name in NEW_HAIR_FIELDS:
            values.pop(name, None)
        return values


NEW_HAIR_FIELDS = ("cycles", "model", "aspect_ratio", "reflection", "transmission",
                   "secondary_reflection")
"""HairParameters fields the binding before ABI v2 does not know (Chiang 3.4 only)."""


def old_surface(material):
    """A surface material as the old binding's Lambertian one: its root node's colour and
    emission (the comparison scenes' meshes are Diffuse, or Principled with a Base Color)."""
    root = material.nodes[-1]
    material.albedo = tuple(root.get("base_color", root.get("color", (0.8, 0.8, 0.8))))[:3]
    material.emission = tuple(root.get("emission", (0.0, 0.0, 0.0)))[:3]
    material.kind = "DIFFUSE"


def for_old_binding(data):
    """A copy of ``data`` whose hair materials the old binding reads."""
    data = copy.copy(data)
    data.materials = [copy.copy(m) for m in data.materials]
    for material in data.materials:
        if material.hair is not None:
            material.hair = OldHair(material.hair)
        elif material.kind == "SURFACE":
            old_surface(material)
    return data


class Version:
    """One Hairis version: its binding, its library and the scene built with them."""

    def __init__(self, name, package, library_path):
        self.name = name
        self.native = package.native
        self.engine = package.engine
        self.tables = package.tables
        self.library = self.native.load_library(library_path)
        self.baked = {}
        self.adapt = for_old_binding if name == "old" else (lambda data: data)

    def bake(self, data):
        """Tables for every hair material of ``data`` (index → Tables)."""
        data = self.adapt(data)
        for index, material in data.hair_materials():
            node = self.tables.principled_struct(self.library, material.hair)
            with self.library.fiber_principled(node) as fiber:
                self.baked[index] = self.library.bake_tables(fiber)

    def render(self, data, strategy, samples, seed):
        """(rgba, seconds, stats) of one render of ``data``."""
        data = self.adapt(data)
        settings = type("Settings", (), {})()
        settings.samples, settings.max_bounces, settings.strategy = samples, data.bounces, strategy
        settings.multiple_weight, settings.n_h, settings.seed = 0.0, 2, seed
        settings.threads = THREADS
        settings.integrator, settings.huang_sampling = "PATH", "STRATEGY"
        settings.max_transparent_bounces = 8
        if self.name == "old":
            args = (self.library, settings)
        else:
            args = (settings,)
        tables = self.baked if strategy == "TABLE" else {}
        with self.engine.build_native_scene(self.library, data, tables) as scene:
            start = time.process_time()
            rgba, stats = scene.render(self.engine.render_settings(*args))
            seconds = time.process_time() - start
        return rgba, seconds, stats


def cycles_render(scene, samples, seed):
    """(rgb, seconds) of a Cycles render."""
    scene.cycles.samples = samples
    start = time.process_time()
    rgb, _wall = helpers.render_pixels(scene, "CYCLES", seed, ARGS.workdir)
    return rgb, time.process_time() - start


def slope(low, high):
    """Time per sample from the times at LOW and HIGH samples."""
    return (high - low) / float(HIGH - LOW)


def main():
    """Runs every scene, writes the JSON and the markdown table."""
    new_package = PACKAGE
    versions = [Version("new", new_package, helpers.bundled_library(PACKAGE))]
    if OLD_ADDON and OLD_LIBRARY:
        versions.append(Version("old", import_package(OLD_ADDON, "hairis_old"), OLD_LIBRARY))
    results = {"low": LOW, "high": HIGH, "repeats": REPEATS, "threads_per_render": THREADS,
               "scenes": {},
               "blender": bpy.app.version_string, "threads": os.cpu_count()}
    for name in SCENES:
        scene, bounces = make_scene(name)
        data = new_package.export.export_scene(bpy.context.evaluated_depsgraph_get())
        data.bounces = bounces
        for version in versions:
            version.baked = {}
            version.bake(data)
        runs = {}
        for repeat in range(REPEATS):
            for version in versions:
                for strategy in ("TABLE", "ANALYTIC"):
                    key = "%s %s" % (version.name, strategy)
                    images = []
                    times = []
                    for samples in (LOW, HIGH):
                        rgba, seconds, stats = version.render(data, strategy, samples, 7 + repeat)
                        images.append(rgba)
                        times.append(seconds)
                    run = runs.setdefault(key, {"per_sample": [], "means": []})
                    run["per_sample"].append(slope(*times))
                    run["means"].append(images[1][..., :3].reshape(-1, 3).mean(axis=0).tolist())
                    if hasattr(stats, "rays"):
                        camera = float(stats.camera_rays)
                        run["rays_per_sample"] = float(stats.rays) / camera
                        run["shadow_rays_per_sample"] = float(stats.shadow_rays) / camera
                    log("%s %s: %.3f ms per sample" % (name, key, 1e3 * run["per_sample"][-1]))
            times = [cycles_render(scene, samples, 7 + repeat)[1] for samples in (LOW, HIGH)]
            run = runs.setdefault("cycles", {"per_sample": [], "means": []})
            run["per_sample"].append(slope(*times))
            log("%s cycles: %.3f ms per sample" % (name, 1e3 * run["per_sample"][-1]))
        for run in runs.values():
            run["median_per_sample"] = statistics.median(run["per_sample"])
            if run["means"]:
                run["mean_rgb"] = np.mean(np.asarray(run["means"]), axis=0).tolist()
        results["scenes"][name] = {"bounces": bounces, "runs": runs,
                                   "resolution": [scene.render.resolution_x,
                                                  scene.render.resolution_y]}
    os.makedirs(OUT, exist_ok=True)
    with open(os.path.join(OUT, "render_versions.json"), "w") as handle:
        json.dump(results, handle, indent=1)
    lines = ["# Render time per sample: new Hairis, old Hairis, Cycles (Blender %s)" %
             results["blender"], "",
             "CPU time per sample on %d thread(s) per render: median over %d repeats of "
             "(t(%d spp) − t(%d spp)) / %d; ratios of medians." %
             (THREADS, REPEATS, HIGH, LOW, HIGH - LOW), "",
             "| scene | method | ms / spp | new / old | / Cycles | rays / sample | shadow rays "
             "/ sample | mean RGB (%d spp) |" % HIGH,
             "|---|---|---|---|---|---|---|---|"]
    for name, scene in results["scenes"].items():
        runs = scene["runs"]
        cycles = runs["cycles"]["median_per_sample"]
        for key in sorted(runs):
            run = runs[key]
            per = run["median_per_sample"]
            old = runs.get(key.replace("new", "old")) if key.startswith("new") else None
            ratio_old = "%.2f" % (per / old["median_per_sample"]) if old else ""
            mean = run.get("mean_rgb")
            lines.append("| %s | %s | %.2f | %s | %.2f | %s | %s | %s |" % (
                name, key, 1e3 * per, ratio_old, per / cycles,
                "%.2f" % run["rays_per_sample"] if "rays_per_sample" in run else "",
                "%.2f" % run["shadow_rays_per_sample"] if "shadow_rays_per_sample" in run else "",
                ", ".join("%.4f" % v for v in mean) if mean else ""))
    with open(os.path.join(OUT, "render_versions.md"), "w") as handle:
        handle.write("\n".join(lines) + "\n")
    print("\n".join(lines), flush=True)


helpers.run([main])
