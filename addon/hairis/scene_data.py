"""What an export produces: a scene as plain Python and numpy values (:class:`SceneData`),
which the engine hands to the native library."""

import math
from dataclasses import dataclass, field

import numpy as np

from . import hair_mix
from .hair_material import HairParameters
from .surfaces import ImageData

DEFAULT_ALBEDO = (0.8, 0.8, 0.8)
"""Cycles' default surface (no material): a 0.8 grey diffuse."""


class ExportError(Exception):
    """The scene cannot be rendered as it is (no camera, unsupported camera, ...)."""


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
class EnvironmentData(ImageData):
    """A world whose Background Color is an Environment Texture (through a Mapping node)."""

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
