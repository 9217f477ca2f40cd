"""Dual scattering study (issue 14): bias and noise of Hairis' DUAL_SCATTERING integrator
against converged path tracing, and its error at equal time against Cycles 3.4.

Runs inside Blender through tests/blender/run_test.py (dual_scattering_study does it and
then writes the report):

    /usr/bin/python3 tests/blender/run_test.py --blender blender --zip build/hairis-addon.zip \\
        --timeout 20000 bench/studies/dual_scattering_study/dual_scattering_study.py

Cases: particle hair on a diffuse sphere, in three colours (Principled Hair Melanin 0.1, 0.5,
0.9; Melanin Redness 0.5, Roughness and Radial Roughness 0.3) and two lightings (a sun with a
world colour; an area light in a black world), 8 bounces. Per case, in one Blender run:

1. a hair mask: a transparent-film Cycles render with the sphere itself hidden (its hair
   stays), mask = alpha > 0.5;
2. the reference: Hairis PATH (TABLE strategy) at REF_SPP samples, seed 1000, and Cycles at
   CYCLES_REF_SPP (seed 1000) as a check of the reference (their per-channel means);
3. DUAL_SCATTERING at each of SPPS, PATH and Cycles at each of PATH_SPPS, two seeds each
   (1 and 2), every render timed (wall time of bpy.ops.render.render(), one thread for Hairis
   and for Cycles, after a warm-up render of each method that also bakes the tables and
   computes the dual-scattering averages);
4. per render: the per-channel mean error over the hair pixels against the reference, the
   noise-corrected RMSE over the hair pixels (the reference's own noise, estimated from its two
   halves, subtracted), and the variance from the two seeds; for DUAL at its highest spp, its
   bias per pixel and over 4×4 and 16×16 blocks (bias_by_scale).

Writes dual_scattering.json and dual_scattering_images.npz; the report (tables,
the crossover times, difference images) is dual_scattering_report.py's.

Environment: HAIRIS_DUAL_RESOLUTION (64x64), HAIRIS_DUAL_REF_SPP (1024),
HAIRIS_DUAL_CYCLES_REF_SPP (256; 0 leaves Cycles' reference out), HAIRIS_DUAL_SPPS (1,4,16,64),
HAIRIS_DUAL_PATH_SPPS (4,16,64), HAIRIS_DUAL_CASES (all: blonde_sun, brunette_sun, black_sun,
blonde_area, brunette_area, black_area), HAIRIS_DUAL_OUT (default: this folder), HAIRIS_DUAL_PROBE=1
(one render of each method at 4 spp per case, timings only), HAIRIS_DUAL_MODEL (CHIANG, or
HUANG: the node's Huang model, Blender 4.0 or newer, e.g. the bpy 4.5 wheel through
run_test.py --bpy-python; Coat and Radial Roughness are Chiang's alone), HAIRIS_DUAL_EXACT
(Exact Bounces; unset: the add-on's default), HAIRIS_DUAL_SCENE (sphere, or head: the demo
head's thicker hair, 96x72 by default), HAIRIS_DUAL_RANDOM_COLOR and HAIRIS_DUAL_RANDOM_ROUGHNESS
(the node's per-strand inputs, 0), HAIRIS_DUAL_SKIN (the skin's colour, 0.7,0.5,0.4),
HAIRIS_DUAL_BOUNCES (Max Bounces of every method, 8), HAIRIS_DUAL_BOUNCE_LIMIT (BOUNCES, or
NONE: DUAL adds every order of scattering).
"""

import json
import math
import os
import sys
import time

import bpy
import numpy as np
from mathutils import Vector

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))  # the repository
sys.path.insert(0, os.path.join(ROOT, "tests", "blender"))
import helpers  # noqa: E402

ARGS = helpers.setup_compare()

# The hair: "sphere" (the study's ball, the default) or "head" (the demo head of
# scripts/render_demo.py in the case's colour and lighting: longer, thicker hair on a larger
# head, a scene the integrator was not tuned on).
SCENE = os.environ.get("HAIRIS_DUAL_SCENE", "sphere")
if SCENE not in ("sphere", "head"):
    raise SystemExit("HAIRIS_DUAL_SCENE must be sphere or head (got %r)" % SCENE)
RESOLUTION = tuple(int(v) for v in os.environ.get(
    "HAIRIS_DUAL_RESOLUTION", "64x64" if SCENE == "sphere" else "96x72").split("x"))
