"""Procedural albedo textures for the demo scenes, in plain numpy.

Every generator returns a float32 array of shape ``(H, W, 3)`` holding sRGB-encoded
values in [0, 1], row 0 at the *bottom* of the image (Blender's pixel order, so that
``v = 0`` is row 0). Generators are deterministic for a given ``seed``.

Printed material is composed in ink coverages (cyan, magenta, yellow in [0, 1]) and turned
into colour by :func:`cmy_to_srgb`, a Beer-Lambert density model of transparent inks on
white paper, so that pictures and charts are made of the colourants LightFade fades.
"""

from __future__ import annotations

import numpy as np

# Optical densities (red, green, blue channel) of a solid layer of each ink, and the
# paper's linear reflectance. Tuned so that solids land near ISO coated print primaries.
INK_DENSITY = {
    "c": np.array([1.30, 0.38, 0.12]),
    "m": np.array([0.10, 1.20, 0.50]),
    "y": np.array([0.02, 0.08, 1.15]),
}
PAPER_WHITE = np.array([0.90, 0.89, 0.84])


def linear_to_srgb(x):
    """sRGB transfer function (IEC 61966-2-1), linear [0, 1] -> encoded [0, 1]."""
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def srgb_to_linear(x):
    """Inverse sRGB transfer function, encoded [0, 1] -> linear [0, 1]."""
    x = np.clip(x, 0.0, 1.0)
    return np.where(x <= 0.04045, x / 12.92, np.power((x + 0.055) / 1.055, 2.4))


def cmy_to_srgb(c, m, y, paper=PAPER_WHITE):
    """Colour of cyan, magenta and yellow ink coverages printed on white paper.

    Parameters
    ----------
    c, m, y : array_like
        Ink coverages in [0, 1], broadcastable to one shape ``(...)``.
    paper : array_like, shape (3,)
        Linear reflectance of the bare paper.

    Returns
    -------
    ndarray, shape (..., 3), float32
        sRGB-encoded colour, ``R = paper * 10 ** -(c D_c + m D_m + y D_y)`` per channel.
    """
    c, m, y = (np.asarray(a, dtype=np.float64)[..., None] for a in (c, m, y))
    D = c * INK_DENSITY["c"] + m * INK_DENSITY["m"] + y * INK_DENSITY["y"]
    return linear_to_srgb(np.asarray(paper) * 10.0 ** (-D)).astype(np.float32)


# --- noise --------------------------------------------------------------------------------


def _upsample(grid, h, w):
    """Bilinear upsampling of a small 2-D grid to (h, w)."""
    gh, gw = grid.shape
    yy = np.linspace(0, gh - 1, h)
    xx = np.linspace(0, gw - 1, w)
    y0 = np.floor(yy).astype(int).clip(0, gh - 2)
    x0 = np.floor(xx).astype(int).clip(0, gw - 2)
    fy = (yy - y0)[:, None]
    fx = (xx - x0)[None, :]
    fy = fy * fy * (3 - 2 * fy)  # smoothstep hides the grid
    fx = fx * fx * (3 - 2 * fx)
    a = grid[y0][:, x0]
    b = grid[y0][:, x0 + 1]
    c = grid[y0 + 1][:, x0]
    d = grid[y0 + 1][:, x0 + 1]
    return (a * (1 - fx) + b * fx) * (1 - fy) + (c * (1 - fx) + d * fx) * fy


def fractal_noise(h, w, rng, cells=(4, 4), octaves=4, gain=0.5):
    """Value noise in about [-1, 1]: ``octaves`` layers, each with twice the cells."""
    out = np.zeros((h, w))
    amp, total = 1.0, 0.0
    ch, cw = cells
    for _ in range(octaves):
        grid = rng.uniform(-1, 1, size=(max(ch, 1) + 2, max(cw, 1) + 2))
        out += amp * _upsample(grid, h, w)
        total += amp
        amp *= gain
        ch, cw = ch * 2, cw * 2
    return out / total


def _uv(h, w):
    """Texel-centre coordinates u (across) and v (up), both in [0, 1]."""
    v = (np.arange(h) + 0.5) / h
    u = (np.arange(w) + 0.5) / w
    return np.meshgrid(u, v)


def _smoothstep(e0, e1, x):
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3 - 2 * t)


# --- wood -------------------------------------------------------------------------------------


