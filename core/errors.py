"""``simparity.core.errors``: the path plugins import (docs/plugins.md), an alias of :mod:`simparity.core.model.errors`."""

from simparity.core.model.errors import *  # noqa: F401,F403  (the public names of the data model)