REF_SPP = int(os.environ.get("HAIRIS_DUAL_REF_SPP", "1024"))
CYCLES_REF_SPP = int(os.environ.get("HAIRIS_DUAL_CYCLES_REF_SPP", "256"))
BIAS_BLOCKS = (1, 4, 16)  # pixel, strand bundles, the ball's regions (64-pixel images)
SPPS = [int(v) for v in os.environ.get("HAIRIS_DUAL_SPPS", "1,4,16,64").split(",")]
PATH_SPPS = [int(v) for v in os.environ.get("HAIRIS_DUAL_PATH_SPPS", "4,16,64").split(",")]
OUT = os.environ.get("HAIRIS_DUAL_OUT", HERE)
PROBE = os.environ.get("HAIRIS_DUAL_PROBE", "0") == "1"
BOUNCES = int(os.environ.get("HAIRIS_DUAL_BOUNCES", "8"))
REF_SEED = 1000
SEEDS = (1, 2)
COLOURS = {"blonde": 0.1, "brunette": 0.5, "black": 0.9}
LIGHTINGS = ("sun", "area")
ALL_CASES = ["%s_%s" % (c, light) for light in LIGHTINGS for c in COLOURS]
# Other lightings (not in the default cases): "world" and "sunonly", the sun case's two
# emitters alone; "backsun", the sun case with the sun behind the hair.
CASES = os.environ.get("HAIRIS_DUAL_CASES", ",".join(ALL_CASES)).split(",")
METHODS = ("DUAL", "PATH", "CYCLES")
MODEL = os.environ.get("HAIRIS_DUAL_MODEL", "CHIANG")
# Diagnostic: the Huang node's Aspect Ratio (HAIRIS_DUAL_HUANG_ASPECT; Blender's default 0.85).
HUANG_ASPECT = (float(os.environ["HAIRIS_DUAL_HUANG_ASPECT"])
                if "HAIRIS_DUAL_HUANG_ASPECT" in os.environ else None)
# Diagnostic: Hair Volume (HAIRIS_DUAL_VOLUME=LAYER, the default, or UNBOUNDED).
VOLUME = os.environ.get("HAIRIS_DUAL_VOLUME", "LAYER")
# Bounce Limit (HAIRIS_DUAL_BOUNCE_LIMIT=BOUNCES, the default, or NONE: every order).
BOUNCE_LIMIT = os.environ.get("HAIRIS_DUAL_BOUNCE_LIMIT", "BOUNCES")
# Exact Bounces (HAIRIS_DUAL_EXACT; unset: the add-on's default).
EXACT = int(os.environ["HAIRIS_DUAL_EXACT"]) if "HAIRIS_DUAL_EXACT" in os.environ else None
# The node's Random Color and Random Roughness (per-strand variation; 0 by default).
RANDOM_COLOR = float(os.environ.get("HAIRIS_DUAL_RANDOM_COLOR", "0"))
RANDOM_ROUGHNESS = float(os.environ.get("HAIRIS_DUAL_RANDOM_ROUGHNESS", "0"))
# Diagnostic: the sphere's diffuse colour (HAIRIS_DUAL_SKIN=r,g,b; 0,0,0 removes its light).
SKIN = tuple(float(v) for v in os.environ.get("HAIRIS_DUAL_SKIN", "0.7,0.5,0.4").split(","))
if MODEL not in ("CHIANG", "HUANG"):
    raise SystemExit("HAIRIS_DUAL_MODEL must be CHIANG or HUANG (got %r)" % MODEL)
if MODEL == "HUANG" and bpy.app.version < (4, 0, 0):
    helpers.skip("HAIRIS_DUAL_MODEL=HUANG needs Blender 4.0 or newer (this is %s)"
                 % bpy.app.version_string)
START = time.monotonic()


def log(message):
    """Prints with a timestamp, flushed (Blender buffers stdout)."""
    print("[dual_study %7.1f s] %s" % (time.monotonic() - START, message), flush=True)


def look_at(obj, target):
    """Points an object's −Z axis at ``target`` (+Y up)."""
    direction = Vector(target) - obj.location
    obj.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()