def wood_planks(size, extent=(4.0, 4.0), plank_width=0.16, plank_length=1.3, seed=1,
                base=(0.66, 0.47, 0.29), dark=(0.50, 0.33, 0.19)):
    """Oak floor boards, planks running along u.

    Parameters
    ----------
    size : (int, int)
        Image (height, width) in texels.
    extent : (float, float)
        Physical size (along u, along v) in metres that the image covers.
    plank_width, plank_length : float
        Board dimensions in metres; end joints are staggered per row.
    base, dark : (float, float, float)
        sRGB tones of the lightest and darkest boards (default: honey oak).
    """
    h, w = size
    rng = np.random.default_rng(seed)
    U, V = _uv(h, w)
    x = U * extent[0]
    y = V * extent[1]
    row = np.floor(y / plank_width).astype(int)
    n_rows = row.max() + 1
    offsets = rng.uniform(0, plank_length, n_rows)
    xs = x + offsets[row]
    col = np.floor(xs / plank_length).astype(int)
    plank_id = row * 1000 + col
    # per-plank tone: hash the id to a stable random number
    tone = np.sin(plank_id * 12.9898 + seed * 78.233) * 43758.5453
    tone = tone - np.floor(tone)  # [0, 1)
    base = np.asarray(base, dtype=float)  # sRGB
    dark = np.asarray(dark, dtype=float)
    col_rgb = base + (dark - base) * (0.25 + 0.6 * tone)[..., None]
    # grain: long streaks along u, wobbling with low-frequency noise
    wob = fractal_noise(h, w, rng, cells=(int(extent[1] * 3), int(extent[0] * 1)), octaves=3)
    fine = fractal_noise(h, w, rng, cells=(int(extent[1] * 40), int(extent[0] * 2)), octaves=2)
    yy = (y - row * plank_width) / plank_width
    grain = np.sin((yy * 9 + tone * 7 + wob * 1.8) * 2 * np.pi)
    streak = 0.5 + 0.5 * grain
    col_rgb *= (0.93 + 0.07 * streak + 0.05 * fine)[..., None]
    # dark joints between boards
    ey = np.minimum(yy, 1 - yy) * plank_width
    ex = np.abs(((xs / plank_length) + 0.5) % 1.0 - 0.5) * plank_length
    joint = 1 - 0.55 * (1 - _smoothstep(0.0, 0.0025, np.minimum(ey, ex)))
    col_rgb *= joint[..., None]
    return np.clip(col_rgb, 0, 1).astype(np.float32)


def painted_wood(size, colour, seed=2):
    """Painted, slightly worn wood: a flat paint colour with faint brush/grain streaks along u."""
    h, w = size
    rng = np.random.default_rng(seed)
    streak = fractal_noise(h, w, rng, cells=(48, 3), octaves=3)
    blotch = fractal_noise(h, w, rng, cells=(6, 6), octaves=3)
    lin = srgb_to_linear(np.asarray(colour, dtype=np.float64))
    f = 1 + 0.06 * streak + 0.05 * blotch
    return linear_to_srgb(lin * f[..., None]).astype(np.float32)


# --- fabric -----------------------------------------------------------------------------------


def _weave(h, w, threads_u, threads_v):
    """Plain-weave modulation in about [0.85, 1.05]: threads_u threads across u."""
    U, V = _uv(h, w)
    a = np.sin(U * threads_u * np.pi) ** 2
    b = np.sin(V * threads_v * np.pi) ** 2
    over = ((np.floor(U * threads_u) + np.floor(V * threads_v)) % 2).astype(float)
    return 0.86 + 0.16 * (over * a + (1 - over) * b)


