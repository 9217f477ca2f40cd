"""What differs between the Blender versions Hairis supports (3.4 to 5.x).

Hairis reads Cycles' node trees; their sockets and some Python API names changed over those
versions. Everything version-dependent is decided here, from ``bpy.app.version`` (and from
what the running Blender has, never from socket indices), so the other modules read one name:

- the supported versions: 3.4 and newer within the major versions Hairis knows (3, 4, 5);
  :func:`version_problem` names the running version and the supported ones otherwise;
- the Principled BSDF's inputs and meaning changed in 4.0 (a layered model; Specular → Specular
  IOR Level, Emission → Emission Color, ...): :func:`cycles_surfaces` says which Cycles the
  surface nodes follow and surfaces.py reads each version's sockets; :func:`find_input` takes
  the first of an input's names that is present;
- ``use_nodes`` of materials and worlds is deprecated from 5.0 (always on; reading it warns):
  :func:`uses_nodes`;
- the Principled Hair BSDF's ``model`` (4.0+: 'CHIANG' or 'HUANG'; 3.4 has only Chiang);
- a render pass's ``rect.foreach_set``: (pixels, channels) rows in 3.4, a flat float buffer in 4.5+:
  :func:`set_pass_pixels`;
- how Cycles converts lights (``hairis_scene_add_light``'s ``cycles`` option): as 3.4 before
  4.0, as 4.5 from 4.0 on (area lights 4/π brighter, suns a cone of constant radiance, spots
  without 3.4's cosine); point and spot lights are spheres in 4.0 and disks with Soft Falloff
  (``use_soft_falloff``, default on) from 4.1: :func:`cycles_lights`, :func:`soft_falloff`;
- whether rays hit a hair strand from inside its tube (``hairis_render``'s
  ``curve_backfaces``): Cycles with Embree 3 (Blender 3.4) culls those back faces, Blender's
  builds from 3.6 use Embree 4, whose curve filter does not: :func:`curve_backfaces`;
- Cycles' Curves > Shape (``scene.cycles_curves.shape``, ``hairis_render``'s ``curve_shape``):
  RIBBONS and THICK in every version, THICK_LINEAR from 5.0: :func:`curve_shape`;
- how many transparent surfaces a path crosses under Max Bounces: Transparent
  (``hairis_render``'s ``transparent_limit``): the setting + 1 up to 4.5, the setting (at
  least 1) from 5.0, where Cycles stores the setting itself: :func:`transparent_limit`.
"""

import bpy
import numpy as np

MINIMUM_VERSION = (3, 4, 0)
"""The oldest Blender Hairis supports (bl_info's "blender")."""

KNOWN_MAJOR_VERSIONS = (3, 4, 5)
"""Major versions whose node and Python APIs Hairis was written and tested against."""

SUPPORTED_TEXT = "Blender 3.4 to 5.x (tested: 3.4, 4.5 LTS, 5.0)"

NODES_ALWAYS_ON = (5, 0, 0)
"""From 5.0 materials and worlds always use nodes (``use_nodes`` is deprecated); lights not."""


def running_version():
    """``bpy.app.version`` as a tuple (a function, so tests can stand in another version)."""
    return tuple(bpy.app.version)


def version_string(version=None):
    """'4.5.15' for (4, 5, 15)."""
    return ".".join(str(part) for part in (version or running_version()))


def cycles_version(version=None):
    """The "major.minor" of the Blender (and so the Cycles) whose hair model hairis follows:
    Cycles 4.2 changed where the Chiang model applies the cuticle tilt."""
    version = running_version() if version is None else version
    return "%d.%d" % (version[0], version[1])


def version_problem(version=None):
    """None when Hairis supports ``version`` (default: the running one), else why not."""
    version = tuple(version or running_version())
    if version < MINIMUM_VERSION:
        return ("Hairis does not support Blender %s: it needs %s"
                % (version_string(version), SUPPORTED_TEXT))
    if version[0] not in KNOWN_MAJOR_VERSIONS:
        return ("Hairis does not support Blender %s (a major version it does not know): it "
                "supports %s" % (version_string(version), SUPPORTED_TEXT))
    return None


def uses_nodes(idblock):
    """True when a material, world or light is shaded by its node tree."""
    if idblock is None or getattr(idblock, "node_tree", None) is None:
        return False
    if running_version() >= NODES_ALWAYS_ON and isinstance(
            idblock, (bpy.types.Material, bpy.types.World)):
        return True
    return bool(getattr(idblock, "use_nodes", False))


def find_input(node, names):
    """The first of ``names`` that ``node`` has as an input (by name or identifier), or None.

    Enabled sockets win over disabled ones of the same name.
    """
    for name in names:
        found = None
        for socket in node.inputs:
            if socket.name == name or socket.identifier == name:
                if getattr(socket, "enabled", True):
                    return socket
                found = found or socket
        if found is not None:
            return found
    return None


def hair_model(node):
    """The Principled Hair BSDF's model: 'CHIANG' before 4.0, else the node's ``model``."""
    return getattr(node, "model", "CHIANG")


def set_pass_pixels(render_pass, rgba):
    """Writes (height, width, channels) float pixels into a RenderPass (whichever layout it
    takes)."""
    pixels = np.ascontiguousarray(rgba, np.float32)
    try:
        render_pass.rect.foreach_set(pixels.reshape(-1))
    except (TypeError, ValueError):
        render_pass.rect.foreach_set(pixels.reshape(-1, pixels.shape[-1]))


