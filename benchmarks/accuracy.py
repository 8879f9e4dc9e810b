"""The paper's Section 4 study, redone: layers × time steps against a reference.

    ./run py -m benchmarks.accuracy             # writes docs/accuracy.md and docs/img/accuracy_*.png
    ./run py -m benchmarks.accuracy --no-write  # print only

Ten seeded random CMY mixtures (:mod:`benchmarks.problem`) are faded with 2…128
layers × 5/25/125 steps, for both schemes, and compared with a 1024-layer ×
625-step reference of the paper's scheme (Tables 1–3, with the paper's kinetics,
``kinetics="paper"``): max RMS ΔR, max ΔE*ab (the paper's metric), max CIEDE2000,
and the time per sample on one core. A denser sweep with the product's
first-order kinetics then traces each scheme's cost–accuracy frontier and picks
the production default: the cheapest setting whose max ΔE00 to the (first-order)
reference is <= 0.3, checked again on 100 held-out mixtures.
"""

from __future__ import annotations

import argparse
import pathlib
import statistics
import time

import numpy as np

from benchmarks.problem import cmy_problem, random_mixtures
from lightfade_addon.core import simulate
from lightfade_addon.core.colour.colorimetry import (
    delta_E_2000,
    delta_E_ab,
    reflectance_to_Lab,
    rms_delta_R,
)

ROOT = pathlib.Path(__file__).resolve().parents[1]
LAYERS = (2, 4, 8, 16, 32, 64, 128)
STEPS = (5, 25, 125)
REFERENCE = dict(layers=1024, steps=625, scheme="paper")
TARGET_DE00 = 0.3

# Paper, Tables 1-3 (max RMS dR, max dE*ab, seconds per sample), for comparison.
PAPER_RMS = {2: (0.0626, 0.0352, 0.0302), 4: (0.0371, 0.0129, 0.0085),
             8: (0.0311, 0.0071, 0.0027), 16: (0.0297, 0.0058, 0.0013),
             32: (0.0293, 0.0055, 0.0010), 64: (0.0292, 0.0054, 0.0009),
             128: (0.0292, 0.0054, 0.0009)}
PAPER_DE = {2: (6.2203, 3.8875, 3.4764), 4: (3.3564, 1.2955, 0.9543),
            8: (2.7686, 0.6476, 0.2844), 16: (2.6603, 0.5102, 0.1225),
            32: (2.6333, 0.4882, 0.0872), 64: (2.6265, 0.4827, 0.0811),
            128: (2.6248, 0.4813, 0.0798)}
PAPER_TIME = {2: (0.6, 2.9, 14.0), 4: (0.7, 3.2, 15.4), 8: (0.8, 3.6, 17.6),
              16: (1.0, 4.4, 21.5), 32: (1.5, 6.3, 30.7), 64: (3.5, 15.8, 76.6),
              128: (8.6, 36.8, 179.0)}


def solves(layers, steps, scheme):
    """Work of a setting in layer solves: layers × flux solves (a cost that is not noisy)."""
    return layers * ((2 * steps if scheme == "heun" else steps) + 1)


class Study:
    """Runs settings on a fixed set of mixtures and scores them against the reference."""

    def __init__(self, mixtures, problem, repeat=3, kinetics="first-order"):
        self.c = mixtures
        self.problem = dict(problem, kinetics=kinetics)
        problem = self.problem
        self.repeat = repeat
        self.lam = problem["wavelengths"]
        t0 = time.perf_counter()
        self.ref = self.run(**REFERENCE)
        self.ref_seconds = time.perf_counter() - t0
        self.ref_Lab = reflectance_to_Lab(self.ref, self.lam)
        self.initial_Lab = reflectance_to_Lab(
            simulate(concentrations=self.c, **dict(problem, duration=0.0), layers=1,
                     steps=1).initial, self.lam)

    def run(self, **setting):
        return simulate(concentrations=self.c, workers=1, **self.problem, **setting).reflectance

    def score(self, layers, steps, scheme, timed=True):
        times = []
        for _ in range(self.repeat if timed else 1):
            t0 = time.perf_counter()
            R = self.run(layers=layers, steps=steps, scheme=scheme)
            times.append(time.perf_counter() - t0)
        Lab = reflectance_to_Lab(R, self.lam)
        return dict(
            layers=layers, steps=steps, scheme=scheme,
            rms=float(rms_delta_R(R, self.ref).max()),
            dE=float(delta_E_ab(Lab, self.ref_Lab).max()),
            dE00=float(delta_E_2000(Lab, self.ref_Lab).max()),
            seconds=statistics.median(times) / len(self.c),
            work=solves(layers, steps, scheme),
        )

    def fade(self):
        """How much the reference fades: ΔE00 from the unexposed state."""
        return delta_E_2000(self.initial_Lab, self.ref_Lab)


