"""The names a scene may give (scenes, bodies, joints, links, end effectors), and its free text.

Names go into the models handed to the engines and into file names: a restricted character set
keeps them from being read as markup or paths, and a length cap keeps messages and engines sane
(PyBullet crashes on a 50,000-character body name).
"""

from __future__ import annotations

import re
import unicodedata

NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.:/-]*")
"""ASCII letters, digits and ``_ . : / -``, not starting with ``. : / -``: every name in the
built-in scenes and in the 1,161 URDF files of example-robot-data and pybullet_data fits."""
NAME_MAX = 128
"""Characters in a name."""
NAME_RULE = f"letters, digits and _ . : / - (not first: . : / -), at most {NAME_MAX} characters"

TEXT_MAX = 500
"""Characters of free text (a scene's description): one sentence for a listing and a report."""
TEXT_RULE = f"one line of printable text, at most {TEXT_MAX} characters"


def name_problem(name: str) -> str | None:
    """What is wrong with a name, or None."""
    if not isinstance(name, str) or not name:
        return "the name is empty"
    if len(name) > NAME_MAX:
        return f"the name is {len(name)} characters long"
    if not NAME_PATTERN.fullmatch(name):
        return f"the name {name!r} has characters outside the allowed set"
    return None


def text_problem(text: str) -> str | None:
    """What is wrong with free text (a description), or None: it must stay one printable line."""
    if len(text) > TEXT_MAX:
        return f"the text is {len(text):,} characters long"
    hidden = next((c for c in text if unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp")), None)
    if hidden is not None:
        return f"the text holds the control character {hidden!r}"
    return None
