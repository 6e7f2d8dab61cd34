"""Keep freed heap memory in the process, so batched temporaries are not page-faulted back in.

glibc returns the top of the heap to the operating system whenever more than 128 KiB of it is
free, and serves blocks from 128 KiB up (its dynamic threshold) with fresh ``mmap`` pages. A
batched NumPy expression over B = 10,000 bodies allocates and frees dozens of 80 KiB - 1 MiB
temporaries per step, so every step faults the same pages in again: measured on this project's
quaternion-to-matrix conversion at B = 10,000, 1.07 ms with glibc's defaults against 0.12 ms with
the thresholds below (BENCHMARKS.md). Raising them keeps freed blocks for reuse; the peak memory
is unchanged (freed blocks are reused, not added), only its return to the OS is deferred.
"""

from __future__ import annotations

import ctypes
import functools
import platform

M_TRIM_THRESHOLD, M_MMAP_THRESHOLD = -1, -3
"""mallopt parameter numbers (glibc's malloc.h)."""

TRIM_THRESHOLD_BYTES = 512 << 20
"""Free heap top kept before it is returned to the OS."""

MMAP_THRESHOLD_BYTES = 32 << 20
"""Blocks up to this size come from the heap (glibc's largest allowed value on 64-bit)."""


@functools.cache
def keep_freed_memory() -> bool:
    """Raise glibc's trim and mmap thresholds once per process; False where there is no glibc."""
    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        return False
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    return bool(mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD_BYTES)) and bool(mallopt(M_MMAP_THRESHOLD,
                                                                                  MMAP_THRESHOLD_BYTES))
