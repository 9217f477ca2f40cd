"""Scene export: the evaluated depsgraph → plain numpy arrays (:class:`SceneData`).

Nothing here needs the native library, so the export can be tested on its own. All bulk
data moves with ``foreach_get`` into numpy and is transformed in numpy; the only per-point
calls left are ``ParticleSystem.co_hair``, which is the one accessor Blender 3.4's Python API
has for the evaluated particle path cache (see :func:`export_particle_hair`).

Rules follow Cycles 3.4 (``intern/cycles/blender/curves.cpp``, ``object.cpp``, ``light.cpp``):

- particle hair: systems of type HAIR drawn as PATH whose modifier is enabled for the
  depsgraph's mode; ``2**render_step + 1`` keys per strand (``display_step`` in the viewport,
  plus ``kink_extra_steps`` for spiral kink); only the children when there are any, else the
  parents; radius ``radius_scale·0.5·(tip + (root − tip)·shape(1 − t))`` with t the
  object-space arc-length fraction, 0 at the tip with ``use_close_tip``; material slot
  ``settings.material``;
- Curves objects: the ``radius`` point attribute, 0.005 without it; material slot 1; for Huang
  materials the curve normals (``Curves.normals``: Blender's ``curves_normals_point_domain_calc``,
  which Cycles reads into its normal attribute), in object space as Cycles uses them;
- curve radii scale with the cube root of the object matrix's determinant (Hair::apply_transform);
- hair inputs fed by node chains (node_eval): evaluated per curve (Hair Info Random, Length)
  or per point (Intercept: the object-space arc-length fraction) and sent as curve inputs;
  an unlinked Random is the per-strand random number (a hash of the curve's index within its
  object, uniform in [0, 1]) wherever Random Color or Random Roughness reads it (Chiang; Huang
  hair takes each input's unlinked value).

The Principled Hair BSDF's Huang model (Blender 4.0+) follows Cycles 4.5/5.0
(``kernel/svm/closure.h``): its inputs by identifier, Aspect Ratio above 1 as its inverse,
negative lobe multipliers as 0, and all three ≤ 0 as no closure at all (black, opaque strands).
"""

import math
import os
from dataclasses import dataclass, field, replace

import bpy
import numpy as np

from . import compat, hair_mix, node_eval, surfaces

DEFAULT_CURVES_RADIUS = 0.005
"""Cycles' radius for Curves without a ``radius`` attribute."""
RENDER_BYTES_PER_POINT = 220
"""What the library holds per hair point at its peak while it builds and renders a scene (its
copies of the points, the curve segments and Embree's BVH over them), with a margin."""
RENDER_BYTES_PER_CURVE = 64
"""The same per curve (its duplicated end points and its offsets)."""

DEFAULT_ALBEDO = (0.8, 0.8, 0.8)
"""Cycles' default surface (no material): a 0.8 grey diffuse."""

PARAMETRIZATIONS = {"ABSORPTION": 0, "MELANIN": 1, "COLOR": 2}
"""Principled Hair BSDF ``parametrization`` → hairis_parametrization."""

HAIR_INPUTS = (
    # (HairParameters field, node input identifier, number of components, models reading it)
    ("color", "Color", 3, ("CHIANG", "HUANG")),
    ("melanin", "Melanin", 1, ("CHIANG", "HUANG")),
    ("melanin_redness", "Melanin Redness", 1, ("CHIANG", "HUANG")),
    ("tint", "Tint", 3, ("CHIANG", "HUANG")),
    ("absorption_coefficient", "Absorption Coefficient", 3, ("CHIANG", "HUANG")),
    ("aspect_ratio", "Aspect Ratio", 1, ("HUANG",)),
    ("roughness", "Roughness", 1, ("CHIANG", "HUANG")),
    ("radial_roughness", "Radial Roughness", 1, ("CHIANG",)),
    ("coat", "Coat", 1, ("CHIANG",)),
    ("ior", "IOR", 1, ("CHIANG", "HUANG")),
    ("offset", "Offset", 1, ("CHIANG", "HUANG")),
    ("random_color", "Random Color", 1, ("CHIANG", "HUANG")),
    ("random_roughness", "Random Roughness", 1, ("CHIANG", "HUANG")),
    ("random", "Random", 1, ("CHIANG", "HUANG")),
    ("reflection", "R lobe", 1, ("HUANG",)),
    ("transmission", "TT lobe", 1, ("HUANG",)),
    ("secondary_reflection", "TRT lobe", 1, ("HUANG",)),
)
"""Every input of the Principled Hair BSDF node the models read, by socket identifier (the
lobe multipliers are shown as Reflection, Transmission and Secondary Reflection)."""

HUANG_LOBES = ("reflection", "transmission", "secondary_reflection")

HUANG_MATERIAL_ONLY = ("aspect_ratio",) + HUANG_LOBES
"""Huang inputs that cannot vary per strand: linked, they render with their unlinked value."""

HUANG_CYCLES = (4, 5, 0)
"""Hairis' Huang is Cycles 4.5's (5.0's is the same); 4.0 to 4.4 integrate it differently."""

HAIR_NODE_IDNAME = "ShaderNodeBsdfHairPrincipled"

CURVE_INPUT_NAMES = {"absorption_coefficient": "absorption"}
"""HairParameters fields whose C API curve-input name differs (the others are the same)."""

READ_BY = {"color": {"COLOR"}, "melanin": {"MELANIN"}, "melanin_redness": {"MELANIN"},
           "tint": {"MELANIN"}, "random_color": {"MELANIN"},
           "absorption_coefficient": {"ABSORPTION"}}
"""Inputs only one parametrization reads (Blender hides them under the others)."""

TINY_COLOUR = 1e-30
"""The smallest colour component hairis takes (0 would be infinite absorption)."""

INPUT_RANGES = {
    "color": (TINY_COLOUR, math.inf), "tint": (TINY_COLOUR, math.inf),
    "absorption_coefficient": (0.0, math.inf), "ior": (1.0 + 1e-6, math.inf),
    "offset": (-math.pi / 2, math.pi / 2),
}
"""Where hairis clamps an input that varies per strand; the others are clamped to [0, 1]."""

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "FONT", "META"}
"""Object types exported as triangle meshes (through ``Object.to_mesh``)."""


class ExportError(Exception):
    """The scene cannot be rendered as it is (no camera, unsupported camera, ...)."""


@dataclass
class HairParameters:
    """A Principled Hair BSDF node's values: the model ('CHIANG' or 'HUANG') and its inputs
    (the other model's inputs keep their defaults and are not passed to the library)."""

    model: str = "CHIANG"
    parametrization: int = PARAMETRIZATIONS["COLOR"]
    color: tuple = (0.017513, 0.005763, 0.002059)
    melanin: float = 0.8
    melanin_redness: float = 1.0
    tint: tuple = (1.0, 1.0, 1.0)
    absorption_coefficient: tuple = (0.245531, 0.52, 1.365)
    roughness: float = 0.3
    radial_roughness: float = 0.3
    coat: float = 0.0
    ior: float = 1.55
    offset: float = math.radians(2.0)
    random_color: float = 0.0
    random_roughness: float = 0.0
    random: float = 0.0
    aspect_ratio: float = 0.85
    reflection: float = 1.0
    transmission: float = 1.0
    secondary_reflection: float = 1.0
    cycles: str = "3.4"
    """The Blender version whose Cycles evaluates the node (compat.cycles_version)."""
    strand_inputs: dict = field(default_factory=dict, compare=False, repr=False)
    """Inputs that vary per curve or point: field name → node_eval.Field (their values above
    are what the fiber, and so the TABLE strategy's tables, take)."""

    def as_dict(self):
        """The fiber's values keyed by C field name."""
        return {name: getattr(self, name) for name in self.__dataclass_fields__
                if name != "strand_inputs"}

    @property
    def scatters(self):
        """False for a Huang node whose three lobe multipliers are <= 0: Cycles makes no
        closure for it (the strands are black and opaque)."""
        return self.model != "HUANG" or any(getattr(self, name) > 0.0 for name in HUANG_LOBES)

    @property
    def oriented(self):
        """True when the fiber's cross-section is elliptical (Huang with Aspect Ratio != 1):
        its major axis follows the curve normals."""
        return self.model == "HUANG" and self.aspect_ratio != 1.0


