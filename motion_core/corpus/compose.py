"""Compose actions into one continuous clip: timeline -> path -> feet -> pose -> joints."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import gaussian_filter1d

from .actions import POSTURE, REGISTERED, Spec, Timeline, apply, duration_of, hold_posture, sample_spec
from .gait import plan_feet
from .rig import SIDES, make_reachable, pose

FPS = 20.0


@dataclass
class Composed:
    """joints: (T, 22, 3) metres; segments: (start_frame, end_frame, spec), end exclusive."""

    joints: np.ndarray
    segments: list[tuple[int, int, Spec]]
    fps: float = FPS


def _smooth_noise(rng: np.random.Generator, T: int, amp: float, sigma: float = 8.0) -> np.ndarray:
    x = gaussian_filter1d(rng.normal(0.0, 1.0, T), sigma, mode="nearest")
    return amp * x / max(x.std(), 1e-6)


def compose(
    plan: list[tuple[Spec, float]], rng: np.random.Generator, lead: float = 0.4, tail: float = 0.4, fps: float = FPS
) -> Composed:
    """Render (spec, seconds) segments one after another, with idle lead-in and tail.

    Segments that leave a posture (seated, lying) must be followed by the action that
    leaves it; see :func:`sample_sequence`.
    """
    frames = [max(2, round(d * fps)) for _, d in plan]
    n_lead, n_tail = round(lead * fps), round(tail * fps)
    T = n_lead + sum(frames) + n_tail
    tl = Timeline.empty(T, fps, rng)
    segs = []
    t = n_lead
    for (spec, _), n in zip(plan, frames, strict=True):
        apply(spec, tl, t, t + n)
        segs.append((t, t + n, spec))
        t += n
    for i, (_, b, spec) in enumerate(segs):
        if spec.kind in ("sit_down", "lie_down"):
            hold_posture(tl, b - 1, segs[i + 1][0] if i + 1 < len(segs) else T)

    ch = tl.ch
    # Natural variation: body proportions stay fixed, but posture and idle motion differ.
    ch.pelvis_y += rng.uniform(-0.015, 0.01)
    ch.spine_bend += _smooth_noise(rng, T, 0.03) + rng.uniform(-0.03, 0.05)
    ch.spine_side += _smooth_noise(rng, T, 0.02)
    ch.neck_pitch += _smooth_noise(rng, T, 0.05)
    ch.pelvis_roll += _smooth_noise(rng, T, 0.015, 12.0)
    for s in SIDES:
        a = ch.arms[s]
        a.flex += _smooth_noise(rng, T, 0.05) + rng.uniform(-0.05, 0.05)
        a.abduct += _smooth_noise(rng, T, 0.03) + rng.uniform(-0.03, 0.05)
        a.elbow += np.abs(_smooth_noise(rng, T, 0.08)) + rng.uniform(0.0, 0.15)

    # Path: integrate heading and body-frame velocity.
    ch.heading = np.cumsum(tl.yaw_rate) / fps
    h = ch.heading
    v = tl.vel
    world = np.stack([v[:, 0] * np.cos(h) + v[:, 1] * np.sin(h), -v[:, 0] * np.sin(h) + v[:, 1] * np.cos(h)], -1)
    ch.root_xz = np.cumsum(world, axis=0) / fps

    plan_feet(ch, tl.gait, fps, tl.overrides)

    # Arms swing against the legs: the left arm goes forward as the right foot does.
    fwd_dir = np.stack([np.sin(h), np.cos(h)], -1)
    foot_fwd = {s: ((ch.feet[s].ankle[:, [0, 2]] - ch.root_xz) * fwd_dir).sum(-1) for s in SIDES}
    swing = gaussian_filter1d(tl.arm_swing * (foot_fwd["r"] - foot_fwd["l"]), 1.0)
    ch.arms["l"].flex += swing
    ch.arms["r"].flex -= swing
    ch.spine_twist += -0.15 * swing

    # The pelvis may sit off the path (seated, squatting, lunging): body-frame offset.
    off = tl.pelvis_offset
    ch.root_xz = ch.root_xz + np.stack(
        [off[:, 0] * np.cos(h) + off[:, 1] * np.sin(h), -off[:, 0] * np.sin(h) + off[:, 1] * np.cos(h)], -1
    )
    make_reachable(ch)
    ch.pelvis_y = np.maximum(ch.pelvis_y, 0.1)
    for finish in tl.finishers:
        finish(ch)
    joints = pose(ch)
    for post in tl.posers:
        post(ch, joints)
    return Composed(joints=joints, segments=segs, fps=fps)


def sample_clip(
    rng: np.random.Generator, kind: str | None = None, kinds: list[str] | None = None
) -> tuple[Composed, Spec]:
    """One single-action clip of 2-10 s (idle lead-in and tail included), of ``kind`` or of one
    drawn from ``kinds`` (default CATALOGUE)."""
    spec = sample_spec(rng, kind, kinds)
    dur = duration_of(spec, rng)
    lead, tail = rng.uniform(0.2, 0.6), rng.uniform(0.2, 0.6)
    dur = min(dur, 10.0 - lead - tail)
    if spec.kind in REGISTERED and REGISTERED[spec.kind].owns_clip:
        # A floor kind (push-ups, crawling) starts and ends in its own posture: its generator
        # writes the whole clip, holding that posture at both ends instead of idle standing.
        return compose([(spec, dur + lead + tail)], rng, 0.0, 0.0), spec
    before = {"stand_up": "sit_down", "get_up": "lie_down"}.get(spec.kind)
    if before is None:
        return compose([(spec, dur)], rng, lead, tail), spec
    # Clips that start seated or lying: render the way down too, then keep only the lead-in
    # (holding the posture) and the action, so the clip starts at rest in that posture.
    pre = Spec(before)
    full = compose([(pre, duration_of(pre, rng)), (spec, dur)], rng, 0.2, tail)
    start = full.segments[1][0] - round(lead * full.fps)
    seg = (full.segments[1][0] - start, full.segments[1][1] - start, spec)
    return Composed(joints=full.joints[start:], segments=[seg], fps=full.fps), spec


def sample_sequence(rng: np.random.Generator, n_segments: int, max_seconds: float = 40.0) -> Composed:
    """A BABEL-style sequence of 3-6 actions, respecting postures (sit down -> stand up...)."""
    plan: list[tuple[Spec, float]] = []
    total = 0.0
    posture = "standing"
    while len(plan) < n_segments:
        if posture == "sitting":
            spec = Spec("stand_up")
        elif posture == "lying":
            spec = Spec("get_up")
        else:
            spec = sample_spec(rng)
            if spec.kind in ("stand_up", "get_up"):
                continue
            if len(plan) == n_segments - 1 and spec.kind in ("sit_down", "lie_down"):
                continue
        d = duration_of(spec, rng)
        if total + d > max_seconds - 1.0:
            break
        plan.append((spec, d))
        total += d
        posture = POSTURE.get(spec.kind, (posture, posture))[1]
    while posture != "standing" and plan:  # never end a sequence seated or lying
        last = plan.pop()
        total -= last[1]
        posture = (
            "standing" if all(POSTURE.get(s.kind, ("", "standing"))[1] == "standing" for s, _ in plan[-1:]) else posture
        )
    return compose(plan, rng, rng.uniform(0.2, 0.5), rng.uniform(0.2, 0.5))
