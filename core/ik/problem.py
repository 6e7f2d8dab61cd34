"""``simparity.core.ik.problem``: the path plugins import (docs/plugins.md), an alias of :mod:`simparity.core.model.ik_problem`."""

from simparity.core.model.ik_problem import *  # noqa: F401,F403  (the public names of the data model)
