"""Mesh materials: a Blender material's surface node tree → hairis surface nodes.

A material becomes a list of node option dicts in the C API's terms (``hairis_scene_add_
surface_material``), children before parents, the root last; ``shader1``/``shader2`` of Mix and
Add Shaders are positions in that list and ``base_color_texture``/``color_texture`` positions
in the exporter's texture list (:class:`TextureData`). The engine turns positions into the C
API's indices.

What is read (compat.cycles_surfaces picks the Cycles whose node semantics hairis follows:
3.4 before Blender 4.0, 4.5 from 4.0 on; sockets are found by identifier or name):

- Principled BSDF, Diffuse BSDF, Glossy BSDF, Emission, Mix Shader and Add Shader; any other
  shader node is a warning naming it, and hairis shades the material's viewport colour as a
  diffuse albedo in its place (a Principled Hair BSDF on a mesh: grey diffuse, in export.py);
- colour inputs (Base Color, Color) fed by an Image Texture, directly or through Reroutes, with
  its image (a file by path, packed/generated/edited images as pixels), colour space, Linear or
  Closest interpolation, extension, and a Mapping node (Point, Texture or Vector) between it and
  the UV map (its Vector unlinked, or a UV Map / Texture Coordinate UV output);
- every other input by its unlinked value; a linked one is a warning.

Inputs hairis does not model are warnings when they change the image: Transmission, Alpha,
Anisotropic, normal and tangent inputs, 4.x Sheen and Thin Film; Subsurface is approximated as
diffuse (Cycles' random walk is not traced), 3.4's Multiscatter GGX by 4.x's energy
compensation, and roughness below 0.0178 renders as a very sharp GGX instead of a mirror.
"""

import math
import os
from dataclasses import dataclass

import bpy
import numpy as np

from . import compat

MIRROR_ROUGHNESS = math.sqrt(3.2e-4)
"""Below this roughness Cycles renders a perfect mirror; hairis a sharp GGX lobe."""

LINEAR_COLOR_SPACES = {"Linear", "Linear Rec.709", "Non-Color", "Raw", "Linear BT.709"}
"""Image colour spaces whose values are scene-linear Rec.709 (or data) as stored."""
SRGB_COLOR_SPACES = {"sRGB", "sRGB 2.1"}

INTERPOLATIONS = {"Linear": "linear", "Closest": "closest"}
EXTENSIONS = {"REPEAT": "repeat", "EXTEND": "extend", "CLIP": "clip", "MIRROR": "mirror"}
MAPPINGS = {"POINT": "point", "TEXTURE": "texture", "VECTOR": "vector"}
DISTRIBUTIONS = {"GGX": "ggx", "MULTI_GGX": "multi_ggx"}

PRINCIPLED_INPUTS = {
    # The Cycles version → (option, socket names, components) read as plain values.
    "3.4": (
        ("metallic", ("Metallic",), 1), ("roughness", ("Roughness",), 1), ("ior", ("IOR",), 1),
        ("specular", ("Specular",), 1), ("specular_tint", ("Specular Tint",), 1),
        ("subsurface", ("Subsurface",), 1), ("subsurface_color", ("Subsurface Color",), 3),
        ("sheen", ("Sheen",), 1), ("sheen_tint", ("Sheen Tint",), 1),
        ("coat", ("Clearcoat",), 1), ("coat_roughness", ("Clearcoat Roughness",), 1),
    ),
    "4.5": (
        ("metallic", ("Metallic",), 1), ("roughness", ("Roughness",), 1), ("ior", ("IOR",), 1),
        ("specular", ("Specular IOR Level", "Specular"), 1),
        ("specular_tint_color", ("Specular Tint",), 3),
        ("subsurface", ("Subsurface Weight",), 1),
        ("coat", ("Coat Weight",), 1), ("coat_roughness", ("Coat Roughness",), 1),
        ("coat_ior", ("Coat IOR",), 1), ("coat_tint", ("Coat Tint",), 3),
        ("diffuse_roughness", ("Diffuse Roughness",), 1),
    ),
}
"""The Principled BSDF inputs hairis renders, per Cycles version."""

