"""The staged kinds (motion_core/corpus/kinds): registered one entry each, kept out of what the
models were trained on, realistic, deterministic, and each told apart by its verifier rule."""

from __future__ import annotations

import hashlib

import numpy as np
import pytest

from motion_core.body.features import features_to_joints, joints_to_features
from motion_core.body.skeleton import HUMANML3D
from motion_core.corpus import CATALOGUE, distinct_actions, sample_clip
from motion_core.corpus.actions import REGISTERED, Timeline, sample_spec
from motion_core.corpus.gait import plan_feet
from motion_core.corpus.kinds import REGISTRY, all_kinds, staged_kinds
from motion_core.corpus.kinds.channels import extra
from motion_core.corpus.kinds.check import BUILT_IN_OVERLAPS, OTHER_MAX, OWN_MIN, rule_rates, unexplained
from motion_core.corpus.rig import pose
from motion_core.corpus.text import captions_for
from motion_core.verify.kind_rules import RULES
from motion_core.verify.realism import realism
from motion_core.verify.rules import verify

STAGED = staged_kinds()


def test_staged_kinds_stay_out_of_training():
    assert len(STAGED) >= 40  # the product asks for 40 new kinds
    assert not set(STAGED) & set(CATALOGUE)
    assert all(not REGISTRY[k].trained for k in STAGED)
    assert all(k.split(":")[0] in CATALOGUE for k in distinct_actions())
    rng = np.random.default_rng(0)
    assert all(sample_spec(rng).kind in CATALOGUE for _ in range(500))
    assert all_kinds()[: len(CATALOGUE)] == list(CATALOGUE) and set(STAGED) <= set(all_kinds())
    assert set(all_kinds(staged=False)) == set(CATALOGUE)


def test_every_registered_kind_is_one_complete_entry():
    for name, kind in REGISTRY.items():
        assert REGISTERED[name] is kind and name in RULES
        assert kind.catalogue["variants"] and len(kind.catalogue["dur"]) == 2
        assert len(kind.captions) >= 5 and kind.looks


@pytest.mark.parametrize("kind", STAGED)
def test_staged_kind_is_realistic_verified_and_deterministic(kind):
    for seed in (11, 12, 13):
        clip, spec = sample_clip(np.random.default_rng(seed), kind)
        assert spec.kind == kind and 2.0 <= len(clip.joints) / clip.fps <= 10.05
        again, spec2 = sample_clip(np.random.default_rng(seed), kind)
        assert spec2 == spec and np.array_equal(again.joints, clip.joints)
        j = features_to_joints(joints_to_features(clip.joints))
        r = realism(j)
        assert not r.violations(), (spec, r)
        v = verify(j, spec.labels())
        assert v.passed, (spec, v.checks, v.measures)
        caps = captions_for(spec, np.random.default_rng(seed), 3)
        assert len(set(caps)) == 3 and all("{" not in c for c in caps)
        for side in ("left", "right"):  # side words come from the labels
            if spec.side == side:
                assert all(("right" if side == "left" else "left") not in c for c in caps), caps


def _check(rates: dict, worst_max: float) -> None:
    for kind, r in rates["kinds"].items():
        assert r["own"] >= OWN_MIN, (kind, r)
        assert r["other"] <= OTHER_MAX, (kind, r)
        assert r["other_worst"] <= worst_max, (kind, r)  # every other kind, not just on average
        # at most one clip in 40: the gait's rare fast-start foot lag, which the build's realism
        # rejection regenerates (built-in walks: 7 of 400)
        assert r["realism_violations"] <= rates["clips_per_kind"] // 40, (kind, r)
    # the built-in rules pass no staged kind more often than that either, but for the overlaps
    # check.BUILT_IN_OVERLAPS names (and docs/new-kinds.md explains)
    per = {rule: v["all"] for rule, v in rates["built_in_rules_per_staged_kind"].items()}
    assert not unexplained(per, worst_max), unexplained(per, worst_max)
    assert set(BUILT_IN_OVERLAPS) <= set(CATALOGUE)


