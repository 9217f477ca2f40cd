#!/usr/bin/env python3
"""Throughput study (issue 6): Blender evaluation, export, native build + BVH and a render
of a particle-hair head with 10k, 100k and 1M rendered strands, with peak memory.

Driver (outside Blender, a Python with numpy; each N runs in a fresh Blender process so that
the peak RSS is per N)::

    /usr/bin/python3 bench/studies/export_study/export_study.py --zip build/hairis-addon.zip \
        [--blender /usr/bin/blender] [--strands 10000 100000 1000000] [--out this folder]

writes ``export_study.json`` and ``export_study.md`` to ``--out``. For each N it runs this
same file inside Blender through tests/blender/run_test.py with HAIRIS_STUDY_STRANDS=N and
HAIRIS_STUDY_RESULT=<json path>.

Inside Blender the scene is: a UV sphere with a hair particle system of N/100 parents and 100
interpolated children each (``rendered_child_count``), render_step 3 (9 keys per strand), a
Principled Hair material, a sun, a camera, 256×256; the ANALYTIC strategy, 4 samples. It is
rendered with F12 (``bpy.ops.render.render``), the real path: Blender builds and evaluates the
render depsgraph, then calls the engine. Wrappers around the add-on's functions time:

- eval: from the start of the render operator to the engine's call of ``export_scene`` (the
  render depsgraph's evaluation, including the particle child path cache);
- export: ``export.export_scene(depsgraph, camera)``;
- build+BVH: a probe made right after the export, outside the engine: the same SceneData with
  a 16×16 camera is loaded into a native scene (``engine.build_native_scene``: the ctypes
  copies) and rendered with 1 sample (``hairis_render``: its scene copy, curve layout, Embree
  BVH build and a negligible 256-pixel render). The C API has no separate build figure;
- render: the engine's own 256×256 × 4 spp render (``hairis_render``'s seconds, which include
  the BVH build again);
- memory: ``ru_maxrss`` (the process' peak RSS so far) at each phase boundary, the current RSS
  (VmRSS), the renderer's ``peak_memory_bytes`` and the exported arrays' bytes.
"""

import json
import os
import platform
import resource
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))  # the repository
STRANDS_ENV = "HAIRIS_STUDY_STRANDS"
RESULT_ENV = "HAIRIS_STUDY_RESULT"
CHILDREN = 100
RENDER_STEP = 3
RESOLUTION = 256
SAMPLES = 4
PROBE_RESOLUTION = 16
MB = 1024.0 * 1024.0


def peak_rss_mb():
    """The process' peak resident set so far (ru_maxrss is in KiB on Linux)."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def current_rss_mb():
    """The process' resident set now (VmRSS)."""
    try:
        with open("/proc/self/status") as status:
            for line in status:
                if line.startswith("VmRSS:"):
                    return int(line.split()[1]) / 1024.0
    except OSError:
        pass
    return float("nan")


# ---- Inside Blender --------------------------------------------------------------------------

