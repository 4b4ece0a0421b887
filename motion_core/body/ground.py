"""A body that stands on the floor at every frame, not only at its lowest one.

Decoded motions drift vertically by a few centimetres: the root height and the leg chain
each carry some error, and rigid bones move the feet again. Putting the clip's lowest foot
point on y = 0 (one shift for the whole clip) then leaves most frames hovering, and a walk
whose stance foot hovers 5 cm up has both feet "in the air" for tens of frames. Every
method's real-clip walks failed the verifier's no-flight rule that way while ground truth
passed all of them (docs/training-log.md, 2026-11-26).

The fix, per frame:

1. **Support frames**: the lowest foot point (ankles and toes) is near the floor, under
   ``height`` above the clip's lowest, and the slowest foot point moves slower than
   ``speed``: a foot bears weight there.
2. **Drop**: on a support frame the body is lowered by the lowest foot point's height, so
   that foot touches y = 0; between support frames (a jump's flight, a run's float) the
   drop is interpolated linearly from the support frames either side, so the flight keeps
   its own height over the ground. The drop is at most ``max_shift`` and never lowers a
   foot below the floor.
3. The whole body moves by the drop: the pose, and so every verifier reading other than
   heights, is untouched.

Chosen on validation prompts (``tools/ground_check.py``, ``results/ground_choice.json``):
on 1,000 procedural and 149 real validation clips the defaults change no ground-truth
verdict, a centimetre below the height where real hops began to flatten (8 cm) and below the
speed where a real run lost a flight (0.45 m/s), and they raise all four methods' pass rates
on both sources. Smoothing the drop let the stance foot hover again at the ends of each
support run. Real motion moves too: its stance toes wander 0-4 cm over the floor, and here
they touch it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .skeleton import HUMANML3D, Skeleton


@dataclass(frozen=True)
class GroundConfig:
    # m above the clip's lowest foot point: a lower foot may bear weight. At 8 cm the low
    # flights of real one-foot hops (6-8 cm) counted as support and were flattened
    height: float = 0.06
    # m/s: the slowest foot point (3D) moves slower than this on a support frame (a planted
    # foot; the foot lock's plants are under 0.35). At 0.45 and more a real run's slow,
    # low flight counted as support
    speed: float = 0.3
    max_shift: float = 0.2  # m: the most a frame is lowered (a correction, not a new motion)
    fps: float = 20.0


def support_frames(
    joints: np.ndarray, skeleton: Skeleton = HUMANML3D, cfg: GroundConfig = GroundConfig()
) -> np.ndarray:
    """(T,) bool: frames where a foot bears weight. joints: (T, J, 3), y up, the clip's
    lowest foot point at y = 0."""
    feet = [i for pair in skeleton.feet for i in pair]
    p = joints[:, feet]  # (T, 4, 3)
    low = p[..., 1].min(1)
    v = np.zeros(len(p))
    if len(p) > 1:
        step = np.linalg.norm(np.diff(p, axis=0), axis=-1).min(1) * cfg.fps
        # a frame's speed is the slower of its two steps, so the first and last frame of a
        # plant count although the foot moves on one side of them
        v[:-1] = step
        v[1:] = np.minimum(v[1:], step)
    return (low < cfg.height) & (v < cfg.speed)


def ground(joints: np.ndarray, skeleton: Skeleton = HUMANML3D, cfg: GroundConfig = GroundConfig()) -> np.ndarray:
    """The motion lowered frame by frame so that a weight-bearing foot touches y = 0.

    Args: joints (T, J, 3), y up. Returns (T, J, 3), the same dtype, with no foot point below
    y = 0 and the lowest one over the clip on it.
    """
    feet = [i for pair in skeleton.feet for i in pair]
    j = joints - np.array([0.0, joints[:, feet, 1].min(), 0.0], dtype=joints.dtype)
    low = j[:, feet, 1].min(1)
    support = support_frames(j, skeleton, cfg)
    if not support.any():
        return j
    t = np.arange(len(j))
    drop = np.interp(t, t[support], low[support])  # held constant before the first / after the last
    drop = np.minimum(np.clip(drop, 0.0, cfg.max_shift), low)
    out = j.copy()
    out[..., 1] -= drop[:, None].astype(j.dtype)
    return out
