"""Whether a tolerances file's ``metric`` names something a run can write: the metric catalogue's names and families.

A bound whose metric is misspelled (``positon_error_max``) matches no row, so it holds nothing and the gate passes
on it: a tolerances file is refused (exit 2) where a metric written out is neither a catalogue name
(:data:`core.model.metric_catalogue.CATALOGUE`) nor a member of one of its families (``hard_<target>_solved``), or
where a pattern can match neither (:func:`unknown_metric`), naming the closest names.
"""

from __future__ import annotations

import difflib
import fnmatch
import re

from simparity.core.model.metric_catalogue import CATALOGUE, FAMILIES, family_of, is_non_negative

WILDCARDS = re.compile(r"[*?\[]")
"""What makes an fnmatch pattern a pattern rather than a name written out."""

CLOSEST_NAMES = 3
"""Closest catalogue names a refusal suggests."""

CLOSE_ENOUGH = 0.6
"""difflib's ratio from which a catalogue name counts as close to a misspelling (its default: a typo of one or two
letters in a name of ten scores above 0.8, an unrelated name below 0.5)."""


def family_templates() -> tuple[str, ...]:
    """The families as a reader writes them: ``hard_<member>_solved``, ``invariance_ratio_<member>``."""
    return tuple(f.name("<member>") for f in FAMILIES)


def _can_match_family(pattern: str) -> bool:
    """Whether a pattern might match some family member: its text before the first wildcard and a family's prefix
    are one the other's beginning (necessary for any match; a pattern such as ``invariance_*_rescale`` spans two
    families and is accepted)."""
    head = WILDCARDS.split(pattern, maxsplit=1)[0]
    return any(head.startswith(f.prefix) or f.prefix.startswith(head) for f in FAMILIES)


def unknown_metric(pattern: str) -> str:
    """Why a bound's ``metric`` can match no metric a run writes ("" when it can): a name neither catalogued nor a
    family member, or a pattern that matches no catalogue name and cannot match a family member."""
    if not WILDCARDS.search(pattern):
        if pattern in CATALOGUE or family_of(pattern) is not None:
            return ""
        return f"{pattern!r:.80} is not a metric of the catalogue"
    if any(fnmatch.fnmatchcase(name, pattern) for name in CATALOGUE) or _can_match_family(pattern):
        return ""
    return f"the pattern {pattern!r:.80} matches no metric of the catalogue"


def closest(pattern: str) -> list[str]:
    """The catalogue names (and family templates) closest to ``pattern``, the closest first (difflib)."""
    return difflib.get_close_matches(pattern, list(CATALOGUE) + list(family_templates()), n=CLOSEST_NAMES,
                                     cutoff=CLOSE_ENOUGH)


def allowed_text(pattern: str) -> str:
    """What a refused ``metric`` could have been, for the one-line message: the closest names, then where the
    others are listed."""
    near = closest(pattern)
    return ("closest: " + ", ".join(near) + "; or " if near else "") + (
        "a metric of docs/metrics.md (a name, or a family's such as hard_<target>_solved), or a pattern matching one")


def non_negative(pattern: str) -> bool:
    """Whether every metric ``pattern`` can match is >= 0 (errors, drifts, residuals, times, rates: not an order), so
    that a bound whose every value is below 0 holds no value of it. A family member is non-negative."""
    if not WILDCARDS.search(pattern):
        return is_non_negative(pattern)
    return all(is_non_negative(name) for name in CATALOGUE if fnmatch.fnmatchcase(name, pattern))
