"""Parts: several recipes in one material, each by a mask.

``properties``  ``Material.lightfade.parts`` and ``lanes``: the parts an artist lists,
                the preparation of each recipe in use; :func:`.properties.set_parts`
``operators``   ``lightfade.part_add`` and ``lightfade.part_remove``
``panel``       Material Properties > LightFade > Parts

How parts age (mask weights shared out where masks overlap, one aging group lane per
recipe, Apply) is :mod:`..aging.parts`.  Nothing is imported here, so that the aging
package and this one can import each other's modules.
"""
