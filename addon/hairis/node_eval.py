"""Node chains feeding the Principled Hair BSDF's inputs, evaluated with numpy per curve or
per point, as Cycles' SVM evaluates them per shading point.

A chain is compiled once per material (:func:`compile_input`) into a :class:`Field`: a
function of a curve set's Hair Info (:class:`Strands`) whose domain is known from what it
reads — ``'material'`` (no Hair Info: one value), ``'curve'`` (Random, Length) or
``'point'`` (Intercept). Cycles evaluates the chain at the hit from Intercept interpolated
along the segment; hairis evaluates it at the points and the renderer interpolates the result,
which is the same wherever the chain is linear in Intercept between two points.

Supported (read by socket identifier, the same in Blender 3.4, 4.x and 5.0): Hair Info
(Intercept, Random, Length, Is Strand), Value, RGB, Math, Map Range (Float), Clamp, ColorRamp,
Mix (Float, Vector, Color) and MixRGB, Separate/Combine RGB and Separate/Combine Color (RGB
mode), Invert, and reroutes and muted nodes between them. Anything else raises
:class:`Unsupported` naming the node; the caller then uses the hair input's unlinked value.

Cycles' rules followed here (intern/cycles/kernel/svm): implicit conversions colour → float by
Rec.709 luminance, vector → float by the average, float → colour/vector by repetition; Math
with its safe operations (division by zero gives 0, ...); Map Range clamped to its To range
whenever Clamp is on; a ColorRamp baked to 256 entries (Blender's own evaluation at i/255) and
interpolated linearly between them (not at all for Constant); MixRGB's factor clamped to
[0, 1]; the per-strand random number Cycles' own (:func:`strand_random`).
"""

import math
from dataclasses import dataclass

import numpy as np

RAMP_TABLE_SIZE = 256
"""Cycles bakes a ColorRamp into this many entries (RAMP_TABLE_SIZE)."""

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
"""Rec.709 luminance: Cycles' colour-to-float conversion in Blender's default colour space."""

DOMAINS = ("material", "curve", "point")

FLOAT_EPSILON = float(np.finfo(np.float32).eps)
"""Cycles' FLT_EPSILON (Math's Compare)."""


class Unsupported(Exception):
    """A node (or a setting of it) in a chain that hairis cannot evaluate."""

    def __init__(self, node, reason):
        super().__init__(reason)
        self.node = node
        self.reason = reason

    def describe(self):
        """'<label> <name>: <reason>' for warnings."""
        return "%s %r %s" % (self.node.bl_label or self.node.bl_idname, self.node.name, self.reason)


@dataclass
class Strands:
    """What Hair Info reads for one curve set: per curve ``random`` and object-space
    ``length``, per point ``intercept`` (the arc-length fraction from the root)."""

    counts: np.ndarray
    random: np.ndarray
    intercept: np.ndarray
    length: np.ndarray

    @property
    def curve_count(self):
        return int(self.counts.size)

    @property
    def point_count(self):
        return int(self.intercept.size)

    def size(self, domain):
        """Number of values of a domain."""
        return {"material": 1, "curve": self.curve_count, "point": self.point_count}[domain]

    def widen(self, values, domain, to):
        """(n, k) values of ``domain`` as values of the wider domain ``to``."""
        if domain == to:
            return values
        if to == "point" and domain == "curve":
            return np.repeat(values, self.counts, axis=0)
        return np.broadcast_to(values, (self.size(to), values.shape[1]))


def strands_of(first, positions_object, random):
    """The :class:`Strands` of curves ``first`` (curve+1 offsets) with object-space points,
    as Cycles computes them: intercept = chord length from the root over the curve's length."""
    first = np.asarray(first, dtype=np.int64)
    counts = np.diff(first)
    positions = np.asarray(positions_object, dtype=np.float64)
    step = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    step = np.concatenate([[0.0], step])
    step[first[:-1]] = 0.0  # no step into the first point of a curve
    cumulative = np.cumsum(step)
    start = cumulative[first[:-1]]
    along = cumulative - np.repeat(start, counts)
    length = np.add.reduceat(step, first[:-1]) if counts.size else np.zeros(0)
    total = np.repeat(length, counts)
    intercept = np.divide(along, total, out=np.zeros_like(along), where=total > 0.0)
    return Strands(counts=counts, random=np.asarray(random, dtype=np.float64),
                   intercept=intercept, length=length)


_U32 = np.uint64(0xFFFFFFFF)


