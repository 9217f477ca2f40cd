"""Speed at scale: Cycles against Hairis on big grooms, both engines in one Blender process.

A head-sized sphere (radius 0.1) with a particle groom of 1000 parents and interpolated
children (25k and 250k strands) and a Curves groom of 1M strands of 9 points built with numpy
(Blender 4.5+: ``Curves.add_curves`` is missing in 3.4, so 3.4 skips it), a sun, an area light
and a grey world, 8 bounces, 160×160, 16 and 64 spp, 2 threads each. For every case the scene
is built once; then each repeat renders each sample count with both engines, alternating which
goes first. Prints one RUN line per render (the image mean per channel, the wall time of
``bpy.ops.render.render()``, and for Hairis its stages: export, tables, scene hand-over,
native scene/BVH build and rendering) and one SUMMARY line per case and sample count (medians).

Knobs (environment): SCALE_CASES (comma-separated of p25k, p250k, c1m), SCALE_SPP (16,64),
SCALE_REPEATS (3), SCALE_ENGINES (CYCLES,HAIRIS), SCALE_PROFILE=1 (cProfile of the first Hairis
export of each case, top functions), SCALE_MEMORY=1 (one render per case and engine, then the
growth of the process' peak resident size: run it with one engine and one case per process),
SCALE_CURVES (the Curves case's strand count).

    /usr/bin/python3 tests/blender/run_test.py --bpy-python .venvs/bpy-4.5/bin/python \\
        --zip build/hairis-addon.zip --timeout 7200 bench/studies/groom_scale/groom_scale.py
"""
import cProfile
import importlib
import io
import math
import os
import pstats
import resource
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..",
                                "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
CASES = {"p25k": ("particles", 25), "p250k": ("particles", 250),
         "c1m": ("curves", int(os.environ.get("SCALE_CURVES", "1000000")))}


def knob(name, default):
    return [item for item in os.environ.get(name, default).split(",") if item]


def base_scene():
    scene = helpers.reset()
    helpers.make_camera(scene, location=(0.0, -0.75, 0.05), resolution=(160, 160),
                        percentage=100)
    helpers.make_world(scene, color=(0.5, 0.5, 0.5), strength=0.3)
    helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(3.0),
                       rotation=(math.radians(40), 0.0, math.radians(30)))
    helpers.make_light(scene, "AREA", "Panel", location=(-0.4, -0.5, 0.5), energy=20.0,
                       size=0.3, rotation=(math.radians(50), 0.0, math.radians(-40)))
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.15, "Melanin Redness": 0.8, "Roughness": 0.3, "Radial Roughness": 0.3,
        "Coat": 0.0, "IOR": 1.55, "Offset": math.radians(2.0)})
    skin = helpers.make_diffuse_material("Skin", (0.7, 0.5, 0.4, 1.0))
    helpers.match_cycles(scene, 16, 8)
    helpers.use_table(scene, 8, threads=2)
    return scene, hair, skin


def particle_groom(scene, hair, skin, children):
    settings = helpers.make_groom_head(scene, hair, skin, children, 0.004)
    settings.tip_radius = 0.2
    settings.use_close_tip = True
    settings.shape = 0.3
    return 1000 * children


def curves_groom(scene, hair, skin, count, points=9):
    """``count`` strands of ``points`` points on a sphere of radius 0.1, out along the normal
    and drooping, tapering radii; built with numpy on the Curves datablock."""
    helpers.make_sphere("Head", 0.1, (0.0, 0.0, 0.0), skin)
    curves = bpy.data.hair_curves.new("Groom")
    curves.add_curves([points] * count)
    rng = np.random.default_rng(11)
    normal = rng.normal(size=(count, 3))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    root = 0.1 * normal
    length = rng.uniform(0.15, 0.25, (count, 1, 1))
    t = np.linspace(0.0, 1.0, points)[None, :, None]
    droop = np.array([0.0, 0.0, -1.0])
    positions = root[:, None, :] + length * (normal[:, None, :] * t + 0.6 * droop * t * t)
    curves.position_data.foreach_set("vector", positions.astype(np.float32).reshape(-1))
    radii = curves.attributes.new("radius", "FLOAT", "POINT")
    radius = np.broadcast_to(0.0008 * (1.0 - 0.8 * t[0, :, 0]), (count, points))
    radii.data.foreach_set("value", np.ascontiguousarray(radius, np.float32).reshape(-1))
    curves.materials.append(hair)
    obj = bpy.data.objects.new("Groom", curves)
    scene.collection.objects.link(obj)
    return count


