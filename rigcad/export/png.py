"""Greyscale PNG bytes of integer images that are data, not figures (the projector's basis images,
the calibration screen's patterns, simulated captures): 8-bit or 16-bit, one channel, exactly the
array's values, and a gAMA chunk of 1.0 saying so: the levels are linear in light (the projector
or screen is to show them through a linear response), not sRGB-encoded. gAMA rather than the sRGB
chunk (which would declare sRGB's curve) or cICP (PNG's third edition, 2025: few decoders read it
yet); no cHRM, as grey has no primaries. Written with Pillow (which matplotlib already depends
on), with no text or time chunks, so the same array always gives the same bytes. Figures go
through rigcad.plots instead.
"""

from __future__ import annotations

import io

import numpy as np

from rigcad.errors import ExportError

#: zlib level of the PNG stream: the default of libpng and Pillow; fixed so that the bytes are too.
COMPRESS_LEVEL = 6
#: The gAMA chunk's value: the image's gamma times 100000 (PNG 11.3.3.2); 1.0 = linear levels.
GAMMA_LINEAR = 100_000


def gray_png(image: np.ndarray) -> bytes:
    """PNG bytes of ``image`` (rows, columns), uint8 (8-bit) or uint16 (16-bit greyscale), row 0 at
    the top, levels linear (gAMA 1.0). Raises ExportError for any other shape or dtype."""
    a = np.asarray(image)
    if a.ndim != 2 or a.dtype not in (np.dtype(np.uint8), np.dtype(np.uint16)) or 0 in a.shape:
        raise ExportError(f"greyscale PNG of an array of shape {a.shape} and dtype {a.dtype}: need a non-empty "
                          "2-D uint8 (8-bit) or uint16 (16-bit) array")
    from PIL import Image, PngImagePlugin

    chunks = PngImagePlugin.PngInfo()
    chunks.add(b"gAMA", GAMMA_LINEAR.to_bytes(4, "big"))  # before IDAT, as PNG requires
    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(a)).save(buf, format="PNG", compress_level=COMPRESS_LEVEL, pnginfo=chunks)
    return buf.getvalue()