@dataclass
class MaterialData:
    """One scene material: ``kind`` is 'HAIR' (``hair`` set), 'HAIR_MIX' (``mixture`` set: a
    Mix/Add Shader of the HAIR materials before it), 'SURFACE' (``nodes`` set: the surface node
    options of surfaces.py, root last) or 'DIFFUSE' (``albedo``, ``emission``)."""

    name: str
    kind: str
    hair: HairParameters = None
    albedo: tuple = DEFAULT_ALBEDO
    emission: tuple = (0.0, 0.0, 0.0)
    nodes: list = None
    mixture: hair_mix.Mixture = None
    material_name: str = None
    """The Blender material it came from (None for the default material)."""
    source: object = None
    """The original ``bpy.types.Material`` (None for the default material)."""


@dataclass
class CurvesData:
    """Hair curves in world space: curve c has points ``first[c] .. first[c+1]−1``."""

    name: str
    source: str
    """'PARTICLES' or 'CURVES'."""
    material: int
    first: np.ndarray
    positions: np.ndarray
    radii: np.ndarray
    inputs: dict = field(default_factory=dict)
    """Node inputs varying per curve or point: C API name → ('curve' | 'point', float32 array
    of (curves or points, components))."""
    normals: np.ndarray = None
    """(points, 3) curve normals (Curves objects with a Huang material), or None."""

    @property
    def curve_count(self):
        """Number of curves."""
        return int(self.first.size - 1)

    @property
    def point_count(self):
        """Number of points."""
        return int(self.positions.shape[0])


@dataclass
class MeshData:
    """A world-space triangle mesh with one scene material index per triangle, and per
    triangle corner (triangles, 3, ·) its world-space normals and UV map (or None)."""

    name: str
    positions: np.ndarray
    indices: np.ndarray
    materials: np.ndarray
    normals: np.ndarray = None
    uvs: np.ndarray = None


@dataclass
class LightData:
    """A light: ``kind`` 'SUN', 'POINT', 'SPOT' or 'AREA'; unused fields keep their defaults."""

    name: str
    kind: str
    color: tuple
    strength: float = 0.0
    """Sun strength in W/m², or point/area power in W."""
    direction: tuple = (0.0, 0.0, 1.0)
    angle: float = 0.0
    position: tuple = (0.0, 0.0, 0.0)
    radius: float = 0.0
    matrix: np.ndarray = None
    """Row-major 4×4 light-to-world (spot and area lights)."""
    shape: str = "SQUARE"
    size_x: float = 0.0
    size_y: float = 0.0
    spot_size: float = math.radians(45.0)
    spot_blend: float = 0.15
    soft_falloff: bool = True
    """Blender 4.1+'s Soft Falloff of point and spot lights (always a disk before)."""
    cycles: str = "3.4"
    """The Cycles whose light conversion this Blender's Cycles uses (compat.CYCLES_LIGHTS)."""


@dataclass
class EnvironmentData:
    """A world whose Background Color is an Environment Texture (through a Mapping node)."""

    image_name: str
    path: str = None
    """An image file the library reads, or None when ``pixels`` hold the image."""
    pixels: np.ndarray = None
    """(height, width, channels) floats, bottom row first, for packed or generated images."""
    color_space: str = "linear"
    """'linear' or 'srgb' (the image's colour space)."""
    matrix: np.ndarray = None
    """Row-major 4×4 world → texture map before the Mapping (Texture Coordinate Object)."""
    mapping: str = "point"
    rotation: tuple = (0.0, 0.0, 0.0)
    scale: tuple = (1.0, 1.0, 1.0)
    strength: float = 1.0
    sampling: str = "auto"
    """World > Settings > Sampling: 'auto', 'manual' or 'none'."""
    map_resolution: int = 1024

    def options(self):
        """The world options of hairis_render.h (without the image or pixels)."""
        values = {"strength": float(self.strength), "color_space": self.color_space,
                  "mapping": self.mapping, "rotation": self.rotation, "scale": self.scale,
                  "sampling": self.sampling}
        if self.matrix is not None:
            values["matrix"] = np.asarray(self.matrix, np.float64).reshape(-1)
        if self.sampling == "manual":
            values["map_resolution"] = int(self.map_resolution)
        return values


@dataclass
class CameraData:
    """The camera: row-major camera-to-world without scale, view_frame corners, resolution."""

    name: str
    camera_to_world: np.ndarray
    orthographic: bool
    frame: np.ndarray
    width: int
    height: int


@dataclass
class SceneData:
    """Everything a render needs, as plain Python and numpy values."""

    materials: list = field(default_factory=list)
    textures: list = field(default_factory=list)
    """surfaces.TextureData of the surface materials, referred to by position."""
    curves: list = field(default_factory=list)
    meshes: list = field(default_factory=list)
    lights: list = field(default_factory=list)
    world_color: tuple = (0.0, 0.0, 0.0)
    world_strength: float = 0.0
    world_environment: EnvironmentData = None
    """Set when the world is an Environment Texture (then world_color is not used)."""
    camera: CameraData = None
    warnings: list = field(default_factory=list)
    material_calls: list = field(default_factory=list)
    """(material name_full or None, for_hair) of each first request of a material, in order: the
    order :func:`export_shading` asks for them again (None, None: the default material)."""
    slot_signature: tuple = None
    """:func:`slot_signature` of the exported depsgraph."""

    def warn(self, message):
        """Records a warning once."""
        if message not in self.warnings:
            self.warnings.append(message)

    def hair_materials(self):
        """(index, MaterialData) of every hair material."""
        return [(i, m) for i, m in enumerate(self.materials) if m.kind == "HAIR"]

    def save_npz(self, path):
        """Writes the arrays and a summary to an ``.npz`` file (debugging and tests)."""
        arrays = {}
        for i, curves in enumerate(self.curves):
            for name, (domain, values) in curves.inputs.items():
                arrays["curves%d_input_%s_%s" % (i, domain, name)] = values
            arrays["curves%d_first" % i] = curves.first
            arrays["curves%d_positions" % i] = curves.positions
            arrays["curves%d_radii" % i] = curves.radii
            arrays["curves%d_material" % i] = np.array(curves.material)
            arrays["curves%d_name" % i] = np.array(curves.name)
            arrays["curves%d_source" % i] = np.array(curves.source)
            if curves.normals is not None:
                arrays["curves%d_normals" % i] = curves.normals
        for i, mesh in enumerate(self.meshes):
            arrays["mesh%d_positions" % i] = mesh.positions
            arrays["mesh%d_indices" % i] = mesh.indices
            arrays["mesh%d_materials" % i] = mesh.materials
            arrays["mesh%d_name" % i] = np.array(mesh.name)
        for i, material in enumerate(self.materials):
            arrays["material%d_kind" % i] = np.array(material.kind)
            arrays["material%d_name" % i] = np.array(material.name)
            if material.hair is not None:
                for key, value in material.hair.as_dict().items():
                    arrays["material%d_hair_%s" % (i, key)] = np.array(value)
        arrays["world"] = np.array(tuple(self.world_color) + (self.world_strength,))
        if self.camera is not None:
            arrays["camera_to_world"] = self.camera.camera_to_world
            arrays["camera_frame"] = self.camera.frame
            arrays["camera_size"] = np.array([self.camera.width, self.camera.height])
        arrays["counts"] = np.array([len(self.curves), len(self.meshes), len(self.materials),
                                     len(self.lights)])
        np.savez(path, **arrays)


# ---- Small helpers ---------------------------------------------------------------------------

def _matrix(matrix):
    """A mathutils 4×4 matrix as a float64 numpy array (row-major)."""
    return np.array([tuple(row) for row in matrix], dtype=np.float64)


def _transform_points(matrix, points):
    """Applies a 4×4 numpy matrix to (n, 3) points."""
    return points @ matrix[:3, :3].T + matrix[:3, 3]


