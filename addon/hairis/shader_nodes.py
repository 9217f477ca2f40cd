"""Shader node trees as Cycles reads them: the active output, the node feeding a Surface,
hair materials, and a mesh material's surface nodes."""

from . import compat, hair_mix, node_eval, surfaces
from .convert import rgb

HAIR_NODE_IDNAME = "ShaderNodeBsdfHairPrincipled"


def output_node(node_tree):
    """The active output node Cycles would use (target CYCLES, else ALL)."""
    if node_tree is None:
        return None
    node = None
    getter = getattr(node_tree, "get_output_node", None)
    if getter is not None:
        for target in ("CYCLES", "ALL"):
            try:
                node = getter(target)
            except (TypeError, ValueError):
                node = None
            if node is not None:
                return node
    for node in node_tree.nodes:
        if node.type in {"OUTPUT_MATERIAL", "OUTPUT_WORLD", "OUTPUT_LIGHT"}:
            if getattr(node, "is_active_output", True):
                return node
    return None


def find_input(node, name):
    """The node input called ``name`` (by name or identifier), preferring enabled sockets."""
    return compat.find_input(node, (name,))


def surface_node(material):
    """The shader node connected to the active material output's Surface, or None."""
    if material is None or not compat.uses_nodes(material):
        return None
    output = output_node(material.node_tree)
    if output is None:
        return None
    surface = find_input(output, "Surface")
    if surface is None:
        return None
    node, _ = node_eval.source(surface)
    return node


def hair_node(material):
    """The Principled Hair BSDF connected to the material output, or None."""
    node = surface_node(material)
    if node is not None and node.bl_idname == HAIR_NODE_IDNAME:
        return node
    return None


def is_hair_material(material):
    """True for a material whose output is fed by a Principled Hair BSDF, or by a Mix/Add
    Shader tree that holds one (hair_mix)."""
    return hair_mix.has_hair_leaf(surface_node(material), HAIR_NODE_IDNAME)


def read_surface_nodes(material, warn, add_texture):
    """A mesh material's surface nodes (surfaces.py), root last: the viewport colour as a
    diffuse albedo without nodes, a black diffuse when nothing feeds the Surface (Cycles
    renders it black)."""
    version = compat.cycles_surfaces()
    if not compat.uses_nodes(material):
        color = tuple(min(max(c, 0.0), 1.0) for c in rgb(material.diffuse_color))
        return [{"type": "diffuse", "cycles": version, "color": color}]
    node = surface_node(material)
    if node is None:
        return [{"type": "diffuse", "cycles": version, "color": (0.0, 0.0, 0.0)}]
    reader = surfaces.SurfaceReader(material, warn, add_texture, node_eval.source, version)
    return reader.read(node)
