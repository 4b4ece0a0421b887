"""Foot locking: planted feet stop sliding, legs stay rigid, nothing jumps."""

from __future__ import annotations

import numpy as np
import pytest

from motion_core.body.features import features_to_joints
from motion_core.body.footlock import (
    FootLockConfig,
    _reachable,
    _smoothstep,
    contact_phases,
    foot_offsets,
    lock_feet,
    two_bone_ik,
)
from motion_core.body.skeleton import HUMANML3D

LEFT_ANKLE, LEFT_TOE = HUMANML3D.feet[0]
LEFT_KNEE = HUMANML3D.parents[LEFT_ANKLE]
LEFT_HIP = HUMANML3D.parents[LEFT_KNEE]
LEG = {LEFT_KNEE, LEFT_ANKLE, LEFT_TOE, *(j for pair in HUMANML3D.feet for j in pair)}
LEG |= {HUMANML3D.parents[a] for a, _ in HUMANML3D.feet}


def bone_lengths(j: np.ndarray) -> np.ndarray:
    """(T, J-1) lengths of every bone."""
    return np.stack([np.linalg.norm(j[:, c] - j[:, p], axis=-1) for c, p in enumerate(HUMANML3D.parents) if p >= 0], 1)


def phase_slides(j: np.ndarray, toe: int, phases: list[tuple[int, int]]) -> list[float]:
    return [float(np.linalg.norm(j[s:e, toe][:, [0, 2]] - j[s, toe][[0, 2]], axis=-1).max()) for s, e in phases]


@pytest.fixture(scope="module")
def sliding(real_features: np.ndarray) -> dict:
    """The real fixture motion with its left foot made to slide 4 mm a frame (0.08 m/s)
    through each of its plants, the knee re-solved so that the leg stays rigid."""
    j = features_to_joints(real_features.astype(np.float64))
    phases = contact_phases(j, LEFT_TOE)
    assert len(phases) >= 3
    drift = np.zeros((len(j), 3))
    for s, e in phases:
        drift[s:e, 0] = 0.004 * (np.arange(s, e) - (s + e) / 2)
    thigh = float(np.linalg.norm(j[0, LEFT_KNEE] - j[0, LEFT_HIP]))
    shin = float(np.linalg.norm(j[0, LEFT_ANKLE] - j[0, LEFT_KNEE]))
    out = j.copy()
    knee, ankle = two_bone_ik(j[:, LEFT_HIP], j[:, LEFT_KNEE], j[:, LEFT_ANKLE] + drift, thigh, shin)
    out[:, LEFT_KNEE], out[:, LEFT_ANKLE] = knee, ankle
    out[:, LEFT_TOE] = ankle + (j[:, LEFT_TOE] - j[:, LEFT_ANKLE])
    return {"joints": out, "phases": phases}


def test_two_bone_ik_reaches_the_target_with_the_bone_lengths_kept() -> None:
    rng = np.random.default_rng(0)
    hip = rng.normal(size=(50, 3))
    knee = hip + rng.normal(size=(50, 3))
    target = hip + rng.normal(size=(50, 3)) * 0.5
    k, a = two_bone_ik(hip, knee, target, 0.45, 0.42)
    np.testing.assert_allclose(np.linalg.norm(k - hip, axis=-1), 0.45, atol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(a - k, axis=-1), 0.42, atol=1e-9)
    reach = np.linalg.norm(target - hip, axis=-1)
    ok = (reach < 0.87) & (reach > 0.03)
    np.testing.assert_allclose(a[ok], target[ok], atol=1e-9)


def test_a_sliding_planted_foot_is_locked_and_the_skeleton_stays_rigid(sliding: dict) -> None:
    j = sliding["joints"]
    before = phase_slides(j, LEFT_TOE, sliding["phases"])
    res = lock_feet(j)
    after = phase_slides(res.joints, LEFT_TOE, sliding["phases"])
    assert np.mean(before) > 0.02  # the input really slides (cm, not mm)
    assert np.mean(after) < 0.2 * np.mean(before), (np.mean(before), np.mean(after))
    # rigid: every bone keeps its length in every frame
    # (to 1e-6: the fixture's own bones vary by 2.5e-7 m over the clip; the IK uses their mean)
    np.testing.assert_allclose(bone_lengths(res.joints), bone_lengths(j), atol=1e-6)
    # only leg joints below the hips move
    untouched = [i for i in range(22) if i not in LEG]
    np.testing.assert_array_equal(res.joints[:, untouched], j[:, untouched])
    # no jump: no joint moves faster in a frame than before plus the ramp's allowance
    cfg = FootLockConfig()
    step_before = np.linalg.norm(np.diff(j, axis=0), axis=-1).max()
    step_after = np.linalg.norm(np.diff(res.joints, axis=0), axis=-1).max()
    assert step_after <= step_before + 1.5 * cfg.ramp_speed / cfg.fps + 1e-6


