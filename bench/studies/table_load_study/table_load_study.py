"""Sizes and times of a material's sampling tables (issue 12), measured inside Blender.

Run through tests/blender/run_test.py (as the Blender tests are):

    /usr/bin/python3 tests/blender/run_test.py --blender blender --zip build/hairis-addon.zip \\
        bench/studies/table_load_study/table_load_study.py

For Blender's default Principled Hair BSDF (Chiang with the running Blender's Cycles semantics,
and Huang from Blender 4.0, also with Random Color, whose tables hold the absorption part):
the bake (hairis_tables_bake with the add-on's options, all threads and one), the file's size
and the image's size in memory, Blender loading and packing the image, and what a render does
with it: the add-on's image_tables from the file and from the packed bytes (the first load
reads, validates and keeps the decoded file; later ones read the bytes and find it by their
fingerprint), then the TABLE sampler built from the loaded tables (the near-field CDFs).
Medians of REPEATS (7) runs. Writes HAIRIS_STUDY_OUT (default: this folder)/
table_load_<blender>.{json,md}.
"""

import json
import os
import statistics
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))  # the repository
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
import helpers  # noqa: E402

ARGS, PACKAGE = helpers.setup()
REPEATS = int(os.environ.get("HAIRIS_STUDY_REPEATS", "7"))
if REPEATS < 2:
    raise SystemExit("HAIRIS_STUDY_REPEATS must be 2 or more: the first load is timed apart "
                     "from the rest (got %d)" % REPEATS)
OUT = os.environ.get("HAIRIS_STUDY_OUT", HERE)


def timed_runs(function, repeats=REPEATS):
    """(seconds of each call, last result) of ``function()`` over ``repeats`` calls."""
    seconds, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        seconds.append(time.perf_counter() - start)
    return seconds, result


def timed(function, repeats=REPEATS):
    """(median seconds, last result) of ``function()`` over ``repeats`` calls."""
    seconds, result = timed_runs(function, repeats)
    return statistics.median(seconds), result


def measure(library, model):
    """Sizes and times of the default Principled Hair node's tables for ``model``
    (HUANG_ABSORPTION: Huang with Random Color 0.5)."""
    tables = PACKAGE.tables
    helpers.reset()
    material = helpers.make_hair_material("Hair", "MELANIN")
    node = material.node_tree.nodes["Principled Hair BSDF"]
    if model != "CHIANG":
        node.model = "HUANG"
    if model == "HUANG_ABSORPTION":
        node.inputs["Random Color"].default_value = 0.5
    params = tables.material_parameters(material)
    absorption = bool(getattr(params, "varies_absorption", False))
    if model == "HUANG_ABSORPTION" and not absorption:
        raise AssertionError("Random Color did not ask for the absorption part")
    fiber = library.fiber_principled(params.as_dict())
    results = {"model": model, "parameters": params.as_dict()}

    results["bake_s"], baked = timed(lambda: library.bake_tables(
        fiber, tables.bake_options(library, absorption=absorption)), 3)
    results["bake_1_thread_s"], _ = timed(lambda: library.bake_tables(
        fiber, tables.bake_options(library, threads=1, absorption=absorption)), 3)
    path = os.path.join(ARGS.workdir, "hairis_Hair_%s.exr" % model.lower())
    baked.write(path)
    results["file_bytes"] = os.path.getsize(path)

    def load_image():
        for image in list(bpy.data.images):
            bpy.data.images.remove(image)
        image = bpy.data.images.load(path)
        image.pack()
        return image

    results["blender_load_and_pack_s"], image = timed(load_image, 3)
    width, height = image.size
    results["image"] = [width, height]
    results["image_bytes_in_memory"] = width * height * 4 * 4
    image.unpack(method="REMOVE")
    image = bpy.data.images.load(path)
    seconds, loaded = timed_runs(lambda: tables.image_tables(library, image))
    results["load_file_first_s"] = seconds[0]
    results["load_file_s"] = statistics.median(seconds[1:])
    image.pack()
    results["load_packed_s"], loaded = timed(lambda: tables.image_tables(library, image))
    if model == "CHIANG":  # the C API's sampler has no curve normal to orient a Huang fiber
        results["sampler_s"], _ = timed(lambda: library.sampler("TABLE", fiber, loaded))
    return results


def rows(r):
    """The markdown rows of one model's results."""
    width, height = r["image"]
    name = {"CHIANG": "Chiang", "HUANG": "Huang",
            "HUANG_ABSORPTION": "Huang, Random Color"}[r["model"]]
    lines = ["| %s: image | %d × %d RGBA float, %.2f MB in memory |" % (
                 name, width, height, r["image_bytes_in_memory"] / 1e6),
             "| %s: file (EXR, ZIP) | %.2f MB |" % (name, r["file_bytes"] / 1e6),
             "| %s: bake, all threads | %.2f s |" % (name, r["bake_s"]),
             "| %s: bake, 1 thread | %.2f s |" % (name, r["bake_1_thread_s"]),
             "| %s: Blender loads the image datablock and packs its file (no decode) | %.1f ms |"
             % (name, 1e3 * r["blender_load_and_pack_s"]),
             "| %s: add-on tables from the file, first load (read, validate) | %.1f ms |" % (
                 name, 1e3 * r["load_file_first_s"]),
             "| %s: add-on tables from the file again (read, fingerprint) | %.1f ms |" % (
                 name, 1e3 * r["load_file_s"]),
             "| %s: add-on tables from the packed bytes | %.1f ms |" % (
                 name, 1e3 * r["load_packed_s"])]
    if "sampler_s" in r:
        lines.append("| %s: TABLE sampler from the loaded tables | %.1f ms |" % (
            name, 1e3 * r["sampler_s"]))
    return lines


def main():
    """Measures Chiang (and Huang, from Blender 4.0) and writes the JSON and markdown."""
    library = PACKAGE.native.load_library(helpers.bundled_library(PACKAGE))
    models = ["CHIANG"] + (["HUANG", "HUANG_ABSORPTION"] if helpers.VERSION >= (4, 0, 0) else [])
    results = {"blender": bpy.app.version_string, "threads": os.cpu_count(),
               "models": [measure(library, model) for model in models]}
    os.makedirs(OUT, exist_ok=True)
    name = "table_load_%s" % ".".join(bpy.app.version_string.split(".")[:2])
    with open(os.path.join(OUT, name + ".json"), "w") as f:
        json.dump(results, f, indent=1)
    huang = " Huang also with Random Color 0.5." if len(models) > 1 else ""
    lines = ["# Table sizes and times, Blender %s" % results["blender"], "",
             "Blender's default Principled Hair BSDF (each model it has), the add-on's bake "
             "options.%s Medians of %d runs (bakes: 3; a file's first load is one run, "
             "its loads again the median of the other %d) on %d cores. Reproduce: "
             "`table_load_study.py` (see its docstring)."
             % (huang, REPEATS, REPEATS - 1, results["threads"]),
             "", "| what | value |", "|---|---|"]
    for r in results["models"]:
        lines += rows(r)
    with open(os.path.join(OUT, name + ".md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines), flush=True)


helpers.run([main])
