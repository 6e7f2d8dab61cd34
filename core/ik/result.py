"""``simparity.core.ik.result``: the path plugins import (docs/plugins.md), an alias of :mod:`simparity.core.model.ik_result`."""

from simparity.core.model.ik_result import *  # noqa: F401,F403  (the public names of the data model)
