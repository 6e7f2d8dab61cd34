"""Modules stay small enough to read (issue #40): none of the package's over :data:`MAX_LINES` lines unless its
docstring says why (:data:`REASON`)."""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LAYERS = ("core", "references", "comparisons", "reports")
MAX_LINES = 600
"""Lines a module stays within (issue #40): past it a module usually glues several concepts."""
REASON = "Over 600 lines:"
"""How a longer module's docstring starts its reason (``Over 600 lines: one engine's adapter ...``)."""


@pytest.mark.parametrize("layer", LAYERS)
def test_no_module_is_long_without_a_reason(layer):
    long = []
    for path in sorted((ROOT / layer).rglob("*.py")):
        text = path.read_text(encoding="utf-8")
        docstring = ast.get_docstring(ast.parse(text)) or ""
        if text.count("\n") > MAX_LINES and REASON not in docstring:
            long.append(f"{path.relative_to(ROOT)}: {text.count(chr(10))} lines")
    assert not long, f"modules over {MAX_LINES} lines whose docstring gives no reason ({REASON!r} ...): {long}"
