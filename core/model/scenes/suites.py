"""Where a scene belongs: the built-in suites (:data:`SUITES`) and its place in a ``[sweep]`` (:class:`SweepPoint`)."""

from __future__ import annotations

from dataclasses import dataclass

from simparity.core.model.errors import SceneError

SUITES = ("default", "hard", "contact", "bench", "articulated", "robots")
"""Named groups of built-in scenes (``simparity run --suite``): ``default`` is what ``simparity
run`` runs; ``hard`` gathers the numerical-stability cases, each with the verdict it must earn
in the shipped tolerances; ``contact`` every scene with planes; ``bench`` the real arms whose IK
``simparity bench`` times (10,000 targets each); ``articulated`` the joint-space dynamics of real robot arms and
the crafted arm; ``robots`` the robot corpus: every robot description the dependencies' wheels ship, each file through
every importer (``docs/robots.md``). A scene may be in several."""



@dataclass(frozen=True)
class SweepPoint:
    """Where a scene sits in the ``[sweep]`` of its file: one variant of the scene the file declares
    (``docs/scenes.md``, "Sweeps").

    Attributes
    ----------
    base : str
        The name the file gives the scene (``[scene] name``); the variant's own name is derived from it
        and the values, for display only.
    values : tuple of (str, int or float)
        Each swept key (its path as the ``[sweep]`` table writes it, e.g. ``"body[ball].restitution"``)
        with this variant's value, in the sweep's order. A value is the number written into the file, in
        the file's ``length_unit``: an int for whole-number keys (seeds, counts), else a float.
    index : int
        The variant's position in the sweep's order, from 0.
    count : int
        Variants the file expands into.
    """

    base: str
    values: tuple[tuple[str, int | float], ...]
    index: int
    count: int

    def __post_init__(self) -> None:
        object.__setattr__(self, "values", tuple((str(k), v) for k, v in self.values))
        if not 0 <= self.index < self.count:
            raise SceneError("<code>", "sweep", f"variant index {self.index} of {self.count} variants",
                             "an index from 0 to count - 1")

    @property
    def keys(self) -> tuple[str, ...]:
        """The swept keys, in the sweep's order."""
        return tuple(key for key, _ in self.values)