class Stages:
    """Times the Hairis stages of the next render by wrapping the add-on's functions."""

    def __init__(self, name, profile):
        self.package = name
        self.engine = importlib.import_module(name + ".engine")
        self.export = importlib.import_module(name + ".export")
        self.native = importlib.import_module(name + ".native")
        self.profile = profile
        self.times = {}
        self.stats = None
        self.profiled = set()
        self.case = None
        self._wrap()

    def _timed(self, key, function):
        def wrapper(*args, **kwargs):
            start = time.monotonic()
            try:
                return function(*args, **kwargs)
            finally:
                self.times[key] = self.times.get(key, 0.0) + time.monotonic() - start
        return wrapper

    def _wrap(self):
        export_scene = self.export.export_scene

        def export(depsgraph, camera=None):
            if self.profile and self.case not in self.profiled:
                self.profiled.add(self.case)
                profiler = cProfile.Profile()
                result = profiler.runcall(export_scene, depsgraph, camera)
                text = io.StringIO()
                pstats.Stats(profiler, stream=text).sort_stats("cumulative").print_stats(18)
                print("PROFILE %s export\n%s" % (self.case, text.getvalue()), flush=True)
                return result
            return export_scene(depsgraph, camera)

        self.export.export_scene = self._timed("export", export)
        self.engine.build_native_scene = self._timed("handover", self.engine.build_native_scene)
        cls = self.engine.HairisRenderEngine
        cls._resolve_tables = self._timed("tables", cls._resolve_tables)
        render = self.native.Scene.render_progressive

        def progressive(scene, *args, **kwargs):
            out = render(scene, *args, **kwargs)
            self.stats = out[2]
            return out
        self.native.Scene.render_progressive = progressive

    def reset(self, case):
        self.case, self.times, self.stats = case, {}, None

    def summary(self):
        stats = self.stats
        build = getattr(stats, "build_seconds", float("nan")) if stats else float("nan")
        native = getattr(stats, "seconds", float("nan")) if stats else float("nan")
        peak = getattr(stats, "peak_memory_bytes", 0) if stats else 0
        return {"export": self.times.get("export", 0.0), "tables": self.times.get("tables", 0.0),
                "handover": self.times.get("handover", 0.0), "bvh": build,
                "render": native - build, "peak_mb": peak / 2.0 ** 20}


def maxrss_mb():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main():
    name = getattr(PACKAGE, "__name__", PACKAGE)
    stages = Stages(name, os.environ.get("SCALE_PROFILE") == "1")
    memory = os.environ.get("SCALE_MEMORY") == "1"
    engines = knob("SCALE_ENGINES", "CYCLES,HAIRIS")
    spps = [int(s) for s in knob("SCALE_SPP", "16,64")]
    repeats = 1 if memory else int(os.environ.get("SCALE_REPEATS", "3"))
    info = helpers.machine_info()
    print("MACHINE %s" % info, flush=True)
    for case in knob("SCALE_CASES", "p25k,p250k,c1m"):
        kind, amount = CASES[case]
        if kind == "curves" and "add_curves" not in bpy.types.Curves.bl_rna.functions:
            print("SKIP %s: this Blender's Curves have no add_curves" % case, flush=True)
            continue
        start = time.monotonic()
        scene, hair, skin = base_scene()
        strands = (particle_groom if kind == "particles" else curves_groom)(
            scene, hair, skin, amount)
        bpy.context.view_layer.update()
        print("SCENE %s: %d strands, built in %.1f s, peak RSS %.0f MB" % (
            case, strands, time.monotonic() - start, maxrss_mb()), flush=True)
        results = {}
        for repeat in range(repeats):
            for spp in spps:
                order = engines if repeat % 2 == 0 else engines[::-1]
                for engine in order:
                    helpers.set_samples(scene, spp)
                    stages.reset(case)
                    before = maxrss_mb()
                    image, seconds = helpers.render_pixels(scene, engine, 1, ARGS.workdir)
                    mean = image.reshape(-1, 3).mean(axis=0)
                    line = "RUN %s spp %d repeat %d %s: mean %s total %.2f s" % (
                        case, spp, repeat, engine, np.round(mean, 5), seconds)
                    if engine == "HAIRIS":
                        line += " " + " ".join(
                            "%s %.2f" % item for item in stages.summary().items())
                    if memory:
                        line += " maxrss %.0f MB -> %.0f MB (+%.0f MB)" % (
                            before, maxrss_mb(), maxrss_mb() - before)
                    print(line, flush=True)
                    results.setdefault((spp, engine), []).append((seconds, mean))
        for spp in spps:
            row = {engine: results.get((spp, engine), []) for engine in engines}
            text = []
            for engine, runs in row.items():
                if runs:
                    text.append("%s %.2f s mean %s" % (
                        engine, float(np.median([r[0] for r in runs])),
                        np.round(np.median([r[1] for r in runs], axis=0), 4)))
            if all(row.get(e) for e in ("CYCLES", "HAIRIS")):
                ratio = np.median([r[0] for r in row["HAIRIS"]]) / np.median(
                    [r[0] for r in row["CYCLES"]])
                text.append("ratio %.2f" % ratio)
            print("SUMMARY %s spp %d (%d strands, Blender %s): %s" % (
                case, spp, strands, bpy.app.version_string, "; ".join(text)), flush=True)
    print("LOAD end %s" % (list(os.getloadavg()),), flush=True)


helpers.run_script(main)