def _uniform_scale(matrix):
    """Cycles' radius scale for a transform: cbrt(|det(M3×3)|)."""
    return float(abs(np.linalg.det(matrix[:3, :3])) ** (1.0 / 3.0))


def _warn_non_uniform_scale(obj, matrix, warn):
    """Cycles intersects the hair of a non-uniformly scaled object in object space (its tubes
    squashed by the scale); hairis renders round tubes in world space: a warning says so."""
    stretch = np.linalg.svd(matrix[:3, :3], compute_uv=False)
    if stretch[0] > 0.0 and stretch[-1] < stretch[0] * (1.0 - 1e-4):
        warn("object %r has a non-uniform scale (%s): Cycles renders its hair with strands "
             "squashed by that scale, hairis with round strands of the mean radius; apply the "
             "scale (Object > Apply > Scale) for the same image"
             % (obj.name, ", ".join("%.3g" % v for v in stretch)))


def _rgb(value):
    return tuple(float(v) for v in tuple(value)[:3])


def render_resolution(scene):
    """The output size in pixels: resolution × percentage / 100 (integer, as Blender)."""
    render = scene.render
    width = render.resolution_x * render.resolution_percentage // 100
    height = render.resolution_y * render.resolution_percentage // 100
    return int(width), int(height)


def is_render_depsgraph(depsgraph):
    """True for a final-render depsgraph (F12), False for the viewport's."""
    return getattr(depsgraph, "mode", "VIEWPORT") == "RENDER"


# ---- Node trees ------------------------------------------------------------------------------

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


def _input(node, name):
    """The node input called ``name`` (by name or identifier), preferring enabled sockets."""
    return compat.find_input(node, (name,))


def surface_node(material):
    """The shader node connected to the active material output's Surface, or None."""
    if material is None or not compat.uses_nodes(material):
        return None
    output = output_node(material.node_tree)
    if output is None:
        return None
    surface = _input(output, "Surface")
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


def _socket_value(socket, components):
    value = socket.default_value
    if components == 1:
        return float(value)
    values = tuple(float(v) for v in tuple(value)[:components])
    if len(values) != components:
        raise ValueError("input %r has %d components, expected %d"
                         % (socket.name, len(values), components))
    return values


def _clamped(values, field_name, material_name, input_name, warnings):
    """Values of a node chain clamped to what hairis takes for the input, with a warning
    when any was outside."""
    low, high = INPUT_RANGES.get(field_name, (0.0, 1.0))
    values = np.asarray(values, dtype=np.float64)
    finite = np.nan_to_num(values, nan=low, posinf=high, neginf=low)
    clamped = np.clip(finite, low, high)
    if values.size and (np.any(clamped != values)):
        warnings.append("material %r: the node chain into the Principled Hair BSDF's %r gives "
                        "values from %.6g to %.6g, outside [%.6g, %.6g]; hairis clamps them"
                        % (material_name, input_name, float(np.nanmin(values)),
                           float(np.nanmax(values)), low, high))
    return clamped


def _huang_checks(values, material_name, warnings):
    """Cycles' rules for the Huang inputs: an error (or None), warnings appended."""
    aspect = values["aspect_ratio"]
    if not (math.isfinite(aspect) and aspect > 0.0):
        return ("material %r: the Principled Hair BSDF's Aspect Ratio is %g; Hairis needs a "
                "finite value above 0 (values above 1 render as their inverse, as in Cycles)"
                % (material_name, aspect))
    for name, label in zip(HUANG_LOBES, ("Reflection", "Transmission", "Secondary Reflection")):
        value = values[name]
        if not math.isfinite(value):
            return ("material %r: the Principled Hair BSDF's %s is %g; it must be finite"
                    % (material_name, label, value))
        if value < 0.0:
            warnings.append("material %r: %s is %g; Cycles uses 0 for a negative lobe "
                            "multiplier, and so does hairis" % (material_name, label, value))
            values[name] = 0.0
    if all(values[name] <= 0.0 for name in HUANG_LOBES):
        warnings.append("material %r: Reflection, Transmission and Secondary Reflection are all "
                        "0: Cycles makes no closure for this Principled Hair BSDF, so the strands "
                        "are black and block light; hairis renders them the same" % material_name)
    if compat.running_version() < HUANG_CYCLES:
        warnings.append("material %r: Blender %s's Cycles integrates the Huang model differently "
                        "from Cycles 4.5, which hairis follows; expect small differences"
                        % (material_name, compat.version_string()))
    return None


def read_hair_node(node, material_name="?"):
    """Reads a Principled Hair BSDF node: returns (HairParameters, warnings, error or None).

    Reads the inputs of the node's model (Blender 4.x's ``model``: Chiang or Huang) by
    identifier; a missing input or an unknown model is an error for this material. For
    Chiang, a linked input the parametrization reads is compiled (node_eval): a chain of one
    value is folded into the parameters, one that reads Hair Info goes into
    ``strand_inputs``, and one with an unsupported node is a warning naming it (the input's
    unlinked value is used). An unlinked Random is Cycles' per-strand random number wherever
    Random Color or Random Roughness can use it; the fiber's own Random is then 0.5 (the
    middle strand). Huang's Aspect Ratio and lobe multipliers take their unlinked value, with
    a warning when linked.
    """
    warnings = []
    model = compat.hair_model(node)
    if model not in ("CHIANG", "HUANG"):
        return None, warnings, ("material %r: the Principled Hair BSDF model %r is not supported "
                                "(Hairis implements Chiang and Huang)" % (material_name, model))
    parametrization = getattr(node, "parametrization", None)
    if parametrization not in PARAMETRIZATIONS:
        return None, warnings, ("material %r: unknown Principled Hair parametrization %r"
                                % (material_name, parametrization))
    values = {"model": model, "parametrization": PARAMETRIZATIONS[parametrization],
              "cycles": compat.cycles_version()}
    sockets = {}
    for field_name, input_name, components, models in HAIR_INPUTS:
        if model not in models:
            continue
        socket = _input(node, input_name)
        if socket is None:
            return None, warnings, ("material %r: the Principled Hair BSDF has no %r input in "
                                    "Blender %s; Hairis supports %s"
                                    % (material_name, input_name, compat.version_string(),
                                       compat.SUPPORTED_TEXT))
        try:
            values[field_name] = _socket_value(socket, components)
        except (TypeError, ValueError) as error:
            return None, warnings, "material %r: %s" % (material_name, error)
        sockets[field_name] = socket
    if model == "HUANG":
        error = _huang_checks(values, material_name, warnings)
        if error is not None:
            return None, warnings, error
    strand_inputs = {}
    for field_name, input_name, components, _ in HAIR_INPUTS:
        if field_name not in sockets:
            continue
        socket = sockets[field_name]
        if parametrization not in READ_BY.get(field_name, {parametrization}):
            continue  # hidden by the parametrization: Cycles does not read it either
        if not getattr(socket, "is_linked", False):
            continue
        if field_name in HUANG_MATERIAL_ONLY:
            # The fiber's shape and lobe multipliers are what its tables are baked for.
            warnings.append("material %r: input %r of the Principled Hair BSDF is linked; "
                            "hairis uses its unlinked value for Huang hair"
                            % (material_name, socket.name))
            continue
        try:
            compiled = node_eval.compile_input(socket, components)
        except node_eval.Unsupported as error:
            warnings.append("material %r: %s; hairis uses the unlinked value of the Principled "
                            "Hair BSDF's %r input" % (material_name, error.describe(), input_name))
            continue
        if compiled.domain == "material":
            value = _clamped(compiled.evaluate(None), field_name, material_name, input_name,
                             warnings)[0]
            values[field_name] = float(value[0]) if components == 1 else tuple(map(float, value))
        else:
            strand_inputs[field_name] = compiled
    # Cycles feeds an unlinked Random with the curve's random number, per strand.
    random_socket = sockets["random"]
    randomized = values["random_roughness"] > 0.0 or "random_roughness" in strand_inputs or (
        parametrization == "MELANIN" and (values["random_color"] > 0.0
                                          or "random_color" in strand_inputs))
    if randomized and "random" not in strand_inputs and not getattr(random_socket, "is_linked",
                                                                    False):
        strand_inputs["random"] = node_eval.Field("curve", 1, lambda s: s.random.reshape(-1, 1))
    if "random" in strand_inputs:
        # The fiber (what tables are baked for) is the middle strand: Random Color and Random
        # Roughness then scale nothing.
        values["random"] = 0.5
    values["strand_inputs"] = strand_inputs
    return HairParameters(**values), warnings, None


