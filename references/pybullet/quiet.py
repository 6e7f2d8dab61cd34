"""PyBullet, imported without its "pybullet build time" banner.

The C extension prints the banner through C's stdio (seen on stdout and on stderr depending
on how the streams are attached), so it would land in ``simparity export ... > model.urdf``
and in every log; :func:`references.common.quiet.captured_output` keeps it off. A failing import
still raises as usual.
"""

from __future__ import annotations

from simparity.references.common.quiet import captured_output

with captured_output():
    import pybullet