def _rotate(x, k):
    """32-bit left rotation of uint64-held words."""
    return ((x << np.uint64(k)) | (x >> np.uint64(32 - k))) & _U32


def _lookup3_final(a, b, c):
    """The final mixing of Bob Jenkins' lookup3 (public domain, burtleburtle.net/bob/c/
    lookup3.c), on uint64 arrays holding 32-bit words: each step xors one word into the next
    and subtracts a rotation of the former."""
    words = [a, b, c]
    for into, source, k in ((2, 1, 14), (0, 2, 11), (1, 0, 25), (2, 1, 16), (0, 2, 4),
                            (1, 0, 14), (2, 1, 24)):
        words[into] = ((words[into] ^ words[source]) - _rotate(words[source], k)) & _U32
    return words[2]


def strand_random(curve_indices):
    """Per-strand random numbers in [0, 1] for curves of these indices (within their object):
    lookup3's hashword of the two words (index, 0) with initial value 13, mapped to float by
    n · 2^−32 in single precision — Cycles' curve random attribute (hash_uint2_to_float(index,
    0)), so a strand gets the number Cycles gives it."""
    with np.errstate(over="ignore"):
        index = np.asarray(curve_indices, dtype=np.uint64) & _U32
        start = np.full(index.shape, 0xDEADBEEF + (2 << 2) + 13, dtype=np.uint64)
        a = (start + index) & _U32
        b = start & _U32
        c = start & _U32
        hashed = _lookup3_final(a, b, c)
    # In single precision, as Cycles converts it: (float)n · (1 / (float)0xFFFFFFFF).
    return (hashed.astype(np.float32) * np.float32(1.0 / 4294967296.0)).astype(np.float64)


@dataclass
class Field:
    """A compiled chain: ``evaluate(strands)`` gives (n, components) values of ``domain``
    (n = 1 for 'material', then strands may be None)."""

    domain: str
    components: int
    function: object

    def evaluate(self, strands=None):
        values = np.asarray(self.function(strands), dtype=np.float64)
        return values.reshape(-1, self.components)


def constant(values):
    """A 'material' field of fixed values."""
    array = np.asarray(values, dtype=np.float64).reshape(1, -1)
    return Field("material", array.shape[1], lambda strands: array)


def combine(function, *fields, components=None):
    """A field of ``function(*arrays)`` on the widest domain of ``fields``."""
    domain = max((f.domain for f in fields), key=DOMAINS.index)

    def run(strands):
        arrays = [f.evaluate(strands) for f in fields]
        if strands is not None:
            arrays = [strands.widen(a, f.domain, domain) for a, f in zip(arrays, fields)]
        return function(*arrays)

    if components is None:
        components = max(f.components for f in fields)
    return Field(domain, components, run)


def convert(field, components, luminance_for_colour=True):
    """Cycles' implicit conversion to a socket of ``components`` (1 or 3)."""
    if field.components == components:
        return field
    if components == 3:
        return combine(lambda a: np.repeat(a, 3, axis=1), field, components=3)
    weights = LUMINANCE if luminance_for_colour else np.full(3, 1.0 / 3.0)
    return combine(lambda a: (a @ weights).reshape(-1, 1), field, components=1)


# ---- Links -----------------------------------------------------------------------------------

def _live_links(socket):
    return [link for link in socket.links
            if getattr(link, "is_valid", True) and not getattr(link, "is_muted", False)]


def source(socket):
    """The (node, output socket) feeding ``socket``, through reroutes and muted nodes; (None,
    None) when nothing does."""
    seen = set()
    while socket is not None and socket.is_linked:
        links = _live_links(socket)
        if not links:
            return None, None
        link = links[0]
        node = link.from_node
        if node.as_pointer() in seen:
            return None, None
        seen.add(node.as_pointer())
        if node.type == "REROUTE":
            socket = node.inputs[0] if len(node.inputs) else None
            continue
        if getattr(node, "mute", False):
            through = [internal.from_socket for internal in node.internal_links
                       if internal.to_socket == link.from_socket]
            if not through:
                return None, None
            socket = through[0]
            continue
        return node, link.from_socket
    return None, None


def _components(socket):
    return 1 if socket.type in {"VALUE", "INT", "BOOLEAN"} else 3


def _default(socket):
    value = socket.default_value
    if _components(socket) == 1:
        return constant([float(value)])
    return constant([float(v) for v in tuple(value)[:3]])


def _input(node, identifier):
    for socket in node.inputs:
        if socket.identifier == identifier:
            return socket
    raise Unsupported(node, "has no input %r in this Blender" % identifier)


