"""Reading input files safely: regular files only, of bounded size, every OS error a SceneError;
TOML files (scenes, tolerances) decoded with the line and column of a mistake.

A folder, a FIFO or a device (``/dev/zero``) is never opened: opening a FIFO blocks forever and a
device can be endless. Paths the OS rejects (a component longer than it allows, a NUL byte) are
reported like a missing file, never as a traceback.
"""

from __future__ import annotations

import os
import re
import stat
import sys

from simparity.core.model.errors import SceneError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - exercised on Python 3.10 only
    import tomli as tomllib

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
    assert info is not None  # _look returns a stat whenever it reports no problem
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


_TOML_POSITION = re.compile(r"\(at line (\d+), column (\d+)\)")
MAX_NESTING_HINT = "TOML nested at most a few hundred levels deep"
_BOMS = {b"\xef\xbb\xbf": "UTF-8", b"\xff\xfe": "UTF-16", b"\xfe\xff": "UTF-16"}


def _decode(path: str, data: bytes) -> str:
    for bom, codec in _BOMS.items():
        if data.startswith(bom):
            raise SceneError(path, "line 1, column 1", f"the file starts with a {codec} byte-order mark (BOM)",
                             "UTF-8 without a BOM (save it as plain UTF-8)")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data[: err.start].count(b"\n") + 1
        column = err.start - (data.rfind(b"\n", 0, err.start) + 1) + 1
        raise SceneError(path, f"line {line}, column {column}", f"not UTF-8 text: byte {data[err.start]:#04x} "
                         f"({err.reason})", "UTF-8 text") from None


def read_toml(path: str | os.PathLike, max_bytes: int = MAX_FILE_BYTES, what: str = "file") -> dict:
    """The parsed TOML of ``path`` (read by :func:`read_input`); SceneError with the line and column
    of a syntax or encoding mistake, a BOM named as such, and too deep a nesting refused."""
    source = os.fspath(path)
    text = _decode(source, read_input(source, max_bytes, what))
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        where = _TOML_POSITION.search(str(err))
        key = f"line {where.group(1)}, column {where.group(2)}" if where else "-"
        problem = _TOML_POSITION.sub("", str(err)).strip()
        raise SceneError(source, key, f"not valid TOML: {problem}", "TOML (https://toml.io)") from None
    except RecursionError:
        raise SceneError(source, "-", "arrays or tables nested too deeply", MAX_NESTING_HINT) from None
