"""``simparity.core.results``: the path plugins import (docs/plugins.md), an alias of :mod:`simparity.core.model.results`."""

from simparity.core.model.results import *  # noqa: F401,F403  (the public names of the data model)
