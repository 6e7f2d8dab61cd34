"""The names a scene may give (scenes, bodies, joints, links, end effectors).

Names go into the models handed to the engines and into file names: a restricted character set
keeps them from being read as markup or paths, and a length cap keeps messages and engines sane
(PyBullet crashes on a 50,000-character body name).
"""

from __future__ import annotations

import re

NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.:/-]*")
NAME_MAX = 128
NAME_RULE = f"letters, digits and _ . : / - (not first: . : / -), at most {NAME_MAX} characters"


def name_problem(name: str) -> str | None:
    """What is wrong with a name, or None."""
    if not isinstance(name, str) or not name:
        return "the name is empty"
    if len(name) > NAME_MAX:
        return f"the name is {len(name)} characters long"
    if not NAME_PATTERN.fullmatch(name):
        return f"the name {name!r} has characters outside the allowed set"
    return None
