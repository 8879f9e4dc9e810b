"""How each bundled recipe fades: the issue-25 criteria, measured on palettes.

    python -m benchmarks.recipes [--exact] [--recipe NAME ...]

Every palette is aged with the core on the path ``age-image`` uses
(:class:`lightfade_addon.core.aging.ager.TextureAger`: the grid, the unmixer, the aging
table), or with ``--exact`` on the reference path (one direct simulation per colour),
under daylight through window glass (``daylight-glass``, CIE ID65) at 2,000 lux for
8 h a day, 365 days a year (5.84 Mlx·h a year). Printed per recipe:

* Dyed Fabric, Painted Wood (neutrals): the largest chroma gain, ΔC*ab, before the
  colour has faded CIEDE2000 5 and 12 (limits 4 and 6); chromatic colours: the largest
  hue turn, |Δh|, by then (limits 20° and 30°); ΔL* at the end (must be > 0), and the
  dose to ΔE00 5 (Painted Wood / Dyed Fabric: at least 3×).
* Printed Paper: Δb* of greys when they have faded ΔE00 5 (must be < 0).
* Bare Wood at 22 Mlx·h: ΔL*, Δa*, Δb*, ΔE*ab per wood (pale: ΔL* −13…−2, Δa* +1…+8,
  Δb* +5…+14, ΔE*ab 7–22; dark, L* < 60: ΔL* >= 0).
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from lightfade_addon.core.aging.ager import Light, TextureAger, age_image_exact
from lightfade_addon.core.colour.colorimetry import (
    XYZ_to_Lab,
    delta_E_2000,
    delta_E_ab,
    linear_srgb_to_XYZ,
    srgb_decode,
)
from lightfade_addon.core.fading.recipes import RECIPES

#: Daylight through window glass, 2,000 lux, 8 h a day (the issue's light).
LIGHT = Light("daylight-glass", False, 2000.0, 8.0, 365.0)

#: Upholstery and paint neutrals, encoded sRGB 0..255.
NEUTRALS = {
    "black": (28, 28, 30), "charcoal": (58, 58, 60), "dark grey": (90, 90, 90),
    "mid grey": (128, 128, 128), "light grey": (196, 196, 196), "greige": (186, 178, 165),
    "beige grey": (165, 158, 146), "taupe": (125, 112, 102), "warm grey": (140, 134, 126),
    "cool grey": (120, 126, 132), "oatmeal": (215, 205, 185), "grey brown": (95, 85, 75),
}

#: Chromatic upholstery and paint colours, encoded sRGB 0..255.
CHROMATIC = {
    "red": (180, 30, 35), "crimson": (150, 20, 50), "burgundy": (110, 30, 45),
    "rust": (170, 80, 40), "orange": (220, 120, 40), "mustard": (205, 165, 50),
    "olive": (110, 110, 50), "sage": (140, 160, 120), "green": (50, 120, 60),
    "teal": (30, 120, 120), "sky blue": (120, 170, 220), "navy": (30, 40, 90),
    "royal blue": (40, 70, 160), "purple": (100, 60, 130), "pink": (230, 160, 170),
    "brown": (110, 72, 48), "tan": (190, 150, 110), "plum": (90, 40, 70),
}

#: Woods, encoded sRGB 0..255 (CIELAB near published values: maple about L* 80,
#: birch 81/7/20, beech 72/9/18, pine 78/6/27, oak 68/7/22; walnut about 43,
#: steamed beech 60/14/18, cherry 55/17/25, mahogany 42/18/20).
WOODS = {
    "maple": (222, 196, 160), "birch": (228, 195, 157), "beech": (205, 170, 140),
    "pine": (225, 190, 140), "oak": (196, 161, 124), "walnut": (118, 94, 78),
    "steamed beech": (170, 131, 108), "cherry": (160, 115, 83), "mahogany": (128, 86, 68),
}

def sweep(n=240, seed=25):
    """Random sRGB colours (0..255), split by CIELAB chroma: (neutrals C* < 10, chromatic
    C* >= 15); colours the named palettes do not cover."""
    rgb = np.random.default_rng(seed).integers(0, 256, (n, 3))
    # half of them near the grey axis, where on-tone fading is hardest
    grey = rgb[: n // 2].mean(axis=1, keepdims=True)
    rgb[: n // 2] = np.clip(grey + (rgb[: n // 2] - grey) * 0.12, 0, 255).round()
    C = chroma(lab_of(rgb))
    neutral = {f"n{i}": tuple(int(v) for v in c) for i, c in enumerate(rgb[C < 10])}
    chromatic = {f"c{i}": tuple(int(v) for v in c) for i, c in enumerate(rgb[C >= 15])}
    return neutral, chromatic


YEARS = np.concatenate([[0.0], np.geomspace(0.02, 2000.0, 160)])


def lab_of(rgb255):
    rgb = np.asarray(rgb255, float) / 255.0
    return XYZ_to_Lab(linear_srgb_to_XYZ(srgb_decode(rgb)))


def age_palette(colours, recipe, years=YEARS, exact=False, light=LIGHT):
    """CIELAB (T, N, 3) of ``colours`` (name -> sRGB 0..255) at each of ``years``."""
    rgb = (np.array(list(colours.values()), float) / 255.0).reshape(1, -1, 3)
    if exact:
        aged = age_image_exact(rgb, years, recipe, light)
    else:
        ager = TextureAger(rgb, recipe, [light], max_years=float(max(years)),
                           encoding="srgb")
        aged = [ager.age(y) for y in years]
    return np.stack([lab_of(255.0 * a.reshape(-1, 3)) for a in aged])


def hue_turn(lab0, lab):
    """|Δh| in degrees between two CIELAB colours (..., 3)."""
    h0 = np.arctan2(lab0[..., 2], lab0[..., 1])
    h = np.arctan2(lab[..., 2], lab[..., 1])
    return np.degrees(np.abs((h - h0 + np.pi) % (2 * np.pi) - np.pi))


def chroma(lab):
    return np.hypot(lab[..., 1], lab[..., 2])


def until(dE, limit):
    """Index of the last step whose ΔE00 is still below ``limit`` + 1 (the first at or above
    it), or None when the colour never fades that far."""
    over = np.nonzero(dE >= limit)[0]
    return None if over.size == 0 else int(over[0])


def fade_metrics(labs, years=YEARS):
    """Per colour: chroma gain and hue turn up to ΔE00 5 and 12, years to 5, final ΔL*."""
    lab0 = labs[0]
    dE = delta_E_2000(np.broadcast_to(lab0, labs.shape), labs)            # (T, N)
    dC = chroma(labs) - chroma(lab0)
    dh = hue_turn(np.broadcast_to(lab0, labs.shape), labs)
    rows = []
    for n in range(labs.shape[1]):
        row = {}
        for limit in (5, 12):
            i = until(dE[:, n], limit)
            end = labs.shape[0] if i is None else i + 1
            row[f"dC{limit}"] = float(dC[:end, n].max())
            row[f"dh{limit}"] = float(dh[:end, n].max())
            row[f"reached{limit}"] = i is not None
        i5 = until(dE[:, n], 5)
        row["years5"] = np.nan if i5 is None else _crossing(years, dE[:, n], 5.0, i5)
        row["dL"] = float(labs[-1, n, 0] - lab0[n, 0])
        row["dL_min"] = float((labs[1:, n, 0] - lab0[n, 0]).min())
        row["dE_end"] = float(dE[-1, n])
        rows.append(row)
    return rows


def _crossing(years, dE, level, i):
    """Years at which ΔE00 crosses ``level`` (linear between steps i-1 and i)."""
    if i == 0:
        return float(years[0])
    y0, y1, e0, e1 = years[i - 1], years[i], dE[i - 1], dE[i]
    return float(y0 + (y1 - y0) * (level - e0) / max(e1 - e0, 1e-12))


def _print_fabric_table(name, colours, rows, neutral):
    print(f"\n{name}: {'neutrals' if neutral else 'chromatic colours'}")
    what = "dC*ab" if neutral else "|dh| deg"
    print(f"  {'colour':<12} {'L*':>5} {'C*':>5}  {what + ' @dE00 5':>15} {what + ' @12':>13}"
          f"  {'years to 5':>10} {'dL* end':>8} {'min dL*':>8} {'dE00 end':>8}")
    for (cname, rgb), r in zip(colours.items(), rows):
        lab = lab_of(rgb)
        k = "dC" if neutral else "dh"
        a = f"{r[k + '5']:6.1f}" + ("" if r["reached5"] else " (n/r)")
        b = f"{r[k + '12']:6.1f}" + ("" if r["reached12"] else " (n/r)")
        print(f"  {cname:<12} {lab[0]:5.1f} {chroma(lab):5.1f}  {a:>15} {b:>13}"
              f"  {r['years5']:10.2f} {r['dL']:8.1f} {r['dL_min']:8.2f} {r['dE_end']:8.1f}")
    k = "dC" if neutral else "dh"
    lim = (4, 6) if neutral else (20, 30)
    w5 = max(r[k + "5"] for r in rows)
    w12 = max(r[k + "12"] for r in rows)
    print(f"  worst: {w5:.1f} (limit {lim[0]}), {w12:.1f} (limit {lim[1]}); "
          f"lowest dL* on the way {min(r['dL_min'] for r in rows):.3f} (limit > 0)")


def _worst(rows, colours, key):
    k = max(range(len(rows)), key=lambda i: rows[i][key])
    return rows[k][key], list(colours.items())[k]


def fabric_and_paint_sweep(exact):
    neutral, chromatic = sweep()
    print(f"\nsweep: {len(neutral)} random neutrals (C*ab < 10), {len(chromatic)} random "
          f"chromatic colours (C*ab >= 15); worst of each, with the colour (sRGB)")
    for name in ("dyed-fabric", "painted-wood"):
        rn = fade_metrics(age_palette(neutral, RECIPES[name], exact=exact))
        rc = fade_metrics(age_palette(chromatic, RECIPES[name], exact=exact))
        (a, ca), (b, cb) = _worst(rn, neutral, "dC5"), _worst(rn, neutral, "dC12")
        (c, cc), (d, cd) = _worst(rc, chromatic, "dh5"), _worst(rc, chromatic, "dh12")
        low = min(r["dL_min"] for r in rn + rc)
        print(f"  {name}: neutrals dC*ab {a:.1f} @5 {ca[1]} (limit 4), {b:.1f} @12 {cb[1]} "
              f"(limit 6); chromatic |dh| {c:.1f} @5 {cc[1]} (limit 20), {d:.1f} @12 {cd[1]} "
              f"(limit 30); lowest dL* {low:.3f}")


def fabric_and_paint(exact):
    years5 = {}
    for name in ("dyed-fabric", "painted-wood"):
        for neutral, colours in ((True, NEUTRALS), (False, CHROMATIC)):
            t0 = time.perf_counter()
            rows = fade_metrics(age_palette(colours, RECIPES[name], exact=exact))
            _print_fabric_table(name, colours, rows, neutral)
            print(f"  ({time.perf_counter() - t0:.1f} s)")
            years5.setdefault(name, []).extend(r["years5"] for r in rows)
    ratio = np.array(years5["painted-wood"]) / np.array(years5["dyed-fabric"])
    names = list(NEUTRALS) + list(CHROMATIC)
    print(f"\npainted-wood / dyed-fabric dose to dE00 5: min {np.nanmin(ratio):.2f} "
          f"({names[int(np.nanargmin(ratio))]}), median {np.nanmedian(ratio):.2f}, "
          f"max {np.nanmax(ratio):.2f} (limit >= 3)")


def printed_paper(exact):
    greys = {k: v for k, v in NEUTRALS.items()
             if k in ("black", "charcoal", "dark grey", "mid grey", "light grey", "cool grey",
                      "warm grey")}
    labs = age_palette(greys, RECIPES["printed-paper"], exact=exact)
    dE = delta_E_2000(np.broadcast_to(labs[0], labs.shape), labs)
    print("\nprinted-paper greys: db* and da* when faded dE00 5 and at the end")
    print(f"  {'grey':<12} {'b* 0':>6} {'db* @5':>7} {'da* @5':>7} {'db* end':>8} {'dL* end':>8}")
    for n, g in enumerate(greys):
        i = until(dE[:, n], 5) or -1
        d = labs[:, n] - labs[0, n]
        print(f"  {g:<12} {labs[0, n, 2]:6.1f} {d[i, 2]:7.1f} {d[i, 1]:7.1f} {d[-1, 2]:8.1f}"
              f" {d[-1, 0]:8.1f}")


def bare_wood(exact, dose=22e6):
    years = dose / LIGHT.annual_dose
    steps = np.concatenate([[0.0], years * np.geomspace(1 / 64, 1, 25)])
    labs = age_palette(WOODS, RECIPES["bare-wood"], years=steps, exact=exact)
    eighth = int(np.argmin(np.abs(steps - years / 8)))
    print(f"\nbare-wood at {dose / 1e6:g} Mlx·h of daylight through glass "
          f"(pale: dL* -13..-2, da* +1..+8, db* +5..+14, dE*ab 7..22; dark: dL* >= 0)")
    print(f"  {'wood':<14} {'L*':>5} {'a*':>5} {'b*':>5}  {'dL*':>6} {'da*':>6} {'db*':>6}"
          f" {'dE*ab':>6} {'dE at 1/8':>9} {'min dL* on the way':>18}")
    for n, w in enumerate(WOODS):
        d = labs[-1, n] - labs[0, n]
        e = delta_E_ab(labs[0, n], labs[-1, n])
        e8 = delta_E_ab(labs[0, n], labs[eighth, n])
        low = (labs[1:, n, 0] - labs[0, n, 0]).min()
        print(f"  {w:<14} {labs[0, n, 0]:5.1f} {labs[0, n, 1]:5.1f} {labs[0, n, 2]:5.1f}  "
              f"{d[0]:6.1f} {d[1]:6.1f} {d[2]:6.1f} {e:6.1f} {e8:9.1f} {low:18.2f}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--exact", action="store_true", help="the reference path, not the grid")
    p.add_argument("--part", nargs="*", default=["fabric", "paper", "wood"],
                   choices=["fabric", "paper", "wood"])
    args = p.parse_args(argv)
    print(f"light: {LIGHT.spectrum}, {LIGHT.lux:g} lux x {LIGHT.hours_per_day:g} h/day = "
          f"{LIGHT.annual_dose / 1e6:.2f} Mlx·h a year; path: "
          f"{'exact (direct simulation)' if args.exact else 'grid (age-image)'}")
    if "fabric" in args.part:
        fabric_and_paint(args.exact)
        fabric_and_paint_sweep(args.exact)
    if "paper" in args.part:
        printed_paper(args.exact)
    if "wood" in args.part:
        bare_wood(args.exact)


if __name__ == "__main__":
    main()
