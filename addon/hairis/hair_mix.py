"""Hair materials as artists build them: a Mix Shader / Add Shader tree whose leaves are
Principled Hair BSDFs, as Cycles renders it.

Cycles makes one closure per Principled Hair BSDF leaf, weighted by the product of the mix
factors on its way to the output (a Mix Shader gives its first shader 1 − Fac and its second
Fac, clamped to [0, 1]; an Add Shader gives both sides 1). A factor may be a constant or a
chain node_eval evaluates (Hair Info Random through a ColorRamp or a Math Greater Than): then
the weights vary per curve or point. Any other shader node in the tree is reported by the
caller and left out.
"""

import numpy as np

from . import compat, node_eval

MIX_NODES = {"ShaderNodeMixShader", "ShaderNodeAddShader"}


def _factor(node, material_name, warnings):
    """A Mix Shader's Fac as a field clamped to [0, 1] (Cycles' svm_node_mix_closure)."""
    socket = compat.find_input(node, ("Fac", "Factor"))
    if socket is None:
        return node_eval.constant([0.5])
    try:
        field = node_eval.compile_input(socket, 1)
    except node_eval.Unsupported as error:
        warnings.append("material %r: %s; hairis uses the unlinked Fac (%g) of Mix Shader %r"
                        % (material_name, error.describe(), float(socket.default_value),
                           node.name))
        field = node_eval.constant([float(socket.default_value)])
    return node_eval.combine(lambda f: np.clip(np.nan_to_num(f, nan=0.0), 0.0, 1.0), field)


def closures(root, hair_idname, material_name="?"):
    """The hair closures under ``root`` (the node feeding the output's Surface).

    Returns (leaves, others, warnings): leaves are (Principled Hair node, weight field of one
    component) in the tree's order; others are the shader nodes that are neither a hair leaf
    nor a Mix/Add Shader; warnings name what could not be evaluated.
    """
    leaves, others, warnings = [], [], []

    def visit(node, weight):
        if node is None:
            return  # an unlinked shader input: no closure
        if node.bl_idname == hair_idname:
            leaves.append((node, weight))
            return
        if node.bl_idname not in MIX_NODES:
            others.append(node)
            return
        shaders = [s for s in node.inputs if s.type == "SHADER"][:2]
        if node.bl_idname == "ShaderNodeMixShader":
            fac = _factor(node, material_name, warnings)
            parts = (node_eval.combine(lambda w, f: w * (1.0 - f), weight, fac),
                     node_eval.combine(lambda w, f: w * f, weight, fac))
        else:
            parts = (weight, weight)
        for socket, part in zip(shaders, parts):
            child, _ = node_eval.source(socket)
            visit(child, part)

    visit(root, node_eval.constant([1.0]))
    return leaves, others, warnings


def has_hair_leaf(root, hair_idname):
    """True when ``root`` is a Principled Hair BSDF or a Mix/Add Shader tree holding one."""
    if root is None:
        return False
    if root.bl_idname == hair_idname:
        return True
    if root.bl_idname not in MIX_NODES:
        return False
    return any(has_hair_leaf(node_eval.source(s)[0], hair_idname)
               for s in root.inputs if s.type == "SHADER")


class Mixture:
    """A hair mixture of the exported scene: ``closures`` are the scene material indices of
    its leaves (HAIR materials), ``weights`` their weight fields, ``strand_inputs`` the node
    inputs that vary per strand, shared by every leaf that reads them (field name → Field)."""

    def __init__(self, closures, weights, strand_inputs):
        self.closures = closures
        self.weights = weights
        self.strand_inputs = strand_inputs

    def material_weights(self):
        """The weights the library takes per material: a constant's value, and 1 where the
        weight varies per strand (the strand's own value replaces it)."""
        return [float(w.evaluate(None)[0, 0]) if w.domain == "material" else 1.0
                for w in self.weights]

    def strand_weights(self, strands):
        """The curve inputs of the weights that vary per strand: 'weight<k>' → (domain,
        float32 values)."""
        return {"weight%d" % k: (w.domain, w.evaluate(strands).astype(np.float32))
                for k, w in enumerate(self.weights) if w.domain != "material"}


def shared_strand_inputs(material_name, leaves, identifiers):
    """The strand inputs of a mixture from its leaves' (node, HairParameters): each input once;
    a warning when leaves feed one input from different chains (hairis gives every leaf the
    first one's values). ``identifiers``: field name → the node's input identifier. Returns
    (strand_inputs, warnings)."""
    merged, owner, warnings = {}, {}, []
    for node, params in leaves:
        for name, field in params.strand_inputs.items():
            if name not in merged:
                merged[name], owner[name] = field, node
                continue
            identifier = identifiers[name]
            if name == "random" or _origin(owner[name], identifier) == _origin(node, identifier):
                continue  # an unlinked Random is Cycles' per-strand random in every leaf
            warnings.append("material %r: the Principled Hair BSDFs %r and %r feed %r from "
                            "different node chains; hairis gives both the values of %r's"
                            % (material_name, owner[name].name, node.name, identifier,
                               owner[name].name))
    return merged, warnings


def _origin(node, identifier):
    """The node output feeding a hair node's input, as a comparable key."""
    source, output = node_eval.source(compat.find_input(node, (identifier,)))
    return None if source is None else (source.as_pointer(), output.identifier)
