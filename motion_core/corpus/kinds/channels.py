"""Channels the rig does not drive: the head turned on the neck, the shoulders raised.

``rig.pose`` places the head from the neck by the chest's frame and the neck's pitch only, and
the shoulders rigidly on the chest: it has no neck yaw and no collar channel. Rather than a
second copy of its forward kinematics, these two act on its joints afterwards (a
``Timeline.posers`` entry, which compose runs right after ``rig.pose``), about the skeleton's
own joints with its own rest offsets (``rig.OFF``, read from ``body/skeleton.HUMANML3D``), in
the chest frame that ``rig.pose`` used (``ik.chest_frame``):

- ``neck_yaw`` turns the head's bone (neck to head) about the chest's up axis, inside the
  neck's pitch, as a yaw joint between the chest and the nod would (+: to the body's left);
- ``collar_lift[side]`` turns the collar's bone (collar to shoulder) up about the chest's
  forward axis at the collar joint (a shrug), and the arm below goes with its shoulder
  without turning: the shoulder blade slides up, the arm hangs the way its channels say.

Every bone keeps its length exactly. A kind that also puts a hand on a target (ik.py) solves
it on ``rig.pose``'s shoulders, so it should not lift that arm's collar at the same time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..actions import Timeline
from ..rig import OFF, SIDES, SIGN, Channels, J, _mv, rot_x, rot_y, rot_z
from .ik import SIDE_NAME, chest_frame


@dataclass
class Extra:
    """The extra channels of one clip, each (T,) radians."""

    neck_yaw: np.ndarray
    collar_lift: dict[str, np.ndarray]

    def __call__(self, ch: Channels, joints: np.ndarray) -> None:
        """Apply them to rig.pose's joints of the same channels, in place."""
        R3 = chest_frame(ch)
        if np.any(self.neck_yaw):
            nod = R3 @ rot_y(self.neck_yaw) @ rot_x(ch.neck_pitch)
            joints[:, J("head")] = joints[:, J("neck")] + _mv(nod, OFF[J("head")])
        for s in SIDES:
            lift = self.collar_lift[s]
            if not np.any(lift):
                continue
            name = SIDE_NAME[s]
            sh = J(f"{name}_shoulder")
            raised = joints[:, J(f"{name}_collar")] + _mv(R3 @ rot_z(SIGN[s] * lift), OFF[sh])
            moved = raised - joints[:, sh]
            for k in ("shoulder", "elbow", "wrist"):
                joints[:, J(f"{name}_{k}")] += moved


def extra(tl: Timeline) -> Extra:
    """The timeline's extra channels: zero, and registered as its poser, on first use."""
    for p in tl.posers:
        if isinstance(p, Extra):
            return p
    T = tl.ch.T
    ex = Extra(neck_yaw=np.zeros(T), collar_lift={s: np.zeros(T) for s in SIDES})
    tl.posers.append(ex)
    return ex