def rug(size, seed=3):
    """Patterned wool rug (Persian-like): red field, blue/green medallion, ivory/gold borders.

    The long side runs along u. Saturated reds, blues and greens so that fading shows.
    """
    h, w = size
    rng = np.random.default_rng(seed)
    U, V = _uv(h, w)
    aspect = w / h
    # coordinates centred, in units of the short side
    x = (U - 0.5) * aspect
    y = V - 0.5
    red = np.array([0.62, 0.09, 0.10])
    navy = np.array([0.10, 0.16, 0.42])
    green = np.array([0.12, 0.42, 0.28])
    ivory = np.array([0.90, 0.84, 0.68])
    gold = np.array([0.86, 0.62, 0.16])
    sky = np.array([0.30, 0.55, 0.78])
    out = np.empty((h, w, 3))
    out[:] = red
    # distance to the edge, in short-side units
    d_edge = np.minimum(0.5 * aspect - np.abs(x), 0.5 - np.abs(y))

    def band(lo, hi):
        return (d_edge >= lo) & (d_edge < hi)

    out[band(0.0, 0.03)] = navy
    out[band(0.03, 0.045)] = ivory
    # main border: navy with gold/green repeating diamonds
    b = band(0.045, 0.13)
    out[b] = navy
    t = np.where(np.abs(y) > 0.5 - 0.13, x, y)  # coordinate along the border
    r = (d_edge - 0.0875) / 0.04
    ph = (t / 0.09) % 1.0 - 0.5
    diamond = (np.abs(ph) * 2.2 + np.abs(r)) < 0.9
    out[b & diamond] = gold
    out[b & diamond & ((np.abs(ph) * 2.2 + np.abs(r)) < 0.45)] = green
    out[band(0.13, 0.145)] = ivory
    out[band(0.145, 0.16)] = green
    # field: red with a lattice of small sky/ivory motifs
    field = d_edge >= 0.16
    gx = (x / 0.12) % 1.0 - 0.5
    gy = (y / 0.12) % 1.0 - 0.5
    motif = (np.abs(gx) + np.abs(gy)) < 0.18
    out[field & motif] = ivory
    out[field & motif & ((np.abs(gx) + np.abs(gy)) < 0.09)] = sky
    # central medallion: concentric lozenges navy / green / ivory / red
    lz = np.abs(x) / 1.0 + np.abs(y) / 0.62
    out[field & (lz < 0.55)] = navy
    out[field & (lz < 0.46)] = green
    out[field & (lz < 0.40)] = ivory
    out[field & (lz < 0.34)] = red
    out[field & (lz < 0.20)] = gold
    out[field & (lz < 0.12)] = navy
    # corner spandrels in green
    cs = (np.abs(x) - (0.5 * aspect - 0.16)) ** 2 + (np.abs(y) - 0.34) ** 2 < 0.12**2
    out[field & cs] = green
    lin = srgb_to_linear(out)
    wool = _weave(h, w, threads_u=w / 3, threads_v=h / 3)
    mottle = 1 + 0.08 * fractal_noise(h, w, rng, cells=(8, int(8 * aspect)), octaves=4)
    lin = lin * (wool * mottle)[..., None]
    return linear_to_srgb(lin).astype(np.float32)


def fabric(size, colour, threads=(180, 180), seed=4):
    """Plain-weave dyed cloth of one colour (sRGB), with stripes of slightly darker weft."""
    h, w = size
    rng = np.random.default_rng(seed)
    lin = srgb_to_linear(np.asarray(colour, dtype=np.float64))
    weave = _weave(h, w, threads[0], threads[1])
    slub = 1 + 0.06 * fractal_noise(h, w, rng, cells=(60, 4), octaves=2)
    U, _ = _uv(h, w)
    stripe = 1 - 0.12 * (np.sin(U * 2 * np.pi * 9) > 0.85)
    return linear_to_srgb(lin * (weave * slub * stripe)[..., None]).astype(np.float32)


# --- printed pictures ---------------------------------------------------------------------