def table(rows, key, fmt, paper=None):
    """A Markdown table layers × steps for one scheme's metric (paper value beside)."""
    head = "| layers | " + " | ".join(f"{s} steps" for s in STEPS) + " |"
    lines = [head, "|---:|" + "---:|" * len(STEPS)]
    for L in LAYERS:
        cells = []
        for k, T in enumerate(STEPS):
            v = fmt.format(rows[(L, T)][key])
            if paper is not None:
                v += f" ({fmt.format(paper[L][k])})"
            cells.append(v)
        lines.append(f"| {L} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def frontier(points):
    """Points not beaten on both work and error, sorted by work."""
    best, out = np.inf, []
    for p in sorted(points, key=lambda p: (p["work"], p["dE00"])):
        if p["dE00"] < best:
            out.append(p)
            best = p["dE00"]
    return out


def plot(grid, sweep, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    ax = axes[0]
    for scheme, colour_ in (("paper", "tab:blue"), ("heun", "tab:orange")):
        pts = [p for p in sweep if p["scheme"] == scheme]
        ax.scatter([p["seconds"] * 1e3 for p in pts], [p["dE00"] for p in pts], s=10,
                   color=colour_, alpha=0.35)
        fr = frontier(pts)
        ax.plot([p["seconds"] * 1e3 for p in fr], [p["dE00"] for p in fr], "-o", ms=3,
                color=colour_, label=f"scheme '{scheme}' (frontier)")
    ax.axhline(TARGET_DE00, color="grey", ls="--", lw=1)
    ax.text(ax.get_xlim()[0] if False else 0.02, TARGET_DE00 * 1.08, "ΔE00 = 0.3",
            color="grey", transform=ax.get_yaxis_transform())
    ax.set(xscale="log", yscale="log", xlabel="time per sample on one core (ms)",
           ylabel="max CIEDE2000 to the reference", title="Cost–accuracy frontier")
    ax.legend(fontsize=8)

    ax = axes[1]
    for k, (T, marker) in enumerate(zip(STEPS, "o^s")):
        ax.plot(LAYERS, [PAPER_DE[L][k] for L in LAYERS], ":" + marker, color="grey",
                label=f"paper, {T} steps")
        ax.plot(LAYERS, [grid[("paper", L, T)]["dE"] for L in LAYERS], "-" + marker,
                color="tab:blue", label=f"ours 'paper', {T} steps")
        ax.plot(LAYERS, [grid[("heun", L, T)]["dE"] for L in LAYERS], "--" + marker,
                color="tab:orange", label=f"ours 'heun', {T} steps")
    ax.set(xscale="log", yscale="log", xlabel="layers", ylabel="max ΔE*ab to the reference",
           title="Table 2 redone (grey: the paper's values)")
    ax.set_xticks(LAYERS, [str(L) for L in LAYERS])
    ax.legend(fontsize=6, ncol=3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only")
    parser.add_argument("--repeat", type=int, default=3, help="timed runs per setting")
    args = parser.parse_args(argv)

    problem = cmy_problem()
    tables = Study(random_mixtures(10), problem, args.repeat, kinetics="paper")
    fade_paper = tables.fade()
    print(f"reference {REFERENCE}, paper kinetics: {tables.ref_seconds:.1f} s for 10 samples; "
          f"fade ΔE00 from unexposed: mean {fade_paper.mean():.1f}, max {fade_paper.max():.1f}")
    grid = {}
    for scheme in ("paper", "heun"):
        for L in LAYERS:
            for T in STEPS:
                grid[(scheme, L, T)] = tables.score(L, T, scheme)
        print(f"table done: {scheme}")

    study = Study(random_mixtures(10), problem, 1, kinetics="first-order")
    fade = study.fade()
    print(f"reference {REFERENCE}, first-order kinetics: fade ΔE00 from unexposed: "
          f"mean {fade.mean():.1f}, max {fade.max():.1f}")

    sweep_layers = (2, 3, 4, 5, 6, 8, 10, 12, 16, 24, 32)
    sweep_steps = (1, 2, 3, 4, 5, 6, 8, 10, 12, 16, 20, 25, 32, 48, 64)
    sweep = [study.score(L, T, s, timed=False) for s in ("paper", "heun")
             for L in sweep_layers for T in sweep_steps]
    # time the sweep points by their work: seconds per layer-solve from the timed grid
    rate = statistics.median(p["seconds"] / p["work"] for p in grid.values())
    for p in sweep:
        p["seconds"] = p["work"] * rate
    # The cheapest setting within the target on the ten mixtures that also holds on
    # 100 held-out ones (a setting tuned on ten samples alone can sit on the edge).
    held_out = Study(random_mixtures(100, seed=7), problem, 1, kinetics="first-order")
    for choice in sorted((p for p in sweep if p["dE00"] <= TARGET_DE00),
                         key=lambda p: (p["work"], p["dE00"])):
        check = held_out.score(choice["layers"], choice["steps"], choice["scheme"], timed=False)
        print(f"candidate {choice['scheme']} {choice['layers']}x{choice['steps']}: "
              f"max ΔE00 {choice['dE00']:.3f} (10), {check['dE00']:.3f} (100 held out)")
        if check["dE00"] <= TARGET_DE00:
            break

    md = render(tables, fade_paper, fade, grid, sweep, choice, check, rate)
    if args.no_write:
        print(md)
        return
    img = ROOT / "docs" / "img" / "accuracy_frontier.png"
    plot(grid, sweep, img)
    from benchmarks.gamut import HEADING        # keep benchmarks.gamut's section

    doc = ROOT / "docs" / "accuracy.md"
    kept = doc.read_text().partition(HEADING) if doc.exists() else ("", "", "")
    doc.write_text(md + ("\n" + kept[1] + kept[2] if kept[1] else ""))
    print(f"wrote docs/accuracy.md and {img.relative_to(ROOT)}")


def render(study, fade, fade_first, grid, sweep, choice, check, rate):
    g = {s: {(L, T): grid[(s, L, T)] for L in LAYERS for T in STEPS} for s in ("paper", "heun")}
    fr = {s: frontier([p for p in sweep if p["scheme"] == s]) for s in ("paper", "heun")}
    out = [
        "# Accuracy study: layers and time steps (the paper's Section 4, redone)",
        "",
        "Generated by `./run py -m benchmarks.accuracy` — do not edit by hand.",
        "",
        "Ten seeded random mixtures of the bundled cyan, magenta and yellow dyes on paper "
        "(`benchmarks/problem.py`), faded in CIE D65 daylight to a heavy fade "
        f"(ΔE00 from the unexposed state: mean {fade.mean():.1f}, max {fade.max():.1f}), "
        "compared with a reference of 1024 layers × 625 steps of the paper's scheme "
        f"({study.ref_seconds:.1f} s for the ten samples here). 41 wavelengths, 300–780 nm. "
        "Times are per sample on one core (the ten samples run as one batch, `workers=1`); "
        "the paper's are in parentheses (one 2.8 GHz Xeon E5462 core). Our dyes are "
        "parametric, not Yang's measured data, so the error values are comparable in "
        "trend and size, not digit by digit.",
        "",
        "Tables 1–3 use the paper's rate law (`kinetics=\"paper\"`, equation 3 as printed), "
        "the comparison the paper invites. The frontier and the production default below "
        "use the product's first-order kinetics (`kinetics=\"first-order\"`, see "
        "[physics.md](physics.md)) against its own 1024 × 625 reference "
        f"(fade ΔE00 from the unexposed state: mean {fade_first.mean():.1f}, "
        f"max {fade_first.max():.1f}).",
        "",
        "![frontier](img/accuracy_frontier.png)",
        "",
    ]
    for scheme, title in (("paper", "Scheme `paper`, paper kinetics (equations 1–5 exactly)"),
                          ("heun", "Scheme `heun` (predictor–corrector, second order), paper kinetics")):
        out += [f"## {title}", "",
                "Max RMS ΔR (Table 1; paper in parentheses):", "",
                table(g[scheme], "rms", "{:.4f}", PAPER_RMS if scheme == "paper" else None), "",
                "Max ΔE*ab (Table 2; paper in parentheses):", "",
                table(g[scheme], "dE", "{:.4f}", PAPER_DE if scheme == "paper" else None), "",
                "Max CIEDE2000:", "",
                table(g[scheme], "dE00", "{:.4f}"), "",
                "Time per sample, ms (Table 3; paper in seconds in parentheses):", "",
                table({k: dict(v, ms=v["seconds"] * 1e3) for k, v in g[scheme].items()},
                      "ms", "{:.2f}", PAPER_TIME if scheme == "paper" else None), ""]
    out += ["## Cost–accuracy frontier and the production default (first-order kinetics)", "",
            f"A denser sweep (layers 2…32 × steps 1…64, both schemes, first-order kinetics) "
            f"scored by max ΔE00; "
            f"cost is the number of layer solves (layers × flux solves per run: "
            f"steps + 1 for `paper`, 2 × steps + 1 for `heun`), converted to time at the "
            f"measured {rate * 1e9:.0f} ns per layer solve per sample. The frontier "
            "(settings no other setting beats on both cost and error):", "",
            "| scheme | layers | steps | layer solves | ms per sample | max ΔE00 | max ΔE*ab |",
            "|---|---:|---:|---:|---:|---:|---:|"]
    for s in ("paper", "heun"):
        for p in fr[s]:
            if p["dE00"] < 3:
                out.append(f"| {s} | {p['layers']} | {p['steps']} | {p['work']} | "
                           f"{p['seconds'] * 1e3:.3f} | {p['dE00']:.3f} | {p['dE']:.3f} |")
    out += ["",
            f"**Production default** (cheapest with max ΔE00 <= {TARGET_DE00} on the ten "
            f"mixtures and on 100 held-out ones): "
            f"`layers={choice['layers']}, steps={choice['steps']}, scheme=\"{choice['scheme']}\"` "
            f"— max ΔE00 {choice['dE00']:.3f}, max ΔE*ab {choice['dE']:.3f} on the ten "
            f"mixtures; on 100 held-out mixtures max ΔE00 {check['dE00']:.3f}, "
            f"max ΔE*ab {check['dE']:.3f}. These are `simulate()`'s defaults.", ""]
    return "\n".join(out)


if __name__ == "__main__":
    main()
