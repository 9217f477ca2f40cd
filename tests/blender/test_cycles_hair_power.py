"""Hairis against Cycles on the hair pixels alone, with the power to see a 1% bias there.

The scene is test_cycles_compare's (Chiang hair: particle hair at Offset 2° on a diffuse
sphere, a Curves object at −4°, a sun, a point light with a radius, an area light and a world
colour; Cycles matched by helpers.match_cycles, Hairis at its default strategy) at BOUNCES
bounces, so multiple scattering between strands is compared, framed as a square crop of the
hair. A mask marks the hair pixels: Cycles renders the scene once with every hair material
replaced by an emission of its own primary colour and everything else black, and a pixel is
hair where the hair covers at least half of it.

Both engines render SEEDS images of SAMPLES samples; compare_stats.compare_hair compares, per
channel, the mean over all hair pixels and over each hair material's pixels (Welch's t,
Šidák-corrected over masks × channels) and the hair mean of every 16×16 block. From the
seed-to-seed variances it measures, it computes the smallest bias of the hair mean found with
90% power at the test's false-alarm level, and fails when that exceeds 1% in a channel
(tests/blender/POWER.md explains the computation).

Negative control: the Hairis side is rendered again with a deliberate error (every light and
the world 2% brighter), and the same comparison must find it. (The other Blender's Chiang tilt
convention moves this hair's mean by 0.1-0.25%, below what the test is sized for, so it is not
a control; POWER.md.) Blender 3.4 is skipped: one 16×16 block of its hair
differs from Cycles 3.4 beyond the noise (tests/allowed_skips.txt).
"""

import math
import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare_stats  # noqa: E402
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
if helpers.VERSION < (4, 0, 0):
    helpers.skip("Blender %s: a block of the hair differs from Cycles beyond the noise "
                 "(under investigation)" % bpy.app.version_string)
SAMPLES = int(os.environ.get("HAIRIS_POWER_SAMPLES", "192"))
SEEDS = int(os.environ.get("HAIRIS_POWER_SEEDS", "16"))
BOUNCES = 8
RESOLUTION = (48, 48)
MASK_SAMPLES = 64
LARGEST_BIAS = 0.01
"""The relative bias of the hair mean the comparison must find with 90% power."""
HAIR = "Hair"
"""The hair material (the head's)."""


def make_scene(samples):
    """test_cycles_compare's head of hair at BOUNCES bounces, denser, without the Curves object
    (whose self-crossing strands multiply the noise), the camera on the head's left edge
    (hair against the sky and over the skin)."""
    scene = helpers.make_compare_scene(samples, BOUNCES, "TABLE", resolution=RESOLUTION,
                                       curves_offset=math.radians(-4.0))
    bpy.data.objects.remove(bpy.data.objects["Curls"])
    bpy.data.objects["Head"].particle_systems[0].settings.count = 2000
    camera = scene.camera
    camera.location = (-0.9, -3.2, -0.5)
    camera.data.lens = 100.0
    bpy.context.view_layer.update()
    return scene


def hair_mask():
    """(height, width) bool: the pixels the hair covers at least half of, from a Cycles render
    of the scene with the hair emitting white and everything else black."""
    scene = make_scene(MASK_SAMPLES)
    helpers.match_cycles(scene, MASK_SAMPLES, 0)
    for material in bpy.data.materials:
        tree = material.node_tree
        output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
        emission = tree.nodes.new("ShaderNodeEmission")
        colour = 1.0 if material.name == HAIR else 0.0
        helpers.socket(emission, "Color").default_value = (colour, colour, colour, 1.0)
        helpers.socket(emission, "Strength").default_value = 1.0
        tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
    helpers.socket(scene.world.node_tree.nodes["Background"], "Strength").default_value = 0.0
    image, _seconds = helpers.render_pixels(scene, "CYCLES", 1, ARGS.workdir, "mask")
    return image.mean(axis=2) >= 0.5


def render_stack(scene, engine, name):
    """SEEDS renders of ``engine`` as a (seeds, height, width, 3) array and their seconds."""
    images, seconds = [], 0.0
    for seed in range(1, SEEDS + 1):
        image, elapsed = helpers.render_pixels(scene, engine, seed, ARGS.workdir,
                                               "%s_%d" % (name, seed))
        assert np.all(np.isfinite(image)), "%s rendered non-finite pixels" % engine
        images.append(image)
        seconds += elapsed
    return np.stack(images), seconds


def brighter_light(scene):
    """Every light and the world 2% brighter; returns the function that undoes it."""
    lights = [obj.data for obj in scene.objects if obj.type == "LIGHT"]
    energies = [light.energy for light in lights]
    strength = helpers.socket(scene.world.node_tree.nodes["Background"], "Strength")
    world = strength.default_value
    for light in lights:
        light.energy *= 1.02
    strength.default_value = world * 1.02

    def undo():
        for light, energy in zip(lights, energies):
            light.energy = energy
        strength.default_value = world
    return undo


CONTROLS = (("light x1.02", brighter_light),)


def test_hair_matches_cycles_with_power():
    """Hairis' hair pixels are Cycles' within the noise, the comparison has the power to see a
    1% bias of their mean, and it finds every deliberate error of CONTROLS."""
    start, cpu = time.monotonic(), time.process_time()
    mask = hair_mask()
    print("hair mask: %d of %d pixels" % (mask.sum(), mask.size))
    assert mask.sum() >= mask.size // 3, "the crop is not mostly hair: %d pixels" % mask.sum()
    masks = {"hair": mask}
    scene = make_scene(SAMPLES)
    cycles, cycles_time = render_stack(scene, "CYCLES", "cycles")
    hairis, hairis_time = render_stack(scene, "HAIRIS", "hairis")
    print("render time for %d x %d samples at %d bounces: cycles %.1f s, hairis %.1f s"
          % (SEEDS, SAMPLES, BOUNCES, cycles_time, hairis_time))
    dump = os.environ.get("HAIRIS_COMPARE_DUMP")
    stacks = {"cycles": cycles, "hairis": hairis, "mask": mask}
    figures = compare_stats.hair_statistics(cycles, hairis, masks)
    compare_stats.print_hair_statistics(figures, "hairis vs cycles")
    missed = []
    for label, change in CONTROLS:
        undo = change(scene)
        try:
            bpy.context.view_layer.update()
            control, _seconds = render_stack(scene, "HAIRIS", "control")
        finally:
            undo()
            bpy.context.view_layer.update()
        stacks[label] = control
        found = compare_stats.hair_statistics(cycles, control, masks)
        compare_stats.print_hair_statistics(found, "control (%s)" % label)
        if not found["detected"]:
            missed.append(label)
    if dump:
        np.savez(dump, **stacks)
    print("hair power test: %.1f s wall, %.1f s CPU in this process"
          % (time.monotonic() - start, time.process_time() - cpu))
    compare_stats.assert_hair(figures, LARGEST_BIAS)
    assert not missed, "the comparison did not find the deliberate errors %s" % missed


helpers.run([test_hair_matches_cycles_with_power])
