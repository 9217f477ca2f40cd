"""Hairis against Cycles with hair materials as artists build them: Mix Shaders of Principled
Hair BSDFs.

The comparison scene of test_cycles_compare (particle hair on a diffuse sphere, a Curves
object, sun, point and area lights, a world colour), with
  * the Curves object's material a Mix Shader of a brown and a grey melanin Principled Hair
    BSDF whose Fac is Hair Info Random > 0.7 (a Math Greater Than): the weights vary per
    strand, and Hair Info Random on Curves is Cycles' own number, so the same strands are grey;
  * the particle hair's material a Mix Shader, Fac 0.35, of its brown Principled Hair BSDF and
    a grey one: constant weights.
Both engines render SEEDS images of SAMPLES samples with the Analytic strategy (no tables to
bake), compared per 4×4 block by compare_stats.compare (channel means within 2%, mean t² and
max |t| within the noise bounds). The export test checks the mixture's weights and that a node
hairis cannot mix is a warning naming it.
"""

import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import helpers  # noqa: E402

ARGS = helpers.setup_compare()
SAMPLES, SEEDS = helpers.compare_counts(samples=16, seeds=5)
BOUNCES, BLOCK = helpers.COMPARE_BOUNCES, helpers.COMPARE_BLOCK
GREY = {"Melanin": 0.1, "Melanin Redness": 0.0, "Roughness": 0.35, "Radial Roughness": 0.4}


def add_grey(material, factor):
    """Puts a Mix Shader between ``material``'s Principled Hair BSDF and its output, mixing in
    a grey one by ``factor`` (a number, or a function of the tree that returns the socket to
    link to Fac); returns the Mix Shader."""
    tree = material.node_tree
    brown = tree.nodes["Principled Hair BSDF"]
    output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL")
    grey = tree.nodes.new("ShaderNodeBsdfHairPrincipled")
    grey.name = "Grey"
    grey.parametrization = "MELANIN"
    for key, value in GREY.items():
        helpers.socket(grey, key).default_value = value
    mix = tree.nodes.new("ShaderNodeMixShader")
    fac = helpers.socket(mix, "Fac")
    if callable(factor):
        tree.links.new(factor(tree), fac)
    else:
        fac.default_value = factor
    shaders = [s for s in mix.inputs if s.type == "SHADER"]
    tree.links.new(brown.outputs[0], shaders[0])
    tree.links.new(grey.outputs[0], shaders[1])
    tree.links.new(mix.outputs[0], output.inputs["Surface"])
    return mix


def random_above(threshold):
    """Fac from Hair Info Random > ``threshold`` (Math Greater Than)."""
    def link(tree):
        info = tree.nodes.new("ShaderNodeHairInfo")
        math_node = tree.nodes.new("ShaderNodeMath")
        math_node.operation = "GREATER_THAN"
        math_node.inputs[1].default_value = threshold
        tree.links.new(info.outputs["Random"], math_node.inputs[0])
        return math_node.outputs[0]
    return link


def make_scene():
    """The comparison scene with the two mixed hair materials."""
    scene = helpers.make_compare_scene(SAMPLES, BOUNCES, "ANALYTIC")
    dyed = bpy.data.materials["Dyed"]
    node = dyed.node_tree.nodes["Principled Hair BSDF"]
    node.parametrization = "MELANIN"
    helpers.socket(node, "Melanin").default_value = 0.8
    helpers.socket(node, "Melanin Redness").default_value = 0.6
    add_grey(dyed, random_above(0.7))
    add_grey(bpy.data.materials["Hair"], 0.35)
    bpy.context.view_layer.update()
    return scene


def test_mixture_export():
    """The export makes a HAIR material per Principled Hair BSDF and a HAIR_MIX of them: per
    strand weights (1 − Fac, Fac) for the Curves object, 0.65 and 0.35 for the particle hair;
    no warning. A Transparent BSDF in the tree is left out with a warning naming it."""
    make_scene()
    export = helpers.module("export")
    data = export.export_scene(bpy.context.evaluated_depsgraph_get())
    assert not data.warnings, data.warnings
    mixes = {m.name: m for m in data.materials if m.kind == "HAIR_MIX"}
    assert set(mixes) == {"Dyed", "Hair"}, [(m.name, m.kind) for m in data.materials]
    hair = mixes["Hair"].mixture
    assert np.allclose(hair.material_weights(), [0.65, 0.35]), hair.material_weights()
    grey = data.materials[hair.closures[1]].hair
    assert abs(grey.melanin - 0.1) < 1e-6 and grey.melanin_redness == 0.0, grey
    curves = next(c for c in data.curves if c.source == "CURVES")
    domain0, w0 = curves.inputs["weight0"]
    domain1, w1 = curves.inputs["weight1"]
    assert domain0 == domain1 == "curve", (domain0, domain1)
    random = helpers.module("node_eval").strand_random(np.arange(w1.size))
    assert np.array_equal(w1.reshape(-1), (random > 0.7).astype(np.float32)), w1.reshape(-1)
    assert np.array_equal(w0 + w1, np.ones_like(w0))
    assert 0 < w1.sum() < w1.size, w1.sum()

    tree = bpy.data.materials["Hair"].node_tree
    mix = next(n for n in tree.nodes if n.bl_idname == "ShaderNodeMixShader")
    transparent = tree.nodes.new("ShaderNodeBsdfTransparent")
    tree.links.new(transparent.outputs[0], [s for s in mix.inputs if s.type == "SHADER"][1])
    data = export.export_scene(bpy.context.evaluated_depsgraph_get())
    assert any("'Hair'" in w and transparent.name in w and "leaves it out" in w
               and "meshes" not in w for w in data.warnings), data.warnings
    print("mixture export: %d of %d curves grey; warning: %s"
          % (int(w1.sum()), w1.size, data.warnings[0]))


def test_mixture_matches_cycles():
    """Cycles and Hairis render the mixed hair materials to the same image within the noise."""
    scene = make_scene()
    helpers.compare_with_cycles(scene, SEEDS, ARGS.workdir, BLOCK, " (mix shader)")


helpers.run([test_mixture_export, test_mixture_matches_cycles])
