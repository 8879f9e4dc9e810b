"""Writing the figures of docs/img (shared by the tools that draw them)."""

from __future__ import annotations

import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]


def pyplot():
    """matplotlib's pyplot on the file-only Agg backend (no screen here or in CI)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save(fig, name):
    """Lay out ``fig`` and write it to docs/img/``name`` at the docs' resolution."""
    fig.tight_layout()
    path = ROOT / "docs" / "img" / name
    fig.savefig(path, dpi=110)
    print(f"wrote {path.relative_to(ROOT)}")