def blender_main():
    """Builds the head, renders it with F12 and writes the measurements as JSON."""
    import dataclasses
    import math

    import bpy

    sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
    import helpers

    strands = int(os.environ[STRANDS_ENV])
    result_path = os.environ[RESULT_ENV]
    parents = max(1, strands // CHILDREN)
    _, package = helpers.setup()
    export = sys.modules["hairis.export"]
    engine = sys.modules["hairis.engine"]
    native = sys.modules["hairis.native"]

    marks = []

    def mark(name):
        marks.append({"phase": name, "t": time.monotonic(), "peak_rss_mb": peak_rss_mb(),
                      "rss_mb": current_rss_mb()})
        print("export_study: %-22s peak RSS %8.1f MB, RSS %8.1f MB"
              % (name, marks[-1]["peak_rss_mb"], marks[-1]["rss_mb"]), flush=True)

    mark("start")
    scene = helpers.reset()
    scene.render.engine = "HAIRIS"
    helpers.make_camera(scene, location=(0.5, -7.0, 0.6), resolution=(RESOLUTION, RESOLUTION),
                        percentage=100)
    helpers.make_world(scene, color=(0.05, 0.05, 0.05), strength=1.0)
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": 0.5, "Roughness": 0.3, "Radial Roughness": 0.3})
    skin = helpers.make_surface_material("Skin")
    head = helpers.make_particle_hair(scene, count=parents, children=CHILDREN,
                                      hair_material=hair, skin_material=skin)
    settings = head.particle_systems[0].settings
    settings.render_step = RENDER_STEP
    settings.hair_length = 0.6
    settings.radius_scale = 0.005
    helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(5.0))
    scene.hairis.strategy = "ANALYTIC"
    scene.hairis.samples = SAMPLES
    scene.hairis.threads = 0
    bpy.context.view_layer.update()
    mark("scene built")

    record = {"strands_requested": strands, "parents": parents, "children_per_parent": CHILDREN,
              "render_step": RENDER_STEP, "keys_per_strand": (1 << RENDER_STEP) + 1,
              "resolution": [RESOLUTION, RESOLUTION], "samples": SAMPLES,
              "strategy": "ANALYTIC", "blender_version": bpy.app.version_string,
              "python": platform.python_version()}
    original_export = export.export_scene
    original_render = native.Scene.render

    def probe(data):
        """1 spp at 16×16 of the exported data: native scene copies + Embree BVH build."""
        library = native.load_library()
        small = dataclasses.replace(data, camera=dataclasses.replace(
            data.camera, width=PROBE_RESOLUTION, height=PROBE_RESOLUTION))
        struct = {"samples": 1, "strategy": "analytic", "threads": 0}
        start = time.monotonic()
        with engine.build_native_scene(library, small, {}) as native_scene:
            loaded = time.monotonic()
            mark("probe: scene loaded")
            _, stats = original_render(native_scene, struct)
            done = time.monotonic()
            mark("probe: BVH built")
        record["native_load_seconds"] = loaded - start
        record["probe_render_seconds"] = stats.seconds
        record["probe_wall_seconds"] = done - loaded
        record["build_bvh_seconds"] = (loaded - start) + stats.seconds
        record["probe_peak_memory_bytes"] = int(stats.peak_memory_bytes)

    def timed_export(depsgraph, camera=None):
        mark("export: enter")
        record["eval_seconds"] = marks[-1]["t"] - record["_render_start"]
        start = time.monotonic()
        data = original_export(depsgraph, camera)
        record["export_seconds"] = time.monotonic() - start
        mark("export: done")
        record["curves"] = [{"name": c.name, "source": c.source, "curves": c.curve_count,
                             "points": c.point_count} for c in data.curves]
        record["strands"] = sum(c.curve_count for c in data.curves)
        record["points"] = sum(c.point_count for c in data.curves)
        record["positions_bytes"] = sum(c.positions.nbytes for c in data.curves)
        record["radii_bytes"] = sum(c.radii.nbytes for c in data.curves)
        record["first_bytes"] = sum(c.first.nbytes for c in data.curves)
        record["mesh_bytes"] = sum(m.positions.nbytes + m.indices.nbytes + m.materials.nbytes
                                   for m in data.meshes)
        record["export_array_bytes"] = (record["positions_bytes"] + record["radii_bytes"] +
                                        record["first_bytes"] + record["mesh_bytes"])
        record["warnings"] = list(data.warnings)
        probe(data)
        mark("render: start")
        return data

    def timed_render(native_scene, settings, progress=None, out=None):
        start = time.monotonic()
        rgba, stats = original_render(native_scene, settings, progress, out)
        record["render_wall_seconds"] = time.monotonic() - start
        record["render_seconds"] = stats.seconds
        record["render_peak_memory_bytes"] = int(stats.peak_memory_bytes)
        record["camera_rays"] = int(stats.camera_rays)
        record["render_mean"] = [float(v) for v in rgba.reshape(-1, 4).mean(axis=0)]
        mark("render: done")
        return rgba, stats

    export.export_scene = timed_export
    native.Scene.render = timed_render
    try:
        record["_render_start"] = time.monotonic()
        mark("F12: start")
        bpy.ops.render.render()
        record["f12_seconds"] = time.monotonic() - record.pop("_render_start")
        mark("F12: done")
    finally:
        export.export_scene = original_export
        native.Scene.render = original_render
    if "render_seconds" not in record:
        raise RuntimeError("the engine did not render (see the log above)")
    origin = marks[0]["t"]
    record["marks"] = [dict(m, t=m["t"] - origin) for m in marks]
    record["peak_rss_mb"] = peak_rss_mb()
    record["render_path_seconds"] = record["render_seconds"] - record["probe_render_seconds"]
    with open(result_path, "w") as out:
        json.dump(record, out, indent=1)
    print("export_study: wrote %s" % result_path, flush=True)
    sys.stdout.flush()
    sys.exit(0)


# ---- Driver ----------------------------------------------------------------------------------

def machine_info(blender):
    """nproc, CPU model, RAM and the Blender version."""
    info = {"nproc": os.cpu_count(), "platform": platform.platform()}
    try:
        with open("/proc/cpuinfo") as cpuinfo:
            for line in cpuinfo:
                if line.startswith("model name"):
                    info["cpu"] = line.split(":", 1)[1].strip()
                    break
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemTotal:"):
                    info["ram_gib"] = round(int(line.split()[1]) / 1024.0 / 1024.0, 1)
    except OSError:
        pass
    try:
        version = subprocess.run([blender, "--version"], stdout=subprocess.PIPE,
                                 stderr=subprocess.DEVNULL, universal_newlines=True, timeout=60)
        info["blender"] = version.stdout.splitlines()[0].strip()
    except (OSError, subprocess.SubprocessError, IndexError):
        info["blender"] = "?"
    return info


def fmt(value, digits=2):
    return "—" if value is None else ("%.*f" % (digits, value))


