"""The aging node group: :func:`..core.colourtable.evaluate` as a shader node tree.

One group per aged copy, inserted between the artist's own Base Color graph and the
BSDF's colour socket (:func:`..copies.insert_group`). It reads the object's exposure
maps (lux per light group) and hands the annual doses to the **evaluation group** of
the copy's colour table (one per table, ``LF_Eval_*``, shared by every copy aged with
the same recipe and light set: the file keeps its nodes once, and EEVEE compiles one
shader for them), which reads the table (:func:`..core.colourtable.atlas_pixels`) and
the scene's years through an Attribute node (View Layer: the scene's custom property
``lightfade_years``), so Cycles (CPU and GPU), EEVEE and the Material Preview evaluate
the aging themselves: no Python per pixel or per years change, and the .blend renders
its aging where LightFade is not installed.

Stages (node names start with the stage; the groups read left to right). The copy's:

``uv``
    the exposure UV map.
``rates``
    each exposure map (Linear) times its hours a year, summed per spectrum: lux·h a year
    (in units of the dose axis's ``low`` dose, which the mix's ratios do not see): the
    evaluation group's ``Rate`` inputs.

The evaluation group's:

``years``
    the scene's years.
``dose``
    the dose ``d = years · Σ rates`` and its fractional node
    ``s = min(d / low, 1) + per_decade · log10(max(d, low) / low)`` (at most ``T - 1``),
    ``t = min(floor s, T - 2)``.
``mix``
    the light-mix vertices (slots) and weights of :func:`..core.table.simplex_slots`.
``unmix``
    the colour's cube coordinates ``u = clip(rgb, 0, 1) ** (1 / gamma) · (A - 1)`` (the
    factor ``A - 1`` of red and green folded into their atlas coordinates); the blue
    node ``b = min(floor u_b, A - 2)``; the unmixing ``Φ`` from its tiles ``b`` and
    ``b + 1`` (bilinear over red and green, a Mix over blue); the change table's
    coordinates ``k = clip(Φ, 0, 1) ** (1 / power)`` and the node ``k3_0 = min(floor
    k3 (N - 1), N - 2)``: the clip after the interpolation puts the gamut's faces on
    the change table's own planes.
``table``
    per mix vertex, the four tiles (``k3_0``, ``k3_0 + 1``) × (``t``, ``t + 1``), each
    looked up with Linear interpolation (bilinear over k1 and k2), linear over k3 and
    dose (Mix nodes), weighted over the vertices (two spectra: one more Mix).
    The lookups are Equirectangular Environment Textures, not Image Textures: EEVEE
    mip-maps an Image Texture, and the lookup coordinates jump between tiles at the
    artist's sharp colour edges, so it would read a blurred table there.
``colour``
    ``XYZ = M · rgb``, times ``exp(change)``, back to linear sRGB.
``gamut``
    :func:`..core.gamut.into_gamut`'s rule: towards the grey of the clipped luminance.
``switch``
    zero years passes the original colour through untouched (not for a table with a
    history, whose dose 0 is the restoration).

**Cost.** Cycles interprets the group per shading point, one SVM instruction per node
plus one per implicit float-to-vector conversion, so the group is written in few
nodes: vector nodes for three channels at once, a Mix node for each linear
interpolation (``a`` itself at factor 0: the switch), constants folded into the
multiply-adds, floats broadcast once (Combine XYZ) instead of converted at every use.
``benchmarks/live_room.py`` measures the render against the same room after Reset;
the copy's gate (:func:`..copies.gate_rays`) keeps the group off at 0 years and off the
rays the scene's *Aged Colour On* leaves out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import bpy
import numpy as np

from ...core.colour.colorimetry import XYZ_to_linear_srgb, linear_srgb_to_XYZ
from ...core.colour.gamut import LUMA
from .years import YEARS_PROP
from .graph import Graph, Sock
from .instances import tile_uv

#: Bumped whenever the group's nodes change: an older group is rebuilt (Age).
GROUP_VERSION = 7
#: Custom property on the group tree holding :data:`GROUP_VERSION`.
VERSION_KEY = "lightfade_aging_version"
#: Name prefix of the shared evaluation groups, and the property naming their table.
EVAL_PREFIX = "LF_Eval_"
EVAL_KEY = "lightfade_eval"


@dataclass(frozen=True)
class GroupSpec:
    """What one copy's group reads: the exposure maps and the shared colour table."""

    uv_map: str
    maps: tuple              # agingdata.MapInput: image, spectrum index, hours a year
    table_image: object
    table_size: tuple        # (W, H)
    side: int                # N
    T: int
    q: int
    S: int                   # spectra
    gamma: float
    per_decade: float
    low_dose: float          # lux·h of dose node 1
    history: bool
    unmix_side: int          # A
    power: float
    unmix_y: int             # first texel row of the unmixing's tiles
    per_row: int             # unmixing tiles per row
    tile: str = ""           # instances: the attribute holding each one's atlas tile

    @property
    def P(self):
        return self.side + 2