def make_case_scene(colour, lighting):
    """Particle hair of ``colour`` on a diffuse sphere (SCENE) under ``lighting``, both engines
    alike."""
    scene = helpers.reset()
    if SCENE == "head":
        camera = helpers.make_camera(scene, location=(0.0, -7.5, 0.3), resolution=RESOLUTION,
                                     percentage=100)
    else:
        camera = helpers.make_camera(scene, location=(0.0, -4.6, 1.2), resolution=RESOLUTION,
                                     percentage=100)
        look_at(camera, (0.0, 0.0, 0.55))
    if lighting in ("sun", "backsun"):
        helpers.make_world(scene, color=(0.4, 0.5, 0.7), strength=0.8)
        helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(1.0),
                           rotation=(math.radians(40), 0.0,
                                     math.radians(35 if lighting == "sun" else 215)))
    elif lighting == "world":  # diagnostic: the sun case's world alone
        helpers.make_world(scene, color=(0.4, 0.5, 0.7), strength=0.8)
    elif lighting == "sunonly":  # diagnostic: the sun case's sun alone
        helpers.make_world(scene, color=(0.0, 0.0, 0.0), strength=0.0)
        helpers.make_light(scene, "SUN", "Sun", energy=3.0, angle=math.radians(1.0),
                           rotation=(math.radians(40), 0.0, math.radians(35)))
    else:
        helpers.make_world(scene, color=(0.0, 0.0, 0.0), strength=0.0)
        light = helpers.make_light(scene, "AREA", "Panel", location=(2.0, -2.2, 2.6),
                                   energy=250.0, shape="SQUARE", size=1.2)
        look_at(light, (0.0, 0.0, 0.6))
    hair = helpers.make_hair_material("Hair", "MELANIN", **{
        "Melanin": COLOURS[colour], "Melanin Redness": 0.5, "Roughness": 0.3,
        "Radial Roughness": 0.3, "Coat": 0.0, "IOR": 1.55, "Random Color": RANDOM_COLOR,
        "Random Roughness": RANDOM_ROUGHNESS})
    if MODEL == "HUANG":
        for node in hair.node_tree.nodes:
            if node.bl_idname == "ShaderNodeBsdfHairPrincipled":
                node.model = "HUANG"
                if HUANG_ASPECT is not None:
                    helpers.socket(node, "Aspect Ratio").default_value = HUANG_ASPECT
    skin = helpers.make_diffuse_material("Skin", SKIN + (1.0,))
    if SCENE == "head":  # helpers.make_demo_head's hair
        sphere = helpers.make_particle_hair(scene, count=1500, children=10,
                                            location=(0.0, 0.0, 0.3), scale=1.3,
                                            hair_material=hair, skin_material=skin)
    else:
        sphere = helpers.make_particle_hair(scene, count=1500, children=8,
                                            location=(0.0, 0.0, 0.0), scale=1.0,
                                            hair_material=hair, skin_material=skin)
        helpers.configure(sphere.modifiers["Hair"].particle_system.settings, hair_length=0.5,
                          radius_scale=0.006, root_radius=1.0, tip_radius=0.5,
                          child_radius=0.08, render_step=3)
    helpers.match_cycles(scene, 4, BOUNCES)
    scene.cycles.diffuse_bounces = 4  # Hairis' max_diffuse_bounces default
    scene.render.threads_mode = "FIXED"
    scene.render.threads = 1
    hairis = scene.hairis
    hairis.max_bounces = BOUNCES
    hairis.strategy = "TABLE"
    hairis.dual_hair_volume = VOLUME
    hairis.dual_bounce_limit = BOUNCE_LIMIT
    if EXACT is not None:
        hairis.dual_exact_bounces = EXACT
    hairis.auto_bake = True
    hairis.threads = 1
    bpy.context.view_layer.update()
    return scene, sphere


def render(scene, method, samples, seed):
    """(image, seconds) of ``method`` (DUAL, PATH or CYCLES) at ``samples`` spp."""
    helpers.set_samples(scene, samples)
    if method != "CYCLES":
        scene.hairis.integrator = "DUAL_SCATTERING" if method == "DUAL" else "PATH"
    engine = "CYCLES" if method == "CYCLES" else "HAIRIS"
    image, seconds = helpers.render_pixels(scene, engine, seed, ARGS.workdir)
    assert np.all(np.isfinite(image)), "%s rendered non-finite pixels" % method
    return image, seconds


def hair_mask(scene, sphere):
    """Pixels the hair covers: alpha > 0.5 of a transparent-film Cycles render without the
    sphere (the add-on does not pass Film > Transparent to Hairis)."""
    sphere.show_instancer_for_render = False
    scene.render.film_transparent = True
    helpers.set_samples(scene, 16)
    rgba, _ = helpers.render_pixels(scene, "CYCLES", scene.cycles.seed, ARGS.workdir, "mask",
                                    alpha=True)
    sphere.show_instancer_for_render = True
    scene.render.film_transparent = False
    return rgba[..., 3] > 0.5


