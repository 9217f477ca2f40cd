"""Properties: ``scene.hairis`` (render settings) and ``material.hairis`` (sampling tables)."""

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty
from bpy.props import StringProperty

from . import compositor

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
     "Path-traces the first bounces, then approximates light through other strands in closed "
     "form (Zinke et al. 2008) from the baked tables, which is biased but less noisy", 1),
)
"""Values match the C API's ``integrator`` (path | dual_scattering)."""

N_H_ITEMS = tuple(
    (str(n), str(n), "Multiple-scattering distribution through %d strand%s"
     % (n, "" if n == 1 else "s"), i)
    for i, n in enumerate((1, 2, 4, 8, 16)))


class HairisRenderSettings(bpy.types.PropertyGroup):
    """Render settings of the Hairis engine (``scene.hairis``)."""

    samples: IntProperty(
        name="Samples", description="Number of samples to render for each pixel",
        default=64, min=1, max=1 << 24, soft_max=4096)
    use_adaptive_sampling: BoolProperty(
        name="Noise Threshold",
        description="Stop sampling a pixel once its estimated noise is below the threshold, "
                    "as Cycles' adaptive sampling does",
        default=True)
    adaptive_threshold: FloatProperty(
        name="Noise Threshold",
        description="Noise level at which a pixel stops sampling, lower values reduce noise at "
                    "the cost of render time (zero: set automatically from the samples)",
        default=0.01, min=0.0, max=1.0, soft_min=0.001, precision=4)
    adaptive_min_samples: IntProperty(
        name="Min Samples",
        description="Samples every pixel gets before adaptive sampling may stop it, so that "
                    "small noisy features are found (zero: set automatically from the "
                    "threshold)",
        default=0, min=0, max=4096)
    time_limit: FloatProperty(
        name="Time Limit",
        description="Stop the render after this time, keeping the samples done (zero: no "
                    "limit)",
        default=0.0, min=0.0, step=100.0, unit="TIME_ABSOLUTE")
    preview_samples: IntProperty(
        name="Viewport Samples",
        description="Number of samples to render in the viewport, unlimited if 0",
        default=1024, min=0, soft_min=1, max=1 << 24)
    use_denoising: BoolProperty(
        name="Denoise",
        description="Denoise the final render with the compositor's Denoise node, guided by "
                    "Hairis' albedo and normal passes",
        default=False, update=compositor.denoise_update)
    max_bounces: IntProperty(
        name="Max Bounces", description="Total maximum number of bounces, as in Cycles",
        default=12, min=0, max=1024)
    integrator: EnumProperty(
        name="Integrator", description="How light reaching hair is computed",
        items=INTEGRATOR_ITEMS, default="PATH")
    dual_hair_volume: EnumProperty(
        name="Hair Volume",
        description="What Dual Scattering takes the hair around a point to be",
        items=(("LAYER", "Layer",
                "A layer over what is under it, so light comes back only from the strands "
                "behind the point", 0),
               ("UNBOUNDED", "Unbounded",
                "Zinke et al.'s semi-infinite hair volume, which makes light hair over a head "
                "too bright", 1)),
        default="LAYER")
    dual_exact_bounces: IntProperty(
        name="Exact Bounces",
        description="Bounces path-traced before Dual Scattering closes the path, since each "
                    "one more leaves less light to the approximation (less bias, more noise)",
        default=3, min=0, max=1024, soft_max=8)
    dual_bounce_limit: EnumProperty(
        name="Bounce Limit",
        description="Which orders of scattering Dual Scattering adds where it closes a path",
        items=(("BOUNCES", "Max Bounces",
                "Only the orders path tracing reaches within Max Bounces, so the image matches "
                "Cycles' with the same limit", 0),
               ("NONE", "None",
                "Every order, as Zinke et al., which makes light hair brighter than Cycles "
                "renders it with a low Max Bounces", 1)),
        default="BOUNCES")
    max_transparent_bounces: IntProperty(
        name="Transparent Max Bounces",
        description="Maximum number of transparent crossings, as in Cycles, where Huang hair "
                    "lets rays through outside its elliptical cross-section",
        default=8, min=0, max=1024)
    strategy: EnumProperty(
        name="Strategy", description="How hair scattering directions are sampled",
        items=STRATEGY_ITEMS, default="TABLE")
    huang_sampling: EnumProperty(
        name="Huang Sampling",
        description="How Huang hair is sampled, except under Dual Scattering, whose MIS needs "
                    "the strategy's density",
        items=(("STRATEGY", "Strategy",
                "The strategy above with its exact density, which converges to Cycles' Huang "
                "eval rather than to Cycles' image", 0),
               ("CYCLES", "Cycles",
                "Cycles' own Huang sampler, so the image converges to what Cycles renders; with "
                "the Table strategy, light samples read the tables' baked f instead of Cycles' "
                "slower eval", 1)),
        default="CYCLES")
    multiple_weight: FloatProperty(
        name="Multiple Weight",
        description="Share of samples drawn from the multiple-scattering distribution (Table "
                    "and Gaussian), best at 0 for Table since a path tracer follows multiple "
                    "scattering itself",
        default=0.0, min=0.0, max=1.0, subtype="FACTOR")
    n_h: EnumProperty(
        name="Strands (n_h)",
        description="Number of strands light crosses in the multiple-scattering distribution",
        items=N_H_ITEMS, default="2")
    seed: IntProperty(
        name="Seed", description="Random seed, which gives the same image whatever the thread "
                                 "count",
        default=0, min=0)
    threads: IntProperty(
        name="Threads", description="Number of render and bake threads, all cores if 0",
        default=0, min=0, max=1024)
    huang_bake: EnumProperty(
        name="Huang Bake",
        description="How finely the tables of Huang hair bake the f that shades its light "
                    "samples",
        items=(("FAST", "Fast",
                "Bakes in seconds, with the baked f slightly off Cycles towards single lights",
                0),
               ("FINE", "Fine",
                "Bakes the f on a finer quadrature, closer to Cycles, in many times the time",
                1)),
        default="FAST")
    auto_bake: BoolProperty(
        name="Auto Bake",
        description="Bake missing or stale sampling tables when rendering, since the Table "
                    "strategy and Dual Scattering refuse materials without current tables",
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
    def huang_f_refinement(self):
        """The bake option huang_f_refinement that ``huang_bake`` stands for."""
        return 2 if self.huang_bake == "FINE" else 1

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
    baked_huang_f_refinement: IntProperty(
        name="Baked Huang Bake", min=0, default=0,
        description="The Huang f refinement the tables were baked with (0: not a Huang bake, "
        "or not recorded)")
    baked_huang_absorption: BoolProperty(
        name="Baked Absorption Part", default=False,
        description="Whether the tables hold the Huang absorption part, which shades strands "
        "of their own colour without noise")

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
