"""The solver defaults are the ones the accuracy study chose (docs/accuracy.md)."""

import inspect
import pathlib
import re

from lightfade_addon.core import simulate

DOC = pathlib.Path(__file__).resolve().parents[2] / "docs" / "accuracy.md"


def test_simulate_defaults_are_the_documented_production_default():
    text = DOC.read_text()
    m = re.search(r'\*\*Production default\*\*.*?`layers=(\d+), steps=(\d+), scheme="(\w+)"`',
                  text, re.S)
    assert m, "docs/accuracy.md has no production default line"
    params = inspect.signature(simulate).parameters
    assert (params["layers"].default, params["steps"].default, params["scheme"].default) == (
        int(m.group(1)), int(m.group(2)), m.group(3))
