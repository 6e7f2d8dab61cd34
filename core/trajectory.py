"""``simparity.core.trajectory``: the path plugins import (docs/plugins.md), an alias of :mod:`simparity.core.model.trajectory`."""

from simparity.core.model.trajectory import *  # noqa: F401,F403  (the public names of the data model)
