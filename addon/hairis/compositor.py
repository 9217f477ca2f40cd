"""Denoise in one click: the compositor's Denoise node fed with Hairis' denoising passes.

Blender's compositor already runs OpenImageDenoise (with its albedo and normal guides, on the
final render, saved with it and visible in the node editor), so Hairis only builds the node
tree: Render Layers → Denoise (Image, Denoising Normal, Denoising Albedo) → the output (the
Composite node up to 4.x, the compositing node group's Group Output from 5.0). The nodes it
adds carry ``NODE_PREFIX`` in their names, so turning Denoise off removes exactly them and
links the image straight to the output again.
"""

import bpy

from . import compat

NODE_PREFIX = "Hairis "
DENOISE_NODE = NODE_PREFIX + "Denoise"
LAYERS_NODE = NODE_PREFIX + "Render Layers"
OUTPUT_NODE = NODE_PREFIX + "Output"
GROUP_NAME = "Hairis Compositing"

NODE_GROUP_COMPOSITOR = (5, 0, 0)
"""From 5.0 the scene's compositor is a node group (``scene.compositing_node_group``) that
ends in a Group Output; before, ``scene.node_tree`` ends in a Composite node."""


def denoising_available():
    """True when this Blender was built with OpenImageDenoise, which the Denoise node runs
    (without it the node passes the image through unchanged)."""
    try:
        import _cycles
    except ImportError:
        return False
    return bool(getattr(_cycles, "with_openimagedenoise", False))


def compositor_tree(scene, create):
    """The scene's compositing node tree (made when ``create``), or None."""
    if compat.running_version() >= NODE_GROUP_COMPOSITOR:
        tree = scene.compositing_node_group
        if tree is None and create:
            tree = bpy.data.node_groups.new(GROUP_NAME, "CompositorNodeTree")
            tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
            scene.compositing_node_group = tree
        return tree
    if create:
        scene.use_nodes = True
    return scene.node_tree


def _output(tree):
    """The node the image ends in: a Composite node, or (5.0+) a Group Output."""
    kinds = ("NodeGroupOutput",) if compat.running_version() >= NODE_GROUP_COMPOSITOR \
        else ("CompositorNodeComposite",)
    for node in tree.nodes:
        if node.bl_idname in kinds:
            return node
    node = tree.nodes.new(kinds[0])
    node.name = OUTPUT_NODE
    node.location = (600.0, 0.0)
    return node


def _render_layers(tree, scene):
    for node in tree.nodes:
        if node.bl_idname == "CompositorNodeRLayers" and node.scene in (None, scene):
            return node
    node = tree.nodes.new("CompositorNodeRLayers")
    node.name = LAYERS_NODE
    node.location = (0.0, 0.0)
    return node


def _link(tree, output, node_input):
    for link in list(node_input.links):
        tree.links.remove(link)
    tree.links.new(output, node_input)


def use_denoise_nodes(scene, enable):
    """Builds (``enable``) or removes the Denoise node between Render Layers and the output."""
    tree = compositor_tree(scene, enable)
    if tree is None:
        return
    denoise = tree.nodes.get(DENOISE_NODE)
    if not enable:
        if denoise is not None:
            source = denoise.inputs["Image"].links
            source = source[0].from_socket if source else None
            targets = [link.to_socket for link in denoise.outputs["Image"].links]
            tree.nodes.remove(denoise)
            for target in targets if source is not None else ():
                tree.links.new(source, target)
        return
    for layer in scene.view_layers:
        layer.update_render_passes()  # the Render Layers node gains the denoising outputs
    layers = _render_layers(tree, scene)
    output = _output(tree)
    if denoise is None:
        denoise = tree.nodes.new("CompositorNodeDenoise")
        denoise.name = DENOISE_NODE
        denoise.location = (300.0, 0.0)
    _link(tree, layers.outputs["Image"], denoise.inputs["Image"])
    for guide, name in (("Normal", "Denoising Normal"), ("Albedo", "Denoising Albedo")):
        socket = layers.outputs.get(name)
        if socket is not None:
            _link(tree, socket, denoise.inputs[guide])
    _link(tree, denoise.outputs["Image"], output.inputs[0])


def denoise_update(settings, context):
    """``scene.hairis.use_denoising``'s update: the compositor follows the setting."""
    scene = settings.id_data
    use_denoise_nodes(scene, settings.use_denoising and denoising_available())
