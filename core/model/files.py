"""Reading input files safely: regular files only, of bounded size, every OS error a SceneError;
TOML files (scenes, tolerances) decoded with the line and column of a mistake; XML (URDF) parsed
without a document type declaration and nested at most :data:`MAX_XML_DEPTH` deep.

A folder, a FIFO or a device (``/dev/zero``) is never opened: opening a FIFO blocks forever and a
device can be endless. Paths the OS rejects (a component longer than it allows, a NUL byte) are
reported like a missing file, never as a traceback.
"""

from __future__ import annotations

import os
import re
import stat
import sys
import xml.etree.ElementTree as ET

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
    except ValueError as err:  # an integer beyond Python's 4,300 digits (tomllib raises no TOMLDecodeError for it)
        raise SceneError(source, "-", f"a number too long to read: {str(err).split(';')[0]}", "numbers a float64 "
                         "holds (at most ~1.8e308)") from None


MAX_XML_DEPTH = 100
"""Deepest nesting of elements an XML (URDF) file may have [levels, the root element is level 1]: real URDF
files nest fewer than 10 deep (robot/link/visual/geometry/mesh is 5); writing or indenting a tree recurses
once per level, so a file 1,000 deep would exhaust Python's stack in the exporter."""
_XML_NESTING_ALLOWED = f"elements nested at most {MAX_XML_DEPTH} levels deep (URDF files nest fewer than 10)"
_NO_DOCTYPE = "a document without <!DOCTYPE ...>: URDF has no DTD, and its entities are never expanded or fetched"


class _GuardedTree(ET.TreeBuilder):
    """ElementTree's tree builder that refuses a document type declaration (so no entity, internal, parameter or
    external, is ever declared, expanded or fetched) and elements nested deeper than :data:`MAX_XML_DEPTH`."""

    def __init__(self, source: str) -> None:
        super().__init__()
        self.source = source
        self.depth = 0

    def start(self, tag: str, attrs: dict[str, str]) -> ET.Element:
        self.depth += 1
        if self.depth > MAX_XML_DEPTH:
            raise SceneError(self.source, f"<{tag}> at depth {self.depth}",
                             f"elements nested more than {MAX_XML_DEPTH} levels deep", _XML_NESTING_ALLOWED)
        return super().start(tag, attrs)

    def end(self, tag: str) -> ET.Element:
        self.depth -= 1
        return super().end(tag)

    def doctype(self, name: str, pubid: str | None, system: str | None) -> None:
        """Called by the parser at ``<!DOCTYPE``, before any of its declarations is read."""
        raise SceneError(self.source, f"<!DOCTYPE {name}>", "a document type declaration (DTD)", _NO_DOCTYPE)


def parse_xml(data: str | bytes, source: str, root: str) -> ET.Element:
    """The root element of the XML ``data`` (bytes: its XML declaration's encoding is honoured), which must be
    ``<root>``; SceneError (naming ``source``) for malformed XML, an unknown encoding, a ``<!DOCTYPE>`` (DTDs
    and entities refused outright), elements nested deeper than :data:`MAX_XML_DEPTH`, or another root."""
    allowed = f"a well-formed <{root}> document"
    parser = ET.XMLParser(target=_GuardedTree(source))
    try:
        parser.feed(data)
        element = parser.close()
    except ET.ParseError as err:
        raise SceneError(source, root, f"not well-formed XML ({err})", allowed) from None
    except (LookupError, ValueError) as err:  # an encoding Python does not know
        raise SceneError(source, root, f"unreadable encoding ({err})", "UTF-8, Latin-1, UTF-16, ...") from None
    if element.tag != root:
        raise SceneError(source, element.tag, f"the root element is not <{root}>", f"<{root}>")
    return element
