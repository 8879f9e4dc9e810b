"""Aging textures: the aging table built from the grid, its numpy evaluator, texels, restore, noticeable-fade years."""