def compile_socket(socket, components, stack=()):
    """The field feeding an input ``socket``, converted to ``components``."""
    node, output = source(socket)
    if node is None:
        return convert(_default(socket), components)
    if node.as_pointer() in stack:
        raise Unsupported(node, "is part of a cycle")
    field = _compile_output(node, output, stack + (node.as_pointer(),))
    from_colour = output.type == "RGBA"
    return convert(field, components, luminance_for_colour=from_colour)


def _in(node, identifier, components, stack):
    return compile_socket(_input(node, identifier), components, stack)


# ---- Nodes -----------------------------------------------------------------------------------

def _hair_info(node, output, stack):
    name = output.identifier
    if name == "Intercept":
        return Field("point", 1, lambda s: s.intercept.reshape(-1, 1))
    if name == "Random":
        return Field("curve", 1, lambda s: s.random.reshape(-1, 1))
    if name == "Length":
        return Field("curve", 1, lambda s: s.length.reshape(-1, 1))
    if name == "Is Strand":
        return constant([1.0])
    raise Unsupported(node, "output %r is not supported (Intercept, Random, Length and Is Strand "
                            "are)" % output.name)


def _safe_divide(a, b):
    return np.divide(a, b, out=np.zeros_like(a), where=b != 0.0)


def _safe_power(a, b):
    with np.errstate(all="ignore"):
        bad = (a < 0.0) & (b != np.trunc(b))
        result = np.where(a == 0.0, np.where(b == 0.0, 1.0, 0.0), np.power(np.abs(a), b)
                          * np.where((a < 0.0) & (np.mod(b, 2.0) == 1.0), -1.0, 1.0))
        result = np.where(b == 0.0, 1.0, result)
    return np.where(bad, 0.0, result)


def _wrap(value, high, low):
    span = high - low
    with np.errstate(all="ignore"):
        wrapped = value - span * np.floor(_safe_divide(value - low, span))
    return np.where(span != 0.0, wrapped, low)


def _smooth_min(a, b, k):
    with np.errstate(all="ignore"):
        h = np.maximum(k - np.abs(a - b), 0.0) / np.where(k != 0.0, k, 1.0)
    return np.where(k != 0.0, np.minimum(a, b) - h ** 3 * k / 6.0, np.minimum(a, b))


def _fract(a):
    return a - np.floor(a)


MATH = {
    "ADD": lambda a, b, c: a + b,
    "SUBTRACT": lambda a, b, c: a - b,
    "MULTIPLY": lambda a, b, c: a * b,
    "DIVIDE": lambda a, b, c: _safe_divide(a, b),
    "MULTIPLY_ADD": lambda a, b, c: a * b + c,
    "POWER": lambda a, b, c: _safe_power(a, b),
    "LOGARITHM": lambda a, b, c: np.where((a > 0.0) & (b > 0.0), _safe_divide(
        np.log(np.where(a > 0.0, a, 1.0)), np.log(np.where(b > 0.0, b, 1.0))), 0.0),
    "SQRT": lambda a, b, c: np.sqrt(np.maximum(a, 0.0)),
    "INVERSE_SQRT": lambda a, b, c: np.where(a > 0.0, 1.0 / np.sqrt(np.where(a > 0.0, a, 1.0)),
                                             0.0),
    "ABSOLUTE": lambda a, b, c: np.abs(a),
    "EXPONENT": lambda a, b, c: np.exp(a),
    "MINIMUM": lambda a, b, c: np.minimum(a, b),
    "MAXIMUM": lambda a, b, c: np.maximum(a, b),
    "LESS_THAN": lambda a, b, c: (a < b).astype(np.float64),
    "GREATER_THAN": lambda a, b, c: (a > b).astype(np.float64),
    "SIGN": lambda a, b, c: np.sign(a),
    "COMPARE": lambda a, b, c: ((a == b) | (np.abs(a - b) <= np.maximum(c, FLOAT_EPSILON)))
    .astype(np.float64),
    "SMOOTH_MIN": lambda a, b, c: _smooth_min(a, b, c),
    "SMOOTH_MAX": lambda a, b, c: -_smooth_min(-a, -b, c),
    "ROUND": lambda a, b, c: np.floor(a + 0.5),
    "FLOOR": lambda a, b, c: np.floor(a),
    "CEIL": lambda a, b, c: np.ceil(a),
    "TRUNC": lambda a, b, c: np.trunc(a),
    "FRACT": lambda a, b, c: _fract(a),
    "MODULO": lambda a, b, c: np.where(b != 0.0, np.fmod(a, np.where(b != 0.0, b, 1.0)), 0.0),
    "FLOORED_MODULO": lambda a, b, c: np.where(b != 0.0, a - np.floor(_safe_divide(a, b)) * b, 0.0),
    "WRAP": lambda a, b, c: _wrap(a, b, c),
    "SNAP": lambda a, b, c: np.floor(_safe_divide(a, b)) * b,
    "PINGPONG": lambda a, b, c: np.where(b != 0.0, np.abs(
        _fract(_safe_divide(a - b, b * 2.0)) * b * 2.0 - b), 0.0),
    "SINE": lambda a, b, c: np.sin(a),
    "COSINE": lambda a, b, c: np.cos(a),
    "TANGENT": lambda a, b, c: np.tan(a),
    "SINH": lambda a, b, c: np.sinh(a),
    "COSH": lambda a, b, c: np.cosh(a),
    "TANH": lambda a, b, c: np.tanh(a),
    "ARCSINE": lambda a, b, c: np.arcsin(np.clip(a, -1.0, 1.0)),
    "ARCCOSINE": lambda a, b, c: np.arccos(np.clip(a, -1.0, 1.0)),
    "ARCTANGENT": lambda a, b, c: np.arctan(a),
    "ARCTAN2": lambda a, b, c: np.arctan2(a, b),
    "RADIANS": lambda a, b, c: a * (math.pi / 180.0),
    "DEGREES": lambda a, b, c: a * (180.0 / math.pi),
}
"""Blender's Math operations as Cycles' svm_math evaluates them."""