def write_markdown(path, info, runs):
    lines = [
        "# Export and BVH throughput (issue 6)",
        "",
        "Particle hair on a UV sphere: N/100 parents × 100 interpolated children, 9 keys per "
        "strand (render_step 3), Principled Hair, a sun, 256×256, ANALYTIC, %d spp, rendered "
        "with F12 (render depsgraph). Each N ran in a fresh Blender process. Generated by "
        "`export_study.py` (see its docstring for what each column times)." % SAMPLES,
        "",
        "Machine: %s cores, %s, %s GiB RAM, %s." % (
            info.get("nproc"), info.get("cpu", "?"), info.get("ram_gib", "?"),
            info.get("blender", "?")),
        "",
        "| N strands | points | Blender eval s | export s | build+BVH s | render s (4 spp) "
        "| peak RSS MB | renderer peak MB | export arrays MB |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in runs:
        lines.append("| %d | %d | %s | %s | %s | %s | %.0f | %.0f | %.1f |" % (
            r["strands"], r["points"], fmt(r["eval_seconds"]), fmt(r["export_seconds"]),
            fmt(r["build_bvh_seconds"]), fmt(r["render_seconds"]), r["peak_rss_mb"],
            r["render_peak_memory_bytes"] / MB, r["export_array_bytes"] / MB))
    lines += [
        "",
        "- *Blender eval*: render operator start → the engine's `export_scene` call (render "
        "depsgraph evaluation, particle child path cache).",
        "- *export*: `export.export_scene` (the `co_hair` stream and numpy).",
        "- *build+BVH*: `engine.build_native_scene` (ctypes copies) + a 1-spp 16×16 "
        "`hairis_render` of the same data (scene copy, curve layout, Embree BVH).",
        "- *render*: `hairis_render` seconds of the 256×256 × 4 spp render (includes its own "
        "BVH build; path tracing alone ≈ render − probe render: %s)." % ", ".join(
            "%s s at %dk" % (fmt(r["render_path_seconds"]), r["strands"] // 1000) for r in runs),
        "- *peak RSS*: `ru_maxrss` of the Blender process at the end (whole process, "
        "Blender included); *renderer peak*: `hairis_render_stats.peak_memory_bytes`; "
        "*export arrays*: positions + radii + offsets (+ the head mesh).",
        "",
        "Peak RSS (MB) after each phase:",
        "",
        "| N | scene built | export enter (after eval) | export done | probe loaded "
        "| probe BVH | render done |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in runs:
        by = {m["phase"]: m["peak_rss_mb"] for m in r["marks"]}
        lines.append("| %d | %s |" % (r["strands"], " | ".join(
            "%.0f" % by.get(p, float("nan")) for p in (
                "scene built", "export: enter", "export: done", "probe: scene loaded",
                "probe: BVH built", "render: done"))))
    big = [r for r in runs if r["strands"] >= 1000000]
    lines.append("")
    if big:
        r = big[-1]
        fits = r["peak_rss_mb"] < 8192
        lines.append("**1M strands within 8 GB: %s.** %d strands rendered at 256×256 × 4 spp "
                     "with a process peak RSS of %.0f MB (%.2f GiB, Blender included) and a "
                     "renderer peak of %.0f MB." % (
                         "yes" if fits else "no", r["strands"], r["peak_rss_mb"],
                         r["peak_rss_mb"] / 1024.0, r["render_peak_memory_bytes"] / MB))
    with open(path, "w") as out:
        out.write("\n".join(lines) + "\n")


def driver():
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--zip", default=os.path.join(ROOT, "build", "hairis-addon.zip"))
    parser.add_argument("--blender", default="/usr/bin/blender")
    parser.add_argument("--strands", type=int, nargs="+", default=[10000, 100000, 1000000])
    parser.add_argument("--out", default=HERE)
    parser.add_argument("--timeout", type=float, default=3600.0)
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    runs = []
    for strands in args.strands:
        result = os.path.join(args.out, ".export_study_%d.json" % strands)
        if os.path.exists(result):
            os.remove(result)
        env = dict(os.environ, **{STRANDS_ENV: str(strands), RESULT_ENV: result})
        command = [sys.executable, os.path.join(ROOT, "tests", "blender", "run_test.py"),
                   "--blender", args.blender, "--zip", os.path.abspath(args.zip),
                   "--timeout", str(args.timeout), os.path.abspath(__file__)]
        print("export_study: N = %d: %s" % (strands, " ".join(command)), flush=True)
        start = time.monotonic()
        code = subprocess.run(command, env=env).returncode
        if code != 0 or not os.path.exists(result):
            sys.exit("export_study: the Blender run for N = %d failed (exit code %d)"
                     % (strands, code))
        with open(result) as f:
            record = json.load(f)
        os.remove(result)
        record["process_seconds"] = time.monotonic() - start
        runs.append(record)
    info = machine_info(args.blender)
    with open(os.path.join(args.out, "export_study.json"), "w") as out:
        json.dump({"machine": info, "runs": runs}, out, indent=1)
    write_markdown(os.path.join(args.out, "export_study.md"), info, runs)
    print(open(os.path.join(args.out, "export_study.md")).read())


if __name__ == "__main__":
    import importlib.util
    if importlib.util.find_spec("bpy") is None:
        driver()
    else:
        blender_main()