def _interface(tree):
    """Color in, Color out (the group's sockets, on 4.x and 5.x)."""
    tree.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    tree.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")


def _rates(g, spec, uv):
    """Annual dose per spectrum at the shading point in units of the dose axis's node 1
    (``low_dose`` lux·h) a year: ``lux · hours / low``."""
    g.stage = "rates"
    rates = [None] * spec.S
    for m in spec.maps:
        colour, _alpha = g.image(m.image, uv, "Linear", "EXTEND")
        lux = g.separate(colour)[0].max(0.0) * (float(m.hours) / float(spec.low_dose))
        k = m.spectrum
        rates[k] = lux if rates[k] is None else rates[k] + lux
    return [r if r is not None else 0.0 for r in rates]


def _total(rates):
    total = rates[0]
    for r in rates[1:]:
        total = total + r
    return total


def _dose(g, spec, years, total):
    g.stage = "dose"
    x = total * years                             # d / low; max(d, low) / low = max(x, 1)
    k = float(spec.per_decade) / math.log(10.0)
    s = g.math("MULTIPLY_ADD", x.max(1.0).ln(), k, x.min(1.0))
    s = s.min(float(spec.T - 1))
    t = s.floor().min(float(spec.T - 2))
    return t, s - t


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
    base_slot = base[0]                          # radix[0] is 1
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


def _unmix(g, spec, colour):
    """The change table's coordinates of ``colour``: ``k1``, ``k2`` in [0, 1] (scaled
    where they are used), the node ``k3_0`` and fraction of ``k3``.

    ``Φ`` is read from the unmixing's tiles ``b`` and ``b + 1`` like the change's
    (:func:`_table`: Equirectangular lookups of atlas texel coordinates), tile ``b`` at
    column ``b mod per_row`` and row ``b div per_row`` above the change's tiles.
    """
    g.stage = "unmix"
    W, H = spec.table_size
    A, PA, pi = spec.unmix_side, float(spec.unmix_side + 2), math.pi
    inv = 1.0 / float(spec.gamma)
    clipped = g.vector("MINIMUM", g.vector("MAXIMUM", colour, (0.0, 0.0, 0.0)), (1.0, 1.0, 1.0))
    r, gg, b = g.separate(g.power(clipped, (inv, inv, inv)))
    n = float(A - 1)
    b = b * n
    b0 = b.floor().min(float(A - 2))
    phi_r = g.math("MULTIPLY_ADD", r, -2.0 * pi * n / W, pi - 3.0 * pi / W)
    theta_g = g.math("MULTIPLY_ADD", gg, pi * n / H, pi * (spec.unmix_y + 1.5) / H - 0.5 * pi)
    reads = []
    for bi in (b0, b0 + 1.0):
        if spec.per_row >= A:                    # one row of tiles
            col, theta = bi, theta_g
        else:
            row = (bi * (1.0 / spec.per_row)).floor()
            col = g.math("MULTIPLY_ADD", row, -float(spec.per_row), bi)
            theta = g.math("MULTIPLY_ADD", row, pi * PA / H, theta_g)
        phi = g.math("MULTIPLY_ADD", col, -2.0 * pi * PA / W, phi_r)
        reads.append(g.environment(spec.table_image,
                                   g.combine(phi.cos(), phi.sin(), theta.tan()), "Linear"))
    y = g.lerp(reads[0], reads[1], b - b0)
    inv_p = 1.0 / float(spec.power)
    unit = g.vector("MINIMUM", g.vector("MAXIMUM", y, (0.0, 0.0, 0.0)), (1.0, 1.0, 1.0))
    k1, k2, k3 = g.separate(g.power(unit, (inv_p, inv_p, inv_p)))
    k3 = k3 * float(spec.side - 1)
    k3_0 = k3.floor().min(float(spec.side - 2))
    return k1, k2, k3_0, k3 - k3_0


