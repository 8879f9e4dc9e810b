"""Blender's equirectangular environment map: pixel directions, solid angles, scene frame.

The mapping is Cycles' ``direction_to_equirectangular`` (``intern/cycles/kernel/camera/
projection.h``, range ``(-2π, π, -π, π)``), used by the Environment Texture node::

    u = (atan2(d.y, d.x) - π) / (-2π) = 0.5 - atan2(d.y, d.x) / 2π
    v = (acos(d.z / |d|) - π) / (-π)  = 1 - acos(d.z / |d|) / π

so u = 0 (left) looks along -X, u = 0.25 along +Y, u = 0.5 along +X, u = 0.75 along -Y,
and v = 1 is the zenith (+Z), v = 0 the nadir.  An image's pixel (row j, column i) covers
v in [j, j+1] / H and u in [i, i+1] / W, with row 0 at v = 0: Blender stores image pixels
bottom row first, so a map array indexed ``[row, column]`` with row 0 = the nadir is
exactly what ``image.pixels.foreach_set`` takes (after adding the RGBA channels).

Geographic to scene: ``north`` is the counterclockwise angle (degrees, about +Z) from the
scene's +Y axis to geographic north; east is north turned 90° clockwise seen from above.
So geographic north is ``(-sin n, cos n, 0)`` and east ``(cos n, sin n, 0)`` in the scene.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["check_width", "grid", "direction_to_pixel", "scene_axes", "enu_to_scene",
           "scene_to_enu", "sun_direction_scene", "north_from_sun_position_addon"]


def check_width(width):
    """The map's width, validated: a multiple of 4, at least 16 (so the horizon is a row
    boundary: height = width // 2 is even)."""
    width = int(width)
    if width < 16 or width % 4:
        raise ValueError(f"sky map width must be a multiple of 4 and at least 16, got {width}")
    return width


@functools.lru_cache(maxsize=8)
def grid(width):
    """Pixel-centre directions and solid angles of a (width // 2, width) map.

    Returns
    -------
    directions : numpy.ndarray
        (H, W, 3) unit vectors in scene coordinates, row 0 at the nadir.
    solid_angle : numpy.ndarray
        (H, 1) steradians per pixel of each row (they sum to 4π over the map).
    """
    W = check_width(width)
    H = W // 2
    u = (np.arange(W) + 0.5) / W
    v = (np.arange(H) + 0.5) / H
    phi = -2.0 * np.pi * u + np.pi
    theta = -np.pi * v + np.pi
    st = np.sin(theta)[:, None]
    d = np.stack(np.broadcast_arrays(st * np.cos(phi)[None, :], st * np.sin(phi)[None, :],
                                     np.cos(theta)[:, None]), axis=-1)
    edges = np.pi - np.pi * np.arange(H + 1) / H        # θ of each row's edges, nadir first
    omega = (2.0 * np.pi / W) * (np.cos(edges[1:]) - np.cos(edges[:-1]))
    d.setflags(write=False)
    omega = omega[:, None]
    omega.setflags(write=False)
    return d, omega


def direction_to_pixel(directions, width):
    """Flat pixel index (row * W + column) of scene directions, Cycles' mapping.

    Parameters
    ----------
    directions : array_like
        (..., 3) vectors, scene coordinates (need not be unit length).
    width : int
        Map width W (height W // 2).
    """
    W = check_width(width)
    H = W // 2
    d = np.asarray(directions, dtype=float)
    n = np.linalg.norm(d, axis=-1)
    u = (np.arctan2(d[..., 1], d[..., 0]) - np.pi) / (-2.0 * np.pi)
    v = (np.arccos(np.clip(d[..., 2] / n, -1.0, 1.0)) - np.pi) / (-np.pi)
    col = np.clip(np.floor(u * W).astype(int), 0, W - 1)
    row = np.clip(np.floor(v * H).astype(int), 0, H - 1)
    return row * W + col


def scene_axes(north=0.0):
    """Scene vectors of geographic east, north and up for a ``north`` angle in degrees."""
    n = np.radians(north)
    return (np.array([np.cos(n), np.sin(n), 0.0]), np.array([-np.sin(n), np.cos(n), 0.0]),
            np.array([0.0, 0.0, 1.0]))


def enu_to_scene(enu, north=0.0):
    """(..., 3) east-north-up vectors to scene coordinates."""
    E, N, U = scene_axes(north)
    enu = np.asarray(enu, dtype=float)
    return enu[..., :1] * E + enu[..., 1:2] * N + enu[..., 2:3] * U


def scene_to_enu(vectors, north=0.0):
    """(..., 3) scene vectors to east-north-up components."""
    v = np.asarray(vectors, dtype=float)
    return np.stack([v @ a for a in scene_axes(north)], axis=-1)


def sun_direction_scene(zenith, azimuth, north=0.0):
    """Unit vectors towards the sun in scene coordinates.

    Parameters
    ----------
    zenith, azimuth : array_like
        Degrees; azimuth clockwise from geographic north (east = 90°).
    north : float
        Counterclockwise degrees from the scene's +Y axis to geographic north, about +Z.

    Returns
    -------
    numpy.ndarray
        (..., 3) unit vectors.

    Examples
    --------
    >>> np.round(sun_direction_scene(90.0, 90.0), 6)        # due east on the horizon
    array([1., 0., 0.])
    >>> np.round(sun_direction_scene(90.0, 0.0, north=90.0), 6)  # north is -X
    array([-1.,  0.,  0.])
    """
    z, a = np.radians(np.asarray(zenith, dtype=float)), np.radians(np.asarray(azimuth, dtype=float))
    enu = np.stack([np.sin(z) * np.sin(a), np.sin(z) * np.cos(a), np.cos(z)], axis=-1)
    return enu_to_scene(enu, north)


def north_from_sun_position_addon(north_offset):
    """Our ``north`` (degrees) from Blender's Sun Position add-on's ``north_offset``.

    The add-on (``sun_position/sun_calc.py``: ``azimuth += north_offset``, then
    ``get_sun_vector``: ``(sin θ sin A, sin θ cos A, cos θ)`` with θ the zenith angle)
    puts geographic azimuth ``a`` at ``a + north_offset`` clockwise from +Y, so north
    turns *clockwise* by ``north_offset``; ours turns counterclockwise.

    Parameters
    ----------
    north_offset : float
        The add-on's property, radians (as stored in ``scene.sun_pos_properties``).

    Returns
    -------
    float
        ``-degrees(north_offset)``.
    """
    return -float(np.degrees(north_offset))
