"""Image files for the command line, through OpenImageIO: PNG, TIFF, OpenEXR, JPEG.

Pixels cross this module as float32 arrays *as stored*: an integer sample ``v`` of
``b`` bits becomes ``v / (2**b - 1)`` and goes back by rounding, so a file read and
written unchanged keeps every pixel; half and float samples (EXR, float TIFF) are
passed through. Nothing is decoded or colour-managed here; the colour space the file
declares travels in :attr:`ImageInfo.metadata` to the files written from it.

>>> rgb, alpha, info = read_image("photo.png")                            # doctest: +SKIP
>>> write_image("photo_5y.png", aged, alpha, info.dtype, info.metadata)  # doctest: +SKIP

OpenImageIO (``pip install OpenImageIO``) is a dependency of the command line only:
inside Blender, images go through Blender's own ``bpy.data.images``. This module is
not part of ``core/`` (numpy and colour-science only) and imports nothing from Blender.
"""

from __future__ import annotations

import os
import pathlib
from dataclasses import dataclass, field

import numpy as np

from .output import captured

__all__ = ["ImageInfo", "read_image", "write_image", "FORMATS", "COLOUR_METADATA"]

#: File extension -> (OpenImageIO format name, sample types it can be written with).
FORMATS = {
    ".png": ("png", ("uint8", "uint16")),
    ".tif": ("tiff", ("uint8", "uint16", "half", "float")),
    ".tiff": ("tiff", ("uint8", "uint16", "half", "float")),
    ".exr": ("openexr", ("half", "float")),
    ".jpg": ("jpeg", ("uint8",)),
    ".jpeg": ("jpeg", ("uint8",)),
}

#: Attributes that say how to interpret the stored values, kept from a file read to the
#: files written from it (OpenImageIO's names: its colour space, an ICC profile, a
#: gamma, OpenEXR's primaries and white).
COLOUR_METADATA = ("oiio:ColorSpace", "oiio:Gamma", "ICCProfile", "chromaticities",
                   "whiteLuminance")

_INTEGER = {"uint8": np.uint8, "uint16": np.uint16}
_FLOAT = {"half": np.float16, "float": np.float32}


@dataclass(frozen=True)
class ImageInfo:
    """What :func:`read_image` found in a file.

    Attributes
    ----------
    format : str
        OpenImageIO's format name: ``"png"``, ``"tiff"``, ``"openexr"``, ``"jpeg"``, ...
    dtype : str
        Stored sample type: ``"uint8"``, ``"uint16"``, ``"half"`` or ``"float"``
        (other integer depths are read as ``"uint16"``).
    mode : str
        The stored channels: ``"RGB"``, ``"RGBA"``, ``"Y"`` (grey), ``"YA"``, ...
        Everything is returned as RGB (+ alpha).
    width, height : int
        Pixels.
    metadata : dict
        The file's :data:`COLOUR_METADATA` attributes, name -> value.
    """

    format: str
    dtype: str
    mode: str
    width: int
    height: int
    metadata: dict = field(default_factory=dict, compare=False)

    @property
    def bits(self):
        """Bits per sample: 8, 16 (uint16 or half) or 32 (float)."""
        return {"uint8": 8, "uint16": 16, "half": 16, "float": 32}[self.dtype]

    @property
    def linear(self):
        """True when the values are scene-linear (float samples or a linear colour space)."""
        space = str(self.metadata.get("oiio:ColorSpace", "")).lower()
        return self.dtype in _FLOAT or space.startswith(("lin", "aces", "scene_linear"))

    @property
    def colorspace(self):
        """The colour space OpenImageIO reports, e.g. ``"srgb_rec709_scene"``, or ``""``."""
        return str(self.metadata.get("oiio:ColorSpace", ""))


def _oiio(path, verb):
    try:
        import OpenImageIO
    except ImportError:
        raise ValueError(f"cannot {verb} {str(path)!r}: image files need OpenImageIO "
                         f"(pip install OpenImageIO)") from None
    return OpenImageIO


def _fail(path, why):
    return ValueError(f"cannot read {str(path)!r}: {why}")


# -- reading ---------------------------------------------------------------------------