def poster(size, seed=5):
    """A colourful printed picture: cyan sky, yellow sun, magenta hills, overlapping CMY discs.

    Composed in ink coverages, so it has strong magenta, cyan and yellow areas and their
    overprints (red, green, blue), and a white paper margin.
    """
    h, w = size
    rng = np.random.default_rng(seed)
    U, V = _uv(h, w)
    x = U * (w / h)  # units of picture height
    y = V
    c = np.zeros((h, w))
    m = np.zeros((h, w))
    yl = np.zeros((h, w))
    # sky: cyan gradient, deeper at the top
    c += 0.25 + 0.65 * _smoothstep(0.35, 1.0, y)
    # sun: solid yellow disc with an orange rim
    cx, cy = 0.52 * (w / h) / 0.7, 0.80
    r = np.hypot(x - cx, y - cy)
    rim = (r >= 0.095) & (r < 0.115)
    sun = r < 0.095
    c = np.where(sun | rim, 0.0, c)
    yl = np.where(sun | rim, 1.0, yl)
    m = np.where(rim, 0.55, m)
    # hills: three magenta / red / violet layers
    n1 = fractal_noise(1, w, rng, cells=(1, 3), octaves=3)[0]
    n2 = fractal_noise(1, w, rng, cells=(1, 4), octaves=3)[0]
    n3 = fractal_noise(1, w, rng, cells=(1, 5), octaves=3)[0]
    hill1 = y < 0.50 + 0.10 * n1[None, :] + 0.05 * np.sin(x * 5)
    hill2 = y < 0.36 + 0.08 * n2[None, :]
    hill3 = y < 0.20 + 0.06 * n3[None, :]
    c = np.where(hill1, 0.35, c)
    m = np.where(hill1, 0.95, m)
    yl = np.where(hill1, 0.05, yl)
    c = np.where(hill2, 0.0, c)
    m = np.where(hill2, 1.0, m)
    yl = np.where(hill2, 0.9, yl)  # red
    c = np.where(hill3, 0.85, c)
    m = np.where(hill3, 0.0, m)
    yl = np.where(hill3, 1.0, yl)  # green
    # three overprinted discs of pure ink: overlaps give red, green, blue and near-black
    discs = {"c": (0.20, 0.60), "m": (0.32, 0.60), "y": (0.26, 0.50)}
    masks = {k: np.hypot(x - dx * (w / h) / 0.7, y - dy) < 0.085 for k, (dx, dy) in discs.items()}
    union = masks["c"] | masks["m"] | masks["y"]
    c = np.where(union, masks["c"] * 1.0, c)
    m = np.where(union, masks["m"] * 1.0, m)
    yl = np.where(union, masks["y"] * 1.0, yl)
    # halftone-free grain of ink density
    grain = 1 + 0.03 * fractal_noise(h, w, rng, cells=(40, 40), octaves=2)
    c, m, yl = (np.clip(a * grain, 0, 1) for a in (c, m, yl))
    # white paper margin
    mx = 0.06 * h / w
    margin = (U < mx) | (U > 1 - mx) | (V < 0.06) | (V > 0.96)
    c, m, yl = (np.where(margin, 0.0, a) for a in (c, m, yl))
    return cmy_to_srgb(c, m, yl)


CHART_SERIES = ("C", "M", "Y", "CM", "MY", "CY", "CMY")
CHART_LEVELS = tuple(np.linspace(0.0, 1.0, 11))


def colour_chart(size, copies=2):
    """A print-test chart: rows C, M, Y, CM, MY, CY, CMY (top to bottom), columns 0-100 %.

    The chart is printed ``copies`` times side by side (left to right), so that a card over
    one copy keeps a twin of every patch unexposed.

    Returns
    -------
    ndarray, shape (H, W, 3), float32
        The chart on white paper.
    """
    h, w = size
    U, V = _uv(h, w)
    c = np.zeros((h, w))
    m = np.zeros((h, w))
    y = np.zeros((h, w))
    n_rows, n_cols = len(CHART_SERIES), len(CHART_LEVELS)
    margin, gap_copy = 0.04, 0.06  # fractions of the width
    copy_w = (1 - 2 * margin - (copies - 1) * gap_copy) / copies
    top, bottom = 0.92, 0.08  # fractions of the height
    row_h = (top - bottom) / n_rows
    for k in range(copies):
        x0 = margin + k * (copy_w + gap_copy)
        col_w = copy_w / n_cols
        cu = (U - x0) / col_w
        ci = np.floor(cu).astype(int)
        inside_u = (ci >= 0) & (ci < n_cols) & ((cu - ci) > 0.06) & ((cu - ci) < 0.94)
        rv = (top - V) / row_h
        ri = np.floor(rv).astype(int)
        inside_v = (ri >= 0) & (ri < n_rows) & ((rv - ri) > 0.08) & ((rv - ri) < 0.92)
        inside = inside_u & inside_v
        level = np.asarray(CHART_LEVELS)[ci.clip(0, n_cols - 1)]
        for r, series in enumerate(CHART_SERIES):
            sel = inside & (ri == r)
            if "C" in series:
                c[sel] = level[sel]
            if "M" in series:
                m[sel] = level[sel]
            if "Y" in series:
                y[sel] = level[sel]
    img = cmy_to_srgb(c, m, y)
    # thin black registration marks in the four corners of each copy
    for k in range(copies):
        x0 = margin + k * (copy_w + gap_copy)
        for uu in (x0, x0 + copy_w):
            for vv in (bottom, top):
                mark = (np.abs(U - uu) < 0.0015) & (np.abs(V - vv) < 0.02) | (
                    np.abs(V - vv) < 0.0015 * w / h
                ) & (np.abs(U - uu) < 0.02 * h / w)
                img[mark] = 0.05
    return img
