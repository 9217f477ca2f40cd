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
from dataclasses import replace

import bpy
import numpy as np

from . import compat, hair_mix, node_eval
from .convert import matrix_of, rgb, transform_points, uniform_scale, warn_non_uniform_scale
from .hair_material import CURVE_INPUT_NAMES, HAIR_INPUTS, clamped, read_hair_node
from . import memory
from .scene_data import (CameraData, CurvesData, ExportError, LightData, MaterialData, MeshData,
                         SceneData)
from .shader_nodes import (HAIR_NODE_IDNAME, find_input, hair_node, is_hair_material, output_node,
                           read_surface_nodes, surface_node)
from .strands import (curve_normals, drop_short_curves, export_particle_hair,
                      renderable_strands, select_strands)
from .world import read_environment

DEFAULT_CURVES_RADIUS = 0.005
"""Cycles' radius for Curves without a ``radius`` attribute."""

GEOMETRY_TYPES = {"MESH", "CURVE", "SURFACE", "FONT", "META"}
"""Object types exported as triangle meshes (through ``Object.to_mesh``)."""


def render_resolution(scene):
    """The output size in pixels: resolution × percentage / 100 (integer, as Blender)."""
    render = scene.render
    width = render.resolution_x * render.resolution_percentage // 100
    height = render.resolution_y * render.resolution_percentage // 100
    return int(width), int(height)


def is_render_depsgraph(depsgraph):
    """True for a final-render depsgraph (F12), False for the viewport's."""
    return getattr(depsgraph, "mode", "VIEWPORT") == "RENDER"


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
            values = clamped(compiled.evaluate(strands), field_name, material.name,
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
            matrix = matrix_of(instance.matrix_world)
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
            if kind in GEOMETRY_TYPES or kind == "CURVES":
                unsupported = ray_visibility_changes(obj)
                if unsupported:
                    self.data.warn("object %r: %s; Hairis renders it as if visible to every ray"
                                   % (obj.name, " and ".join(unsupported)))
        problem = memory.memory_problem(self.data, memory.available_memory_bytes())
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
                self.export_light(instance.object, matrix_of(instance.matrix_world))
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
        matrix = matrix_of(camera.matrix_world)
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
            self.data.world_color = rgb(world.color)
            self.data.world_strength = 1.0
            return
        output = output_node(world.node_tree)
        surface = find_input(output, "Surface") if output is not None else None
        node, _ = node_eval.source(surface) if surface is not None else (None, None)
        if node is None:
            return  # Cycles: black
        if node.bl_idname != "ShaderNodeBackground":
            self.data.warn("world %r: %s is not supported; using the world colour"
                           % (world.name, node.bl_label or node.bl_idname))
            self.data.world_color = rgb(world.color)
            self.data.world_strength = 1.0
            return
        color = find_input(node, "Color")
        strength = find_input(node, "Strength")
        if strength is not None and strength.is_linked:
            self.data.warn("world %r: input 'Strength' of the Background is linked; hairis uses "
                           "its unlinked value" % world.name)
        self.data.world_color = rgb(color.default_value) if color else (0.0, 0.0, 0.0)
        self.data.world_strength = float(strength.default_value) if strength else 1.0
        if color is not None and color.is_linked:
            environment = read_environment(world, color, self.data.warn)
            if environment is not None:
                environment.strength = self.data.world_strength
                self.data.world_environment = environment

    def export_light(self, obj, matrix):
        """Sun, point, spot and area lights in Blender's units (Cycles' sync_light)."""
        light = obj.data
        color = rgb(light.color)
        if getattr(light, "use_temperature", False):  # Blender 5.0+: colour × blackbody
            color = tuple(c * t for c, t in zip(color, rgb(light.temperature_color)))
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
        world = transform_points(matrix, positions)
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
            flat = compat.flat_triangles(mesh)
            if flat.any():
                corners = positions.reshape(-1, 3).astype(np.float64)[indices.reshape(-1, 3)[flat]]
                ng = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
                length = np.linalg.norm(ng, axis=1)
                own = length > 0.0  # degenerate triangles keep their corner normals
                rows = np.flatnonzero(flat)[own]
                normals[rows] = (ng[own] / length[own, None])[:, None, :]
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
        radii = radii.astype(np.float64) * uniform_scale(matrix)
        warn_non_uniform_scale(obj, matrix, self.data.warn)
        kept = np.nonzero(np.diff(offsets.astype(np.int64)) >= 2)[0]  # Cycles' curve indices
        first, local, radii, dropped = drop_short_curves(offsets, positions, radii)
        if dropped:
            self.data.warn("object %r: %d curves with fewer than 2 points skipped"
                           % (obj.name, dropped))
        if first.size < 2:
            return
        world = transform_points(matrix, local)
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


RAY_VISIBILITY = (("visible_camera", "Camera"), ("visible_diffuse", "Diffuse"),
                  ("visible_glossy", "Glossy"), ("visible_transmission", "Transmission"),
                  ("visible_shadow", "Shadow"))
"""Object Properties > Visibility > Ray Visibility: the property and its label."""


def ray_visibility_changes(obj):
    """What of Cycles' per-object visibility ``obj`` changes that Hairis does not follow: Ray
    Visibility switched off, Holdout or Shadow Catcher (Blender 3.0+ properties)."""
    changes = ["Ray Visibility %s off" % label for name, label in RAY_VISIBILITY
               if not getattr(obj, name, True)]
    if getattr(obj, "is_holdout", False):
        changes.append("Holdout on")
    if getattr(obj, "is_shadow_catcher", False):
        changes.append("Shadow Catcher on")
    return changes


def export_scene(depsgraph, camera=None):
    """Exports the evaluated depsgraph to :class:`SceneData` (raises :class:`ExportError`).

    ``camera`` overrides the scene camera (``RenderEngine.camera_override``).
    """
    return _Exporter(depsgraph, camera).run()


def export_context(context=None):
    """Exports the viewport depsgraph of ``context`` (default ``bpy.context``): for tests."""
    context = context or bpy.context
    return export_scene(context.evaluated_depsgraph_get())