OPTION_RANGES = {
    "metallic": (0.0, 1.0), "roughness": (0.0, 1.0), "ior": (0.0, 1000.0),
    "specular": (0.0, math.inf), "specular_tint": (0.0, 1.0), "subsurface": (0.0, 1.0),
    "sheen": (0.0, math.inf), "sheen_tint": (0.0, 1.0), "coat": (0.0, math.inf),
    "coat_roughness": (0.0, 1.0), "coat_ior": (1.0, 1000.0), "diffuse_roughness": (0.0, 1.0),
}
"""What the C API accepts; values outside are clamped, as Cycles clamps them."""

UNSUPPORTED_PRINCIPLED = {
    # The Cycles version → (socket names, what makes it matter, what hairis does instead).
    "3.4": (
        (("Transmission",), "above 0", "renders the material opaque (Transmission 0)"),
        (("Anisotropic",), "above 0", "renders isotropic reflections (Anisotropic 0)"),
        (("Alpha",), "below 1", "renders the material opaque (Alpha 1)"),
    ),
    "4.5": (
        (("Transmission Weight",), "above 0", "renders the material opaque (Transmission 0)"),
        (("Anisotropic",), "above 0", "renders isotropic reflections (Anisotropic 0)"),
        (("Alpha",), "below 1", "renders the material opaque (Alpha 1)"),
        (("Sheen Weight",), "above 0", "leaves the sheen layer out"),
        (("Thin Film Thickness",), "above 0", "leaves the thin film out"),
    ),
}

NORMAL_INPUTS = ("Normal", "Clearcoat Normal", "Coat Normal", "Tangent")


@dataclass
class ImageData:
    """An image the library reads from a file or takes as pixels (textures and worlds)."""

    image_name: str
    path: str = None
    """An image file the library reads, or None when ``pixels`` hold the image."""
    pixels: np.ndarray = None
    """(height, width, channels) floats, bottom row first (packed, generated, edited images)."""
    color_space: str = "linear"
    """'linear' or 'srgb' (the image's colour space)."""


@dataclass
class TextureData(ImageData):
    """An Image Texture node's image and sampling, as ``hairis_scene_add_texture`` takes it."""

    interpolation: str = "linear"
    extension: str = "repeat"
    mapping: str = "none"
    location: tuple = (0.0, 0.0, 0.0)
    rotation: tuple = (0.0, 0.0, 0.0)
    scale: tuple = (1.0, 1.0, 1.0)

    def key(self):
        """What makes two textures the same texture."""
        return (self.image_name, self.path, self.color_space, self.interpolation,
                self.extension, self.mapping, self.location, self.rotation, self.scale)

    def options(self):
        """The texture options (without the image or pixels)."""
        values = {"color_space": self.color_space, "interpolation": self.interpolation,
                  "extension": self.extension, "mapping": self.mapping}
        if self.mapping != "none":
            values.update(location=self.location, rotation=self.rotation, scale=self.scale)
        return values


def _rgb(value):
    return tuple(float(v) for v in tuple(value)[:3])


def _label(node):
    return "%s %r" % (node.bl_label or node.bl_idname, node.name)


def _value(socket, components):
    value = socket.default_value
    if components == 1:
        return float(value)
    return _rgb(value)


def image_source(image, where, warn, fallback="hairis uses the input's unlinked value",
                 clamp_negative=True):
    """(path, pixels, colour space) of an image, or None with a warning that ends in
    ``fallback`` (what is rendered instead). ``clamp_negative`` sets negative texels of an
    image read as pixels to 0; without it they reach the library, which refuses them by name."""
    name = image.colorspace_settings.name
    if name in SRGB_COLOR_SPACES:
        color_space = "srgb"
    else:
        color_space = "linear"
        if name not in LINEAR_COLOR_SPACES:
            warn("%s: image %r has the colour space %r, which hairis does not convert; it reads "
                 "the values as linear Rec.709" % (where, image.name, name))
    if image.source not in {"FILE", "GENERATED"}:
        warn("%s: %s images are not supported; %s" % (where, image.source.lower(), fallback))
        return None
    if image.source == "FILE" and image.packed_file is None and not image.is_dirty:
        path = bpy.path.abspath(image.filepath, library=image.library)
        if path and os.path.isfile(path) and ";" not in path and path == path.strip():
            return path, None, color_space
    # Packed, generated, edited in memory, or a path the C API cannot take: the pixels.
    width, height = (int(v) for v in image.size)
    channels = int(image.channels)
    if width < 1 or height < 1 or channels < 1:
        warn("%s: image %r has no pixels (a missing file?); %s" % (where, image.name, fallback))
        return None
    pixels = np.empty(width * height * channels, np.float32)
    image.pixels.foreach_get(pixels)
    pixels = pixels.reshape(height, width, channels)
    if clamp_negative and channels >= 3:
        pixels = np.maximum(pixels, 0.0)  # Blender's byte-to-float can leave -0.0
    return None, pixels, color_space


