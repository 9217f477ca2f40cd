"""Hairis: a Blender render engine that importance-samples hair scattering.

The engine renders hair (particle hair and Curves objects) with Cycles' Principled Hair BSDF
through the hairis C library (``lib/libhairis.so`` inside this package, or the file named by
the ``HAIRIS_LIBRARY`` environment variable). The add-on registers without the library; the
preferences and every render then say why it could not be loaded.

It installs as a legacy add-on (``bl_info``, Blender 3.4+) and as an Extension
(``blender_manifest.toml``, Blender 4.2+, where the package is ``bl_ext.<repository>.hairis``):
every import is relative and no module assumes the package's name.

Modules: ``compat`` (what differs between Blender versions), ``native`` (ctypes binding),
``properties`` (``scene.hairis``, ``material.hairis``), ``export`` (depsgraph → numpy),
``tables`` (sampling tables), ``engine`` (the render engine), ``operators``
(``hairis.bake_tables``), ``ui`` (panels), ``preferences``.
"""

bl_info = {
    "name": "Hairis",
    "author": "hairis developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > Render Engine > Hairis",
    "description": "Hair path tracer with importance-sampled fiber scattering (hairis)",
    "category": "Render",
}

from . import engine, operators, preferences, properties, ui  # noqa: E402 (after bl_info)

_modules = (properties, engine, operators, ui, preferences)


def register():
    """Registers properties, the engine, operators, panels and preferences."""
    for module in _modules:
        module.register()


def unregister():
    """Unregisters everything :func:`register` registered."""
    for module in reversed(_modules):
        module.unregister()
