"""The built-in corpus: realism bounds, verifier accuracy, determinism, on-disk format."""

from __future__ import annotations

import json

import numpy as np
import pytest

from motion_core.body.features import features_to_joints, joints_to_features
from motion_core.body.skeleton import HUMANML3D
from motion_core.corpus import (
    CATALOGUE,
    Spec,
    captions_for,
    compose,
    distinct_actions,
    sample_clip,
    sample_sequence,
)
from motion_core.corpus.__main__ import main as corpus_main
from motion_core.data import BabelSegments, HumanML3DDataset
from motion_core.verify.realism import BOUNDS, realism
from motion_core.verify.rules import verify


def test_at_least_40_distinct_actions():
    acts = distinct_actions()
    assert len(acts) >= 40, acts
    kinds = set(CATALOGUE)
    for required in [
        "walk",
        "jog",
        "run",
        "sidestep",
        "walk_backward",
        "turn",
        "circle",
        "raise_arm",
        "wave",
        "punch",
        "reach",
        "clap",
        "throw",
        "kick",
        "step_over",
        "lunge",
        "squat",
        "hop",
        "jump_up",
        "jump_forward",
        "jumping_jacks",
        "sit_down",
        "stand_up",
        "kneel",
        "lie_down",
        "get_up",
        "bow",
        "stretch",
        "turn_around",
    ]:
        assert required in kinds


@pytest.mark.parametrize("kind", sorted(CATALOGUE))
def test_every_action_is_realistic_and_verifiable(kind):
    """Two seeds of every action, through features and back: within bounds and verified."""
    for seed in (11, 12):
        clip, spec = sample_clip(np.random.default_rng(seed), kind)
        assert 2.0 <= len(clip.joints) / clip.fps <= 10.05
        j = features_to_joints(joints_to_features(clip.joints))
        r = realism(j)
        assert not r.violations(), (spec, r)
        v = verify(j, spec.labels())
        assert v.passed, (spec, v.checks, v.measures)


def test_realism_figures_catch_defects():
    """The check is not vacuous: skating, penetration and stretched bones are all caught."""
    clip, _ = sample_clip(np.random.default_rng(3), "raise_arm")
    j = clip.joints.copy()
    j[..., 1] -= j[..., 1].min()
    assert not realism(j).violations()
    skate = j.copy()
    skate[:, [7, 10], 0] += np.linspace(0, 0.2, len(j))[:, None]  # left foot drifts 20 cm while planted
    assert "foot_slide_m" in " ".join(realism(skate).violations())
    sunk = j.copy()
    sunk[:, 11, 1] -= 0.05
    assert "penetration_m" in " ".join(realism(sunk).violations())
    # A body sinking through the floor is caught although the format's y = 0 is its lowest joint.
    kneel_through = j.copy()
    kneel_through[:, 4, 1] = -0.3  # the left knee 30 cm under the floor the feet stand on
    kneel_through[..., 1] -= kneel_through[..., 1].min()
    assert "penetration_m" in " ".join(realism(kneel_through).violations())
    stretched = j.copy()
    stretched[:, 20] += 0.03
    assert "bone_dev_m" in " ".join(realism(stretched).violations())


def test_left_right_and_direction_words_follow_the_motion():
    rng = np.random.default_rng(0)
    for side in ("left", "right"):
        spec = Spec("raise_arm", side=side)
        comp = compose([(spec, 3.0)], rng)
        j = comp.joints
        w = {s: j[:, HUMANML3D.index(f"{s}_wrist"), 1].max() for s in ("left", "right")}
        other = "right" if side == "left" else "left"
        assert w[side] > w[other] + 0.4
        # the raised wrist is on the body's own side (+x is the left when facing +z)
        t = j[:, HUMANML3D.index(f"{side}_wrist"), 1].argmax()
        x = j[t, HUMANML3D.index(f"{side}_wrist"), 0] - j[t, 0, 0]
        assert (x > 0) == (side == "left")
        for cap in captions_for(spec, rng, 3):
            assert side in cap and other not in cap
    for d, sign in (("left", 1), ("right", -1)):
        comp = compose([(Spec("walk", direction=d), 5.0)], rng)
        disp = comp.joints[-1, 0] - comp.joints[0, 0]
        assert np.sign(disp[0]) == sign and abs(disp[0]) > abs(disp[2])  # started facing +z
        assert all(("left" in c) == (d == "left") for c in captions_for(Spec("walk", direction=d), rng, 3))


def test_determinism():
    a, sa = sample_clip(np.random.default_rng([7, 42]))
    b, sb = sample_clip(np.random.default_rng([7, 42]))
    assert sa == sb and np.array_equal(a.joints, b.joints)