def read_surface_nodes(material, warn, add_texture):
    """A mesh material's surface nodes (surfaces.py), root last: the viewport colour as a
    diffuse albedo without nodes, a black diffuse when nothing feeds the Surface (Cycles
    renders it black)."""
    version = compat.cycles_surfaces()
    if not compat.uses_nodes(material):
        color = tuple(min(max(c, 0.0), 1.0) for c in _rgb(material.diffuse_color))
        return [{"type": "diffuse", "cycles": version, "color": color}]
    node = surface_node(material)
    if node is None:
        return [{"type": "diffuse", "cycles": version, "color": (0.0, 0.0, 0.0)}]
    reader = surfaces.SurfaceReader(material, warn, add_texture, node_eval.source, version)
    return reader.read(node)


# ---- Environment Texture worlds -------------------------------------------------------------

ENVIRONMENT_NODE_IDNAME = "ShaderNodeTexEnvironment"
MAPPING_TYPES = {"POINT": "point", "TEXTURE": "texture", "VECTOR": "vector", "NORMAL": "normal"}
LINEAR_COLOR_SPACES = {"Linear", "Linear Rec.709", "Non-Color", "Raw", "Linear BT.709"}
"""Image colour spaces whose values are scene-linear Rec.709 (or data) as stored."""
SRGB_COLOR_SPACES = {"sRGB", "sRGB 2.1"}
SAMPLING_METHODS = {"AUTOMATIC": "auto", "MANUAL": "manual", "NONE": "none"}
"""Cycles' World > Settings > Sampling (``world.cycles.sampling_method``)."""


def _node_label(node):
    return "%s %r" % (node.bl_label or node.bl_idname, node.name)


def _environment_image(world, node, image, warn):
    """(path, pixels, colour space) for an Environment Texture's image, or None."""
    name = image.colorspace_settings.name
    if name in SRGB_COLOR_SPACES:
        color_space = "srgb"
    else:
        color_space = "linear"
        if name not in LINEAR_COLOR_SPACES:
            warn("world %r: image %r has the colour space %r, which hairis does not convert; it "
                 "reads the values as linear Rec.709" % (world.name, image.name, name))
    if image.source not in {"FILE", "GENERATED"}:
        warn("world %r: %s: %s images are not supported; the world is rendered with the "
             "Background's colour" % (world.name, _node_label(node), image.source.lower()))
        return None
    path = None
    if image.source == "FILE" and image.packed_file is None and not image.is_dirty:
        candidate = bpy.path.abspath(image.filepath, library=image.library)
        if candidate and os.path.isfile(candidate) and ";" not in candidate \
                and candidate == candidate.strip():
            path = candidate
    if path is not None:
        return path, None, color_space
    # Packed, generated, edited in memory, or a path the C API cannot take: the pixels.
    width, height = (int(v) for v in image.size)
    channels = int(image.channels)
    if width < 1 or height < 1 or channels < 1:
        warn("world %r: image %r has no pixels (a missing file?); the world is rendered with "
             "the Background's colour" % (world.name, image.name))
        return None
    pixels = np.empty(width * height * channels, np.float32)
    image.pixels.foreach_get(pixels)
    return None, pixels.reshape(height, width, channels), color_space


def _mapping_vector(world, node, warn):
    """The Mapping node's (type, rotation, scale), or None when it cannot be followed."""
    kind = MAPPING_TYPES.get(getattr(node, "vector_type", "POINT"))
    if kind is None:
        warn("world %r: %s has an unknown type %r; ignored"
             % (world.name, _node_label(node), node.vector_type))
        return None
    values = {}
    for name in ("Location", "Rotation", "Scale"):
        socket = _input(node, name)
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
        matrix = _matrix(obj.matrix_world)
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
    found = _environment_image(world, node, image, warn)
    if found is None:
        return None
    path, pixels, color_space = found
    data = EnvironmentData(image_name=image.name, path=path, pixels=pixels,
                           color_space=color_space)
    vector = _input(node, "Vector")
    source, source_socket = node_eval.source(vector) if vector is not None else (None, None)
    if source is not None and source.bl_idname == "ShaderNodeMapping":
        mapping = _mapping_vector(world, source, warn)
        if mapping is not None:
            data.mapping, data.rotation, data.scale = mapping
        inner = _input(source, "Vector")
        data.matrix = _coordinates(world, inner, warn) if inner is not None else np.eye(4)
    elif vector is not None:
        data.matrix = _coordinates(world, vector, warn)
    cycles = getattr(world, "cycles", None)
    method = getattr(cycles, "sampling_method", "AUTOMATIC") if cycles is not None else "AUTOMATIC"
    data.sampling = SAMPLING_METHODS.get(method, "auto")
    if data.sampling == "manual":
        data.map_resolution = int(getattr(cycles, "sample_map_resolution", 1024))
    return data


# ---- The exporter ----------------------------------------------------------------------------

