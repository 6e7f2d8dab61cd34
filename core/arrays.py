"""``simparity.core.arrays``: the path plugins import (docs/plugins.md), an alias of :mod:`simparity.core.model.arrays`."""

from simparity.core.model.arrays import *  # noqa: F401,F403  (the public names of the data model)
