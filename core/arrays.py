"""Read-only arrays for the frozen data model."""

from __future__ import annotations

import numpy as np


def readonly(values, dtype=float, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """A new contiguous array of ``values`` (reshaped to ``shape`` if given) that cannot be written."""
    out = np.array(values, dtype=dtype, order="C")
    if shape is not None:
        out = out.reshape(shape)
    out.setflags(write=False)
    return out
