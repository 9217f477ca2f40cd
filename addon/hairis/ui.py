"""Panels: Hairis render settings, the material/world/light node panels, the table bake.

Blender's generic property panels (output, camera, particles, ...) list the engines they show
for in ``COMPAT_ENGINES``; like Cycles, Hairis adds itself to every panel that lists
``BLENDER_RENDER`` except those it replaces. Cycles' own material/world/light panels cannot be
shared the same way: their ``poll`` calls ``CyclesButtonsPanel.poll``, which reads the *base*
class's ``COMPAT_ENGINES`` (adding Hairis there would show every Cycles panel, sampling and
all). So Hairis draws the Cycles node trees itself, with ``template_node_view`` as Cycles does,
and users keep editing Cycles' nodes.
"""

import bpy

from . import compat, compositor, native, shader_nodes, tables

ENGINE = "HAIRIS"

# Generic panels that Hairis replaces or cannot use (as Cycles excludes them).
EXCLUDED_PANELS = {
    "DATA_PT_area",
    "DATA_PT_camera_dof",
    "DATA_PT_falloff_curve",
    "DATA_PT_light",
    "DATA_PT_preview",
    "DATA_PT_spot",
    "MATERIAL_PT_context_material",
    "MATERIAL_PT_preview",
    "NODE_DATA_PT_light",
    "NODE_DATA_PT_spot",
    "OBJECT_PT_visibility",
    "VIEWLAYER_PT_filter",
    "VIEWLAYER_PT_layer_passes",
    "RENDER_PT_post_processing",
    "RENDER_PT_simplify",
}


def compatible_panels():
    """Blender's generic panels that Hairis shows (those that list BLENDER_RENDER)."""
    panels = []
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if isinstance(engines, set) and "BLENDER_RENDER" in engines \
                and panel.__name__ not in EXCLUDED_PANELS:
            panels.append(panel)
    return panels


def draw_node_input(layout, id_data, input_name):
    """Draws the node tree feeding ``input_name`` of the active output (as Cycles)."""
    if not compat.uses_nodes(id_data):
        if compat.running_version() < compat.NODES_ALWAYS_ON:
            layout.prop(id_data, "use_nodes", icon="NODETREE")
        else:
            layout.label(text="No node tree")
        return False
    node_tree = id_data.node_tree
    output = shader_nodes.output_node(node_tree)
    if output is None:
        layout.label(text="No output node")
        return True
    socket = None
    for candidate in output.inputs:
        if candidate.name == input_name:
            socket = candidate
            break
    if socket is None:
        layout.label(text="Incompatible output node")
    else:
        layout.template_node_view(node_tree, output, socket)
    return True


def draw_library_status(layout, status=None):
    """One line on the native library: its version, or why it is unavailable (and a line on
    an unsupported Blender version)."""
    status = status or native.library_status()
    problem = compat.version_problem()
    if problem:
        column = layout.column(align=True)
        column.alert = True
        for number, line in enumerate(_wrap(problem, 70)):
            column.label(text=line, icon="ERROR" if number == 0 else "BLANK1")
    if status.ok:
        layout.label(text=status.message, icon="CHECKMARK")
    else:
        column = layout.column(align=True)
        column.alert = True
        for number, line in enumerate(_wrap(status.message, 70)):
            column.label(text=line, icon="ERROR" if number == 0 else "BLANK1")
    return status


def _wrap(text, width):
    """Splits ``text`` into lines of at most about ``width`` characters."""
    words, lines, line = text.split(), [], ""
    for word in words:
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = (line + " " + word).strip()
    if line:
        lines.append(line)
    return lines


def draw_props(layout, data, names, active):
    """Draws ``data``'s properties ``names`` in a sub-column, greyed out unless ``active``;
    returns the sub-column."""
    sub = layout.column()
    sub.active = active
    for name in names:
        sub.prop(data, name)
    return sub


def engine_is_hairis(context):
    """True when the scene renders with Hairis."""
    return context.engine == ENGINE


class HairisPanel:
    """Base of the Hairis panels: shown when the render engine is Hairis."""

    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        """Only with the Hairis engine."""
        return context.engine in cls.COMPAT_ENGINES


class RenderPanel(HairisPanel):
    """Base of the Render tab's panels: split properties without decorators, as in Cycles."""

    bl_context = "render"

    def draw(self, context):
        """Sets the layout up and draws the scene's Hairis settings (``draw_settings``)."""
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        self.draw_settings(layout, context.scene.hairis)


class HAIRIS_RENDER_PT_sampling(RenderPanel, bpy.types.Panel):
    """Samples, seed and threads."""

    bl_label = "Sampling"

    def draw_settings(self, layout, settings):
        """Draws the panel."""
        column = layout.column()
        column.prop(settings, "integrator")
        draw_props(column, settings, ("dual_hair_volume", "dual_exact_bounces",
                                      "dual_bounce_limit"),
                   settings.integrator == "DUAL_SCATTERING")
        for name in ("seed", "max_bounces", "max_transparent_bounces", "threads"):
            column.prop(settings, name)