def test_sequences_are_continuous_and_respect_postures():
    for seed in range(3):
        comp = sample_sequence(np.random.default_rng(seed), 5)
        assert 3 <= len(comp.segments) <= 6
        kinds = [s.kind for _, _, s in comp.segments]
        for i, k in enumerate(kinds):
            if k == "sit_down":
                assert kinds[i + 1] == "stand_up"
            if k == "lie_down":
                assert kinds[i + 1] == "get_up"
        j = comp.joints
        v = np.diff(j, axis=0) * comp.fps
        acc = np.linalg.norm(np.diff(v, axis=0), axis=-1).max(-1) * comp.fps
        bounds = [a for a, _, _ in comp.segments[1:]]
        near = np.concatenate([acc[max(0, b - 3) : b + 3] for b in bounds])
        # a join is no harsher than the motion inside the segments
        assert near.max() <= np.percentile(acc, 99.5) + 1e-6
        for a, b, spec in comp.segments:
            assert verify(j[a:b], spec.labels()).passed, spec


def test_built_corpus_format_and_splits(built):
    summary = json.loads((built / "corpus.json").read_text())
    assert summary["clips"] == {"train": 240, "val": 10, "test": 200}
    assert summary["distinct_actions"] >= 40
    train = HumanML3DDataset(built, "train")
    test = HumanML3DDataset(built, "test")
    assert len(train) == 240 and len(test) == 200
    assert not set(train.ids) & set(test.ids)
    s = test[0]
    assert s.features.shape[1] == 263 and 40 <= len(s) <= 200
    assert len(s.captions) == 3 and len({c.text for c in s.captions}) == 3
    norm = train.normalizer()
    assert norm.dim == 263 and np.isfinite(norm.normalize(s.features)).all()
    rows = [json.loads(x) for x in (built / "labels.jsonl").read_text().splitlines()]
    assert all(r["source"] == "procedural" and "kind" in r["labels"] for r in rows)
    seqs = list(BabelSegments(built / "babel" / "test.json"))
    assert len(seqs) == 10
    for m in seqs:
        assert 3 <= len(m.segments) <= 6
        assert 10.0 <= len(m.features) / m.fps <= 40.0 or len(m.segments) >= 3


def test_build_is_deterministic_and_independent_of_workers(built, tmp_path):
    rc = corpus_main(
        [
            "build",
            str(tmp_path),
            "--train",
            "5",
            "--val",
            "0",
            "--test",
            "0",
            "--seq-train",
            "0",
            "--seq-val",
            "0",
            "--seq-test",
            "0",
            "--workers",
            "1",
        ]
    )
    assert rc == 0
    for cid in ("000000", "000004"):
        assert (tmp_path / "new_joint_vecs" / f"{cid}.npy").read_bytes() == (
            built / "new_joint_vecs" / f"{cid}.npy"
        ).read_bytes()
        assert (tmp_path / "texts" / f"{cid}.txt").read_text() == (built / "texts" / f"{cid}.txt").read_text()


def test_check_command_passes_on_the_corpus(built, capsys):
    assert corpus_main(["check", str(built), "--workers", "2"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["violations"] == 0
    for k, bound in BOUNDS.items():
        worst = out["clips"][k]["worst"]
        assert (worst >= bound) if k == "penetration_m" else (worst <= bound)


def test_check_command_fails_on_a_broken_clip(built, tmp_path, capsys):
    import shutil

    bad = tmp_path / "bad"
    shutil.copytree(built, bad)
    rows = [json.loads(x) for x in (bad / "labels.jsonl").read_text().splitlines()]
    p = bad / "new_joint_vecs" / f"{rows[0]['id']}.npy"
    j = features_to_joints(np.load(p).astype(np.float64))
    j[:, 10, 1] -= 0.2  # push the left toe 20 cm into the floor
    j[:, 10, 0] += np.linspace(0, 0.3, len(j))
    np.save(p, joints_to_features(np.concatenate([j, j[-1:]]), canonical=False))
    assert corpus_main(["check", str(bad), "--workers", "1", "--limit", "5"]) == 1


def test_verifier_on_test_split_and_shuffled_labels(built):
    """>= 98% on the corpus's own test clips, near chance on shuffled labels."""
    rows = [json.loads(x) for x in (built / "labels.jsonl").read_text().splitlines()]
    test = [r for r in rows if r["split"] == "test"]
    joints = [features_to_joints(np.load(built / "new_joint_vecs" / f"{r['id']}.npy")) for r in test]
    own = np.mean([verify(j, r["labels"]).passed for j, r in zip(joints, test, strict=True)])
    perm = np.random.default_rng(0).permutation(len(test))
    shuffled = np.mean([verify(joints[i], test[p]["labels"]).passed for i, p in enumerate(perm)])
    assert own >= 0.98, own
    # chance: the fraction of shuffled pairs whose labels happen to describe the motion
    assert shuffled < 0.15, shuffled