class _Exporter:
    """One export pass over a depsgraph (a fresh instance per export: no shared state)."""

    def __init__(self, depsgraph, camera=None):
        self.depsgraph = depsgraph
        self.camera_object = camera
        self.scene = depsgraph.scene
        self.background = is_render_depsgraph(depsgraph)
        self.data = SceneData()
        self._material_index = {}
        self._default_index = None
        self._mesh_cache = {}
        self._texture_index = {}

    # -- materials --

    def default_material(self):
        """The scene index of the default grey diffuse material."""
        if self._default_index is None:
            self._default_index = len(self.data.materials)
            self.data.materials.append(MaterialData(name="(default)", kind="DIFFUSE"))
            self.data.material_calls.append((None, None))
        return self._default_index

    def material(self, material, for_hair):
        """The scene index for a Blender material on hair (``for_hair``) or on a surface."""
        if material is None:
            return self.default_material()
        key = (material.name_full, for_hair)
        index = self._material_index.get(key)
        if index is not None:
            return index
        self.data.material_calls.append(key)
        node = hair_node(material)
        if node is None and for_hair and is_hair_material(material):
            index = self.hair_mixture(material)
            self._material_index[key] = index
            return index
        if node is not None:
            if not for_hair:
                self.data.warn("material %r: Principled Hair BSDF on a mesh is not supported; "
                               "rendering it as grey diffuse" % material.name)
                data = MaterialData(name=material.name, kind="DIFFUSE",
                                    material_name=material.name, source=material.original)
            else:
                params, warnings, error = read_hair_node(node, material.name)
                for warning in warnings:
                    self.data.warn(warning)
                if error is not None:
                    raise ExportError(error)
                if params.scatters:
                    data = MaterialData(name=material.name, kind="HAIR", hair=params,
                                        material_name=material.name, source=material.original)
                else:  # Cycles makes no closure: black, opaque strands
                    data = MaterialData(name=material.name, kind="DIFFUSE", albedo=(0.0, 0.0, 0.0),
                                        material_name=material.name, source=material.original)
        else:
            nodes = read_surface_nodes(material, self.data.warn, self.texture)
            if for_hair:
                self.data.warn("material %r on hair has no Principled Hair BSDF; hairis renders "
                               "the strands with its surface shader" % material.name)
            data = MaterialData(name=material.name, kind="SURFACE", nodes=nodes,
                                material_name=material.name, source=material.original)
        index = len(self.data.materials)
        self.data.materials.append(data)
        self._material_index[key] = index
        return index

    def hair_mixture(self, material):
        """The scene index of a hair material whose output is a Mix/Add Shader tree of
        Principled Hair BSDFs: a HAIR material per leaf, then the HAIR_MIX that mixes them."""
        leaves, others, warnings = hair_mix.closures(surface_node(material), HAIR_NODE_IDNAME,
                                                     material.name)
        for node in others:
            warnings.append("material %r: %s %r is mixed with Principled Hair BSDFs; hairis "
                            "mixes only Principled Hair BSDFs on hair and leaves it out, so its "
                            "share renders black and opaque"
                            % (material.name, node.bl_label or node.bl_idname, node.name))
        read, closures = [], []
        for node, _ in leaves:
            params, leaf_warnings, error = read_hair_node(node, material.name)
            warnings.extend(leaf_warnings)
            if error is not None:
                raise ExportError(error)
            if params.model != "CHIANG":
                raise ExportError(
                    "material %r: Principled Hair BSDF %r uses the Huang model inside a Mix or "
                    "Add Shader; hairis mixes Chiang Principled Hair BSDFs only (switch it to "
                    "Chiang, or connect one Huang node to the output)" % (material.name, node.name))
            read.append((node, params))
            closures.append(len(self.data.materials))
            self.data.materials.append(MaterialData(
                name="%s: %s" % (material.name, node.name), kind="HAIR", hair=params,
                material_name=material.name))
        strand_inputs, shared_warnings = hair_mix.shared_strand_inputs(
            material.name, read, {name: identifier for name, identifier, _, _ in HAIR_INPUTS})
        for warning in warnings + shared_warnings:
            self.data.warn(warning)
        mixture = hair_mix.Mixture(closures, [weight for _, weight in leaves], strand_inputs)
        self.data.materials.append(MaterialData(
            name=material.name, kind="HAIR_MIX", mixture=mixture, material_name=material.name,
            source=material.original))
        return len(self.data.materials) - 1

    def strand_inputs(self, material_index, first, positions_object, curve_indices):
        """``CurvesData.inputs`` for one curve set of a hair material whose inputs vary per
        strand: its chains evaluated on the set's Hair Info (object-space lengths, and the
        per-strand random of each curve's index within its object, as Cycles numbers them),
        clamped with a warning; for a mixture, also the closure weights that vary."""
        material = self.data.materials[material_index]
        mixture = material.mixture if material.kind == "HAIR_MIX" else None
        if mixture is not None:
            fields = mixture.strand_inputs
            varying = any(w.domain != "material" for w in mixture.weights)
        elif material.kind == "HAIR":
            fields, varying = material.hair.strand_inputs, False
        else:
            return {}
        if not fields and not varying:
            return {}
        strands = node_eval.strands_of(first, positions_object,
                                       node_eval.strand_random(curve_indices))
        labels = {name: label for name, label, _, _ in HAIR_INPUTS}
        inputs = mixture.strand_weights(strands) if mixture is not None else {}
        for field_name, compiled in fields.items():
            warnings = []
            values = _clamped(compiled.evaluate(strands), field_name, material.name,
                              labels[field_name], warnings)
            for warning in warnings:
                self.data.warn(warning)
            inputs[CURVE_INPUT_NAMES.get(field_name, field_name)] = (
                compiled.domain, values.astype(np.float32))
        return inputs

    def texture(self, texture):
        """The position of a surfaces.TextureData in the scene's textures (shared when equal)."""
        key = texture.key()
        index = self._texture_index.get(key)
        if index is None:
            index = len(self.data.textures)
            self.data.textures.append(texture)
            self._texture_index[key] = index
        return index

    @staticmethod
    def slot_material(obj, slot_index):
        """The material in slot ``slot_index`` (clamped like Cycles), or None."""
        slots = obj.material_slots
        if len(slots) == 0:
            return None
        slot_index = min(max(int(slot_index), 0), len(slots) - 1)
        return slots[slot_index].material

    # -- objects --

    def run(self):
        """Exports camera, world and every object instance; returns the SceneData."""
        self.export_camera()
        self.export_world()
        use_hair = getattr(self.depsgraph.view_layer, "use_strand", True)
        for instance in self.depsgraph.object_instances:
            obj = instance.object
            kind = obj.type
            matrix = _matrix(instance.matrix_world)
            if kind == "LIGHT":
                self.export_light(obj, matrix)
            elif kind == "CURVES":
                if use_hair:
                    self.export_curves_object(obj, matrix)
            elif kind in GEOMETRY_TYPES:
                show_self = getattr(instance, "show_self", True)
                show_particles = getattr(instance, "show_particles", True)
                if show_self:
                    self.export_mesh(obj, matrix, instance.is_instance)
                if show_particles and use_hair and len(getattr(obj, "particle_systems", ())):
                    if instance.is_instance:
                        self.data.warn("object %r: particle hair on instances is not exported"
                                       % obj.name)
                    else:
                        export_particle_hair(self, obj)
            elif kind in {"VOLUME", "POINTCLOUD", "GPENCIL", "GREASEPENCIL"}:
                self.data.warn("object %r: %s objects are not supported" % (obj.name, kind.lower()))
        problem = memory_problem(self.data, available_memory_bytes())
        if problem:
            raise ExportError(problem)
        self.data.slot_signature = slot_signature(self.depsgraph)
        return self.data

    def run_shading(self, previous):
        """Exports the world, the lights and the materials ``previous`` (a SceneData of the
        same depsgraph's geometry) asked for, in its order; None when a material it names is
        gone."""
        self.export_world()
        for name, for_hair in previous.material_calls:
            if for_hair is None:
                self.default_material()
                continue
            material = _material_named(name, self.depsgraph) if name is not None else None
            if name is not None and material is None:
                return None
            self.material(material, for_hair)
        for instance in self.depsgraph.object_instances:
            if instance.object.type == "LIGHT":
                self.export_light(instance.object, _matrix(instance.matrix_world))
        return self.data

    def export_camera(self):
        """The scene camera (``view_frame`` corners, matrix without scale, resolution)."""
        scene = self.scene
        camera = self.camera_object or scene.camera
        if camera is None:
            raise ExportError("the scene has no camera")
        camera = camera.evaluated_get(self.depsgraph)
        if camera.type != "CAMERA":
            raise ExportError("the scene camera %r is not a camera object" % camera.name)
        cam = camera.data
        if cam.type == "PANO":
            raise ExportError("camera %r: panoramic cameras are not supported" % camera.name)
        width, height = render_resolution(scene)
        if width < 1 or height < 1:
            raise ExportError("the output resolution %d×%d is empty" % (width, height))
        frame = np.array([tuple(v) for v in cam.view_frame(scene=scene)], dtype=np.float32)
        matrix = _matrix(camera.matrix_world)
        axes = matrix[:3, :3]
        norms = np.linalg.norm(axes, axis=0)
        if np.any(norms == 0):
            raise ExportError("camera %r has a zero scale" % camera.name)
        matrix[:3, :3] = axes / norms
        if cam.dof.use_dof:
            self.data.warn("camera %r: depth of field is not supported" % camera.name)
        self.data.camera = CameraData(name=camera.name, camera_to_world=matrix.astype(np.float32),
                                      orthographic=cam.type == "ORTHO", frame=frame,
                                      width=width, height=height)

    def export_world(self):
        """Background colour·strength of a Background node, or ``world.color``, or an
        Environment Texture feeding the Background's Color (:func:`read_environment`)."""
        world = self.scene.world
        if world is None:
            return
        if not compat.uses_nodes(world):
            self.data.world_color = _rgb(world.color)
            self.data.world_strength = 1.0
            return
        output = output_node(world.node_tree)
        surface = _input(output, "Surface") if output is not None else None
        node, _ = node_eval.source(surface) if surface is not None else (None, None)
        if node is None:
            return  # Cycles: black
        if node.bl_idname != "ShaderNodeBackground":
            self.data.warn("world %r: %s is not supported; using the world colour"
                           % (world.name, node.bl_label or node.bl_idname))
            self.data.world_color = _rgb(world.color)
            self.data.world_strength = 1.0
            return
        color = _input(node, "Color")
        strength = _input(node, "Strength")
        if strength is not None and strength.is_linked:
            self.data.warn("world %r: input 'Strength' of the Background is linked; hairis uses "
                           "its unlinked value" % world.name)
        self.data.world_color = _rgb(color.default_value) if color else (0.0, 0.0, 0.0)
        self.data.world_strength = float(strength.default_value) if strength else 1.0
        if color is not None and color.is_linked:
            environment = read_environment(world, color, self.data.warn)
            if environment is not None:
                environment.strength = self.data.world_strength
                self.data.world_environment = environment

    def export_light(self, obj, matrix):
        """Sun, point, spot and area lights in Blender's units (Cycles' sync_light)."""
        light = obj.data
        color = _rgb(light.color)
        if getattr(light, "use_temperature", False):  # Blender 5.0+: colour × blackbody
            color = tuple(c * t for c, t in zip(color, _rgb(light.temperature_color)))
        energy = float(light.energy) * 2.0 ** float(getattr(light, "exposure", 0.0))
        if not getattr(light, "normalize", True):
            self.data.warn("light %r: Normalize off is not supported; hairis normalizes its "
                           "power by its size" % obj.name)
        if compat.uses_nodes(light):
            self.data.warn("light %r: light node trees are ignored" % obj.name)
        version = compat.cycles_lights()
        soft_falloff = compat.soft_falloff(light)
        kind = light.type
        if kind == "SUN":
            direction = matrix[:3, 2]
            norm = np.linalg.norm(direction)
            if norm == 0:
                self.data.warn("light %r has a zero scale; skipped" % obj.name)
                return
            self.data.lights.append(LightData(
                name=obj.name, kind="SUN", color=color, strength=energy,
                direction=tuple(float(v) for v in direction / norm), angle=float(light.angle),
                cycles=version))
        elif kind == "POINT":
            self.data.lights.append(LightData(
                name=obj.name, kind="POINT", color=color, strength=energy,
                position=tuple(float(v) for v in matrix[:3, 3]),
                radius=float(light.shadow_soft_size), soft_falloff=soft_falloff,
                cycles=version))
        elif kind == "SPOT":
            if np.linalg.norm(matrix[:3, 2]) == 0:
                self.data.warn("light %r has a zero scale; skipped" % obj.name)
                return
            if version == "4.5" and abs(np.linalg.det(matrix[:3, :3])) == 0:
                self.data.warn("light %r has a singular matrix; skipped" % obj.name)
                return
            self.data.lights.append(LightData(
                name=obj.name, kind="SPOT", color=color, strength=energy,
                position=tuple(float(v) for v in matrix[:3, 3]),
                radius=float(light.shadow_soft_size), matrix=matrix.astype(np.float32),
                spot_size=float(light.spot_size), spot_blend=float(light.spot_blend),
                soft_falloff=soft_falloff, cycles=version))
        elif kind == "AREA":
            size_y = light.size_y if light.shape in {"RECTANGLE", "ELLIPSE"} else light.size
            if not math.isclose(float(getattr(light, "spread", math.pi)), math.pi, rel_tol=1e-6):
                self.data.warn("light %r: Spread is not supported; hairis emits over the whole "
                               "hemisphere (Spread 180°)" % obj.name)
            self.data.lights.append(LightData(
                name=obj.name, kind="AREA", color=color, strength=energy,
                matrix=matrix.astype(np.float32), shape=light.shape, size_x=float(light.size),
                size_y=float(size_y), cycles=version))
        else:
            self.data.warn("light %r: %s lights are not supported; skipped"
                           % (obj.name, kind.lower()))

    def export_mesh(self, obj, matrix, is_instance):
        """A triangle mesh from ``to_mesh`` + ``loop_triangles``, transformed in numpy."""
        key = obj.name_full if is_instance else None
        local = self._mesh_cache.get(key) if key is not None else None
        if local is None:
            local = self._triangulate(obj)
            if key is not None:
                self._mesh_cache[key] = local
        if local is None:
            return
        positions, indices, slots, normals, uvs = local
        slot_count = len(obj.material_slots)
        slots = np.clip(slots, 0, max(slot_count - 1, 0))
        materials = np.empty(slots.size, np.int32)
        for slot in np.unique(slots):  # only the slots triangles use
            materials[slots == slot] = self.material(self.slot_material(obj, slot),
                                                     for_hair=False)
        world = _transform_points(matrix, positions)
        world_normals = None
        linear = matrix[:3, :3]
        if normals is not None and abs(np.linalg.det(linear)) > 0.0:
            # Normals transform with the inverse transpose: as rows, n · M⁻¹.
            corner = normals.reshape(-1, 3) @ np.linalg.inv(linear)
            length = np.linalg.norm(corner, axis=1)
            bad = ~(length > 0.0)
            if bad.any():  # a zero corner normal (degenerate faces): the triangle's own
                p = world[indices.reshape(-1)].reshape(-1, 3, 3)
                face = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
                face = np.repeat(face, 3, axis=0)
                face[~(np.linalg.norm(face, axis=1) > 0.0)] = (0.0, 0.0, 1.0)
                corner[bad] = face[bad]
                length = np.linalg.norm(corner, axis=1)
            world_normals = (corner / length[:, None]).reshape(-1, 3, 3).astype(np.float32)
        self.data.meshes.append(MeshData(
            name=obj.name, positions=world.astype(np.float32), indices=indices,
            materials=materials.astype(np.int32), normals=world_normals, uvs=uvs))

    @staticmethod
    def _triangulate(obj):
        """(positions, triangle indices, triangle material slots, corner normals, corner UVs)
        in object space, or None; corners (triangles, 3, ·), the UV map Cycles reads by default
        (None without one)."""
        try:
            mesh = obj.to_mesh()
        except RuntimeError:
            return None
        if mesh is None:
            return None
        try:
            mesh.calc_loop_triangles()
            vertex_count = len(mesh.vertices)
            triangle_count = len(mesh.loop_triangles)
            if vertex_count == 0 or triangle_count == 0:
                return None
            positions = np.empty(vertex_count * 3, np.float32)
            mesh.vertices.foreach_get("co", positions)
            indices = np.empty(triangle_count * 3, np.int32)
            mesh.loop_triangles.foreach_get("vertices", indices)
            slots = np.empty(triangle_count, np.int32)
            mesh.loop_triangles.foreach_get("material_index", slots)
            loops = np.empty(triangle_count * 3, np.int32)
            mesh.loop_triangles.foreach_get("loops", loops)
            normals = compat.corner_normals(mesh)[loops].reshape(-1, 3, 3).astype(np.float64)
            uvs = None
            layer = compat.render_uv_layer(mesh)
            if layer is not None:
                uv = np.empty(len(mesh.loops) * 2, np.float32)
                layer.data.foreach_get("uv", uv)
                uvs = uv.reshape(-1, 2)[loops].reshape(-1, 3, 2)
        finally:
            obj.to_mesh_clear()
        return (positions.reshape(-1, 3).astype(np.float64),
                indices.reshape(-1, 3).astype(np.uint32), slots, normals, uvs)

    def export_curves_object(self, obj, matrix):
        """A Curves object (Blender 3.3+ hair): positions, offsets, radius via foreach_get."""
        curves = obj.data
        curve_count = len(curves.curves)
        point_count = len(curves.points)
        if curve_count == 0 or point_count == 0:
            return
        offsets = np.empty(curve_count + 1, np.int32)
        offset_data = curves.curve_offset_data
        if len(offset_data) == curve_count + 1:
            offset_data.foreach_get("value", offsets)
        else:  # defensive: build them from the curve slices
            starts = np.empty(curve_count, np.int32)
            curves.curves.foreach_get("first_point_index", starts)
            offsets[:-1] = starts
            offsets[-1] = point_count
        positions = np.empty(point_count * 3, np.float32)
        position_data = getattr(curves, "position_data", None)
        if position_data is None:
            position_data = curves.attributes["position"].data
        position_data.foreach_get("vector", positions)
        radii = np.full(point_count, DEFAULT_CURVES_RADIUS, np.float32)
        radius = curves.attributes.get("radius")
        if radius is not None and radius.domain == "POINT" and radius.data_type == "FLOAT":
            radius.data.foreach_get("value", radii)
        positions = positions.reshape(-1, 3).astype(np.float64)
        radii = radii.astype(np.float64) * _uniform_scale(matrix)
        _warn_non_uniform_scale(obj, matrix, self.data.warn)
        kept = np.nonzero(np.diff(offsets.astype(np.int64)) >= 2)[0]  # Cycles' curve indices
        first, local, radii, dropped = _drop_short_curves(offsets, positions, radii)
        if dropped:
            self.data.warn("object %r: %d curves with fewer than 2 points skipped"
                           % (obj.name, dropped))
        if first.size < 2:
            return
        world = _transform_points(matrix, local)
        material = self.material(self.slot_material(obj, 0), for_hair=True)
        normals = None
        hair = self.data.materials[material].hair
        if hair is not None and hair.oriented:
            normals = curve_normals(obj, curves, point_count, offsets, self.data)
        keep = renderable_strands(first, world, radii, kept, "object %r" % obj.name,
                                  self.data.warn)
        first, (world, local, radii, normals) = select_strands(first, keep, world, local, radii,
                                                               normals)
        kept = kept[keep]
        if first.size < 2:
            return
        self.data.curves.append(CurvesData(
            name=obj.name, source="CURVES", material=material, first=first,
            positions=world.astype(np.float32), radii=radii.astype(np.float32),
            inputs=self.strand_inputs(material, first, local, kept), normals=normals))


