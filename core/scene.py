"""``simparity.core.scene``: the path plugins import (docs/plugins.md), an alias of the scene types in
:mod:`simparity.core.model.scenes` (one module per kind of scene and per part): a re-export of each."""

from simparity.core.model.scenes.bodies import *  # noqa: F401,F403
from simparity.core.model.scenes.chain import *  # noqa: F401,F403
from simparity.core.model.scenes.chain_contact import *  # noqa: F401,F403
from simparity.core.model.scenes.contact import *  # noqa: F401,F403
from simparity.core.model.scenes.dynamics import *  # noqa: F401,F403
from simparity.core.model.scenes.ik import *  # noqa: F401,F403
from simparity.core.model.scenes.joint_dynamics import *  # noqa: F401,F403
from simparity.core.model.scenes.joint_motion import *  # noqa: F401,F403
from simparity.core.model.scenes.kinematics import *  # noqa: F401,F403
from simparity.core.model.scenes.kinds import *  # noqa: F401,F403
from simparity.core.model.scenes.suites import *  # noqa: F401,F403
from simparity.core.model.scenes.time_functions import *  # noqa: F401,F403
