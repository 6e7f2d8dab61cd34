"""A planted bug: one textual change to one file of core, and how it is applied."""

from __future__ import annotations

import re
from dataclasses import dataclass

SUITES = ("default", "hard", "contact", "articulated")
"""The built-in suites the gate runs on the quick profile (``bench`` is timing only)."""

IDENTIFIER = re.compile(r"[a-z][a-z0-9_]{0,40}")
"""A mutant's id: a Python identifier part (it names a package) and an engine name part (at most 64 characters
with its prefix)."""


class MutationError(ValueError):
    """A mutation that cannot be applied exactly as written: a bug of the suite, never skipped."""


@dataclass(frozen=True)
class Mutation:
    """One realistic bug planted in a copy of core.

    Attributes
    ----------
    id : str
        Short name (:data:`IDENTIFIER`); the copy's package is ``simparity_mutant_<id>``, its engine
        ``mutant-<id>``.
    kind : str
        What kind of bug (integrator weights, frames and conventions, contact response, IK step, ...).
    file : str
        The file under ``core/`` it changes, e.g. ``"quaternion_integrators.py"`` or ``"ik/steps.py"``.
    old, new : str
        The exact text replaced (it must occur exactly once in the file) and its replacement.
    description : str
        The bug in one line, as someone might have written it.
    suites : tuple of str
        The built-in suites whose scenes run the changed code: the gate must catch it on each.
    witness : str
        A built-in scene on which its results differ from core's (checked by the tests).
    """

    id: str
    kind: str
    file: str
    old: str
    new: str
    description: str
    suites: tuple[str, ...]
    witness: str

    def __post_init__(self) -> None:
        if not IDENTIFIER.fullmatch(self.id):
            raise MutationError(f"mutation id {self.id!r} (allowed: {IDENTIFIER.pattern})")
        if self.old == self.new:
            raise MutationError(f"mutation {self.id}: old and new text are the same")
        unknown = set(self.suites) - set(SUITES)
        if not self.suites or unknown:
            raise MutationError(f"mutation {self.id}: suites {self.suites} (allowed: some of {SUITES})")

    def apply(self, text: str) -> str:
        """``text`` (the file's) with :attr:`old` replaced by :attr:`new`; raises MutationError unless
        :attr:`old` occurs exactly once."""
        count = text.count(self.old)
        if count != 1:
            found = "does not occur" if count == 0 else f"occurs {count} times"
            raise MutationError(f"mutation {self.id}: its old text {found} in core/{self.file}: {self.old!r}")
        return text.replace(self.old, self.new)
