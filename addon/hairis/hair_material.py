"""The Principled Hair BSDF node → :class:`HairParameters`: its model, parametrization and
inputs, clamped where Cycles clamps them, as Cycles 3.4 or 4.5/5.0 reads them."""

import math
from dataclasses import dataclass, field

import numpy as np

from . import compat, node_eval
from .shader_nodes import find_input

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

ABSORPTION_INPUTS = ("color", "melanin", "melanin_redness", "tint", "absorption_coefficient",
                     "random_color")
"""Inputs that change only a strand's absorption."""

GEOMETRY_INPUTS = ("roughness", "ior", "offset", "random_roughness")
"""Inputs that change a Huang strand's microfacet chains (its absorption part cannot serve)."""

HUANG_LOBES = ("reflection", "transmission", "secondary_reflection")

HUANG_MATERIAL_ONLY = ("aspect_ratio",) + HUANG_LOBES
"""Huang inputs that cannot vary per strand: linked, they render with their unlinked value."""

HUANG_CYCLES = (4, 5, 0)
"""Hairis' Huang is Cycles 4.5's (5.0's is the same); 4.0 to 4.4 integrate it differently."""

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
    def varies_absorption(self):
        """True for Huang hair whose absorption alone varies per strand (Random Color, or a
        linked colour or melanin input): its tables then need the absorption part, which
        strands of their own roughness, IOR or offset cannot read."""
        if self.model != "HUANG":
            return False
        if any(name in self.strand_inputs for name in GEOMETRY_INPUTS):
            return False
        if "random" in self.strand_inputs and self.random_roughness > 0.0:
            return False
        if any(name in self.strand_inputs for name in ABSORPTION_INPUTS):
            return True
        melanin = self.parametrization == PARAMETRIZATIONS["MELANIN"]
        return "random" in self.strand_inputs and melanin and self.random_color > 0.0

    @property
    def oriented(self):
        """True when the fiber's cross-section is elliptical (Huang with Aspect Ratio != 1):
        its major axis follows the curve normals."""
        return self.model == "HUANG" and self.aspect_ratio != 1.0


def _socket_value(socket, components):
    value = socket.default_value
    if components == 1:
        return float(value)
    values = tuple(float(v) for v in tuple(value)[:components])
    if len(values) != components:
        raise ValueError("input %r has %d components, expected %d"
                         % (socket.name, len(values), components))
    return values


def clamped(values, field_name, material_name, input_name, warnings):
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
        socket = find_input(node, input_name)
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
            value = clamped(compiled.evaluate(None), field_name, material_name, input_name,
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
