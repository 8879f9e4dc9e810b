"""Aging in the material: aged copies, their preparation into data the aging node group reads, the group itself, the years, real aged images."""
