"""Several colour tables built at once (core/aging/tablebuild.build_tables)."""

import threading

import numpy as np
import pytest

from lightfade_addon.core.aging import tablebuild
from lightfade_addon.core.aging.tablebuild import TableSettings, build_table, build_tables
from lightfade_addon.core.fading import cache
from lightfade_addon.core.fading.grid import GridSettings
from lightfade_addon.core.fading.recipes import get_recipe

SMALL = TableSettings(side=5, unmix_side=9, per_decade=4, grid=GridSettings(points=5))
ONE = [("daylight", False)]
TWO = [("daylight", False), ("incandescent", False)]


@pytest.fixture
def empty_cache(tmp_path):
    cache.set_directory(tmp_path)
    yield tmp_path
    cache.set_directory(None)


def test_tables_built_together_are_the_tables_built_alone(empty_cache, monkeypatch):
    """Two builds run at the same time (each waits for the other at its start), each
    table is the one built alone, bit for bit; a repeated request is built once; the
    progress is said from the calling thread only, ending at 1."""
    paper, fabric = get_recipe("printed-paper"), get_recipe("dyed-fabric")
    met = threading.Barrier(2, timeout=30)
    real, built = tablebuild.load_or_build, []

    def together(recipe, keys, settings, **kw):
        built.append(recipe.name)
        met.wait()                                  # broken unless both run at once
        return real(recipe, keys, settings, **kw)

    monkeypatch.setattr(tablebuild, "load_or_build", together)
    said, caller = [], threading.get_ident()
    out = build_tables([(paper, ONE), (fabric, TWO), (paper, ONE)], SMALL,
                       lambda f, m: said.append((f, m, threading.get_ident())), threads=2)
    assert sorted(built) == ["dyed-fabric", "printed-paper"]
    assert set(out) == {tablebuild.table_key(paper, ONE, SMALL),
                        tablebuild.table_key(fabric, TWO, SMALL)}
    for recipe, keys in ((paper, ONE), (fabric, TWO)):
        alone = build_table(recipe, keys, SMALL)
        table = out[tablebuild.table_key(recipe, keys, SMALL)]
        np.testing.assert_array_equal(table.values, alone.values)
        np.testing.assert_array_equal(table.unmix, alone.unmix)
    assert all(t == caller for _f, _m, t in said)
    fractions = [f for f, _m, _t in said]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    assert said[-1][1].endswith("table ready")


def test_a_request_whose_build_fails_is_left_out(empty_cache, monkeypatch):
    paper, fabric = get_recipe("printed-paper"), get_recipe("dyed-fabric")
    real = tablebuild.load_or_build

    def failing(recipe, keys, settings, **kw):
        if recipe.name == "dyed-fabric":
            raise ValueError("does not fade under this light")
        return real(recipe, keys, settings, **kw)

    monkeypatch.setattr(tablebuild, "load_or_build", failing)
    out = build_tables([(paper, ONE), (fabric, ONE)], SMALL)
    assert list(out) == [tablebuild.table_key(paper, ONE, SMALL)]
