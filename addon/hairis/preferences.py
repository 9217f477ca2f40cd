"""Add-on preferences: the state of the native library."""

import bpy

from . import native, ui


class HairisPreferences(bpy.types.AddonPreferences):
    """Shows whether libhairis loaded, its version, or why it did not."""

    bl_idname = __package__

    def draw(self, context):
        """Draws the library status and where it is looked for."""
        layout = self.layout
        status = ui.draw_library_status(layout)
        column = layout.column(align=True)
        column.label(text="Library: %s" % status.path)
        column.label(text="Override with the %s environment variable" % native.LIBRARY_ENV)


classes = (HairisPreferences,)


register, unregister = bpy.utils.register_classes_factory(classes)