def _table(g, spec, cube, vertices, t, ft):
    """Σ over mix vertices of weight · lerp_t lerp_b bilinear_rg(tile) — a vector Sock.

    Each tile is read by an Equirectangular Environment Texture (:meth:`Graph.environment`)
    in the direction ``(cos φ, sin φ, tan θ)`` of atlas texel coordinates (u, v): both
    engines map it to ``u = 0.5 - φ / 2π``, ``v = 0.5 + θ / π``, so
    ``φ = π - 2π u`` (one cosine and sine per tile column, shared by every row) and
    ``θ = π v - π/2`` (one tangent per tile row). The tiles' padding keeps u and v at
    least 1.5 texels inside the atlas: no seam, no pole.
    """
    g.stage = "table"
    W, H = spec.table_size
    P = float(spec.P)
    r, gg, b0, fb = cube
    pi = math.pi
    n = float(spec.side - 1)                                             # u = n · encoded
    phi0 = g.math("MULTIPLY_ADD", b0, -2.0 * pi * P / W,                   # column b0
                  g.math("MULTIPLY_ADD", r, -2.0 * pi * n / W, pi - 3.0 * pi / W))
    columns = [(phi.cos(), phi.sin()) for phi in (phi0, phi0 - 2.0 * pi * P / W)]
    g_off = g.math("MULTIPLY_ADD", gg, pi * n / H, 1.5 * pi / H - 0.5 * pi)
    t_off = g.math("MULTIPLY_ADD", t, pi * P / H, g_off)                  # row t
    steps = []
    for slot, weight in vertices:
        theta0 = t_off if isinstance(slot, float) and slot == 0.0 else \
            g.math("MULTIPLY_ADD", slot, pi * P * float(spec.T) / H, t_off)   # row slot·T + t
        corners = []
        for theta in (theta0, theta0 + pi * P / H):
            lift = theta.tan()
            for cos_phi, sin_phi in columns:
                corners.append(g.environment(spec.table_image,
                                             g.combine(cos_phi, sin_phi, lift), "Linear"))
        step = g.lerp(g.lerp(corners[0], corners[1], fb), g.lerp(corners[2], corners[3], fb), ft)
        steps.append((step, weight))
    if len(steps) == 1:
        return steps[0][0]
    if len(steps) == 2:                            # weights 1 - f and f: one lerp
        return g.lerp(steps[0][0], steps[1][0], steps[1][1])
    change = None
    for step, weight in steps:
        term = g.vector("SCALE", step, None, None, weight)
        change = term if change is None else g.vector("ADD", change, term)
    return change


def _colour(g, colour, change):
    g.stage = "colour"
    to_XYZ = linear_srgb_to_XYZ(np.eye(3)).T            # rows: X, Y, Z of (r, g, b)
    to_rgb = XYZ_to_linear_srgb(np.eye(3)).T
    e = g.power((math.e, math.e, math.e), change)
    XYZ = g.combine(*(g.vector("DOT_PRODUCT", colour, tuple(map(float, row)))
                      for row in to_XYZ))
    aged = g.vector("MULTIPLY", XYZ, e)
    return [g.vector("DOT_PRODUCT", aged, tuple(map(float, row))) for row in to_rgb]


