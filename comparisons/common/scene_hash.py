"""A scene's content hash: what a kept case and a user's engine's answers are keyed by."""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import struct
from collections.abc import Mapping

import numpy as np


def scene_hash(scene) -> str:
    """SHA-256 of a scene's content: every field of its dataclasses that takes part in their equality (not
    ``compare=False`` ones, such as the file a scene was read from: the same file by a relative or an absolute
    path, or moved, is the same scene), arrays by dtype, shape and bytes, floats exactly. The same scene
    loaded twice, in any process, hashes the same."""
    digest = hashlib.sha256()
    _feed(digest, scene)
    return digest.hexdigest()


def _feed(digest, value) -> None:
    """Feed ``value`` to ``digest`` with its type, so different structures never give the same bytes."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        digest.update(f"<{type(value).__qualname__}".encode())
        for f in (f for f in dataclasses.fields(value) if f.compare):
            digest.update(f.name.encode() + b"=")
            _feed(digest, getattr(value, f.name))
        digest.update(b">")
    elif isinstance(value, np.ndarray):
        digest.update(f"<array {value.dtype.str} {value.shape}>".encode())
        digest.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, (list, tuple)):
        digest.update(f"<{type(value).__name__} {len(value)}".encode())
        for item in value:
            _feed(digest, item)
        digest.update(b">")
    elif isinstance(value, Mapping):
        digest.update(f"<dict {len(value)}".encode())
        for k in sorted(value, key=repr):
            _feed(digest, k)
            _feed(digest, value[k])
        digest.update(b">")
    elif isinstance(value, enum.Enum):
        digest.update(f"<enum {type(value).__qualname__}.{value.name}>".encode())
    elif isinstance(value, bool) or value is None:
        digest.update(f"<{value!r}>".encode())
    elif isinstance(value, (int, np.integer)):
        digest.update(f"<int {int(value)}>".encode())
    elif isinstance(value, (float, np.floating)):
        digest.update(b"<float" + struct.pack("<d", float(value)) + b">")
    elif isinstance(value, str):
        digest.update(f"<str {len(value)}>".encode() + value.encode("utf-8", "surrogatepass"))
    else:
        raise TypeError(f"scene_hash: cannot hash a {type(value).__name__}")