class HAIRIS_RENDER_PT_sampling_render(RenderPanel, bpy.types.Panel):
    """F12's adaptive sampling, time limit and denoising, with Cycles' names and meanings."""

    bl_label = "Render"
    bl_parent_id = "HAIRIS_RENDER_PT_sampling"

    def draw_settings(self, layout, settings):
        """Draws the panel."""
        heading = layout.column(align=True, heading="Noise Threshold")
        row = heading.row(align=True)
        row.prop(settings, "use_adaptive_sampling", text="")
        sub = row.row()
        sub.active = settings.use_adaptive_sampling
        sub.prop(settings, "adaptive_threshold", text="")
        column = layout.column(align=True)
        column.prop(settings, "samples", text="Max Samples"
                    if settings.use_adaptive_sampling else "Samples")
        sub = column.column(align=True)
        sub.active = settings.use_adaptive_sampling
        sub.prop(settings, "adaptive_min_samples", text="Min Samples")
        layout.prop(settings, "time_limit")
        available = compositor.denoising_available()
        row = layout.row()
        row.enabled = available
        row.prop(settings, "use_denoising")
        if not available:
            layout.label(text="This Blender was built without OpenImageDenoise", icon="INFO")


class HAIRIS_RENDER_PT_sampling_viewport(RenderPanel, bpy.types.Panel):
    """The viewport's sample count."""

    bl_label = "Viewport"
    bl_parent_id = "HAIRIS_RENDER_PT_sampling"

    def draw_settings(self, layout, settings):
        """Draws the panel."""
        layout.prop(settings, "preview_samples", text="Max Samples")


class HAIRIS_RENDER_PT_strategy(RenderPanel, bpy.types.Panel):
    """The hair sampling strategy and its tables."""

    bl_label = "Hair Sampling Strategy"

    def draw_settings(self, layout, settings):
        """Draws the panel."""
        column = layout.column()
        column.prop(settings, "strategy")
        # Dual Scattering samples Huang with the strategy (its MIS needs the sampler's density).
        draw_props(column, settings, ("huang_sampling",),
                   settings.integrator != "DUAL_SCATTERING")
        draw_props(column, settings, ("multiple_weight", "n_h"),
                   settings.strategy in {"TABLE", "GAUSSIAN"})
        sub = draw_props(column, settings, ("huang_bake", "auto_bake"), settings.needs_tables)
        sub.operator("hairis.bake_tables", icon="RENDER_STILL")
        layout.separator()
        draw_library_status(layout)


class HAIRIS_PT_context_material(HairisPanel, bpy.types.Panel):
    """Material slots (as Cycles' context panel)."""

    bl_label = ""
    bl_context = "material"
    bl_options = {"HIDE_HEADER"}

    @classmethod
    def poll(cls, context):
        """Objects with materials, not grease pencil."""
        if context.active_object and context.active_object.type in {"GPENCIL", "GREASEPENCIL"}:
            return False
        return (context.material or context.object) and engine_is_hairis(context)

    def draw(self, context):
        """Draws the slot list and the material selector."""
        layout = self.layout
        material = context.material
        obj = context.object
        slot = context.material_slot
        space = context.space_data
        if obj:
            sortable = len(obj.material_slots) > 1
            row = layout.row()
            row.template_list("MATERIAL_UL_matslots", "", obj, "material_slots", obj,
                              "active_material_index", rows=4 if sortable else 3)
            column = row.column(align=True)
            column.operator("object.material_slot_add", icon="ADD", text="")
            column.operator("object.material_slot_remove", icon="REMOVE", text="")
            column.separator()
            column.menu("MATERIAL_MT_context_menu", icon="DOWNARROW_HLT", text="")
            if sortable:
                column.separator()
                column.operator("object.material_slot_move", icon="TRIA_UP",
                                text="").direction = "UP"
                column.operator("object.material_slot_move", icon="TRIA_DOWN",
                                text="").direction = "DOWN"
            if obj.mode == "EDIT":
                row = layout.row(align=True)
                row.operator("object.material_slot_assign", text="Assign")
                row.operator("object.material_slot_select", text="Select")
                row.operator("object.material_slot_deselect", text="Deselect")
        row = layout.row()
        if obj:
            row.template_ID(obj, "active_material", new="material.new")
            if slot:
                icon = "MESH_DATA" if slot.link == "DATA" else "OBJECT_DATA"
                row.prop(slot, "link", text="", icon=icon, icon_only=True)
        elif material:
            layout.template_ID(space, "pin_id")


class SurfacePanel(HairisPanel):
    """Base of the Surface panels: the node tree of the ``bl_context`` data block (material or
    world), or its ``plain_color`` property when it uses no nodes."""

    bl_label = "Surface"
    plain_color = ""

    def draw(self, context):
        """Draws the node view, or the plain colour without nodes."""
        layout = self.layout
        layout.use_property_split = True
        id_data = getattr(context, self.bl_context)
        if not draw_node_input(layout, id_data, "Surface"):
            layout.prop(id_data, self.plain_color)


