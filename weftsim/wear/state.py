"""What a stored wear state is: its file name, its response columns, the scene identity it must match, and the
error of a state that cannot be resumed.

Read by :mod:`weftsim.wear.store` (which writes the state) and :mod:`weftsim.wear.resume` (which reads it back as
untrusted input), so that neither imports the other's caller: the store calls the reader, one way.
"""

from __future__ import annotations

import json
from typing import TYPE_CHECKING

from weftsim.errors import WearError

if TYPE_CHECKING:
    from weftsim.params import Scene

STATE = "wear_state.npz"
RESPONSE = ("rapier_acceleration_rms_m_s2", "rapier_acceleration_p99_m_s2", "driving_torque_rms_Nm",
            "driving_torque_p99_Nm", "contact_force_mean_N", "contact_force_p99_N", "contact_force_max_N",
            "solver_rtol", "film_ratio_min", "film_ratio_mean", "mixed_fraction", "sliding_distance_per_rev_m",
            "sliding_work_per_rev_J", "contact_force_sliding_mean_N", "backoffs_after")


class StateMismatch(WearError):
    """The directory's stored state cannot be resumed: another scene or other wear settings, a damaged
    or edited file (:mod:`weftsim.wear.resume`), or more hours than asked for."""


def scene_identity(scene: Scene) -> str:
    """The scene's file keys as canonical JSON: what a stored state must match to be resumed."""
    from weftsim.scene import to_file_keys

    return json.dumps(to_file_keys(scene), sort_keys=True, default=str)