def curve_normals(obj, curves, point_count, offsets, data):
    """The Curves' point normals as Cycles reads them, (kept points, 3) float32, or None.

    ``Curves.normals`` is Blender's ``curves_normals_point_domain_calc`` (the curves' normal
    mode), the array Cycles' ``export_hair_curves`` stores as the normal attribute. It is read
    by iterating the collection: its ``foreach_get`` copies from an array Blender has already
    freed (4.5 and 5.0: the first two normals come back as garbage), while an iteration keeps
    the array alive until it ends. Cycles uses the normals in object space, without the
    object's rotation, and so does hairis (a warning says so when the object is rotated).
    """
    source = getattr(curves, "normals", None)
    if source is None or len(source) != point_count:
        data.warn("object %r: its curve normals cannot be read in Blender %s; elliptical Huang "
                  "fibers on it use Cycles' fallback frame" % (obj.name, compat.version_string()))
        return None
    normals = np.fromiter((c for item in source for c in item.vector), np.float32,
                          count=3 * point_count).reshape(-1, 3)
    if not np.all(np.isfinite(normals)):
        data.warn("object %r: Blender gives non-finite curve normals; hairis uses zero (Cycles' "
                  "fallback frame) there" % obj.name)
        normals = np.where(np.isfinite(normals), normals, 0.0).astype(np.float32)
    keep = np.repeat(np.diff(np.asarray(offsets, np.int64)) >= 2, np.diff(offsets))
    matrix = _matrix(obj.matrix_world)
    scale = _uniform_scale(matrix)
    if scale > 0.0 and not np.allclose(matrix[:3, :3] / scale, np.eye(3), atol=1e-6):
        data.warn("object %r is rotated: Cycles orients elliptical Huang fibers by its curve "
                  "normals in object space (it does not rotate them with the object), and so "
                  "does hairis" % obj.name)
    return np.ascontiguousarray(normals[keep], np.float32)


