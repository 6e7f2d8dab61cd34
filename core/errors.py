"""The project's one exception tree.

Every error a user can cause derives from :class:`SimparityError`; the CLI turns those
into a one-line message and exit code 2. Anything else is a bug and keeps its traceback.
"""

from __future__ import annotations


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
        self.allowed = allowed
        text = f"{source}: {key}: {problem}"
        if allowed:
            text += f" (allowed: {allowed})"
        super().__init__(text)


class UnknownSceneError(SimparityError):
    """A scene name is neither a built-in scene nor an existing file."""


class UnknownEngineError(SimparityError):
    """An engine name is not one simparity knows."""


class DivergedError(SimparityError):
    """A simulation became unstable (an engine reported it, or its state left the finite numbers)."""


class ResultsError(SimparityError):
    """A stored run is missing or unreadable."""
