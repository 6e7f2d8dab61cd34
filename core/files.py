"""Reading input files safely: regular files only, of bounded size, every OS error a SceneError."""

from __future__ import annotations

import os
import stat

from simparity.core.errors import SceneError

MAX_FILE_BYTES = 10_000_000
"""Default largest scene or URDF file read [bytes]: the largest real robot descriptions are ~1 MB
without meshes; beyond 10 MB a file is not a scene."""


def read_input(path: str | os.PathLike, max_bytes: int = MAX_FILE_BYTES, what: str = "file") -> bytes:
    """The bytes of ``path``, refused (SceneError, key ``-``) when it is missing, not a regular file
    (a folder, a FIFO, a device: never opened), larger than ``max_bytes`` or unreadable."""
    source = os.fspath(path)
    try:
        info = os.stat(source)
    except FileNotFoundError:
        raise SceneError(source, "-", f"no such {what}", f"an existing {what}") from None
    except OSError as err:
        raise SceneError(source, "-", f"cannot look at the {what}: {err.strerror or err}", f"a readable {what}") from None
    if not stat.S_ISREG(info.st_mode):
        raise SceneError(source, "-", "not a regular file (a folder, pipe or device is never opened)",
                         f"a regular {what}")
    if info.st_size > max_bytes:
        raise SceneError(source, "-", f"the {what} is {info.st_size:,} bytes", f"at most {max_bytes:,} bytes")
    try:
        with open(source, "rb") as handle:
            data = handle.read(max_bytes + 1)
    except OSError as err:
        raise SceneError(source, "-", f"cannot read the {what}: {err.strerror or err}", f"a readable {what}") from None
    if len(data) > max_bytes:
        raise SceneError(source, "-", f"the {what} grew past {max_bytes:,} bytes while read",
                         f"at most {max_bytes:,} bytes")
    return data


def is_regular_file(path: str | os.PathLike) -> bool:
    """True for an existing regular file; False for anything else, including a path the OS rejects."""
    try:
        return stat.S_ISREG(os.stat(os.fspath(path)).st_mode)
    except (OSError, ValueError):
        return False