def _math(node, output, stack):
    operation = MATH.get(node.operation)
    if operation is None:
        raise Unsupported(node, "operation %s is not supported" % node.operation)
    a, b, c = (_in(node, name, 1, stack) for name in ("Value", "Value_001", "Value_002"))
    use_clamp = bool(getattr(node, "use_clamp", False))

    def run(x, y, z):
        with np.errstate(all="ignore"):
            result = operation(x, y, z)
        return np.clip(result, 0.0, 1.0) if use_clamp else result

    return combine(run, a, b, c, components=1)


def _clamp_range(value, low, high):
    return np.clip(value, np.minimum(low, high), np.maximum(low, high))


def _smoothstep(low, high, x):
    t = np.clip(_safe_divide(x - low, high - low), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def _smootherstep(low, high, x):
    t = np.clip(_safe_divide(x - low, high - low), 0.0, 1.0)
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def _map_range(node, output, stack):
    if getattr(node, "data_type", "FLOAT") != "FLOAT":
        raise Unsupported(node, "with data type %s is not supported (Float is)" % node.data_type)
    kind = node.interpolation_type
    if kind not in {"LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP"}:
        raise Unsupported(node, "interpolation %s is not supported" % kind)
    names = ("Value", "From Min", "From Max", "To Min", "To Max", "Steps")
    fields = [_in(node, name, 1, stack) for name in names]
    clamp = bool(node.clamp)

    def run(value, from_min, from_max, to_min, to_max, steps):
        with np.errstate(all="ignore"):
            span = from_max - from_min
            linear = _safe_divide(value - from_min, span)
            if kind == "LINEAR":
                factor = linear
            elif kind == "STEPPED":
                factor = np.where(steps > 0.0, np.floor(linear * (steps + 1.0))
                                  / np.where(steps > 0.0, steps, 1.0), 0.0)
            else:
                step = _smoothstep if kind == "SMOOTHSTEP" else _smootherstep
                factor = np.where(from_min > from_max, 1.0 - step(from_max, from_min, value),
                                  step(from_min, from_max, value))
            result = np.where(span != 0.0, to_min + factor * (to_max - to_min), 0.0)
        return _clamp_range(result, to_min, to_max) if clamp else result

    return combine(run, *fields, components=1)


def _clamp(node, output, stack):
    kind = getattr(node, "clamp_type", "MINMAX")
    value, low, high = (_in(node, name, 1, stack) for name in ("Value", "Min", "Max"))
    if kind == "RANGE":
        return combine(_clamp_range, value, low, high, components=1)
    return combine(lambda v, a, b: np.minimum(np.maximum(v, a), b), value, low, high,
                   components=1)


def ramp_table(color_ramp):
    """The ColorRamp as Cycles bakes it: RGBA at i/(size − 1), from Blender's own evaluation."""
    return np.array([tuple(color_ramp.evaluate(i / (RAMP_TABLE_SIZE - 1)))[:4]
                     for i in range(RAMP_TABLE_SIZE)], dtype=np.float64)


def ramp_lookup(table, factor, interpolate):
    """Cycles' rgb_ramp_lookup without extrapolation: the factor clamped to [0, 1]."""
    size = table.shape[0]
    f = np.clip(np.nan_to_num(factor, nan=0.0), 0.0, 1.0) * (size - 1)
    index = np.clip(f.astype(np.int64), 0, size - 1)
    t = f - index
    value = table[index]
    if interpolate:
        upper = table[np.minimum(index + 1, size - 1)]
        value = np.where((t > 0.0)[:, None], (1.0 - t)[:, None] * value + t[:, None] * upper, value)
    return value


def _color_ramp(node, output, stack):
    table = ramp_table(node.color_ramp)
    interpolate = node.color_ramp.interpolation != "CONSTANT"
    factor = _in(node, "Fac", 1, stack)
    if output.identifier == "Alpha":
        return combine(lambda f: ramp_lookup(table, f[:, 0], interpolate)[:, 3:4], factor,
                       components=1)
    return combine(lambda f: ramp_lookup(table, f[:, 0], interpolate)[:, :3], factor,
                   components=3)


def _mix(t, a, b):
    return a + t * (b - a)


def _dodge(t, a, b):
    with np.errstate(all="ignore"):
        tmp = 1.0 - t * b
        quotient = a / np.where(tmp > 0.0, tmp, 1.0)
    out = np.where(tmp <= 0.0, 1.0, np.minimum(quotient, 1.0))
    return np.where(a != 0.0, out, a)


def _burn(t, a, b):
    tmp = (1.0 - t) + t * b
    with np.errstate(all="ignore"):
        value = 1.0 - (1.0 - a) / np.where(tmp > 0.0, tmp, 1.0)
    return np.where(tmp <= 0.0, 0.0, np.clip(value, 0.0, 1.0))


def _overlay(t, a, b):
    tm = 1.0 - t
    return np.where(a < 0.5, a * (tm + 2.0 * t * b), 1.0 - (tm + 2.0 * t * (1.0 - b)) * (1.0 - a))


def _divide(t, a, b):
    with np.errstate(all="ignore"):
        divided = (1.0 - t) * a + t * a / np.where(b != 0.0, b, 1.0)
    return np.where(b != 0.0, divided, a)


def _soft_light(t, a, b):
    screen = 1.0 - (1.0 - b) * (1.0 - a)
    return (1.0 - t) * a + t * ((1.0 - a) * b * a + a * screen)


BLENDS = {
    "MIX": lambda t, a, b: _mix(t, a, b),
    "ADD": lambda t, a, b: _mix(t, a, a + b),
    "MULTIPLY": lambda t, a, b: _mix(t, a, a * b),
    "SUBTRACT": lambda t, a, b: _mix(t, a, a - b),
    "SCREEN": lambda t, a, b: 1.0 - ((1.0 - t) + t * (1.0 - b)) * (1.0 - a),
    "DIVIDE": _divide,
    "DIFFERENCE": lambda t, a, b: _mix(t, a, np.abs(a - b)),
    "EXCLUSION": lambda t, a, b: np.maximum(_mix(t, a, a + b - 2.0 * a * b), 0.0),
    "DARKEN": lambda t, a, b: _mix(t, a, np.minimum(a, b)),
    "LIGHTEN": lambda t, a, b: _mix(t, a, np.maximum(a, b)),
    "OVERLAY": _overlay,
    "DODGE": _dodge,
    "BURN": _burn,
    "SOFT_LIGHT": _soft_light,
    "LINEAR_LIGHT": lambda t, a, b: a + t * (2.0 * b - 1.0),
}
"""MixRGB / Mix (Color) blend modes as Cycles' svm_mix evaluates them (the HSV-based Hue,
Saturation, Value and Color modes are not supported)."""


def _blend(node, kind):
    blend = BLENDS.get(kind)
    if blend is None:
        raise Unsupported(node, "blend mode %s is not supported" % kind)
    return blend


def _mix_node(node, output, stack):
    kind = node.data_type
    clamp_factor = bool(getattr(node, "clamp_factor", True))

    def factor_of(t):
        return np.clip(t, 0.0, 1.0) if clamp_factor else t

    if kind == "FLOAT":
        t, a, b = (_in(node, n, 1, stack) for n in ("Factor_Float", "A_Float", "B_Float"))
        return combine(lambda t_, a_, b_: _mix(factor_of(t_), a_, b_), t, a, b, components=1)
    if kind == "VECTOR":
        uniform = getattr(node, "factor_mode", "UNIFORM") == "UNIFORM"
        t = _in(node, "Factor_Float", 1, stack) if uniform else _in(node, "Factor_Vector", 3, stack)
        a, b = (_in(node, n, 3, stack) for n in ("A_Vector", "B_Vector"))
        return combine(lambda t_, a_, b_: _mix(factor_of(t_), a_, b_), t, a, b, components=3)
    if kind == "RGBA":
        return _mix_colors(node, stack, ("Factor_Float", "A_Color", "B_Color"), factor_of,
                           bool(getattr(node, "clamp_result", False)))
    raise Unsupported(node, "with data type %s is not supported" % kind)


def _mix_colors(node, stack, inputs, factor_of, clamp_result):
    """The node's blend mode applied to its (factor, colour, colour) ``inputs``, the factor
    through ``factor_of``, the result clamped to [0, 1] when ``clamp_result``."""
    blend = _blend(node, node.blend_type)
    t = _in(node, inputs[0], 1, stack)
    a, b = (_in(node, n, 3, stack) for n in inputs[1:])

    def run(t_, a_, b_):
        with np.errstate(all="ignore"):
            result = blend(factor_of(t_), a_, b_)
        return np.clip(result, 0.0, 1.0) if clamp_result else result

    return combine(run, t, a, b, components=3)


def _mix_rgb(node, output, stack):
    return _mix_colors(node, stack, ("Fac", "Color1", "Color2"),
                       lambda t: np.clip(t, 0.0, 1.0), bool(getattr(node, "use_clamp", False)))


def _rgb_mode(node):
    mode = getattr(node, "mode", "RGB")
    if mode != "RGB":
        raise Unsupported(node, "mode %s is not supported (RGB is)" % mode)


def _separate(node, output, stack, colour_input, outputs):
    _rgb_mode(node)
    colour = _in(node, colour_input, 3, stack)
    channel = outputs.index(output.identifier)
    return combine(lambda c: c[:, channel:channel + 1], colour, components=1)


def _combine(node, output, stack, inputs):
    _rgb_mode(node)
    channels = [_in(node, n, 1, stack) for n in inputs]
    return combine(lambda r, g, b: np.concatenate([r, g, b], axis=1), *channels, components=3)


def _invert(node, output, stack):
    t = _in(node, "Fac", 1, stack)
    colour = _in(node, "Color", 3, stack)
    return combine(lambda t_, c: t_ * (1.0 - c) + (1.0 - t_) * c, t, colour, components=3)


def _value(node, output, stack):
    return constant([float(output.default_value)])


def _rgb(node, output, stack):
    return constant([float(v) for v in tuple(output.default_value)[:3]])


NODES = {
    "ShaderNodeHairInfo": _hair_info,
    "ShaderNodeValue": _value,
    "ShaderNodeRGB": _rgb,
    "ShaderNodeMath": _math,
    "ShaderNodeMapRange": _map_range,
    "ShaderNodeClamp": _clamp,
    "ShaderNodeValToRGB": _color_ramp,
    "ShaderNodeMix": _mix_node,
    "ShaderNodeMixRGB": _mix_rgb,
    "ShaderNodeSeparateRGB": lambda n, o, s: _separate(n, o, s, "Image", ["R", "G", "B"]),
    "ShaderNodeSeparateColor": lambda n, o, s: _separate(n, o, s, "Color",
                                                         ["Red", "Green", "Blue"]),
    "ShaderNodeCombineRGB": lambda n, o, s: _combine(n, o, s, ["R", "G", "B"]),
    "ShaderNodeCombineColor": lambda n, o, s: _combine(n, o, s, ["Red", "Green", "Blue"]),
    "ShaderNodeInvert": _invert,
}
"""The nodes a chain may hold, by bl_idname."""


def _compile_output(node, output, stack):
    compile_node = NODES.get(node.bl_idname)
    if compile_node is None:
        raise Unsupported(node, "is not supported in a chain feeding the Principled Hair BSDF")
    return compile_node(node, output, stack)


def compile_input(socket, components):
    """The :class:`Field` feeding the hair node's input ``socket`` (raises
    :class:`Unsupported` naming the first node hairis cannot evaluate)."""
    return compile_socket(socket, components)