class HAIRIS_MATERIAL_PT_surface(SurfacePanel, bpy.types.Panel):
    """The material's surface node tree (Cycles nodes)."""

    bl_context = "material"
    plain_color = "diffuse_color"

    @classmethod
    def poll(cls, context):
        """Materials that are not grease pencil."""
        material = context.material
        return material and not material.grease_pencil and engine_is_hairis(context)


class HAIRIS_MATERIAL_PT_tables(HairisPanel, bpy.types.Panel):
    """The sampling tables of a hair material and the bake button."""

    bl_label = "Hairis Sampling Tables"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        """Hair materials (a Principled Hair BSDF at the output)."""
        material = context.material
        return (material is not None and engine_is_hairis(context)
                and shader_nodes.hair_node(material) is not None)

    def draw(self, context):
        """Draws the table state and the bake button."""
        layout = self.layout
        material = context.material
        settings = material.hairis
        status = native.library_status()
        column = layout.column()
        column.template_ID(settings, "table_image", open="image.open")
        if status.ok:
            library = native.load_library(status.path)
            state = tables.quick_state(library, material,
                                       context.scene.hairis.huang_f_refinement)
            text, icon = {
                "OK": ("Tables are current", "CHECKMARK"),
                "MISSING": ("No tables baked", "ERROR"),
                "STALE": ("Tables are stale: the hair parameters changed", "ERROR"),
                "OTHER_BAKE": ("Tables are stale: baked at the other Huang Bake", "ERROR"),
                "NO_ABSORPTION": ("Tables lack the per-strand colour part: bake again",
                                  "ERROR"),
                "ERROR": ("The hair node cannot be read", "ERROR"),
            }[state]
            column.label(text=text, icon=icon)
        else:
            draw_library_status(column, status)
        row = column.row(align=True)
        bake = row.operator("hairis.bake_tables", text="Bake Sampling Tables", icon="RENDER_STILL")
        bake.material = material.name
        bake.force = False
        rebake = row.operator("hairis.bake_tables", text="", icon="FILE_REFRESH")
        rebake.material = material.name
        rebake.force = True


class HAIRIS_WORLD_PT_surface(SurfacePanel, bpy.types.Panel):
    """The world's surface node tree (a Background node)."""

    bl_context = "world"
    plain_color = "color"

    @classmethod
    def poll(cls, context):
        """Scenes with a world."""
        return context.world and engine_is_hairis(context)


class HAIRIS_LIGHT_PT_light(HairisPanel, bpy.types.Panel):
    """The light's type, colour, power and shape (what Hairis renders)."""

    bl_label = "Light"
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        """Light data."""
        return context.light and engine_is_hairis(context)

    def draw(self, context):
        """Draws the light settings Hairis uses."""
        layout = self.layout
        light = context.light
        layout.row().prop(light, "type", expand=True)
        layout.use_property_split = True
        column = layout.column()
        column.prop(light, "color")
        column.prop(light, "energy")
        column.separator()
        if light.type == "POINT":
            column.prop(light, "shadow_soft_size", text="Radius")
        elif light.type == "SUN":
            column.prop(light, "angle")
        elif light.type == "AREA":
            column.prop(light, "shape", text="Shape")
            sub = column.column(align=True)
            if light.shape in {"SQUARE", "DISK"}:
                sub.prop(light, "size")
            else:
                sub.prop(light, "size", text="Size X")
                sub.prop(light, "size_y", text="Y")
        elif light.type == "SPOT":
            column.prop(light, "shadow_soft_size", text="Radius")


class HAIRIS_LIGHT_PT_spot(HairisPanel, bpy.types.Panel):
    """The spot light's cone (as Cycles' Spot Shape panel)."""

    bl_label = "Spot Shape"
    bl_context = "data"
    bl_parent_id = "HAIRIS_LIGHT_PT_light"

    @classmethod
    def poll(cls, context):
        """Spot lights."""
        return context.light and context.light.type == "SPOT" and engine_is_hairis(context)

    def draw(self, context):
        """Draws the cone's size and blend."""
        layout = self.layout
        layout.use_property_split = True
        light = context.light
        column = layout.column()
        column.prop(light, "spot_size", text="Beam Size")
        column.prop(light, "spot_blend", text="Blend")
        column.prop(light, "show_cone")


classes = (
    HAIRIS_RENDER_PT_sampling,
    HAIRIS_RENDER_PT_sampling_render,
    HAIRIS_RENDER_PT_sampling_viewport,
    HAIRIS_RENDER_PT_strategy,
    HAIRIS_PT_context_material,
    HAIRIS_MATERIAL_PT_surface,
    HAIRIS_MATERIAL_PT_tables,
    HAIRIS_WORLD_PT_surface,
    HAIRIS_LIGHT_PT_light,
    HAIRIS_LIGHT_PT_spot,
)


_register_classes, _unregister_classes = bpy.utils.register_classes_factory(classes)


def register():
    """Registers the panels and adds Hairis to Blender's generic panels."""
    _register_classes()
    for panel in compatible_panels():
        panel.COMPAT_ENGINES.add(ENGINE)


def unregister():
    """Removes Hairis from the generic panels and unregisters the panels."""
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if isinstance(engines, set) and panel not in classes:
            engines.discard(ENGINE)
    _unregister_classes()
