"""Reading input files safely: regular files only, of bounded size, every OS error a SceneError.

A folder, a FIFO or a device (``/dev/zero``) is never opened: opening a FIFO blocks forever and a
device can be endless. Paths the OS rejects (a component longer than it allows, a NUL byte) are
reported like a missing file, never as a traceback.
"""

from __future__ import annotations

import os
import stat

from simparity.core.errors import SceneError

MAX_FILE_BYTES = 10_000_000
"""Default largest scene or URDF file read [bytes]: the largest real robot descriptions are ~1 MB
without meshes; beyond 10 MB a file is not a scene."""


def _look(path: str | os.PathLike, what: str) -> tuple[os.stat_result | None, str | None]:
    """(stat of ``path``, None) for a regular file, else (None, why not); nothing is opened."""
    try:
        info = os.stat(os.fspath(path))
    except FileNotFoundError:
        return None, f"no such {what}"
    except (OSError, ValueError) as err:  # a name too long, a NUL byte, no permission on a folder
        return None, f"cannot look at the {what}: {getattr(err, 'strerror', None) or err}"
    if not stat.S_ISREG(info.st_mode):
        return None, "not a regular file (a folder, pipe or device is never opened)"
    return info, None


def file_problem(path: str | os.PathLike, what: str = "file") -> str | None:
    """Why ``path`` cannot be read as a regular file (without opening it), or None if it can."""
    return _look(path, what)[1]


def read_input(path: str | os.PathLike, max_bytes: int = MAX_FILE_BYTES, what: str = "file") -> bytes:
    """The bytes of ``path``, refused (SceneError, key ``-``) when it is missing, not a regular file
    (a folder, a FIFO, a device: never opened), larger than ``max_bytes`` [bytes] or unreadable."""
    source = os.fspath(path)
    info, problem = _look(source, what)
    if problem:
        raise SceneError(source, "-", problem, f"the path of a regular {what}")
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
    return file_problem(path) is None