CYCLES_4_SURFACES = (4, 0, 0)
"""From 4.0 the surface nodes follow Cycles 4.5 (the layered Principled BSDF, multiscatter GGX
by energy compensation, height-correlated shadowing), unchanged up to 5.0."""


def cycles_surfaces(version=None):
    """The Cycles ('3.4' or '4.5') whose surface nodes the running Blender's Cycles has."""
    return "4.5" if tuple(version or running_version()) >= CYCLES_4_SURFACES else "3.4"


def corner_normals(mesh):
    """(loops, 3) float32 corner normals of a mesh with its loop triangles: Blender 4.1+'s
    ``corner_normals``, 3.x's split normals (``calc_normals_split``, which honour smooth and
    flat faces, auto smooth and custom normals)."""
    normals = np.empty(len(mesh.loops) * 3, np.float32)
    corner = getattr(mesh, "corner_normals", None)
    if corner is not None:
        corner.foreach_get("vector", normals)
    else:
        mesh.calc_normals_split()
        mesh.loops.foreach_get("normal", normals)
    return normals.reshape(-1, 3)


def flat_triangles(mesh):
    """(loop triangles,) bool: the triangles Cycles shades with their own geometric normal.

    Blender 4.1+ gives a mesh one normals domain, and Cycles shades every triangle of a 'FACE'
    mesh flat; earlier, flat faces are flat unless Auto Smooth makes split normals of them. A
    flat non-planar quad's corner normal is the polygon's, not its triangles'."""
    count = len(mesh.loop_triangles)
    domain = getattr(mesh, "normals_domain", None)
    if domain is not None:
        return np.full(count, domain == "FACE")
    if getattr(mesh, "use_auto_smooth", False) or getattr(mesh, "has_custom_normals", False):
        return np.zeros(count, bool)
    smooth = np.empty(count, bool)
    mesh.loop_triangles.foreach_get("use_smooth", smooth)
    return ~smooth


def render_uv_layer(mesh):
    """The UV map Cycles reads for an Image Texture's default coordinates (the active render
    one), or None."""
    layers = getattr(mesh, "uv_layers", None)
    if layers is None or len(layers) == 0:
        return None
    for layer in layers:
        if getattr(layer, "active_render", False):
            return layer
    return layers.active


CYCLES_4_LIGHTS = (4, 0, 0)
"""From 4.0 Cycles converts lights as ``cycles=4.5`` says (unchanged up to 5.0)."""

SOFT_FALLOFF = (4, 1, 0)
"""Point and spot lights have Soft Falloff from 4.1; 4.0 always made them spheres."""


def cycles_lights(version=None):
    """The light conversion ('3.4' or '4.5') of the running Blender's Cycles."""
    return "4.5" if tuple(version or running_version()) >= CYCLES_4_LIGHTS else "3.4"


def soft_falloff(light, version=None):
    """A point or spot light's Soft Falloff: its ``use_soft_falloff`` from 4.1, off (a sphere)
    in 4.0, on (the disk, Cycles 3.4's only shape) before."""
    version = tuple(version or running_version())
    if CYCLES_4_LIGHTS <= version < SOFT_FALLOFF:
        return False
    return bool(getattr(light, "use_soft_falloff", True))


EMBREE_4_CURVES = (3, 6, 0)
"""From 3.6 Blender's Cycles traces curves with Embree 4 and no backface culling."""


def curve_backfaces(version=None):
    """``curve_backfaces`` of the running Blender's Cycles: 'hit' from 3.6, else 'ignore'.

    A ray that starts inside another strand's tube (strands that overlap) meets that tube
    from inside; Cycles with Embree 3 lets it pass, with Embree 4 it is a hit.
    """
    return "hit" if tuple(version or running_version()) >= EMBREE_4_CURVES else "ignore"


CURVE_SHAPES = {"THICK": "thick", "RIBBONS": "ribbons", "THICK_LINEAR": "thick_linear"}
"""Cycles' Curves > Shape identifiers and the library's ``curve_shape`` of each."""


def curve_shape(scene):
    """(the library's ``curve_shape``, a warning or None) from Cycles' Curves > Shape.

    Without Cycles' settings (its add-on not registered) curves render as 3D Curves; so does a
    shape Hairis does not know, with a warning that names it.
    """
    curves = getattr(scene, "cycles_curves", None) if scene is not None else None
    shape = str(getattr(curves, "shape", "THICK"))
    if shape in CURVE_SHAPES:
        return CURVE_SHAPES[shape], None
    return "thick", ("Hairis does not render Cycles' curve shape %s: it renders the curves as "
                     "3D Curves (THICK) instead" % shape)


CYCLES_5_TRANSPARENT_LIMIT = (5, 0, 0)
"""From 5.0 Cycles stores Max Bounces: Transparent as set, no longer the setting + 1."""


def transparent_limit(version=None):
    """``transparent_limit`` of the running Blender's Cycles: 'setting' from 5.0, else
    'plus_one' (a path crosses at most max(setting, 1) or setting + 1 transparent surfaces)."""
    version = tuple(version or running_version())
    return "setting" if version >= CYCLES_5_TRANSPARENT_LIMIT else "plus_one"
