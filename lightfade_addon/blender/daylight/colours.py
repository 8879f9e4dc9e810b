"""False colour for doses and years: a log scale, a perceptual ramp, and the legend.

No Blender here: arrays in, arrays (and PNG files) out.  The ramp is viridis (matplotlib's
default, perceptually uniform and readable with colour-vision deficiencies), sampled at
nine points and interpolated linearly in sRGB.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: viridis at 0, 1/8, ..., 1 (sRGB, from matplotlib's _cm_listed table).
VIRIDIS = np.array([
    [0.267004, 0.004874, 0.329415], [0.282623, 0.140926, 0.457517],
    [0.253935, 0.265254, 0.529983], [0.206756, 0.371758, 0.553117],
    [0.163625, 0.471133, 0.558148], [0.127568, 0.566949, 0.550556],
    [0.134692, 0.658636, 0.517649], [0.266941, 0.748751, 0.440573],
    [0.477504, 0.821444, 0.318195], [0.741388, 0.873449, 0.149561],
    [0.993248, 0.906157, 0.143936],
])
#: Colour of texels outside the scale's reach (no dose, or no visible fade in view).
OUTSIDE = np.array([0.55, 0.55, 0.55])


@dataclass(frozen=True)
class LogScale:
    """Values from ``low`` to ``high`` (both > 0) on a log axis; ``reverse`` puts ``low``
    at the bright end (years: the soonest fade is the brightest)."""

    low: float
    high: float
    unit: str
    title: str
    reverse: bool = False

    def position(self, values):
        """0–1 along the ramp (NaN outside the data: zero, inf or NaN values)."""
        v = np.asarray(values, dtype=np.float64)
        ok = np.isfinite(v) & (v > 0)
        t = np.full(v.shape, np.nan)
        t[ok] = (np.log10(np.clip(v[ok], self.low, self.high)) - math.log10(self.low)) / \
            max(math.log10(self.high) - math.log10(self.low), 1e-9)
        return 1.0 - t if self.reverse else t

    def ticks(self):
        """Powers of ten within the scale (with its ends when fewer than three)."""
        lo, hi = math.ceil(math.log10(self.low) - 1e-9), math.floor(math.log10(self.high) + 1e-9)
        values = [10.0 ** k for k in range(lo, hi + 1)]
        if len(values) < 3:
            values = sorted(set(values) | {self.low, self.high})
        return values


def ramp(t):
    """sRGB colours (..., 3) of positions ``t`` in [0, 1]; NaN -> :data:`OUTSIDE`."""
    t = np.asarray(t, dtype=np.float64)
    x = np.clip(np.nan_to_num(t, nan=0.0), 0.0, 1.0) * (len(VIRIDIS) - 1)
    i = np.minimum(x.astype(int), len(VIRIDIS) - 2)
    f = (x - i)[..., None]
    rgb = VIRIDIS[i] * (1 - f) + VIRIDIS[i + 1] * f
    rgb[np.isnan(t)] = OUTSIDE
    return rgb


def dose_scale(doses, span=100.0):
    """Scale of annual doses (lux·h/yr): the largest down to ``1/span`` of it (darker
    texels take the dark end; unlit ones are grey)."""
    v = np.asarray(doses, dtype=np.float64)
    v = v[np.isfinite(v) & (v > 0)]
    high = float(v.max()) if v.size else 1.0
    return LogScale(high / span, high, "lx·h/yr", "Annual dose")


def years_scale(years, horizon):
    """Scale of years until a noticeable fade, from the soonest texels (1st percentile)
    to the slowest that fade within ``horizon`` (99th percentile); the soonest is the
    brightest, texels that do not fade within the horizon are grey."""
    v = np.asarray(years, dtype=np.float64)
    v = v[np.isfinite(v) & (v > 0)]
    if v.size:
        low, high = np.percentile(v, [1.0, 99.0])
    else:
        low, high = 1.0, horizon
    low = max(float(low), horizon * 1e-5)
    high = min(max(float(high), low * 10.0), float(horizon))
    return LogScale(min(low, high / 10.0), high, "years",
                    "Years until a just-noticeable fade (ΔE00 = 1)", reverse=True)


def false_colour(values, scale):
    """(..., 4) sRGB-encoded RGBA of ``values`` on ``scale``."""
    rgb = ramp(scale.position(values))
    return np.concatenate([rgb, np.ones((*rgb.shape[:-1], 1))], axis=-1).astype(np.float32)


def format_value(v):
    """``1e+06`` style labels read badly on a bar: 1, 10, 100, 1k, 10k, 1M, ..."""
    for div, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if v >= div:
            return f"{v / div:g}{suffix}"
    return f"{v:g}"


def write_legend(path, scale, note=""):
    """A PNG colour bar of ``scale`` with its ticks, title and unit (matplotlib).

    Raises :class:`ImportError` with a one-line reason where matplotlib is missing
    (Blender does not bundle it).
    """
    try:
        import matplotlib

        matplotlib.use("Agg")
        from matplotlib import pyplot as plt
        from matplotlib.colors import LinearSegmentedColormap, LogNorm
    except ImportError:
        raise ImportError("the legend image needs matplotlib, which this Python lacks "
                          "(pip install matplotlib into Blender's Python)") from None
    cmap = LinearSegmentedColormap.from_list("lightfade", VIRIDIS)
    if scale.reverse:
        cmap = cmap.reversed()
    fig, ax = plt.subplots(figsize=(6.0, 1.1), dpi=150)
    fig.subplots_adjust(left=0.05, right=0.95, bottom=0.45, top=0.7)
    bar = plt.cm.ScalarMappable(norm=LogNorm(scale.low, scale.high), cmap=cmap)
    cb = fig.colorbar(bar, cax=ax, orientation="horizontal")
    ticks = scale.ticks()
    cb.set_ticks(ticks)
    cb.set_ticklabels([format_value(t) for t in ticks])
    cb.minorticks_off()
    ax.set_title(f"{scale.title} ({scale.unit})", fontsize=9)
    if note:
        fig.text(0.5, 0.04, note, ha="center", fontsize=7, color="0.3")
    fig.savefig(path)
    plt.close(fig)
    return path