def errors(image, reference, mask, ref_mse_channel):
    """Per-channel mean error, noise-corrected MSE and raw MSE over the mask."""
    d = (image - reference)[mask]
    ref_mean = reference[mask].mean(axis=0)
    mse_channel = np.mean(d ** 2, axis=0)
    return {
        "channel_mean": image[mask].mean(axis=0).tolist(),
        "relative_mean_error": (d.mean(axis=0) / ref_mean).tolist(),
        "mean_error_se": np.sqrt(mse_channel / d.shape[0]).tolist(),
        "mse": float(mse_channel.mean()),
        "mse_corrected": float(max(mse_channel.mean() - ref_mse_channel.mean(), 0.0)),
        "whole_image_relative_mean_error":
            ((image - reference).reshape(-1, 3).mean(axis=0)
             / reference.reshape(-1, 3).mean(axis=0)).tolist(),
    }


def block_means(field, mask, size):
    """Means of field over the mask's pixels in size×size blocks, and their pixel counts."""
    h, w = mask.shape
    hb, wb = h // size, w // size
    m = mask[:hb * size, :wb * size].reshape(hb, size, wb, size).astype(np.float64)
    v = field[:hb * size, :wb * size].reshape(hb, size, wb, size, -1) * m[..., None]
    counts = m.sum(axis=(1, 3))
    sums = v.sum(axis=(1, 3))
    keep = counts > 0
    return sums[keep] / counts[keep][:, None], counts[keep]


def bias_by_scale(images, reference, halves, mask, sizes=BIAS_BLOCKS):
    """DUAL's bias at each block size: the RMS over blocks (weighted by their hair pixels) of the
    mean difference from the reference, less the noise of both (from the two seeds' difference
    and the reference's halves), relative to the reference's hair mean. Size 1 is per pixel;
    larger blocks show how much of it is large-scale (the light transport) rather than
    strand-scale."""
    ref_mean = reference[mask].mean()
    mean = 0.5 * (images[0] + images[1])
    out = {}
    for size in sizes:
        d, n = block_means(mean - reference, mask, size)
        spread, _ = block_means(images[0] - images[1], mask, size)
        ref_spread, _ = block_means(halves[0] - halves[1], mask, size)
        # E[d²] = b² + var(seed mean) + var(reference); spread²/4 and ref_spread²/4 estimate both.
        excess = d ** 2 - spread ** 2 / 4.0 - ref_spread ** 2 / 4.0
        b2 = (n[:, None] * excess).sum() / (excess.shape[1] * n.sum())
        out[str(size)] = float(math.sqrt(max(b2, 0.0)) / ref_mean)
    return out


