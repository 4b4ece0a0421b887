"""Several actions in one clip under one sentence (corpus/chain.py) and its verifier (verify/chain.py)."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from motion_core.body.features import features_to_joints, joints_to_features
from motion_core.corpus import sample_clip
from motion_core.corpus.__main__ import main as corpus_main
from motion_core.corpus.actions import sample_spec
from motion_core.corpus.chain import chain_captions, chain_kinds, chain_labels, sample_chain, sample_chain_specs
from motion_core.corpus.kinds import REGISTRY, all_kinds
from motion_core.corpus.text import WHO
from motion_core.data import HumanML3DDataset
from motion_core.verify.realism import realism
from motion_core.verify.rules import verify

N = 40


def _chains(staged: bool, n: int = N, seed: int = 11):
    pool = all_kinds() if staged else None
    for i in range(n):
        rng = np.random.default_rng([seed, i])
        comp = sample_chain(rng, 2 + i % 2, pool)
        yield comp, chain_labels(comp), features_to_joints(joints_to_features(comp.joints))


@pytest.mark.parametrize("staged", [False, True], ids=["built-in kinds", "with the staged kinds"])
def test_a_chain_passes_every_action_in_order_and_not_in_reverse(staged):
    at_true = found = reverse = realistic = 0
    for _, lab, j in _chains(staged):
        at_true += all(verify(j[a:b], x).passed for (a, b), x in zip(lab["frames"], lab["actions"], strict=True))
        found += verify(j, lab).passed
        # reversed order: the same motion does the same actions, the other way round
        reverse += verify(j, {"kind": "chain", "actions": lab["actions"][::-1]}).passed
        realistic += not realism(j).violations()
    assert at_true >= 0.9 * N  # each action, at the frames it was authored in
    assert found >= 0.95 * N  # the cut search finds them
    assert reverse <= 0.05 * N
    assert realistic >= 0.95 * N


def test_a_single_action_is_not_a_chain():
    """One action's clip fails as that action followed by another (the cut search cannot
    pass a motion that does only the first)."""
    passed = 0
    rng = np.random.default_rng(12)
    for _ in range(N):
        clip, spec = sample_clip(rng)
        j = features_to_joints(joints_to_features(clip.joints))
        other = [k for k in chain_kinds() if k != spec.kind]
        second = sample_spec(rng, other[int(rng.integers(len(other)))])
        passed += verify(j, {"kind": "chain", "actions": [spec.labels(), second.labels()]}).passed
    assert passed <= 0.05 * N


def test_chains_draw_only_kinds_that_start_and_end_standing_and_leave_postures():
    kinds = chain_kinds(all_kinds())
    assert "stand_up" not in kinds and "get_up" not in kinds
    assert not [k for k in kinds if k in REGISTRY and REGISTRY[k].posture != ("standing", "standing")]
    assert not [k for k in kinds if k in REGISTRY and REGISTRY[k].family == "stairs"]
    for i in range(200):
        specs = sample_chain_specs(np.random.default_rng([14, i]), 2 + i % 2, all_kinds())
        assert len(specs) == 2 + i % 2
        names = [s.kind for s in specs]
        assert all(a != b for a, b in itertools.pairwise(names))
        for a, b in itertools.pairwise(names):
            if a == "sit_down":
                assert b == "stand_up"
            if a == "lie_down":
                assert b == "get_up"
        assert names[-1] not in ("sit_down", "lie_down")


def test_a_chains_captions_are_one_sentence_with_one_subject():
    for i in range(60):
        rng = np.random.default_rng([15, i])
        specs = sample_chain_specs(rng, 2 + i % 2)
        caps = chain_captions(specs, rng, 3)
        assert 1 <= len(caps) <= 3 and len(set(caps)) == len(caps)
        for c in caps:
            # the subject once, at the start, and a connective between the actions
            assert any(c.startswith(w + " ") for w in WHO) and not any(f" {w} " in c for w in WHO), c
            assert any(k in c for k in (", then", " then ", " and ", "after that", ", ")), c


def test_a_build_with_staged_kinds_and_chains_writes_them_and_the_default_is_unchanged(tmp_path):
    args = ["--val", "0", "--test", "0", "--seq-train", "0", "--seq-val", "0", "--seq-test", "0", "--workers", "1"]
    assert corpus_main(["build", str(tmp_path / "plain"), "--train", "4", *args]) == 0
    grown = tmp_path / "grown"
    rc = corpus_main(
        ["build", str(grown), "--train", "4", *args, "--with-staged", "--chain-train", "6", "--chain-val", "2"]
    )
    assert rc == 0
    summary = json.loads((grown / "corpus.json").read_text())
    assert summary["chains"] == {"train": 6, "val": 2, "test": 0} and summary["staged"] is True
    assert summary["clips"] == {"train": 4, "val": 0, "test": 0}
    assert "chains" not in json.loads((tmp_path / "plain" / "corpus.json").read_text())
    rows = [json.loads(x) for x in (grown / "labels.jsonl").read_text().splitlines()]
    chains = [r for r in rows if r["labels"]["kind"] == "chain"]
    assert len(chains) == 8 and {r["split"] for r in chains} == {"train", "val"}
    train = HumanML3DDataset(grown, "train")
    assert len(train) == 10 and sum(i.startswith("c") for i in train.ids) == 6
    for r in chains:
        s = HumanML3DDataset(grown, r["split"]).load(r["id"])
        assert 2 <= len(r["labels"]["actions"]) <= 3 and len(s.captions) >= 1
        assert verify(features_to_joints(s.features), r["labels"]).passed, r
    # without --with-staged the single clips are the built-in draws, byte for byte
    plain = HumanML3DDataset(tmp_path / "plain", "train")
    direct = sample_clip(np.random.default_rng([0, 0]))[0]
    assert np.allclose(plain.load("000000").features, joints_to_features(direct.joints), atol=1e-5)


@pytest.mark.long
def test_per_kind_table_on_a_grown_corpus(tmp_path, capsys):
    """eval per-kind: every staged kind and the chains get a row entry, ground truth passes,
    and the reconstructions are scored by the same rules."""
    from motion_core.corpus.kinds import staged_kinds
    from motion_core.eval.__main__ import main as eval_main

    data = tmp_path / "grown"
    args = ["build", str(data), "--train", "2", "--val", "0", "--test", "300", "--with-staged"]
    args += ["--seq-train", "0", "--seq-val", "0", "--seq-test", "0", "--chain-test", "4", "--workers", "1"]
    assert corpus_main(args) == 0
    out = tmp_path / "per_kind.json"
    eval_main(["per-kind", "--data", str(data), "--per-kind", "2", "--out", str(out)])
    res = json.loads(out.read_text())
    rows = res["rows"]
    assert set(rows) == {"ground_truth", "vae_reconstruction", "rvq_reconstruction"}
    assert res["clips"]["chain"] == 2 and set(res["clips"]) - {"chain"} <= set(staged_kinds())
    assert len(res["clips"]) >= 0.8 * len(staged_kinds())  # 300 draws from 80 kinds miss a few
    assert rows["ground_truth"]["mean_over_kinds"] >= 0.95 and rows["ground_truth"]["kinds"]["chain"] == 1.0
    for row in rows.values():
        assert set(row["kinds"]) == set(res["clips"]) and all(0.0 <= v <= 1.0 for v in row["kinds"].values())
    assert "mean over kinds" in capsys.readouterr().out


@pytest.mark.long
def test_per_kind_rows_of_generated_motions_from_methods_and_stages(tmp_path):
    """eval per-kind --method: a shipped method and the same weights registered as a network
    in training (a kmm.pt, a denoiser on the VAE it was trained on) score alike at the same
    seeds; each generated row holds every clip once per seed."""
    from motion_core.eval.__main__ import main as eval_main
    from motion_core.inference.checkpoints import WEIGHTS
    from motion_core.inference.registry import unregister_arm

    data = tmp_path / "grown"
    args = ["build", str(data), "--train", "2", "--val", "0", "--test", "40", "--with-staged"]
    args += ["--seq-train", "0", "--seq-val", "0", "--seq-test", "0", "--chain-test", "2", "--workers", "1"]
    assert corpus_main(args) == 0
    out = tmp_path / "per_kind.json"
    methods = ["--method", "kmm", "--method", f"kmm_arm={WEIGHTS / 'kmm.pt'}"]
    methods += ["--method", "baseline:quality", "--method", f"base_arm={WEIGHTS / 'baseline.pt'}"]
    methods += ["--vae", str(WEIGHTS / "vae.pt"), "--seeds", "0", "1"]
    try:
        eval_main(
            ["per-kind", "--data", str(data), "--per-kind", "1", "--no-reconstructions", "--out", str(out), *methods]
        )
    finally:
        unregister_arm("kmm_arm")
        unregister_arm("base_arm")
    res = json.loads(out.read_text())
    rows = res["rows"]
    assert set(rows) == {"ground_truth", "kmm", "kmm_arm", "baseline", "base_arm"} and res["seeds"] == [0, 1]
    assert rows["kmm"]["kinds"] == rows["kmm_arm"]["kinds"]
    assert rows["baseline"]["kinds"] == rows["base_arm"]["kinds"]
    # two seeds of one clip a kind: every rate is a count of two
    assert all(v in (0.0, 0.5, 1.0) for r in ("kmm", "baseline") for v in rows[r]["kinds"].values())


def test_per_kind_method_rows_take_decoding_overrides():
    """eval per-kind --guidance / --steps reach the generator: the same clip and seed decode
    differently at another guidance scale, and alike with the method's own default given
    explicitly."""
    from types import SimpleNamespace

    from motion_core.eval.per_kind import method_rows
    from motion_core.inference.checkpoints import WEIGHTS
    from motion_core.inference.registry import REGISTRY

    clip = SimpleNamespace(captions=["a person claps the hands three times"], frames=60)
    default = REGISTRY["kmm"].default_guidance
    runs = {
        g: method_rows(["kmm"], WEIGHTS / "vae.pt", [0], guidance=g)["kmm"]([clip])[0] for g in (None, default, 3.0)
    }
    assert np.array_equal(runs[None], runs[default])
    assert not np.allclose(runs[None], runs[3.0])
