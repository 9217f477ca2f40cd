"""Properties: ``scene.hairis`` (render settings) and ``material.hairis`` (sampling tables)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty
from bpy.props import StringProperty

STRATEGY_ITEMS = (
    ("UNIFORM", "Uniform", "Sample hair scattering uniformly over the sphere", 0),
    ("ANALYTIC", "Analytic",
     "Chiang 2016 lobe sampling as Cycles and pbrt do (exact density)", 1),
    ("GAUSSIAN", "Gaussian", "The seed's Gaussian densities per lobe", 2),
    ("TABLE", "Table",
     "Baked inverse-CDF tables of the fiber's scattering (needs baked tables)", 3),
)
"""Values and numbers match ``hairis_strategy``."""

INTEGRATOR_ITEMS = (
    ("PATH", "Path Tracing",
     "Unbiased path tracing of every bounce, as Cycles renders hair", 0),
    ("DUAL_SCATTERING", "Dual Scattering (Experimental)",
     "Path tracing of the first bounces (Exact Bounces), then Zinke et al. 2008's dual "
     "scattering: light reaching hair through other strands in closed form from shadow rays "
     "that count the strands, multiple scattering sampled from the baked tables (needs baked "
     "tables). Experimental: biased (at 3 Exact Bounces within about 5% of path tracing in the "
     "mean on the studies' hair, thin or thick, straight or of varied directions; flatter "
     "with fewer)", 1),
)
"""Values match the C API's ``integrator`` (path | dual_scattering)."""

N_H_ITEMS = tuple(
    (str(n), str(n), "Multiple-scattering distribution through %d strand%s"
     % (n, "" if n == 1 else "s"), i)
    for i, n in enumerate((1, 2, 4, 8, 16)))


class HairisRenderSettings(bpy.types.PropertyGroup):
    """Render settings of the Hairis engine (``scene.hairis``)."""

    samples: IntProperty(
        name="Samples", description="Samples per pixel",
        default=64, min=1, max=1 << 24, soft_max=4096)
    max_bounces: IntProperty(
        name="Max Bounces", description="Total maximum number of bounces (as Cycles)",
        default=12, min=0, max=1024)
    integrator: EnumProperty(
        name="Integrator", description="How light reaching hair is computed",
        items=INTEGRATOR_ITEMS, default="PATH")
    dual_hair_volume: EnumProperty(
        name="Hair Volume",
        description="What Dual Scattering takes the hair around a point to be",
        items=(("LAYER", "Layer",
                "A layer over what is under it: light scattered back from the strands behind "
                "the point only, and the head's light reaching hair through strands", 0),
               ("UNBOUNDED", "Unbounded",
                "Zinke et al.'s semi-infinite hair volume (too bright and too red on light hair "
                "over a head)", 1)),
        default="LAYER")
    dual_exact_bounces: IntProperty(
        name="Exact Bounces",
        description="Bounces path-traced before Dual Scattering closes the path: 0 shades the "
                    "first hair hit by dual scattering alone (flattest, least noise); each one "
                    "more leaves less of the light to the approximation (less bias, more noise)",
        default=3, min=0, max=1024, soft_max=8)
    dual_bounce_limit: EnumProperty(
        name="Bounce Limit",
        description="Which orders of scattering Dual Scattering adds where it closes a path",
        items=(("BOUNCES", "Max Bounces",
                "Only those path tracing reaches within Max Bounces, as Cycles renders the "
                "scene", 0),
               ("NONE", "None",
                "Every order, as Zinke et al. (light hair comes out brighter than Cycles "
                "renders it with a low Max Bounces)", 1)),
        default="BOUNCES")
    max_transparent_bounces: IntProperty(
        name="Transparent Max Bounces",
        description="Maximum number of transparent crossings (as Cycles): Huang hair lets rays "
                    "through outside its elliptical cross-section",
        default=8, min=0, max=1024)
    strategy: EnumProperty(
        name="Strategy", description="How hair scattering directions are sampled",
        items=STRATEGY_ITEMS, default="TABLE")
    huang_sampling: EnumProperty(
        name="Huang Sampling",
        description="How Huang hair is sampled. Cycles (the default) renders what Cycles "
                    "renders, and at equal time with less noise than the strategy's tables "
                    "(bench/results/bpy45/render_study_huang.md). Dual Scattering always uses "
                    "the strategy: its MIS needs the sampler's density",
        items=(("STRATEGY", "Strategy",
                "The strategy above, with its exact density (converges to Cycles' Huang eval, "
                "about 1% from Cycles' image; noisier in renders: Cycles' eval, which weights "
                "every sample, is itself a noisy estimate)", 0),
               ("CYCLES", "Cycles",
                "Cycles' own Huang sampler with its weight and pdf 1 for MIS (converges to what "
                "Cycles renders, which mixes that sampler with its eval)", 1)),
        default="CYCLES")
    multiple_weight: FloatProperty(
        name="Multiple Weight",
        description="One-sample mixture weight of the multiple-scattering distribution "
                    "(Table and Gaussian strategies). 0 is best for Table in a path tracer "
                    "(bench/results/mixture_weight.md); Gaussian needs about 0.25",
        default=0.0, min=0.0, max=1.0, subtype="FACTOR")
    n_h: EnumProperty(
        name="Strands (n_h)",
        description="Number of strands light crosses in the multiple-scattering distribution",
        items=N_H_ITEMS, default="2")
    seed: IntProperty(
        name="Seed", description="Random seed: same seed, same image, whatever the thread count",
        default=0, min=0)
    threads: IntProperty(
        name="Threads", description="Render and bake threads (0: all cores)",
        default=0, min=0, max=1024)
    auto_bake: BoolProperty(
        name="Auto Bake",
        description="Bake missing or stale sampling tables when rendering (otherwise the Table "
                    "strategy and Dual Scattering refuse materials without current tables)",
        default=True)

    @classmethod
    def register(cls):
        """Adds ``bpy.types.Scene.hairis``."""
        bpy.types.Scene.hairis = PointerProperty(
            name="Hairis Render Settings", description="Hairis render settings", type=cls)

    @classmethod
    def unregister(cls):
        """Removes ``bpy.types.Scene.hairis``."""
        del bpy.types.Scene.hairis

    @property
    def needs_tables(self):
        """True when rendering needs every hair material's tables."""
        return self.strategy == "TABLE" or self.integrator == "DUAL_SCATTERING"

    @property
    def n_h_value(self):
        """``n_h`` as an int."""
        return int(self.n_h)


class HairisMaterialSettings(bpy.types.PropertyGroup):
    """The sampling tables of a hair material (``material.hairis``)."""

    table_image: PointerProperty(
        name="Sampling Tables", description="The baked sampling tables (float EXR, Non-Color)",
        type=bpy.types.Image)
    baked_parameters: StringProperty(
        name="Baked Parameters",
        description="The fiber parameters the tables were baked for (name=value;...)")
    baked_model: StringProperty(
        name="Baked Model", description="The fiber model the tables were baked for")

    @classmethod
    def register(cls):
        """Adds ``bpy.types.Material.hairis``."""
        bpy.types.Material.hairis = PointerProperty(
            name="Hairis Material Settings", description="Hairis sampling tables", type=cls)

    @classmethod
    def unregister(cls):
        """Removes ``bpy.types.Material.hairis``."""
        del bpy.types.Material.hairis


classes = (HairisRenderSettings, HairisMaterialSettings)


register, unregister = bpy.utils.register_classes_factory(classes)