def study_case(name, keep):
    """Every render of one case; returns its record."""
    colour, lighting = name.split("_")
    scene, sphere = make_case_scene(colour, lighting)
    mask = hair_mask(scene, sphere)
    log("%s: %d hair pixels of %d" % (name, int(mask.sum()), mask.size))
    warmup = {}
    for method in METHODS:
        _, seconds = render(scene, method, 1, 1)
        warmup[method] = seconds
        log("%s warm-up %s: %.2f s" % (name, method, seconds))
    if PROBE:
        for method in METHODS:
            image, seconds = render(scene, method, 4, 1)
            log("%s probe %s 4 spp: %.2f s, hair mean %s"
                % (name, method, seconds, np.round(image[mask].mean(axis=0), 4)))
            keep["%s_%s_probe" % (name, method.lower())] = image.astype(np.float32)
        keep["%s_mask" % name] = mask
        return {"warmup_seconds": warmup}

    # The reference in two halves of REF_SPP/2 samples (seeds 1000 and 1001): their difference
    # estimates the reference's own noise.
    half_a, time_a = render(scene, "PATH", REF_SPP // 2, REF_SEED)
    half_b, time_b = render(scene, "PATH", REF_SPP // 2, REF_SEED + 1)
    reference = 0.5 * (half_a + half_b)
    ref_mse_channel = np.mean(((half_a - half_b)[mask]) ** 2, axis=0) / 4.0
    ref_mean = reference[mask].mean(axis=0)
    log("%s reference: PATH %d spp in %.1f s, hair mean %s, own relative RMSE %.4f"
        % (name, REF_SPP, time_a + time_b, np.round(ref_mean, 4),
           math.sqrt(ref_mse_channel.mean()) / ref_mean.mean()))
    record = {"warmup_seconds": warmup, "hair_pixels": int(mask.sum()),
              "reference": {"spp": REF_SPP, "seconds": time_a + time_b,
                            "channel_mean": ref_mean.tolist(),
                            "noise_mse": float(ref_mse_channel.mean())}}
    if CYCLES_REF_SPP:
        cycles_ref, cycles_time = render(scene, "CYCLES", CYCLES_REF_SPP, REF_SEED)
        d = (cycles_ref - reference)[mask]
        se = np.sqrt(np.mean(d ** 2, axis=0) / d.shape[0])
        record["cycles_reference"] = {
            "spp": CYCLES_REF_SPP, "seconds": cycles_time,
            "channel_mean": cycles_ref[mask].mean(axis=0).tolist(),
            "relative_difference": (d.mean(axis=0) / ref_mean).tolist(),
            "z": (d.mean(axis=0) / se).tolist()}
        log("%s Cycles %d spp: hair mean %s, (Cycles − PATH)/PATH %s"
            % (name, CYCLES_REF_SPP, np.round(cycles_ref[mask].mean(axis=0), 4),
               np.round(d.mean(axis=0) / ref_mean, 4)))
        keep["%s_cycles_reference" % name] = cycles_ref.astype(np.float32)
    keep["%s_reference" % name] = reference.astype(np.float32)
    keep["%s_mask" % name] = mask

    renders = {method: [] for method in METHODS}
    for method in METHODS:
        for samples in (SPPS if method == "DUAL" else PATH_SPPS):
            images, times = [], []
            for seed in SEEDS:
                image, seconds = render(scene, method, samples, seed)
                images.append(image)
                times.append(seconds)
            entry = {"spp": samples, "seconds": times}
            entry["seeds"] = [errors(image, reference, mask, ref_mse_channel) for image in images]
            # Per-pixel variance of one render from the two seeds' difference.
            entry["variance"] = float(np.mean(((images[0] - images[1])[mask]) ** 2) / 2.0)
            renders[method].append(entry)
            e = entry["seeds"][0]
            log("%s %-6s %4d spp: %6.2f s, mean error %s, relative RMSE %.4f"
                % (name, method, samples, np.mean(times),
                   np.round(np.array(e["relative_mean_error"]) * 100, 2),
                   math.sqrt(e["mse_corrected"]) / ref_mean.mean()))
            if samples == max(SPPS if method == "DUAL" else PATH_SPPS):
                keep["%s_%s" % (name, method.lower())] = images[0].astype(np.float32)
                if method == "DUAL":
                    entry["bias_by_block"] = bias_by_scale(images, reference, (half_a, half_b),
                                                           mask)
                    log("%s DUAL bias (relative RMS) by block size %s"
                        % (name, entry["bias_by_block"]))
    record["renders"] = renders
    return record


def main():
    """Runs every case and writes the results."""
    info = helpers.machine_info()
    log("cases %s, %dx%d, %d bounces; %s" % (CASES, RESOLUTION[0], RESOLUTION[1], BOUNCES, info))
    keep = {}
    cases = {}
    for name in CASES:
        cases[name] = study_case(name, keep)
    info["load_average_end"] = list(os.getloadavg())
    info["total_seconds"] = time.monotonic() - START
    results = {"machine": info,
               "settings": {"resolution": list(RESOLUTION), "bounces": BOUNCES,
                            "ref_spp": REF_SPP, "cycles_ref_spp": CYCLES_REF_SPP,
                            "spps": SPPS, "path_spps": PATH_SPPS, "seeds": list(SEEDS),
                            "threads": 1, "probe": PROBE, "model": MODEL,
                            "skin": list(SKIN), "volume": VOLUME, "scene": SCENE,
                            "bounce_limit": BOUNCE_LIMIT.lower(),
                            "random_color": RANDOM_COLOR,
                            "random_roughness": RANDOM_ROUGHNESS,
                            "exact_bounces": (EXACT if EXACT is not None else
                                              bpy.context.scene.hairis.dual_exact_bounces)},
               "cases": cases}
    os.makedirs(OUT, exist_ok=True)
    suffix = "_probe" if PROBE else ""
    with open(os.path.join(OUT, "dual_scattering%s.json" % suffix), "w") as handle:
        json.dump(results, handle, indent=1)
    np.savez_compressed(os.path.join(OUT, "dual_scattering_images%s.npz" % suffix), **keep)
    log("wrote %s" % OUT)


helpers.run_script(main)
