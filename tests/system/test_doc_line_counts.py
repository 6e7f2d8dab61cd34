"""ARCHITECTURE.md's claims of a module's size hold: "`main.py` (…; ≤ N lines)" in a folder's row is measured."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LAYERS = ("core", "references", "comparisons", "reports")
"""The package's folders, where a claimed module lives (not a build/ or a virtual environment's copy)."""
# "`name.py` (… ≤ N lines" within one parenthesis, in a table row whose first cell is the folder ("| `cli/` |").
CLAIM = re.compile(r"`(?P<name>[\w/]+\.py)` \([^()]*?≤ (?P<lines>\d+) lines")
ROW_FOLDER = re.compile(r"^\| `(?P<folder>[\w/]+)/` \|")


def claims(text: str) -> list[tuple[int, str, str, int]]:
    """(line, folder or "", module name, claimed most lines) of each size claim in ``text``."""
    found = []
    for number, line in enumerate(text.splitlines(), start=1):
        row = ROW_FOLDER.match(line)
        for match in CLAIM.finditer(line):
            found.append((number, row.group("folder") if row else "", match.group("name"), int(match.group("lines"))))
    return found


def test_a_claim_is_read_from_a_folder_row():
    assert claims("| `cli/` | `main.py` (each command: parse, call, print; ≤ 600 lines), `x.py` (y) |") == [
        (1, "cli", "main.py", 600)
    ]


def test_architecture_line_counts_hold():
    text = (ROOT / "ARCHITECTURE.md").read_text(encoding="utf-8")
    found = claims(text)
    assert found, "ARCHITECTURE.md claims no module's size: this test reads nothing (update its pattern)"
    for number, folder, name, most in found:
        modules = [path for layer in LAYERS
                   for path in (ROOT / layer).glob(f"**/{folder}/{name}" if folder else f"**/{name}")]
        assert len(modules) == 1, f"ARCHITECTURE.md:{number}: `{name}` names {len(modules)} modules: {modules}"
        lines = len(modules[0].read_text(encoding="utf-8").splitlines())
        assert lines <= most, f"ARCHITECTURE.md:{number}: `{name}` claimed ≤ {most} lines, has {lines}"