def read_image(path):
    """Read an image file as float RGB plus optional alpha.

    Parameters
    ----------
    path : str or os.PathLike
        Any file OpenImageIO reads: PNG (8 or 16 bits; grey, RGB, RGBA, palette), TIFF,
        OpenEXR, JPEG, ... The first subimage is read; an orientation tag is applied.

    Returns
    -------
    rgb : ndarray, float32, shape (H, W, 3)
        Values as stored: integers divided by ``2**bits - 1``, half and float as they
        are. Grey is repeated into R, G, B; palettes are expanded.
    alpha : ndarray, float32, shape (H, W), or None
        Straight (unassociated) alpha, if the file has an alpha channel.
    info : ImageInfo

    Raises
    ------
    ValueError
        The file is missing, a folder, unreadable or damaged; the message names the file.
    """
    path = pathlib.Path(path)
    if not path.exists():
        raise _fail(path, "no such file")
    if path.is_dir():
        raise _fail(path, "it is a folder, not an image")
    oiio = _oiio(path, "read")
    # The format libraries print their own complaint about a bad file on stderr
    # ("libpng error: IDAT: Read error: hit end of file in png reader"): it goes into
    # our one line instead, and is written out as it came when the file reads well.
    try:
        with captured((2,)) as library:
            pixels, spec, dtype, metadata, orientation, fmt = _read(oiio, path)
    except _Unreadable as err:
        said = "; ".join(x.strip() for x in library.all_lines())
        raise _fail(path, f"{err} ({said})" if said else str(err)) from None
    library.replay()
    pixels = np.asarray(pixels).reshape(spec.height, spec.width, spec.nchannels)
    if orientation != 1:
        pixels = _reorient(oiio, pixels, spec, orientation)
    names = [n.upper() for n in spec.channelnames]
    a = spec.alpha_channel if spec.alpha_channel >= 0 else None
    colour = [k for k in range(spec.nchannels) if k != a][:3]
    rgb = pixels[..., colour]
    if rgb.shape[-1] < 3:                                   # grey: repeat it
        rgb = np.repeat(rgb[..., :1], 3, axis=-1)
    scale = np.float32(np.iinfo(_INTEGER[dtype]).max) if dtype in _INTEGER else None
    rgb = _to_float(rgb, scale)
    alpha = _to_float(pixels[..., a], scale) if a is not None else None
    mode = "".join("A" if k == a else names[k][:1] for k in range(spec.nchannels))
    h, w = rgb.shape[:2]
    return rgb, alpha, ImageInfo(fmt, dtype, mode, w, h, metadata)


class _Unreadable(Exception):
    """OpenImageIO could not read the file; the message says why."""


def _read(oiio, path):
    """The first subimage's pixels as stored, its spec, sample type, colour metadata,
    orientation and format name; raises :class:`_Unreadable`."""
    inp = oiio.ImageInput.open(str(path), _unassociated_alpha(oiio))
    if inp is None:
        raise _Unreadable(_reason(oiio.geterror(), "not an image file OpenImageIO reads"))
    try:
        spec = inp.spec()
        dtype = _stored_dtype(spec.format)
        pixels = inp.read_image(0, 0, 0, spec.nchannels, dtype)
        if pixels is None or inp.has_error:
            raise _Unreadable(_reason(inp.geterror(), "damaged or truncated image"))
        metadata = {p.name: p.value for p in spec.extra_attribs if p.name in COLOUR_METADATA}
        return (pixels, spec, dtype, metadata, spec.get_int_attribute("Orientation", 1),
                inp.format_name())
    finally:
        inp.close()


def _unassociated_alpha(oiio):
    """Open options: give alpha as stored (PNG and TIFF are otherwise premultiplied)."""
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    return config


def _reason(message, default):
    message = (message or "").strip().splitlines()
    return message[-1] if message else default


def _stored_dtype(typedesc):
    """The sample type to read as: the stored one, integers widened to 8 or 16 bits."""
    name = str(typedesc)
    if name in ("uint8", "uint16", "half", "float"):
        return name
    if name in ("double", "uint", "int"):
        return "float"
    return "uint16"


def _to_float(samples, scale):
    out = samples.astype(np.float32)
    if scale is not None:
        out /= scale
    return out


def _reorient(oiio, pixels, spec, orientation):
    """Apply an EXIF/TIFF orientation tag with OpenImageIO's ``reorient``."""
    buf = oiio.ImageBuf(oiio.ImageSpec(spec.width, spec.height, spec.nchannels,
                                       str(pixels.dtype)))
    buf.set_pixels(oiio.ROI(), pixels)
    buf.specmod().attribute("Orientation", orientation)
    upright = oiio.ImageBufAlgo.reorient(buf)
    return np.asarray(upright.get_pixels(str(pixels.dtype)))