def _gamut(g, c):
    """:func:`..core.gamut.into_gamut` on the vector ``c``, in vector nodes.

    ``t = clamp(min_k max((1 - Y) / d_k, -Y / d_k), 0, 1)``, ``d = c - Y``: for a channel
    inside [0, 1] both ratios' larger one is at least 1, so only channels outside limit
    ``t``, as in the numpy rule (a tiny offset keeps Blender's safe division, which
    gives 0 for a zero divisor, away from channels that equal ``Y``).
    """
    g.stage = "gamut"
    Y = g.vector("DOT_PRODUCT", c, tuple(float(v) for v in LUMA)).clamp(0.0, 1.0)
    Yv = g.combine(Y, Y, Y)
    d = g.vector("SUBTRACT", c, Yv)
    den = g.vector("ADD", d, (1e-20, 1e-20, 1e-20))
    up = g.vector("DIVIDE", g.vector("SUBTRACT", (1.0, 1.0, 1.0), Yv), den)
    down = g.vector("DIVIDE", g.vector("SUBTRACT", (0.0, 0.0, 0.0), Yv), den)
    tx, ty, tz = g.separate(g.vector("MAXIMUM", up, down))
    t = tx.min(ty).min(tz).clamp(0.0, 1.0)
    out = g.vector("MULTIPLY_ADD", d, g.combine(t, t, t), Yv)
    return g.vector("MINIMUM", g.vector("MAXIMUM", out, (0.0, 0.0, 0.0)), (1.0, 1.0, 1.0))


def build_eval(tree, spec):
    """Fill the empty evaluation group ``tree``: Color and one Rate per spectrum in,
    the aged Color out (every stage from ``years`` on)."""
    tree.interface.new_socket("Color", in_out="INPUT", socket_type="NodeSocketColor")
    for k in range(spec.S):
        tree.interface.new_socket(f"Rate {k}", in_out="INPUT", socket_type="NodeSocketFloat")
    tree.interface.new_socket("Color", in_out="OUTPUT", socket_type="NodeSocketColor")
    g = Graph(tree)
    g.stage = "io"
    gin = g.node("NodeGroupInput", depth=0)
    colour = Sock(g, gin.outputs[0], 0)
    rates = [Sock(g, gin.outputs[1 + k], 0) for k in range(spec.S)]
    g.stage = "years"
    years = g.out(g.node("ShaderNodeAttribute", attribute_type="VIEW_LAYER",
                         attribute_name=YEARS_PROP, depth=0), "Fac")
    g.stage = "rates"
    total = _total(rates)
    t, ft = _dose(g, spec, years, total)
    vertices = _mix(g, spec, rates, total)
    change = _table(g, spec, _unmix(g, spec, colour), vertices, t, ft)
    result = _gamut(g, g.combine(*_colour(g, colour, change)))
    g.stage = "switch"
    if not spec.history:
        result = g.lerp(colour, result, years.gt(0.0))
    g.stage = "io"
    gout = g.node("NodeGroupOutput", (result,))
    gout.is_active_output = True
    g.prune()
    tree[VERSION_KEY] = GROUP_VERSION
    tree[EVAL_KEY] = _eval_key(spec)
    return tree


def _eval_key(spec):
    return f"{spec.table_image.name}|{GROUP_VERSION}"


def eval_group(spec):
    """The evaluation group of ``spec``'s table: found in the file, else built."""
    key = _eval_key(spec)
    for tree in bpy.data.node_groups:
        if tree.name.startswith(EVAL_PREFIX) and tree.get(EVAL_KEY) == key:
            return tree
    name = EVAL_PREFIX + spec.table_image.name
    return build_eval(bpy.data.node_groups.new(name, "ShaderNodeTree"), spec)


def build(tree, spec):
    """Fill the empty group ``tree`` with the aging of ``spec``: the exposure maps'
    annual doses into the table's evaluation group (:func:`eval_group`)."""
    _interface(tree)
    g = Graph(tree)
    g.stage = "io"
    gin = g.node("NodeGroupInput", depth=0)
    colour = Sock(g, gin.outputs[0], 0)
    g.stage = "uv"
    uv = g.out(g.node("ShaderNodeUVMap", uv_map=spec.uv_map, depth=0), "UV")
    if spec.tile:                       # aged per instance: its own tile of the atlas
        uv = tile_uv(g, uv, spec.tile)
    rates = _rates(g, spec, uv)
    g.stage = "eval"
    node = g.node("ShaderNodeGroup", [colour, *rates], node_tree=eval_group(spec))
    g.stage = "io"
    gout = g.node("NodeGroupOutput", (g.out(node),))
    gout.is_active_output = True
    g.prune()
    tree[VERSION_KEY] = GROUP_VERSION
    return tree


def new_group(name, spec):
    """A new group tree ``name`` holding the aging of ``spec``."""
    tree = bpy.data.node_groups.new(name, "ShaderNodeTree")
    return build(tree, spec)
