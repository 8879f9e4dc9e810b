"""The aging node group: :func:`..core.table.evaluate` as a shader node tree.

One group per aged copy, inserted between the artist's own Base Color graph and the
BSDF's colour socket. It reads three images LightFade made (the layouts are
:func:`..core.table.key_pixels`, :func:`..core.table.table_pixels` and the rate map)
and the scene's years through an Attribute node (View Layer: the scene's custom
property ``lightfade_years``), so Cycles (CPU and GPU), EEVEE and the Material Preview
evaluate the aging themselves: no Python per pixel or per years change, and the .blend
renders its aging where LightFade is not installed.

Stages (node names start with the stage; the group reads left to right):

``years``, ``uv``
    the scene's years; the exposure UV map.
``dose``
    the rate map (annual dose per spectrum as a fraction of the last node's, bilinear)
    and the texel's fractional dose node ``s = (T - 1) · min(1, (rate · years)**(1/3))``,
    ``i = min(floor s, T - 2)``.
``mix``
    the light-mix vertices (slots) and weights of :func:`..core.table.simplex_slots`.
``keys``
    the four key texels around the shading point (Closest), decoded, with bilinear
    weights: the change is blended by hand, so a key boundary shows no step.
``table``
    per key and vertex, the table at dose nodes ``i`` and ``i + 1`` (Closest),
    interpolated by ``s - i``; summed with the weights.
``colour``
    ``XYZ = M · rgb``, times ``exp(change)``, back to linear sRGB.
``gamut``
    :func:`..core.gamut.into_gamut`'s rule: towards the grey of the clipped luminance.
``switch``
    zero years passes the original colour through untouched.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np

from ...core.colorimetry import XYZ_to_linear_srgb, linear_srgb_to_XYZ
from ...core.gamut import LUMA
from ..years import YEARS_PROP
from .graph import Graph, Sock

#: Bumped whenever the group's nodes change: an older group is rebuilt.
GROUP_VERSION = 1
#: Custom property on the group tree holding :data:`GROUP_VERSION`.
VERSION_KEY = "lightfade_aging_version"


@dataclass(frozen=True)
class GroupSpec:
    """What one copy's group reads: images, their sizes and the table's shape."""

    uv_map: str
    key_image: object
    key_size: tuple          # (W, H)
    key_extension: str
    rate_image: object
    S: int                   # spectra (rate channels), 1..4
    table_image: object
    table_size: tuple        # (W, H)
    T: int
    slots: int
    per_row: int
    q: int
    max_dose: float          # lux·h


def _interface(tree):
    """Color in, Color out (the group's sockets, on 4.x and 5.x)."""
    tree.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    tree.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")


def _dose(g, spec, years, uv):
    g.stage = "dose"
    colour, alpha = g.image(spec.rate_image, uv, "Linear", "EXTEND")
    rates = g.separate(colour)[:spec.S] + ([alpha] if spec.S == 4 else [])
    total = rates[0]
    for r in rates[1:]:
        total = total + r
    pos = ((total * years) ** (1.0 / 3.0)) * float(spec.T - 1)     # rates: per max_dose
    pos = pos.min(float(spec.T - 1))
    i = pos.floor().min(float(spec.T - 2))
    return rates, total, i, pos - i


def _mix(g, spec, rates, total):
    """[(slot, weight)] of :func:`..core.table.simplex_slots`; weight None for one spectrum."""
    g.stage = "mix"
    S, q = spec.S, spec.q
    if S == 1:
        return [(0.0, None)]
    empty = 1.0 - total.gt(0.0)                  # no light: all weight on spectrum 0
    w = [rates[0] / total + empty] + [r / total for r in rates[1:]]
    J = S - 1
    cum, base, f = 0.0, [], []
    for j in range(J):
        cum = w[j] if j == 0 else cum + w[j]
        yj = (cum * float(q)).clamp(0.0, float(q))
        bj = yj.floor().min(float(q - 1))
        base.append(bj)
        f.append(yj - bj)
    rank = []                                    # fractions going before coordinate j
    for j in range(J):
        r = 0.0
        for i in range(J):
            if i < j:
                r = f[i].gt(f[j]) + r
            elif i > j:
                r = f[i].ge(f[j]) + r
        rank.append(r)
    radix = [float((q + 1) ** j) for j in range(J)]
    base_slot = base[0] * radix[0]
    for j in range(1, J):
        base_slot = base[j] * radix[j] + base_slot
    if J == 1:                                   # one fraction: rank 0
        ordered = f
    else:
        ordered = []                             # f_(k): the fraction of rank k
        for k in range(J):
            fk = 0.0
            for j in range(J):
                is_k = 1.0 - (rank[j] - float(k)).gt(0.5) - (float(k) - rank[j]).gt(0.5)
                fk = f[j] * is_k + fk
            ordered.append(fk)
    out = []
    for k in range(S):
        slot = base_slot
        for j in range(J):
            if k == 0:
                continue
            if J == 1:                           # rank 0: on from the second vertex
                slot = slot + radix[j]
            else:
                slot = rank[j].lt(k - 0.5) * radix[j] + slot
        upper = 1.0 if k == 0 else ordered[k - 1]
        lower = 0.0 if k == J else ordered[k]
        out.append((slot, upper - lower))
    return out


def _keys(g, spec, uv):
    """[(key, weight)] of the four key texels around ``uv`` (bilinear weights)."""
    g.stage = "keys"
    W, H = spec.key_size
    u, v, _ = g.separate(uv)
    px, py = u * float(W) - 0.5, v * float(H) - 0.5
    x0, y0 = px.floor(), py.floor()
    fx, fy = px - x0, py - y0
    out = []
    for dx in (0, 1):
        for dy in (0, 1):
            colour, _a = g.fetch(spec.key_image, (W, H), x0 + float(dx), y0 + float(dy),
                                 spec.key_extension)
            r, gg, b = g.separate(colour)
            key = (r * 255.0).round() * 65536.0 + (gg * 255.0).round() * 256.0 \
                + (b * 255.0).round()
            weight = (fx if dx else 1.0 - fx) * (fy if dy else 1.0 - fy)
            out.append((key, weight))
    return out


def _table(g, spec, keys, vertices, i, f):
    """Σ over keys and vertices of weight · (v_i + f (v_i+1 - v_i)) — a vector Sock."""
    g.stage = "table"
    change = None
    for key, wk in keys:
        for slot, wv in vertices:
            run = key * float(spec.slots) + slot
            row = ((run + 0.5) * (1.0 / spec.per_row)).floor()
            col = (run - row * float(spec.per_row)) * float(spec.T) + i
            lo, _a = g.fetch(spec.table_image, spec.table_size, col, row)
            hi, _a = g.fetch(spec.table_image, spec.table_size, col + 1.0, row)
            step = g.vector("ADD", lo, g.vector("SCALE", g.vector("SUBTRACT", hi, lo),
                                                None, None, f))
            weight = wk if wv is None else wk * wv
            term = g.vector("SCALE", step, None, None, weight)
            change = term if change is None else g.vector("ADD", change, term)
    return change


def _colour(g, colour, change):
    g.stage = "colour"
    to_XYZ = linear_srgb_to_XYZ(np.eye(3)).T            # rows: X, Y, Z of (r, g, b)
    to_rgb = XYZ_to_linear_srgb(np.eye(3)).T
    e = g.combine(*(c.exp() for c in g.separate(change)))
    XYZ = g.combine(*(g.vector("DOT_PRODUCT", colour, tuple(map(float, row)))
                      for row in to_XYZ))
    aged = g.vector("MULTIPLY", XYZ, e)
    return [g.vector("DOT_PRODUCT", aged, tuple(map(float, row))) for row in to_rgb]


def _gamut(g, c):
    g.stage = "gamut"
    Y = (c[0] * float(LUMA[0]) + c[1] * float(LUMA[1]) + c[2] * float(LUMA[2])).clamp(0.0, 1.0)
    d = [ck - Y for ck in c]
    t = None
    for ck, dk in zip(c, d):
        hi, lo = ck.gt(1.0), ck.lt(0.0)
        tk = hi * ((1.0 - Y) / dk) + (1.0 - hi) * (lo * ((0.0 - Y) / dk) + (1.0 - lo))
        t = tk if t is None else t.min(tk)
    t = t.clamp(0.0, 1.0)
    return [(Y + t * dk).clamp(0.0, 1.0) for dk in d]


def build(tree, spec):
    """Fill the empty group ``tree`` with the aging of ``spec``."""
    _interface(tree)
    g = Graph(tree)
    g.stage = "io"
    gin = g.node("NodeGroupInput", depth=0)
    colour = Sock(g, gin.outputs[0], 0)
    g.stage = "years"
    years = g.out(g.node("ShaderNodeAttribute", attribute_type="VIEW_LAYER",
                         attribute_name=YEARS_PROP, depth=0), "Fac")
    g.stage = "uv"
    uv = g.out(g.node("ShaderNodeUVMap", uv_map=spec.uv_map, depth=0), "UV")
    rates, total, i, f = _dose(g, spec, years, uv)
    vertices = _mix(g, spec, rates, total)
    keys = _keys(g, spec, uv)
    change = _table(g, spec, keys, vertices, i, f)
    rgb = _gamut(g, _colour(g, colour, change))
    g.stage = "switch"
    aged = g.combine(*rgb)
    on = years.gt(0.0)
    result = g.vector("ADD", colour, g.vector("SCALE", g.vector("SUBTRACT", aged, colour),
                                              None, None, on))
    g.stage = "io"
    gout = g.node("NodeGroupOutput", (result,))
    gout.is_active_output = True
    tree[VERSION_KEY] = GROUP_VERSION
    return tree


def new_group(name, spec):
    """A new group tree ``name`` holding the aging of ``spec``."""
    tree = bpy.data.node_groups.new(name, "ShaderNodeTree")
    return build(tree, spec)