# -- writing ---------------------------------------------------------------------------


def _quantise(values, dtype):
    v = np.asarray(values, dtype=np.float64)
    if not np.all(np.isfinite(v)):
        raise ValueError("image contains NaN or infinite values")
    if dtype in _FLOAT:
        return v.astype(_FLOAT[dtype])
    top = np.iinfo(_INTEGER[dtype]).max
    return np.rint(np.clip(v, 0.0, 1.0) * top).astype(_INTEGER[dtype])


def _set_attribute(oiio, spec, name, value):
    """``spec.attribute`` for a scalar, a string or an array (an ICC profile's bytes)."""
    if isinstance(value, (str, int, float)):
        spec.attribute(name, value)
        return
    array = np.asarray(value)
    base = "uint8" if array.dtype == np.uint8 else "float"
    spec.attribute(name, oiio.TypeDesc(f"{base}[{array.size}]"),
                   array.astype(np.uint8 if base == "uint8" else np.float32).ravel())


def write_image(path, rgb, alpha=None, dtype="uint8", metadata=None):
    """Write float RGB (and optional alpha) to an image file.

    Parameters
    ----------
    path : str or os.PathLike
        The format follows the extension, see :data:`FORMATS`: ``.png`` (uint8,
        uint16), ``.tif``/``.tiff`` (all four), ``.exr`` (half, float), ``.jpg``/``.jpeg``
        (uint8; alpha is dropped). The file is written under a temporary name in the
        same folder and renamed into place, so a failed write leaves no partial file.
    rgb : array_like, shape (H, W, 3)
        Integer types: values in [0, 1] (clipped), stored as ``round(v * (2**bits - 1))``.
        Half and float: stored as they are.
    alpha : array_like, shape (H, W), optional
        Straight alpha, stored like ``rgb``.
    dtype : {"uint8", "uint16", "half", "float"} or {8, 16}
        Sample type (8 and 16 mean uint8 and uint16).
    metadata : dict, optional
        Attributes to write, e.g. :attr:`ImageInfo.metadata` of the source file (its
        colour space and ICC profile).

    Raises
    ------
    ValueError
        Unknown extension, a sample type the format cannot hold, bad shapes, NaN.
    OSError
        The file cannot be written.
    """
    path = pathlib.Path(path)
    dtype = {8: "uint8", 16: "uint16"}.get(dtype, dtype)
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ValueError(f"cannot write {str(path)!r}: unknown image type "
                         f"(use one of {', '.join(sorted(FORMATS))})")
    if dtype not in fmt[1]:
        raise ValueError(f"cannot write {str(path)!r}: {fmt[0]} files hold "
                         f"{' or '.join(fmt[1])} samples, not {dtype!r}")
    rgb = np.asarray(rgb)
    if rgb.ndim != 3 or rgb.shape[2] != 3 or rgb.shape[0] == 0 or rgb.shape[1] == 0:
        raise ValueError(f"rgb must have shape (H, W, 3), got {rgb.shape}")
    samples = _quantise(rgb, dtype)
    if alpha is not None and fmt[0] != "jpeg":
        alpha = np.asarray(alpha)
        if alpha.shape != rgb.shape[:2]:
            raise ValueError(f"alpha must have shape {rgb.shape[:2]}, got {alpha.shape}")
        samples = np.concatenate([samples, _quantise(alpha, dtype)[..., None]], axis=2)
    oiio = _oiio(path, "write")
    h, w, c = samples.shape
    spec = oiio.ImageSpec(w, h, c, dtype)
    if c == 4:
        spec.alpha_channel = 3
        spec.attribute("oiio:UnassociatedAlpha", 1)
    for name, value in (metadata or {}).items():
        _set_attribute(oiio, spec, name, value)
    if fmt[0] == "jpeg":
        spec.attribute("Compression", "jpeg:95")
    tmp = path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")
    try:
        out = oiio.ImageOutput.create(str(tmp))
        if out is None or not out.open(str(tmp), spec):
            raise OSError(_reason(oiio.geterror() if out is None else out.geterror(),
                                  "cannot open for writing"))
        ok = out.write_image(np.ascontiguousarray(samples))
        error = out.geterror()
        out.close()
        if not ok:
            raise OSError(_reason(error, "write failed"))
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
