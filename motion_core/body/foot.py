"""Foot geometry of the HumanML3D skeleton that the procedural rig and the realism check share."""

from __future__ import annotations

import numpy as np

from .skeleton import HUMANML3D

_J = HUMANML3D.joint_names.index

# foot bone (ankle -> toe) lengths, (left, right)
FOOT = (float(HUMANML3D.bone_lengths[_J("left_foot")]), float(HUMANML3D.bone_lengths[_J("right_foot")]))
FOOT_PITCH_FLAT = float(np.arcsin(0.059 / 0.1434))  # toe below the ankle when flat (rad)
