"""``simparity.core.engine``: the path plugins import (docs/plugins.md), an alias of :mod:`simparity.core.model.engine`."""

from simparity.core.model.engine import *  # noqa: F401,F403  (the public names of the data model)
