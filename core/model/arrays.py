"""Read-only arrays for the frozen data model."""

from __future__ import annotations

import numpy as np


def readonly(values, dtype=float, shape: tuple[int, ...] | None = None) -> np.ndarray:
    """A new contiguous array of ``values`` (reshaped to ``shape`` if given) that cannot be written.

    Raises ValueError for complex ``values`` where ``dtype`` is real: NumPy would drop the imaginary part with
    no more than a warning, and a state with one is no state of a physical body."""
    if np.iscomplexobj(values) and not np.issubdtype(np.dtype(dtype), np.complexfloating):
        raise ValueError(f"complex values where real ones ({np.dtype(dtype).name}) are expected")
    out = np.array(values, dtype=dtype, order="C")
    if shape is not None:
        out = out.reshape(shape)
    out.setflags(write=False)
    return out
