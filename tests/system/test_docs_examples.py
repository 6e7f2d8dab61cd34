"""Every fenced ```toml example in docs/ and README.md loads as written (issue #25): a scene through the scene
loader, a tolerances file ([[bound]] tables) through the tolerances loader. An example that is only part of a
file says so in the docs, on the line before its fence: ``<!-- fragment: what it is part of -->``; it must still
be valid TOML."""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import pytest
from simparity.comparisons.api import load_scene, load_scenes
from simparity.comparisons.gate.tolerances import load_tolerances
from simparity.comparisons.scenes.sweep import SWEEP_TABLE
from simparity.core.model.files import tomllib

ROOT = Path(__file__).resolve().parents[2]
DOCUMENTS = sorted((ROOT / "docs").rglob("*.md")) + [ROOT / "README.md"]
FENCE = re.compile(r"^```toml[ \t]*\n(.*?)^```[ \t]*$", re.DOTALL | re.MULTILINE)
FRAGMENT_MARK = re.compile(r"<!--\s*fragment\b[^>]*-->\Z")
"""The marker of an incomplete example: the last thing before its fence (blank lines aside)."""

MIN_SCENES = 4
"""Complete scene examples the docs hold today (docs/scenes.md: dynamics, kinematics, IK, sweep): fewer found
means the extraction broke, not that the docs got shorter."""
MIN_TOLERANCES = 2
"""Complete tolerances examples today (docs/check.md)."""
MIN_FRAGMENTS = 5
"""Examples marked as fragments today (docs/scenes.md: contact, point masses, two [chain]s; docs/plugins.md)."""

EXPECTED_FAILURES: dict[str, str] = {}
"""``path:line`` of an example of a document this change may not edit (docs/check.md) that does not load, with
why: held as an expected failure until its owner fixes it. Empty: every example loads."""


@dataclass(frozen=True)
class Example:
    """One fenced TOML block: where it is (``docs/x.md:LINE``, the fence's line), its text, and whether the
    docs mark it as a fragment."""

    where: str
    text: str
    fragment: bool

    @property
    def is_tolerances(self) -> bool:
        return "bound" in tomllib.loads(self.text)


def examples_in(markdown: str, where: str) -> list[Example]:
    """The fenced ```toml blocks of ``markdown`` (the text of the document ``where``), in order."""
    examples = []
    for match in FENCE.finditer(markdown):
        line = markdown.count("\n", 0, match.start()) + 1
        marked = FRAGMENT_MARK.search(markdown[: match.start()].rstrip()) is not None
        examples.append(Example(f"{where}:{line}", match.group(1), marked))
    return examples


EXAMPLES = [example for path in DOCUMENTS
            for example in examples_in(path.read_text(encoding="utf-8"), str(path.relative_to(ROOT)))]
COMPLETE = [example for example in EXAMPLES if not example.fragment]


def _param(example: Example):
    reason = EXPECTED_FAILURES.get(example.where)
    marks = [pytest.mark.xfail(reason=reason, strict=True)] if reason else []
    return pytest.param(example, id=example.where, marks=marks)


def test_the_extraction_finds_the_examples():
    """So that a broken extraction (a renamed fence, a moved folder) fails instead of testing nothing."""
    scenes = [example for example in COMPLETE if not example.is_tolerances]
    tolerances = [example for example in COMPLETE if example.is_tolerances]
    assert len(scenes) >= MIN_SCENES and len(tolerances) >= MIN_TOLERANCES
    assert len(EXAMPLES) - len(COMPLETE) >= MIN_FRAGMENTS


def test_a_fragment_is_marked_on_the_line_before_its_fence_only():
    """The marker counts where it stands right before the fence (blank lines aside), not further up."""
    (marked,) = examples_in("<!-- fragment: part of a scene -->\n\n```toml\na = 1\n```\n", "x.md")
    (unmarked,) = examples_in("<!-- fragment -->\nprose\n```toml\na = 1\n```\n", "x.md")
    assert marked.fragment and not unmarked.fragment
    assert (marked.where, marked.text) == ("x.md:3", "a = 1\n")


@pytest.mark.parametrize("example", [_param(e) for e in COMPLETE])
def test_a_complete_example_loads(tmp_path, example):
    """A scene loads (a file with a [sweep] as its variants) under the name it gives; a tolerances file gives
    one bound per [[bound]] table it holds."""
    data = tomllib.loads(example.text)
    path = tmp_path / "example.toml"
    path.write_text(example.text, encoding="utf-8")
    if example.is_tolerances:
        own = [bound for bound in load_tolerances(path) if bound.where.startswith(str(path))]
        assert len(own) == len(data["bound"])
    elif SWEEP_TABLE in data:
        variants = load_scenes(path)
        assert len(variants) > 1 and all(v.sweep.base == data["scene"]["name"] for v in variants)
    else:
        assert load_scene(path).name == data["scene"]["name"]


@pytest.mark.parametrize("example", [pytest.param(e, id=e.where) for e in EXAMPLES if e.fragment])
def test_a_fragment_is_valid_toml(example):
    assert tomllib.loads(example.text)