def _drop_short_curves(offsets, positions, radii):
    """Removes curves with fewer than 2 points; returns (first uint32, positions, radii, n)."""
    keep = np.diff(np.asarray(offsets, dtype=np.int64)) >= 2
    first, (positions, radii) = select_strands(offsets, keep, positions, radii)
    return first, positions, radii, int(np.count_nonzero(~keep))


def renderable_strands(first, positions, radii, numbers, label, warn):
    """The strands (curves) hairis renders, as a boolean mask, with a warning naming ``label``
    and counting the others, which are skipped.

    ``positions`` and ``radii`` are world space; they are judged as the float32 values the
    library gets. A strand with a NaN or infinite position or radius, or a negative radius, is
    skipped: Cycles (Embree) drops only the segments around such a point, which no valid
    strand can reproduce, and a refusal would cost the whole image; the warning names the
    strands (``numbers``: their indices as the artist counts them). Strands of zero length or
    zero radius are never hit, in Cycles either.
    """
    first = np.asarray(first, np.int64)
    counts = np.diff(first)
    positions = np.asarray(positions, np.float32)
    radii = np.asarray(radii, np.float32).reshape(-1)
    curve_of_point = np.repeat(np.arange(counts.size), counts)
    with np.errstate(invalid="ignore", over="ignore"):
        bad_point = ~np.isfinite(positions).all(axis=1) | ~(radii >= 0.0)
        invalid = np.zeros(counts.size, bool)
        invalid[curve_of_point[bad_point]] = True
        step = np.zeros(radii.size, np.float32)
        step[1:] = np.sqrt(np.sum(np.square(positions[1:] - positions[:-1]), axis=1))
        step[first[:-1]] = 0.0  # the step into a curve's first point is from another curve
        moves = np.maximum.reduceat(step, first[:-1]) > 0.0 if counts.size else invalid
        thick = np.maximum.reduceat(radii, first[:-1]) > 0.0 if counts.size else invalid
    zero_length = ~invalid & ~moves
    zero_radius = ~invalid & moves & ~thick
    if invalid.any():
        count = int(np.count_nonzero(invalid))
        listed = ", ".join(str(int(n)) for n in np.asarray(numbers)[invalid][:8])
        warn("%s: skipped %d strand(s) with a NaN or infinite position or a negative or NaN "
             "radius (strand%s %s%s); Cycles leaves out only the segments around such a point"
             % (label, count, "s" if count > 1 else "", listed, ", ..." if count > 8 else ""))
    if zero_length.any():
        warn("%s: skipped %d strand(s) of zero length (all points equal; Cycles shows nothing "
             "there either)" % (label, np.count_nonzero(zero_length)))
    if zero_radius.any():
        warn("%s: skipped %d strand(s) of zero radius (Cycles shows nothing there either)"
             % (label, np.count_nonzero(zero_radius)))
    return ~(invalid | zero_length | zero_radius)


def select_strands(first, keep, *arrays):
    """(first, arrays) of the strands ``keep`` selects: ``arrays`` hold one row per point
    (None passes through)."""
    first = np.asarray(first, np.int64)
    if keep.all():
        return first.astype(np.uint32), arrays
    counts = np.diff(first)
    point_keep = np.repeat(keep, counts)
    selected = tuple(None if a is None else a[point_keep] for a in arrays)
    kept_first = np.zeros(np.count_nonzero(keep) + 1, np.uint32)
    np.cumsum(counts[keep], out=kept_first[1:])
    return kept_first, selected


def shape_radius(time, shape, root, tip):
    """Cycles' ``shaperadius``: the strand radius at arc-length fraction ``time`` ∈ [0, 1]."""
    radius = 1.0 - np.asarray(time, dtype=np.float64)
    if shape < 0.0:
        radius = np.power(radius, 1.0 + shape)
    elif shape > 0.0:
        exponent = 1.0 / (1.0 - shape) if shape < 1.0 else np.inf
        with np.errstate(over="ignore"):
            radius = np.power(radius, exponent)
    return radius * (root - tip) + tip


def _particle_modifier(obj, psys):
    for modifier in obj.modifiers:
        if modifier.type == "PARTICLE_SYSTEM" and modifier.particle_system is not None \
                and modifier.particle_system.name == psys.name:
            return modifier
    return None


def particle_hair_points(obj, psys, first_particle, curve_count, key_count):
    """World positions (curve_count, key_count, 3) of strands from the path cache.

    Blender 3.4's Python API has no bulk accessor for the evaluated path cache:
    ``ParticleHairKey`` holds only the parents' edit keys (``co_local`` in each strand's
    hair space, and ``foreach_get("co")`` on evaluated keys crashes 3.4), and the Curves
    conversion is an operator that edits ``bpy.data``. So this is the one per-point call:
    ``co_hair`` streamed by a generator straight into ``np.fromiter`` (no Python list or
    Vector per point is kept). Everything after it is numpy.
    """
    co_hair = psys.co_hair
    stream = (c for particle in range(first_particle, first_particle + curve_count)
              for step in range(key_count)
              for c in co_hair(obj, particle_no=particle, step=step))
    count = curve_count * key_count * 3
    points = np.fromiter(stream, dtype=np.float32, count=count)
    return points.reshape(curve_count, key_count, 3).astype(np.float64)


