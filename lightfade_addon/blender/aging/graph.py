"""Arithmetic on shader sockets: node trees written like the numpy code they mirror.

A :class:`Graph` wraps a node tree; a :class:`Sock` is an output socket of it.
``a * b + 1`` on socks adds Math nodes (``a * 2.0`` puts the constant in the node's
own input, no Value node); :meth:`Graph.image` samples an image at a computed UV.
Every node gets a readable name (``<stage>.<n>``) and a column by its depth from the
inputs, so the built group reads left to right in the node editor.
"""

from __future__ import annotations

import bpy

_COLUMN = 180
_ROW = 120
#: The Vector Mix node's sockets (Factor_Float, A_Vector, B_Vector; Result_Vector),
#: the same on Blender 4.2 and 5.x.
_MIX_FACTOR, _MIX_A, _MIX_B, _MIX_RESULT = 0, 4, 5, 1


class Sock:
    """An output socket of a :class:`Graph`, with the arithmetic of a float."""

    def __init__(self, graph, socket, depth):
        self.graph, self.socket, self.depth = graph, socket, depth

    def _op(self, op, *others):
        return self.graph.math(op, self, *others)

    def __add__(self, o): return self._op("ADD", o)
    def __radd__(self, o): return self.graph.math("ADD", o, self)
    def __sub__(self, o): return self._op("SUBTRACT", o)
    def __rsub__(self, o): return self.graph.math("SUBTRACT", o, self)
    def __mul__(self, o): return self._op("MULTIPLY", o)
    def __rmul__(self, o): return self.graph.math("MULTIPLY", o, self)
    def __truediv__(self, o): return self._op("DIVIDE", o)
    def __rtruediv__(self, o): return self.graph.math("DIVIDE", o, self)
    def __pow__(self, o): return self._op("POWER", o)

    def gt(self, o):
        """1 where ``self > o``, else 0."""
        return self._op("GREATER_THAN", o)

    def lt(self, o):
        """1 where ``self < o``, else 0."""
        return self._op("LESS_THAN", o)

    def ge(self, o):
        """1 where ``self >= o``, else 0."""
        return 1.0 - self.lt(o)

    def floor(self): return self._op("FLOOR")
    def ln(self): return self._op("LOGARITHM", 2.718281828459045)
    def exp(self): return self._op("EXPONENT")
    def round(self): return self._op("ROUND")
    def cos(self): return self._op("COSINE")
    def sin(self): return self._op("SINE")
    def tan(self): return self._op("TANGENT")
    def min(self, o): return self._op("MINIMUM", o)
    def max(self, o): return self._op("MAXIMUM", o)

    def clamp(self, lo, hi):
        return self.max(lo).min(hi)


class Graph:
    """Builds nodes into ``tree``; ``stage`` names the nodes made next."""

    def __init__(self, tree):
        self.tree = tree
        self.stage = "node"
        self._count = 0
        self._rows = {}
        self._depth = {}

    def _place(self, node, depth):
        row = self._rows.get(depth, 0)
        self._rows[depth] = row + 1
        node.location = (depth * _COLUMN, -row * _ROW)

    def node(self, kind, inputs=(), depth=None, **settings):
        """A new node of ``kind`` with ``settings``; ``inputs`` (index or name → Sock
        or constant) linked or set.  Returns the node."""
        self._count += 1
        node = self.tree.nodes.new(kind)
        node.name = node.label = f"{self.stage}.{self._count}"
        for key, value in settings.items():
            setattr(node, key, value)
        deepest = 0
        for key, value in (inputs.items() if isinstance(inputs, dict) else enumerate(inputs)):
            socket = node.inputs[key]
            if isinstance(value, Sock):
                self.tree.links.new(value.socket, socket)
                deepest = max(deepest, value.depth)
            elif value is not None:
                socket.default_value = value
        depth = deepest + 1 if depth is None else depth
        self._place(node, depth)
        self._depth[node.name] = depth
        return node

    def out(self, node, output=0):
        return Sock(self, node.outputs[output], self._depth.get(node.name, 0))

    def math(self, op, *args):
        node = self.node("ShaderNodeMath", args, operation=op, use_clamp=False)
        return self.out(node)

    def vector(self, op, *args):
        """A Vector Math node (``DOT_PRODUCT``'s output is its ``Value``)."""
        node = self.node("ShaderNodeVectorMath", args, operation=op)
        return self.out(node, "Value" if op == "DOT_PRODUCT" else "Vector")

    @property
    def has_vector_power(self):
        """Whether Vector Math has POWER (Blender 4.3 and later; not 4.2)."""
        ops = bpy.types.ShaderNodeVectorMath.bl_rna.properties["operation"].enum_items
        return "POWER" in ops

    def power(self, base, exponent):
        """``base ** exponent`` per channel of vector socks or constants: one Vector
        Math node where Blender has POWER, else Separate, three Math and Combine."""
        if self.has_vector_power:
            return self.vector("POWER", base, exponent)
        split = [self.separate(v) if isinstance(v, Sock) else [float(c) for c in v]
                 for v in (base, exponent)]
        return self.combine(*(self.math("POWER", b, e) for b, e in zip(*split)))

    def prune(self):
        """Remove the nodes whose outputs reach nothing (the group output stays)."""
        while True:
            dead = [n for n in self.tree.nodes if n.type not in ("GROUP_OUTPUT", "GROUP_INPUT")
                    and not any(o.is_linked for o in n.outputs)]
            if not dead:
                return
            for node in dead:
                self.tree.nodes.remove(node)

    def value(self, v):
        """A constant as a Sock (a Value node)."""
        node = self.node("ShaderNodeValue")
        node.outputs[0].default_value = v
        return self.out(node)

    def lerp(self, a, b, f):
        """``a + f (b - a)`` of vectors ``a``, ``b`` and a float ``f``: one Mix node
        (Vector, uniform factor, unclamped), ``a`` itself where ``f`` is 0."""
        node = self.node("ShaderNodeMix", {_MIX_FACTOR: f, _MIX_A: a, _MIX_B: b},
                         data_type="VECTOR", factor_mode="UNIFORM", clamp_factor=False)
        return self.out(node, _MIX_RESULT)

    def combine(self, x, y, z=0.0):
        return self.out(self.node("ShaderNodeCombineXYZ", (x, y, z)))

    def separate(self, vector):
        node = self.node("ShaderNodeSeparateXYZ", (vector,))
        return [self.out(node, k) for k in range(3)]

    def image(self, image, uv, interpolation="Closest", extension="EXTEND"):
        """Colour and alpha of ``image`` at the vector ``uv`` (a Sock)."""
        node = self.node("ShaderNodeTexImage", {"Vector": uv}, image=image,
                         interpolation=interpolation, extension=extension)
        return self.out(node, "Color"), self.out(node, "Alpha")

    def environment(self, image, direction, interpolation="Linear"):
        """Colour of ``image`` (Equirectangular) in the vector ``direction`` (a Sock).

        Unlike :meth:`image`, EEVEE samples it without mip-maps or anisotropic
        filtering: Linear is plain bilinear in both engines."""
        node = self.node("ShaderNodeTexEnvironment", {"Vector": direction}, image=image,
                         interpolation=interpolation, projection="EQUIRECTANGULAR")
        return self.out(node, "Color")

    def fetch(self, image, size, x, y, extension="EXTEND"):
        """Texel (integer ``x``, ``y``) of an image of ``size`` (W, H), unfiltered."""
        w, h = size
        return self.image(image, self.combine((x + 0.5) * (1.0 / w), (y + 0.5) * (1.0 / h)),
                          "Closest", extension)
