"""The project's one exception tree.

Every error a user can cause derives from :class:`SimparityError`; the CLI turns those
into a one-line message and exit code 2. Anything else is a bug and keeps its traceback.
"""

from __future__ import annotations

import unicodedata

ECHO_LIMIT = 200
"""Characters of a file name, key or value a message echoes before cutting it with an ellipsis:
a message stays one readable line whatever the input holds (a 50,000-character name, 20,000
link names)."""


def one_line(text: object, limit: int = ECHO_LIMIT) -> str:
    """``text`` safe for a one-line message: control and other invisible characters escaped as in
    ``repr`` (a newline becomes ``\\n``), cut to ``limit`` characters with an ellipsis."""
    out = []
    for char in str(text):
        if char == "\t" or unicodedata.category(char) in ("Cc", "Zl", "Zp", "Cf"):
            out.append(repr(char)[1:-1] if char.isascii() else f"\\u{ord(char):04x}")
        else:
            out.append(char)
    cleaned = "".join(out)
    return cleaned if len(cleaned) <= limit else cleaned[: limit - 1] + "…"


ECHO_VALUE = 80
"""Characters of a value's ``repr`` a message echoes (a string of 50,000 characters, a list of a
million numbers) before cutting it with an ellipsis."""


def echo(value: object, limit: int = ECHO_VALUE) -> str:
    """``repr(value)`` for a one-line message: escaped by :func:`one_line`, cut to ``limit`` characters."""
    return one_line(repr(value), limit)


class SimparityError(Exception):
    """Base class of every error simparity raises on purpose."""


class SceneError(SimparityError):
    """A scene file or scene value is invalid.

    Attributes
    ----------
    source : str
        The file (or ``"<scene>"`` when built in code) the value came from.
    key : str
        Dotted key path inside the scene, e.g. ``"body[0].mass"``.
    problem : str
        What was wrong with the value.
    allowed : str
        What would have been accepted.
    """

    def __init__(self, source: str, key: str, problem: str, allowed: str = "") -> None:
        self.source = source
        self.key = key
        self.problem = problem
        self.allowed = allowed or "see docs/scenes.md"
        text = (f"{one_line(source)}: {one_line(key)}: {one_line(problem, 2 * ECHO_LIMIT)} "
                f"(allowed: {one_line(self.allowed, 2 * ECHO_LIMIT)})")
        super().__init__(text)


class UsageError(SimparityError):
    """A command-line argument is invalid (argparse's errors, one line like every other)."""


class UnknownSceneError(SimparityError):
    """A scene name is neither a built-in scene nor an existing file."""


class UnknownEngineError(SimparityError):
    """An engine name is not one simparity knows."""


class PluginError(SimparityError):
    """A user's engine (an installed plugin or a ``module:attr`` spec) raised while it was loaded, built or
    asked what it offers, or broke the engine interface: its cases fail with this message."""


class DivergedError(SimparityError):
    """A simulation became unstable (an engine reported it, or its state left the finite numbers)."""


class ContactError(SimparityError):
    """A contact that core's method cannot resolve (two spheres of a chain touching at once under its one-contact
    impulses); the message says which and why."""


class NotBatchedError(SimparityError):
    """An engine cannot step many copies of a scene in one call (``Simulation.batched``); the message says why, and
    becomes the reason of the case's ``n/a`` batched-timing row."""


class ResultsError(SimparityError):
    """A stored run is missing or unreadable."""


class ToleranceError(SceneError):
    """A tolerances file or one of its values is invalid (file, key, what was wrong, what is allowed)."""


class HistoryError(SimparityError):
    """The run history database cannot be read or written (the CSV results are unaffected)."""


class TransformError(SceneError):
    """A metamorphic transform (``comparisons.invariance.transforms``) is invalid, or cannot be applied to a scene: the
    scene's data cannot express the transformed physics (file or ``<code>``, the transform's key, why)."""


class UnitError(SimparityError):
    """A metric's unit string is not one simparity can convert between unit systems (unknown, or a mix of
    dimensions the transform scales differently): its value is never converted by a guessed factor."""