class SurfaceReader:
    """Reads one material's surface tree (see the module docstring)."""

    def __init__(self, material, warn, add_texture, follow_link, version=None):
        self.material = material
        self.name = material.name
        self.warn = warn
        self.add_texture = add_texture
        """TextureData → its position in the exporter's texture list."""
        self.follow_link = follow_link
        """socket → (node, output socket) feeding it, through reroutes and muted nodes."""
        self.version = version or compat.cycles_surfaces()
        self.nodes = []
        self._done = {}

    # -- the tree --

    def read(self, root):
        """The node list of the tree under ``root`` (the node feeding the output's Surface)."""
        self.visit(root)
        return self.nodes

    def add(self, options):
        self.nodes.append(options)
        return len(self.nodes) - 1

    def empty(self):
        """A shader input with nothing linked: no closure."""
        return self.add({"type": "emission", "strength": 0.0})

    def visit(self, node):
        key = node.as_pointer()
        if key in self._done:
            return self._done[key]
        kind = node.bl_idname
        if kind == "ShaderNodeBsdfPrincipled":
            position = self.principled(node)
        elif kind == "ShaderNodeBsdfDiffuse":
            position = self.diffuse(node)
        elif kind in {"ShaderNodeBsdfGlossy", "ShaderNodeBsdfAnisotropic"}:
            position = self.glossy(node)
        elif kind == "ShaderNodeEmission":
            color = self.plain(node, ("Color",), 3, (1.0, 1.0, 1.0))
            strength = self.plain(node, ("Strength",), 1, 1.0)
            position = self.add({"type": "emission", "color": tuple(max(c, 0.0) for c in color),
                                 "strength": max(strength, 0.0)})
        elif kind in {"ShaderNodeMixShader", "ShaderNodeAddShader"}:
            shaders = [s for s in node.inputs if s.type == "SHADER"]
            children = []
            for socket in shaders[:2]:
                child, _ = self.follow_link(socket)
                children.append(self.visit(child) if child is not None else self.empty())
            while len(children) < 2:
                children.append(self.empty())
            options = {"type": "add", "shader1": children[0], "shader2": children[1]}
            if kind == "ShaderNodeMixShader":
                factor = self.plain(node, ("Fac", "Factor"), 1, 0.5)
                options = {"type": "mix", "factor": min(max(factor, 0.0), 1.0),
                           "shader1": children[0], "shader2": children[1]}
            position = self.add(options)
        else:
            self.warn("material %r: %s is not supported on meshes (node %r); hairis renders the "
                      "material's viewport colour as a diffuse albedo in its place"
                      % (self.name, node.bl_label or kind, node.name))
            position = self.add({"type": "diffuse", "cycles": self.version,
                                 "color": tuple(min(max(c, 0.0), 1.0)
                                                for c in _rgb(self.material.diffuse_color))})
        self._done[key] = position
        return position

    # -- inputs --

    def socket(self, node, names):
        return compat.find_input(node, tuple(names))

    def plain(self, node, names, components, default):
        """An input's unlinked value (a warning when it is linked), or ``default`` without it."""
        socket = self.socket(node, names)
        if socket is None:
            return default
        if socket.is_linked:
            source, _ = self.follow_link(socket)
            if source is not None:
                self.warn("material %r: input %r of %s is linked (to %s); hairis uses its "
                          "unlinked value" % (self.name, socket.name, _label(node), _label(source)))
        return _value(socket, components)

    def color(self, node, names, default):
        """(value, texture position or -1) of a colour input that may hold an Image Texture."""
        socket = self.socket(node, names)
        if socket is None:
            return default, -1
        value = tuple(max(c, 0.0) for c in _rgb(socket.default_value))
        if not socket.is_linked:
            return value, -1
        source, output = self.follow_link(socket)
        if source is None:
            return value, -1
        where = "material %r: %s" % (self.name, _label(source))
        if source.bl_idname != "ShaderNodeTexImage":
            self.warn("material %r: %s feeds %r of %s and is not supported (hairis reads an Image "
                      "Texture on the UV map there); it uses the input's unlinked value"
                      % (self.name, _label(source), socket.name, _label(node)))
            return value, -1
        if (output.identifier or output.name) != "Color":
            self.warn("%s: its %s output is not supported; hairis uses the input's unlinked "
                      "value" % (where, output.name))
            return value, -1
        texture = self.image_texture(source, where)
        return value, (self.add_texture(texture) if texture is not None else -1)

    def image_texture(self, node, where):
        """The :class:`TextureData` of an Image Texture node, or None (warned)."""
        image = node.image
        if image is None:
            self.warn("%s has no image; hairis uses the input's unlinked value" % where)
            return None
        if getattr(node, "projection", "FLAT") != "FLAT":
            self.warn("%s: the %s projection is not supported; hairis projects it flat on the UV "
                      "map" % (where, node.projection.lower()))
        interpolation = INTERPOLATIONS.get(getattr(node, "interpolation", "Linear"))
        if interpolation is None:
            self.warn("%s: %s interpolation is not supported; hairis interpolates linearly"
                      % (where, node.interpolation))
            interpolation = "linear"
        extension = EXTENSIONS.get(getattr(node, "extension", "REPEAT"))
        if extension is None:
            self.warn("%s: the %s extension is not supported; hairis repeats the image"
                      % (where, node.extension))
            extension = "repeat"
        found = image_source(image, where, self.warn)
        if found is None:
            return None
        path, pixels, color_space = found
        texture = TextureData(image_name=image.name_full, path=path, pixels=pixels,
                              color_space=color_space, interpolation=interpolation,
                              extension=extension)
        self.read_vector(node, texture, where)
        return texture

    def read_vector(self, node, texture, where):
        """What feeds the texture's Vector: the UV map, optionally through a Mapping node."""
        vector = self.socket(node, ("Vector",))
        source, output = self.follow_link(vector) if vector is not None else (None, None)
        if source is not None and source.bl_idname == "ShaderNodeMapping":
            kind = MAPPINGS.get(getattr(source, "vector_type", "POINT"))
            if kind is None:
                self.warn("%s: a Mapping of type %s is not supported on UV coordinates; ignored"
                          % (where, source.vector_type.title()))
            else:
                texture.mapping = kind
                values = {}
                for name, default in (("Location", (0.0, 0.0, 0.0)),
                                      ("Rotation", (0.0, 0.0, 0.0)), ("Scale", (1.0, 1.0, 1.0))):
                    socket = self.socket(source, (name,))
                    values[name] = default if socket is None else _rgb(socket.default_value)
                    if socket is not None and socket.is_linked:
                        self.warn("%s: input %r of %s is linked; hairis uses its unlinked value"
                                  % (where, name, _label(source)))
                if any(v == 0.0 for v in values["Scale"]):
                    self.warn("%s: %s has a zero Scale; hairis uses Scale 1"
                              % (where, _label(source)))
                    values["Scale"] = (1.0, 1.0, 1.0)
                texture.location = values["Location"]
                texture.rotation = values["Rotation"]
                texture.scale = values["Scale"]
            inner = self.socket(source, ("Vector",))
            source, output = self.follow_link(inner) if inner is not None else (None, None)
        if source is None:
            return
        if source.bl_idname == "ShaderNodeUVMap":
            self.check_uv_map(getattr(source, "uv_map", ""), where)
            return
        if source.bl_idname == "ShaderNodeTexCoord" and (output.identifier or output.name) == "UV":
            return
        self.warn("%s: %s feeds its Vector and is not supported; hairis reads the texture at the "
                  "UV map" % (where, _label(source)))

    def check_uv_map(self, name, where):
        if name:
            self.warn("%s: UV Map %r: hairis reads the mesh's active render UV map (named maps "
                      "are not supported)" % (where, name))

    # -- shader nodes --

    def check_normals(self, node):
        for name in NORMAL_INPUTS:
            socket = self.socket(node, (name,))
            if socket is not None and socket.is_linked and self.follow_link(socket)[0] is not None:
                self.warn("material %r: input %r of %s is linked; hairis shades with the mesh's "
                          "normals" % (self.name, socket.name, _label(node)))

    def check_roughness(self, node, roughness, what="Roughness"):
        if roughness < MIRROR_ROUGHNESS:
            self.warn("material %r: %s of %s is %.3g, a mirror in Cycles; hairis renders a very "
                      "sharp GGX lobe (roughness %.4f) instead"
                      % (self.name, what, _label(node), roughness, MIRROR_ROUGHNESS))

    def distribution(self, node, approximate_34=False, roughness=0.5):
        distribution = getattr(node, "distribution", "GGX")
        if distribution not in DISTRIBUTIONS:
            self.warn("material %r: %s: the %s distribution is not supported; hairis uses GGX"
                      % (self.name, _label(node), distribution.replace("_", " ").title()))
            return "ggx"
        if approximate_34 and distribution == "MULTI_GGX" and roughness > 0.075:
            self.warn("material %r: %s: Cycles 3.4's random-walk Multiscatter GGX is approximated "
                      "by Cycles 4's energy compensation" % (self.name, _label(node)))
        return DISTRIBUTIONS[distribution]

    def diffuse(self, node):
        color, texture = self.color(node, ("Color",), (0.8, 0.8, 0.8))
        roughness = self.plain(node, ("Roughness",), 1, 0.0)
        self.check_normals(node)
        if any(c > 1.0 for c in color):
            self.warn("material %r: %s: a Color above 1 is clamped to 1"
                      % (self.name, _label(node)))
        return self.add({"type": "diffuse", "cycles": self.version,
                         "color": tuple(min(c, 1.0) for c in color), "color_texture": texture,
                         "roughness": min(max(roughness, 0.0), 1.0)})

    def glossy(self, node):
        color, texture = self.color(node, ("Color",), (0.8, 0.8, 0.8))
        roughness = min(max(self.plain(node, ("Roughness",), 1, 0.5), 0.0), 1.0)
        anisotropy = self.plain(node, ("Anisotropy",), 1, 0.0)
        if anisotropy != 0.0:
            self.warn("material %r: %s: Anisotropy is not supported; hairis renders isotropic "
                      "reflections" % (self.name, _label(node)))
        self.check_normals(node)
        self.check_roughness(node, roughness)
        distribution = self.distribution(node, self.version == "3.4", roughness)
        return self.add({"type": "glossy", "cycles": self.version, "color": color,
                         "color_texture": texture, "roughness": roughness,
                         "distribution": distribution})

    def principled(self, node):
        version = self.version
        options = {"type": "principled", "cycles": version}
        options["base_color"], options["base_color_texture"] = self.color(
            node, ("Base Color",), (0.8, 0.8, 0.8))
        for option, names, components in PRINCIPLED_INPUTS[version]:
            socket = self.socket(node, names)
            if socket is None:
                continue  # an input this Blender does not have (e.g. Diffuse Roughness before 4.3)
            value = self.plain(node, names, components, None)
            if components == 1:
                lo, hi = OPTION_RANGES[option]
                value = min(max(value, lo), hi)
            else:
                value = tuple(max(c, 0.0) for c in value)
            options[option] = value
        emission_names = ("Emission",) if version == "3.4" else ("Emission Color", "Emission")
        emission = self.plain(node, emission_names, 3, (0.0, 0.0, 0.0))
        strength = self.plain(node, ("Emission Strength",), 1, 1.0)
        options["emission"] = tuple(max(c * strength, 0.0) for c in emission)
        options["distribution"] = self.distribution(node, version == "3.4",
                                                    options.get("roughness", 0.5))
        self.check_roughness(node, options.get("roughness", 0.5))
        for names, when, instead in UNSUPPORTED_PRINCIPLED[version]:
            socket = self.socket(node, names)
            if socket is None:
                continue
            value = float(socket.default_value)
            matters = value > 0.0 if when == "above 0" else value < 1.0
            if matters or (socket.is_linked and self.follow_link(socket)[0] is not None):
                self.warn("material %r: %s: %s is not supported; hairis %s"
                          % (self.name, _label(node), socket.name, instead))
        if options.get("subsurface", 0.0) > 0.0:
            self.warn("material %r: %s: subsurface scattering is approximated by diffuse "
                      "reflection of the subsurface colour" % (self.name, _label(node)))
        if version != "3.4" and options.get("coat", 0.0) > 0.0 and max(options["emission"]) > 0.0:
            self.warn("material %r: %s: hairis does not dim the emission under the coat"
                      % (self.name, _label(node)))
        self.check_normals(node)
        return self.add(options)