def test_rules_tell_each_staged_kind_apart():
    """10 clips of every kind (built-in and staged): each staged rule passes >= 95% of its own
    clips, <= 5% of the other kinds' clips given its labels and at most one clip in ten of any
    one other kind; the built-in rules likewise on the staged clips."""
    _check(rule_rates(10, seed=1, with_old_rules=True), 0.1)


@pytest.mark.long
def test_rules_tell_each_staged_kind_apart_40_clips():
    _check(rule_rates(40, seed=0, with_old_rules=True), OTHER_MAX)


# sha256 of the built-in kinds' clips (one of each, from rng [0, 7919, 1]) and of the first 40
# clips of a corpus build (rng [0, i]), joints rounded to 0.1 micrometre, taken before the kind
# registry's third round of kinds (commit 6b7f982): the shipped models were trained on these.
# The digests depend on the CPU's floating point: the same code at 6b7f982 gives the first pair
# on the machines that set them (and on CI), the second on an AMD EPYC VM with AVX2 and no
# AVX-512 (the cause not pinned down: OpenBLAS's core, numba's target, torch's kernels and
# numpy's AVX2 paths do not change it there). A changed clip changes the digest on either.
BUILT_IN_CLIPS = (
    "cde38dde18b860e124fe52836235cc4436a5fd0bb8661f536ab499e2f9672311",
    "8e6b70ca5be2f3ba1080e4f0e023942c273e9a32cdf8b7957e76aa433295bf2b",
)
BUILD_CLIPS = (
    "a90c558bde59a3c98013ba95d107fa8722f31ecab5730953d0450a29b77d6e56",
    "21178f69e774e1a9fb8d414b2d33db49fbc8683aae15aed884a32e195d136ccc",
)


def test_built_in_clips_are_unchanged():
    """The staged kinds, the posers hook and the extra channels leave every built-in clip as it was."""
    h = hashlib.sha256()
    for kind in CATALOGUE:
        clip, spec = sample_clip(np.random.default_rng([0, 7919, 1]), kind)
        h.update(np.round(clip.joints, 7).tobytes())
        h.update(repr(spec).encode())
    first = h.hexdigest()
    h = hashlib.sha256()
    for i in range(40):
        clip, spec = sample_clip(np.random.default_rng([0, i]))
        h.update(np.round(clip.joints, 7).tobytes())
        h.update(repr(spec).encode())
    # both digests from the same platform: a clip changed on one machine cannot pass as the other's
    assert (first, h.hexdigest()) in zip(BUILT_IN_CLIPS, BUILD_CLIPS, strict=True)


def test_extra_channels_turn_the_head_and_lift_the_shoulders_keeping_bones():
    tl = Timeline.empty(20, 20.0, np.random.default_rng(0))
    ex = extra(tl)
    assert extra(tl) is ex and tl.posers == [ex]  # one per timeline, run by compose after rig.pose
    plan_feet(tl.ch, tl.gait, tl.fps)
    j0 = pose(tl.ch)
    j = j0.copy()
    ex(tl.ch, j)
    assert np.array_equal(j, j0)  # zero channels change nothing
    ex.neck_yaw[:] = 0.8
    for s in ("l", "r"):
        ex.collar_lift[s][:] = 0.5
    ex(tl.ch, j)
    for par, c in HUMANML3D.bones():
        assert np.allclose(np.linalg.norm(j[:, c] - j[:, par], axis=-1), np.linalg.norm(j0[:, c] - j0[:, par], axis=-1))
    for name in ("left", "right"):
        for part in ("shoulder", "elbow", "wrist"):  # the arm goes up with its shoulder
            k = HUMANML3D.index(f"{name}_{part}")
            assert (j[:, k, 1] - j0[:, k, 1]).min() > 0.04
    head = HUMANML3D.index("head")
    assert np.abs(j[:, head, 0] - j0[:, head, 0]).min() > 0.015  # turned (its offset is 2.5 cm long)