def test_a_plant_the_leg_cannot_reach_is_left_alone(real_features: np.ndarray) -> None:
    """A standing body gliding 1 m at 0.1 m/s: its toes are 'slow and low' throughout, but
    holding them still would need legs 50 cm longer."""
    j0 = features_to_joints(real_features.astype(np.float64))[:1]
    j = np.repeat(j0, 200, axis=0)
    j[:, :, 2] += np.linspace(0, 1.0, 200)[:, None]
    res = lock_feet(j)
    np.testing.assert_array_equal(res.joints, j)
    assert res.phases == {"left": [], "right": []}


def _offsets_phase_by_phase(
    joints: np.ndarray, toe: int, phases: list[tuple[int, int]], cfg: FootLockConfig
) -> np.ndarray:
    """The reference form of ``foot_offsets``: the loop it was until 2026-11-29, verbatim,
    each phase's correction built on its own and the ramps averaged."""
    T = len(joints)
    total = np.zeros((T, 3))
    weight = np.zeros(T)
    t = np.arange(T)
    for s, e in phases:
        anchor = joints[s:e, toe].mean(0)
        d = np.zeros((T, 3))
        d[:, [0, 2]] = anchor[[0, 2]] - joints[:, toe][:, [0, 2]]
        d[:s] = d[s]
        d[e:] = d[e - 1]
        b_in, b_out = (
            max(cfg.blend, int(np.ceil(1.5 * np.linalg.norm(d[i]) * cfg.fps / cfg.ramp_speed)), 1) for i in (s, e - 1)
        )
        w = np.where(
            t < s,
            _smoothstep(1 - (s - t) / (b_in + 1)),
            np.where(t >= e, _smoothstep(1 - (t - e + 1) / (b_out + 1)), 1.0),
        )
        total += w[:, None] * d
        weight += w
    return total / np.maximum(weight, 1.0)[:, None]


@pytest.mark.parametrize("cfg", [FootLockConfig(), FootLockConfig(blend=0, ramp_speed=0.1)])
def test_all_phases_at_once_equal_the_phase_by_phase_offsets(cfg: FootLockConfig) -> None:
    """``foot_offsets`` builds every phase's ramp as one (P, T) array (a walk's
    plants cost a fast-sampler motion a fifth of its time in a loop); the arithmetic is the
    loop's. Phases close enough for their ramps to overlap, at the clip's ends, one frame long."""
    rng = np.random.default_rng(0)
    j = np.cumsum(rng.normal(0, 0.02, (120, HUMANML3D.n_joints, 3)), axis=0)
    phases = [(0, 4), (7, 19), (21, 22), (40, 70), (74, 80), (111, 120)]
    got = foot_offsets(j, LEFT_TOE, phases, cfg)
    np.testing.assert_array_equal(got, _offsets_phase_by_phase(j, LEFT_TOE, phases, cfg))
    assert np.abs(got[:, [0, 2]]).max() > 0.05 and not got[:, 1].any()
    assert not foot_offsets(j, LEFT_TOE, [], cfg).any()


def test_the_reach_check_of_all_phases_at_once_keeps_the_phase_by_phase_ones() -> None:
    """``_reachable`` tests every plant at once: a plant is kept where its locked ankle (the
    anchor minus the toe added, as ``foot_offsets`` does inside a phase) stays within reach of
    the hip, exactly as the loop over phases decided it."""
    rng = np.random.default_rng(1)
    j = np.cumsum(rng.normal(0, 0.02, (150, HUMANML3D.n_joints, 3)), axis=0)
    phases = [(0, 6), (10, 11), (20, 45), (60, 61), (80, 120), (140, 150)]
    far = []
    for s, e in phases:
        target = j[s:e, LEFT_ANKLE] + _offsets_phase_by_phase(j[s:e], LEFT_TOE, [(0, e - s)], FootLockConfig())
        far.append(np.linalg.norm(target - j[s:e, LEFT_HIP], axis=-1).max())
    reach = float(np.median(far))
    want = [p for p, f in zip(phases, far, strict=True) if f <= reach]
    assert 0 < len(want) < len(phases)
    assert _reachable(j, LEFT_HIP, LEFT_ANKLE, LEFT_TOE, phases, reach) == want
    assert _reachable(j, LEFT_HIP, LEFT_ANKLE, LEFT_TOE, [], reach) == []
