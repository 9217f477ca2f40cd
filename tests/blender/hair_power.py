"""What test_cycles_hair_power and test_cycles_huang_power share: a mask of the hair pixels,
stacks of renders per engine, the comparison with the power to see a 1% bias of the hair mean
(compare_stats.hair_statistics) and the negative controls it must find (tests/blender/POWER.md).
"""

import math
import os
import time

import bpy
import numpy as np

import compare_stats
import helpers

BOUNCES = 8
RESOLUTION = (48, 48)
HAIR = "Hair"
"""The hair material of head_scene (the head's)."""
MASK_SAMPLES = 64
LARGEST_BIAS = 0.01
"""The relative bias of the hair mean the comparison must find with 90% power."""


def head_scene(samples, model="CHIANG"):
    """test_cycles_compare's head of hair at BOUNCES bounces, denser, without the Curves object
    (whose self-crossing strands multiply the noise), the camera on the head's left edge
    (hair against the sky and over the skin); the head's Principled Hair BSDF set to
    ``model`` (its other inputs as the node leaves them)."""
    scene = helpers.make_compare_scene(samples, BOUNCES, "TABLE", resolution=RESOLUTION,
                                       curves_offset=math.radians(-4.0), strands=2000)
    bpy.data.objects.remove(bpy.data.objects["Curls"])
    if model != "CHIANG":  # Blender 3.4's node has Chiang's model alone, and no model property
        bpy.data.materials[HAIR].node_tree.nodes["Principled Hair BSDF"].model = model
    camera = scene.camera
    camera.location = (-0.9, -3.2, -0.5)
    camera.data.lens = 100.0
    bpy.context.view_layer.update()
    return scene


def cycles_defaults(scene):
    """Gives ``scene`` back the Cycles settings helpers.match_cycles turns off, at Blender's
    defaults, as a scene set up for Cycles has them: Filter Glossy 1, Clamping Indirect 10,
    Light Threshold 0.01 and a Blackman-Harris pixel filter of 1.5 px."""
    cycles = scene.cycles
    cycles.blur_glossy = 1.0
    cycles.sample_clamp_indirect = 10.0
    cycles.light_sampling_threshold = 0.01
    cycles.pixel_filter_type = "BLACKMAN_HARRIS"
    cycles.filter_width = 1.5
    return scene


def defaults_head_scene(samples):
    """head_scene with Cycles' default Filter Glossy, clamping, light threshold and pixel
    filter (:func:`cycles_defaults`)."""
    return cycles_defaults(head_scene(samples))


def no_filter_glossy(scene):
    """Filter Glossy off for the render that follows (Hairis' side of a control); returns the
    function that undoes it."""
    before = scene.cycles.blur_glossy
    scene.cycles.blur_glossy = 0.0

    def undo():
        scene.cycles.blur_glossy = before
    return undo


def huang_head_scene(samples):
    """head_scene with Huang fibers at Blender's defaults for them (aspect 0.85, lobes at 1)."""
    return head_scene(samples, "HUANG")


def hair_mask(make_scene, hair, workdir):
    """(height, width) bool: the pixels the material named ``hair`` covers at least half of,
    from a Cycles render of ``make_scene(MASK_SAMPLES)`` with that hair emitting white and
    everything else black."""
    scene = make_scene(MASK_SAMPLES)
    helpers.match_cycles(scene, MASK_SAMPLES, 0)
    for material in bpy.data.materials:
        tree = material.node_tree
        output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
        emission = tree.nodes.new("ShaderNodeEmission")
        colour = 1.0 if material.name == hair else 0.0
        helpers.socket(emission, "Color").default_value = (colour, colour, colour, 1.0)
        helpers.socket(emission, "Strength").default_value = 1.0
        tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
    helpers.socket(scene.world.node_tree.nodes["Background"], "Strength").default_value = 0.0
    image, _seconds = helpers.render_pixels(scene, "CYCLES", 1, workdir, "mask")
    return image.mean(axis=2) >= 0.5


def render_stack(scene, engine, name, seeds, workdir):
    """``seeds`` renders of ``engine`` as a (seeds, height, width, 3) array and their seconds."""
    images, seconds = [], 0.0
    for seed in range(1, seeds + 1):
        image, elapsed = helpers.render_pixels(scene, engine, seed, workdir,
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
DEFAULTS_CONTROLS = CONTROLS + (("Filter Glossy off", no_filter_glossy),)
"""The controls of a scene with Cycles' defaults: Hairis without the Filter Glossy Cycles
applies must be found too."""


def check(make_scene, hair, samples, seeds, workdir, controls=CONTROLS):
    """Hairis' pixels of the hair material ``hair`` in ``make_scene(samples)`` are Cycles'
    within the noise of ``seeds`` renders, the comparison has the power to see a LARGEST_BIAS
    bias of their mean, and it finds every deliberate error of ``controls``."""
    start, cpu = time.monotonic(), time.process_time()
    mask = hair_mask(make_scene, hair, workdir)
    print("hair mask: %d of %d pixels" % (mask.sum(), mask.size))
    # A sanity check on the framing; the power the test needs is checked from the noise.
    assert mask.sum() >= mask.size // 4, "the crop is hardly hair: %d pixels" % mask.sum()
    masks = {"hair": mask}
    scene = make_scene(samples)
    cycles, cycles_time = render_stack(scene, "CYCLES", "cycles", seeds, workdir)
    hairis, hairis_time = render_stack(scene, "HAIRIS", "hairis", seeds, workdir)
    print("render time for %d x %d samples: cycles %.1f s, hairis %.1f s"
          % (seeds, samples, cycles_time, hairis_time))
    dump = os.environ.get("HAIRIS_COMPARE_DUMP")
    stacks = {"cycles": cycles, "hairis": hairis, "mask": mask}
    figures = compare_stats.hair_statistics(cycles, hairis, masks)
    compare_stats.print_hair_statistics(figures, "hairis vs cycles")
    missed = []
    for label, change in controls:
        undo = change(scene)
        try:
            bpy.context.view_layer.update()
            control, _seconds = render_stack(scene, "HAIRIS", "control", seeds, workdir)
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
