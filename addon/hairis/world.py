"""Worlds whose Background Color is an Environment Texture → :class:`EnvironmentData`: the
image, its colour space, the Mapping node and the world's sampling settings."""

import numpy as np

from . import node_eval, surfaces
from .convert import matrix_of
from .scene_data import EnvironmentData
from .shader_nodes import find_input

ENVIRONMENT_NODE_IDNAME = "ShaderNodeTexEnvironment"
MAPPING_TYPES = {"POINT": "point", "TEXTURE": "texture", "VECTOR": "vector", "NORMAL": "normal"}
SAMPLING_METHODS = {"AUTOMATIC": "auto", "MANUAL": "manual", "NONE": "none"}
"""Cycles' World > Settings > Sampling (``world.cycles.sampling_method``)."""


def _node_label(node):
    return "%s %r" % (node.bl_label or node.bl_idname, node.name)


def _mapping_vector(world, node, warn):
    """The Mapping node's (type, rotation, scale), or None when it cannot be followed."""
    kind = MAPPING_TYPES.get(getattr(node, "vector_type", "POINT"))
    if kind is None:
        warn("world %r: %s has an unknown type %r; ignored"
             % (world.name, _node_label(node), node.vector_type))
        return None
    values = {}
    for name in ("Location", "Rotation", "Scale"):
        socket = find_input(node, name)
        if socket is None:
            values[name] = (0.0, 0.0, 0.0) if name != "Scale" else (1.0, 1.0, 1.0)
            continue
        if socket.is_linked:
            warn("world %r: input %r of %s is linked; hairis uses its unlinked value"
                 % (world.name, name, _node_label(node)))
        values[name] = tuple(float(v) for v in tuple(socket.default_value)[:3])
    if kind in {"point", "texture"} and any(v != 0.0 for v in values["Location"]):
        warn("world %r: the Location of %s is not supported (a direction is not moved); "
             "hairis uses Location 0" % (world.name, _node_label(node)))
    if any(v == 0.0 for v in values["Scale"]):
        warn("world %r: %s has a zero Scale; hairis uses Scale 1" % (world.name, _node_label(node)))
        values["Scale"] = (1.0, 1.0, 1.0)
    return kind, values["Rotation"], values["Scale"]


def _coordinates(world, vector_socket, warn):
    """The world → texture matrix of what feeds a Vector input: a Texture Coordinate's
    Generated (identity) or Object output, or nothing; None for anything else."""
    node, socket = node_eval.source(vector_socket)
    if node is None:
        return np.eye(4)
    if node.bl_idname != "ShaderNodeTexCoord":
        warn("world %r: %s feeds the texture's Vector and is not supported; hairis looks the "
             "texture up with the ray direction" % (world.name, _node_label(node)))
        return np.eye(4)
    output = socket.identifier or socket.name
    if output == "Generated":
        return np.eye(4)
    if output == "Object":
        obj = getattr(node, "object", None)
        if obj is None:
            return np.eye(4)
        matrix = matrix_of(obj.matrix_world)
        if np.any(matrix[:3, 3] != 0.0):
            warn("world %r: the Texture Coordinate's object %r is not at the origin; hairis "
                 "uses its rotation and scale alone" % (world.name, obj.name))
        linear = matrix[:3, :3]
        if abs(np.linalg.det(linear)) == 0.0:
            warn("world %r: the Texture Coordinate's object %r has a zero scale; ignored"
                 % (world.name, obj.name))
            return np.eye(4)
        out = np.eye(4)
        out[:3, :3] = np.linalg.inv(linear)
        return out
    warn("world %r: the Texture Coordinate's %s output is not supported in the world; hairis "
         "uses Generated (the ray direction)" % (world.name, socket.name))
    return np.eye(4)


def read_environment(world, color_socket, warn):
    """The :class:`EnvironmentData` of a Background Color fed by an Environment Texture
    (optionally through a Mapping node, fed by a Texture Coordinate or nothing), or None
    with a warning naming the node that is not supported."""
    node, _ = node_eval.source(color_socket)
    if node is None:
        return None
    if node.bl_idname != ENVIRONMENT_NODE_IDNAME:
        warn("world %r: %s feeds the Background's Color and is not supported (hairis reads an "
             "Environment Texture, optionally through a Mapping node); it uses the Color's "
             "unlinked value" % (world.name, _node_label(node)))
        return None
    if getattr(node, "projection", "EQUIRECTANGULAR") != "EQUIRECTANGULAR":
        warn("world %r: %s: the %s projection is not supported; the world is rendered with the "
             "Background's colour" % (world.name, _node_label(node), node.projection.lower()))
        return None
    if getattr(node, "interpolation", "Linear") != "Linear":
        warn("world %r: %s: %s interpolation is not supported; hairis interpolates linearly"
             % (world.name, _node_label(node), node.interpolation))
    image = node.image
    if image is None:
        warn("world %r: %s has no image; the world is rendered with the Background's colour"
             % (world.name, _node_label(node)))
        return None
    found = surfaces.image_source(image, "world %r: %s" % (world.name, _node_label(node)), warn,
                                  fallback="the world is rendered with the Background's colour",
                                  clamp_negative=False)
    if found is None:
        return None
    path, pixels, color_space = found
    data = EnvironmentData(image_name=image.name, path=path, pixels=pixels,
                           color_space=color_space)
    vector = find_input(node, "Vector")
    source, source_socket = node_eval.source(vector) if vector is not None else (None, None)
    if source is not None and source.bl_idname == "ShaderNodeMapping":
        mapping = _mapping_vector(world, source, warn)
        if mapping is not None:
            data.mapping, data.rotation, data.scale = mapping
        inner = find_input(source, "Vector")
        data.matrix = _coordinates(world, inner, warn) if inner is not None else np.eye(4)
    elif vector is not None:
        data.matrix = _coordinates(world, vector, warn)
    cycles = getattr(world, "cycles", None)
    method = getattr(cycles, "sampling_method", "AUTOMATIC") if cycles is not None else "AUTOMATIC"
    data.sampling = SAMPLING_METHODS.get(method, "auto")
    if data.sampling == "manual":
        data.map_resolution = int(getattr(cycles, "sample_map_resolution", 1024))
    return data
