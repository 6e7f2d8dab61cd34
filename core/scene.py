"""``simparity.core.scene``: the path plugins import (docs/plugins.md), an alias of :mod:`simparity.core.model.scene`."""

from simparity.core.model.scene import *  # noqa: F401,F403  (the public names of the data model)
