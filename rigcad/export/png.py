"""Greyscale PNG bytes of integer images that are data, not figures (the projector's basis images):
8-bit or 16-bit, one channel, exactly the array's values. Written with Pillow (which matplotlib
already depends on), with no text or time chunks, so the same array always gives the same bytes.
Figures go through rigcad.plots instead.
"""

from __future__ import annotations

import io

import numpy as np

from rigcad.errors import ExportError

#: zlib level of the PNG stream: the default of libpng and Pillow; fixed so that the bytes are too.
COMPRESS_LEVEL = 6


def gray_png(image: np.ndarray) -> bytes:
    """PNG bytes of ``image`` (rows, columns), uint8 (8-bit) or uint16 (16-bit greyscale), row 0 at
    the top. Raises ExportError for any other shape or dtype."""
    a = np.asarray(image)
    if a.ndim != 2 or a.dtype not in (np.dtype(np.uint8), np.dtype(np.uint16)) or 0 in a.shape:
        raise ExportError(f"greyscale PNG of an array of shape {a.shape} and dtype {a.dtype}: need a non-empty "
                          "2-D uint8 (8-bit) or uint16 (16-bit) array")
    from PIL import Image

    buf = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(a)).save(buf, format="PNG", compress_level=COMPRESS_LEVEL)
    return buf.getvalue()