def export_particle_hair(exporter, obj):
    """Exports every rendered hair particle system of the evaluated object ``obj``."""
    data = exporter.data
    matrix = _matrix(obj.matrix_world)
    try:
        inverse = np.linalg.inv(matrix)
    except np.linalg.LinAlgError:
        data.warn("object %r has a singular matrix; its particle hair is skipped" % obj.name)
        return
    scale = _uniform_scale(matrix)
    if any(p.settings.type == "HAIR" for p in obj.particle_systems):
        _warn_non_uniform_scale(obj, matrix, data.warn)
    exported = 0  # strands of this object so far: Cycles numbers them across its systems
    for psys in obj.particle_systems:
        settings = psys.settings
        if settings.type != "HAIR" or settings.render_type != "PATH":
            continue
        modifier = _particle_modifier(obj, psys)
        if modifier is not None:
            enabled = modifier.show_render if exporter.background else modifier.show_viewport
            if not enabled:
                continue
        parent_count = len(psys.particles)
        child_count = len(psys.child_particles)
        if not exporter.background:
            child_count = int(child_count * settings.display_percentage / 100.0)
        if settings.child_type == "NONE" or child_count == 0:
            first_particle, curve_count = 0, parent_count + child_count
        else:
            first_particle, curve_count = parent_count, child_count
        if curve_count == 0:
            continue
        steps = settings.render_step if exporter.background else settings.display_step
        key_count = (1 << steps) + 1
        if settings.kink == "SPIRAL":
            key_count += settings.kink_extra_steps
        points = particle_hair_points(obj, psys, first_particle, curve_count, key_count)
        # co_hair gives (0, 0, 0) where the cache has no key: repeat the previous key, as
        # Cycles does, and drop strands with no key at all.
        valid = np.any(points != 0.0, axis=2)
        present = valid.any(axis=1)
        indices = exported + np.nonzero(present)[0]  # Cycles numbers the object's strands
        exported += int(present.size)
        if not present.all():
            points, valid = points[present], valid[present]
            curve_count = points.shape[0]
            if curve_count == 0:
                continue
        index = np.where(valid, np.arange(key_count)[None, :], 0)
        np.maximum.accumulate(index, axis=1, out=index)
        points = np.take_along_axis(points, index[:, :, None], axis=1)
        # Arc-length fraction in object space, as Cycles.
        local = _transform_points(inverse, points.reshape(-1, 3)).reshape(points.shape)
        segment = np.linalg.norm(np.diff(local, axis=1), axis=2)
        length = np.concatenate([np.zeros((curve_count, 1)), np.cumsum(segment, axis=1)], axis=1)
        total = length[:, -1:]
        time = np.divide(length, total, out=np.zeros_like(length), where=total > 0.0)
        half = settings.radius_scale * 0.5
        radii = shape_radius(time, settings.shape, half * settings.root_radius,
                             half * settings.tip_radius)
        if settings.use_close_tip:
            radii[:, -1] = 0.0
        radii *= scale
        material = exporter.material(exporter.slot_material(obj, settings.material - 1),
                                     for_hair=True)
        first = np.arange(curve_count + 1, dtype=np.uint32) * np.uint32(key_count)
        points, local, radii = points.reshape(-1, 3), local.reshape(-1, 3), radii.reshape(-1)
        keep = renderable_strands(first, points, radii, indices - exported + present.size,
                                  "object %r, particle system %r" % (obj.name, psys.name),
                                  data.warn)
        first, (points, local, radii) = select_strands(first, keep, points, local, radii)
        indices = indices[keep]
        if first.size < 2:
            continue
        data.curves.append(CurvesData(
            name="%s/%s" % (obj.name, psys.name), source="PARTICLES", material=material,
            first=first, positions=points.astype(np.float32), radii=radii.astype(np.float32),
            inputs=exporter.strand_inputs(material, first, local, indices)))


def render_bytes_estimate(points, curves):
    """The bytes the library needs to build and render ``curves`` hair curves of ``points``
    points in all (what it holds beyond the exported arrays)."""
    return int(points) * RENDER_BYTES_PER_POINT + int(curves) * RENDER_BYTES_PER_CURVE


def available_memory_bytes():
    """The memory the system can still give this process (Linux' MemAvailable, else the free
    physical pages), or None where neither is known."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (AttributeError, OSError, ValueError):
        return None


def memory_problem(data, available):
    """None, or why the hair of ``data`` (SceneData) is refused: its estimated render memory
    exceeds ``available`` bytes (None: unknown, never refused). The refusal comes before the
    library allocates, so that a groom too big fails with a message instead of the system
    running out of memory."""
    if available is None or not data.curves:
        return None
    points = sum(curves.point_count for curves in data.curves)
    strands = sum(curves.curve_count for curves in data.curves)
    need = render_bytes_estimate(points, strands)
    if need <= available:
        return None
    return ("the hair of %d object(s) (%d strands, %d points) needs an estimated %.1f GB to "
            "render, more than the %.1f GB of memory available: render fewer strands (fewer "
            "children or curves, or fewer points per strand)"
            % (len(data.curves), strands, points, need / 1e9, available / 1e9))


def _material_named(name_full, depsgraph):
    """The evaluated material whose ``name_full`` is ``name_full``, or None."""
    for material in bpy.data.materials:
        if material.name_full == name_full:
            return material.evaluated_get(depsgraph)
    return None


def slot_signature(depsgraph):
    """Which material each rendered object's slots and hair systems use: a changed material
    assignment changes it (the depsgraph does not always flag it as a geometry change)."""
    signature = []
    for instance in depsgraph.object_instances:
        obj = instance.object
        if obj.type not in GEOMETRY_TYPES and obj.type != "CURVES":
            continue  # no slots to read (Blender 3.4 crashes on an empty's)
        slots = tuple(slot.material.name_full if slot.material else None
                      for slot in obj.material_slots)
        systems = tuple(psys.settings.material for psys in getattr(obj, "particle_systems", ()))
        signature.append((obj.name_full, slots, systems))
    return tuple(signature)


def _shading_only(material):
    """True when a material's shading lives in the material alone: not per strand (Hair Info
    chains, mixture weights per strand) and not along curve normals (an elliptical fiber)."""
    if material.kind == "HAIR":
        return not material.hair.strand_inputs and not material.hair.oriented
    if material.kind == "HAIR_MIX":
        return not material.mixture.strand_inputs and all(
            w.domain == "material" for w in material.mixture.weights)
    return True


def export_shading(depsgraph, previous):
    """``previous`` (the SceneData last exported from this depsgraph) with its materials,
    textures, lights and world exported again, its geometry kept: what an edit of materials,
    lights or the world changes. None when that is not enough and the whole scene must be
    exported: material slots assigned otherwise, a material gone or of another kind or number
    of closures, or a material whose strands carry values of their own (per-strand inputs or
    weights, curve normals)."""
    if previous.slot_signature is None or slot_signature(depsgraph) != previous.slot_signature:
        return None
    shading = _Exporter(depsgraph).run_shading(previous)
    if shading is None or len(shading.materials) != len(previous.materials):
        return None
    for old, new in zip(previous.materials, shading.materials):
        if old.kind != new.kind or not (_shading_only(old) and _shading_only(new)):
            return None
        if old.kind == "HAIR_MIX" and old.mixture.closures != new.mixture.closures:
            return None
    warnings = list(previous.warnings)
    for warning in shading.warnings:
        if warning not in warnings:
            warnings.append(warning)
    return replace(
        previous, materials=shading.materials, textures=shading.textures,
        lights=shading.lights, world_color=shading.world_color,
        world_strength=shading.world_strength, world_environment=shading.world_environment,
        warnings=warnings)


def export_scene(depsgraph, camera=None):
    """Exports the evaluated depsgraph to :class:`SceneData` (raises :class:`ExportError`).

    ``camera`` overrides the scene camera (``RenderEngine.camera_override``).
    """
    return _Exporter(depsgraph, camera).run()


def export_context(context=None):
    """Exports the viewport depsgraph of ``context`` (default ``bpy.context``): for tests."""
    context = context or bpy.context
    return export_scene(context.evaluated_depsgraph_get())
