"""KMM's pieces without the shipped checkpoint: the residual VQ tokeniser, the training mask,
the alignment loss, iterative masked decoding and boundary in-filling."""

from __future__ import annotations

import json

import numpy as np
import pytest
import torch

from motion_core.models.kmm import KMMConfig, KMMGenerator, segment_phase
from motion_core.models.rvq import RVQVAE, EMACodebook, RVQConfig
from motion_core.train.kmm import _batch


def test_ema_codebook_update_matches_the_formula_and_resets_dead_codes():
    book = EMACodebook(3, 2, decay=0.5, dead_threshold=0.3)
    x0 = torch.tensor([[1.0, 0.0], [0.0, 1.0], [5.0, 5.0]])
    book.update(x0, torch.arange(3))  # first call: codes initialised from batch vectors
    assert bool(book.initialised) and book.cluster_size.tolist() == [1.0, 1.0, 1.0]
    book.embed.copy_(x0)
    book.embed_sum.copy_(x0)
    x = torch.tensor([[2.0, 0.0], [4.0, 0.0], [0.0, 3.0]])
    idx = torch.tensor([0, 0, 1])
    book.update(x, idx)
    cs = torch.tensor([0.5 * 1 + 0.5 * 2, 0.5 * 1 + 0.5 * 1, 0.5 * 1 + 0.5 * 0])
    es = 0.5 * x0 + 0.5 * torch.stack([x[0] + x[1], x[2], torch.zeros(2)])
    n = cs.sum()
    smoothed = (cs + 1e-5) / (n + 3e-5) * n
    assert torch.allclose(book.cluster_size, cs)
    assert torch.allclose(book.embed, es / smoothed[:, None], atol=1e-5)
    # code 2 got nothing twice: its count 0.25 < 0.3 -> reset onto one of the batch's vectors
    book.update(x, idx)
    assert any(torch.equal(book.embed[2], v) for v in x)
    assert book.cluster_size[2] == 1.0


def test_residual_quantiser_codes_sum_to_the_quantised_vector():
    torch.manual_seed(1)
    m = RVQVAE(RVQConfig(width=32, code_dim=16, codebook_size=8, quantizers=3, res_blocks=1))
    m.train()
    x = torch.randn(4, 24, m.cfg.feature_dim)
    for _ in range(3):
        m(x)  # initialise and update the codebooks
    m.eval()
    codes, z = m.encode(x)
    assert codes.shape == (4, 6, 3) and z.shape == (4, 6, 16)
    zq, codes2, _ = m.quantizer(z)
    assert torch.equal(codes, codes2)
    assert torch.allclose(zq, m.quantizer.lookup(codes), atol=1e-5)
    # each further layer quantises what is left, so the error does not grow
    errs = [(m.quantizer.lookup(codes[..., : q + 1]) - z).norm() for q in range(3)]
    assert errs[2] <= errs[0] + 1e-5
    # lengths that are not a multiple of 4 are padded, and decode gives 4 frames per token
    codes_odd, _ = m.encode(torch.randn(1, 37, m.cfg.feature_dim))
    assert codes_odd.shape[1] == 10
    assert m.decode(codes_odd).shape == (1, 40, m.cfg.feature_dim)


def test_tokeniser_loss_falls_when_fitting_a_batch():
    torch.manual_seed(2)
    m = RVQVAE(RVQConfig(width=32, code_dim=16, codebook_size=16, quantizers=2, res_blocks=1, quantizer_dropout=0))
    opt = torch.optim.Adam(m.parameters(), 3e-3)
    x = torch.randn(2, 16, m.cfg.feature_dim) * 0.5
    first = None
    for _ in range(60):
        res = m(x)
        opt.zero_grad()
        res["loss"].backward()
        opt.step()
        first = first if first is not None else res["rec_loss"].item()
    assert res["rec_loss"].item() < 0.6 * first


def test_tokeniser_weights_root_and_joint_positions_over_the_other_features():
    """Joints are decoded from the root and the root-relative positions: the loss weighs those
    up by the config's factors (mean weight 1), and a position error costs more than the same
    error in a rotation feature."""
    from motion_core.body.features import HML_LAYOUT

    m = RVQVAE(RVQConfig(width=32, code_dim=16, codebook_size=16, quantizers=2, res_blocks=1, position_weight=4.0))
    w = m.feature_weights()
    assert w.shape == (HML_LAYOUT.dim,) and abs(float(w.mean()) - 1.0) < 1e-6
    assert torch.allclose(w[HML_LAYOUT.ric] / w[HML_LAYOUT.rot6d].mean(), torch.tensor(4.0))
    assert torch.allclose(w[HML_LAYOUT.root_height] / w[HML_LAYOUT.local_vel].mean(), torch.tensor(m.cfg.root_weight))
    flat = RVQVAE(RVQConfig(width=32, code_dim=16, codebook_size=16, quantizers=2, res_blocks=1, position_weight=1.0))
    assert torch.allclose(flat.feature_weights()[HML_LAYOUT.ric], flat.feature_weights()[HML_LAYOUT.rot6d][:63])


def test_keyframe_mask_takes_key_frames_first():
    torch.manual_seed(3)
    gen = KMMGenerator(KMMConfig(d_model=16, layers=1))
    n = 40
    is_key = torch.zeros(200, n, dtype=torch.bool)
    is_key[:, :12] = True  # the 30% key frames of each clip
    valid = torch.ones(200, n, dtype=torch.bool)
    valid[:, 35:] = False  # padding
    masked = gen.training_mask(is_key, valid, torch.Generator().manual_seed(0))
    assert not masked[:, 35:].any()  # padding is never a target
    counts = masked.sum(1)
    assert (counts >= 1).all()
    for row, c in zip(masked, counts, strict=True):
        if c >= 12:
            assert row[:12].all()  # every key frame masked before any other token
        else:
            assert not row[12:].any()  # a small ratio masks key frames only
    rand = KMMGenerator(KMMConfig(d_model=16, layers=1, mask="random"))
    m2 = rand.training_mask(is_key, valid, torch.Generator().manual_seed(0))
    small = m2.sum(1) < 12
    assert m2[small][:, 12:35].any()  # random masking does not prefer key frames


def _toy_data(n_clips: int = 40, seed: int = 0) -> dict:
    rng = np.random.default_rng(seed)
    lens = rng.integers(6, 14, n_clips)
    return {
        "codes": rng.integers(0, 8, (int(lens.sum()), 6)).astype(np.int16),
        "ranks": np.concatenate([rng.permutation(int(n)) for n in lens]).astype(np.int16),
        "offsets": np.concatenate([[0], np.cumsum(lens)]),
        "text": rng.standard_normal((n_clips * 2, 384)).astype(np.float32),
        "text_clip": np.repeat(np.arange(n_clips), 2),
    }


def test_batches_pair_clips_with_their_own_texts():
    data = _toy_data()
    cfg = KMMConfig(codebook_size=8)
    bt = _batch(data, cfg, 16, 1.0, np.random.default_rng(1))
    assert len(bt["caps"]) == 32  # every sample two segments
    for b in range(16):
        segs = bt["seg_ids"][b][bt["valid"][b]]
        assert len(segs.unique()) == 2
        n_first = int((segs == segs[0]).sum())
        clip = int(data["text_clip"][bt["caps"][int(segs[0])]])
        off = data["offsets"]
        assert np.array_equal(bt["codes"][b, :n_first].numpy(), data["codes"][off[clip] : off[clip + 1]])


def test_generator_learns_and_the_alignment_loss_pairs_texts_with_motions():
    torch.manual_seed(4)
    data = _toy_data(16)
    cfg = KMMConfig(codebook_size=8, d_model=32, layers=2)
    gen = KMMGenerator(cfg)
    opt = torch.optim.Adam(gen.parameters(), 3e-3)
    rng = np.random.default_rng(0)
    g = torch.Generator().manual_seed(0)
    text = torch.from_numpy(data["text"])
    hist = []
    for _ in range(80):
        bt = _batch(data, cfg, 16, 0.3, rng)
        st = text[bt["caps"]]
        same = torch.eye(len(st), dtype=torch.bool)
        res = gen.loss(
            bt["codes"], bt["is_key"], bt["valid"], bt["seg_ids"], st, torch.zeros(len(st), dtype=torch.bool), same, g
        )
        opt.zero_grad()
        res["loss"].backward()
        opt.step()
        hist.append((res["ce"].item(), res["align"].item()))
    ce0, al0 = np.mean(hist[:5], 0)
    ce1, al1 = np.mean(hist[-5:], 0)
    assert ce1 < 0.8 * ce0 and al1 < 0.8 * al0
    off = KMMGenerator(KMMConfig(codebook_size=8, d_model=32, layers=1, align=False))
    bt = _batch(data, cfg, 4, 0.0, rng)
    st = text[bt["caps"]]
    res = off.loss(
        bt["codes"],
        bt["is_key"],
        bt["valid"],
        bt["seg_ids"],
        st,
        torch.zeros(4, dtype=torch.bool),
        torch.eye(4, dtype=torch.bool),
        g,
    )
    assert "align" not in res and torch.equal(res["loss"], res["ce"])


@pytest.fixture(scope="module")
def small_generator():
    torch.manual_seed(5)
    return KMMGenerator(KMMConfig(codebook_size=16, d_model=32, layers=2)).eval()


def test_masked_decoding_is_deterministic_and_fills_every_token(small_generator):
    texts, empty = torch.randn(3, 384), torch.randn(384)
    a = small_generator.generate(texts, empty, [5, 7, 6], torch.Generator().manual_seed(1))
    b = small_generator.generate(texts, empty, [5, 7, 6], torch.Generator().manual_seed(1))
    c = small_generator.generate(texts, empty, [5, 7, 6], torch.Generator().manual_seed(2))
    assert a.shape == (18, 6) and torch.equal(a, b) and not torch.equal(a, c)
    assert a.min() >= 0 and a.max() < 16


def test_guidance_one_skips_the_unconditional_pass_and_samples_what_the_formula_does(small_generator):
    texts = torch.randn(3, 384)
    run = lambda empty, scale: small_generator.generate(  # noqa: E731
        texts, empty, [5, 7, 6], torch.Generator().manual_seed(4), guidance=scale
    )
    plain = run(torch.randn(384), 1.0)
    # the unconditional text no longer matters at scale 1 ...
    assert torch.equal(plain, run(torch.randn(384), 1.0))
    # ... and the two-pass formula u + s (c - u) at s -> 1 draws the same codes
    assert torch.equal(plain, run(torch.randn(384), 1.0 + 1e-7))
    assert not torch.equal(plain, run(torch.randn(384), 3.0))


def test_infill_rewrites_only_the_boundary_tokens(small_generator):
    texts, empty = torch.randn(3, 384), torch.randn(384)
    plain = small_generator.generate(texts, empty, [8, 8, 8], torch.Generator().manual_seed(3), infill=0)
    filled = small_generator.generate(texts, empty, [8, 8, 8], torch.Generator().manual_seed(3), infill=2)
    near = torch.zeros(24, dtype=torch.bool)
    for b in (8, 16):
        near[b - 2 : b + 2] = True
    assert torch.equal(plain[~near], filled[~near])
    assert not torch.equal(plain[near], filled[near])


def test_shipped_tokeniser_extracts_to_a_run_and_the_generator_initialises_from_it(tmp_path):
    """extract-rvq writes the shipped tokeniser so that `train kmm-generator --init` can go on
    from the shipped generator: the extracted tokeniser must decode as the shipped one, and
    the generator weights must load unchanged (float16 -> float32)."""
    from motion_core.inference.checkpoints import WEIGHTS, extract_rvq, generator_config, init_generator, load_rvq
    from motion_core.inference.registry import load_method

    shipped = WEIGHTS / "kmm.pt"
    path = extract_rvq(shipped, tmp_path / "rvq")
    rvq, meta = load_rvq(path)
    method = load_method("kmm")
    codes = torch.randint(
        0, rvq.cfg.codebook_size, (1, 12, rvq.cfg.quantizers), generator=torch.Generator().manual_seed(0)
    )
    with torch.no_grad():
        a = rvq.decode(codes)
        b = method.rvq.decode(codes)
    torch.testing.assert_close(a, b)
    np.testing.assert_allclose(meta["mean"], method.normalizer.mean, rtol=1e-6)
    shipped_meta = torch.load(shipped, map_location="cpu", weights_only=False)["meta"]
    assert meta["steps"] == shipped_meta["rvq_steps"]
    assert meta["decoder_only_steps"] == shipped_meta["rvq_decoder_only_steps"]

    gen = KMMGenerator(generator_config(shipped))  # the shipped one reads segment phase
    steps = init_generator(gen, shipped)
    ck = torch.load(shipped, map_location="cpu", weights_only=False)
    assert steps == ck["meta"]["steps"]
    for name, v in gen.state_dict().items():
        torch.testing.assert_close(v, ck["generator"][name].to(v.dtype))


def test_kmm_ablation_scores_states_and_shipped_weights_alike(tmp_path):
    """`evaluate --kmm-ablation` takes a training state or a shipped kmm.pt per arm and
    scores each with the same prompts: the same weights in both formats give the same row."""
    from motion_core.corpus.__main__ import main as corpus_main
    from motion_core.eval.tables import kmm_ablation
    from motion_core.inference.checkpoints import WEIGHTS, extract_rvq

    data = tmp_path / "corpus"
    args = ["build", str(data), "--train", "8", "--val", "2", "--test", "4"]
    args += ["--seq-train", "1", "--seq-val", "1", "--seq-test", "1", "--workers", "1"]
    assert corpus_main(args) == 0
    extract_rvq(WEIGHTS / "kmm.pt", tmp_path / "rvq")
    ck = torch.load(WEIGHTS / "kmm.pt", map_location="cpu", weights_only=False)
    state = tmp_path / "state.pt"
    torch.save({"model": ck["generator"], "step": 7}, state)
    res = kmm_ablation([f"shipped={WEIGHTS / 'kmm.pt'}", f"state={state}"], tmp_path / "rvq", data, n=3)
    assert res["n"] == 3
    assert res["shipped"]["steps"] == ck["meta"]["steps"] and res["state"]["steps"] == 7
    for key in ("pass_rate", "direction_accuracy", "sided_prompts"):
        assert res["shipped"][key] == res["state"][key]


def test_tokeniser_cli_goes_on_from_the_shipped_tokeniser(tmp_path):
    """`train kmm-rvq --init kmm.pt` starts from the shipped tokeniser and counts its steps; a
    rerun resumes instead of initialising again. (The codebooks move by EMA whatever the
    learning rate, so the check is on the convolutions, which a 1e-9 rate leaves in place.)"""
    from motion_core.corpus.__main__ import main as corpus_main
    from motion_core.inference.checkpoints import WEIGHTS, init_rvq, load_rvq
    from motion_core.train.__main__ import main as kmm_main

    data = tmp_path / "corpus"
    args = ["build", str(data), "--train", "6", "--val", "2", "--test", "2"]
    args += ["--seq-train", "0", "--seq-val", "0", "--seq-test", "0", "--workers", "1"]
    assert corpus_main(args) == 0
    shipped = torch.load(WEIGHTS / "kmm.pt", map_location="cpu", weights_only=False)["meta"]
    fresh = RVQVAE(RVQConfig())
    assert init_rvq(fresh, WEIGHTS / "kmm.pt") == shipped["rvq_steps"]
    out = tmp_path / "rvq"
    run = ["kmm-rvq", "--data", str(data), "--out", str(out), "--batch", "2", "--lr", "1e-9", "--save-every", "1"]
    run += ["--init", str(WEIGHTS / "kmm.pt")]
    kmm_main([*run, "--steps", "1"])
    rvq, meta = load_rvq(out / "rvq.pt")
    assert meta["steps"] == shipped["rvq_steps"] + 1 and meta["init"]["steps"] == shipped["rvq_steps"]
    for part in ("encoder", "decoder"):
        a, b = getattr(rvq, part).state_dict(), getattr(fresh, part).state_dict()
        for name in a:
            torch.testing.assert_close(a[name], b[name], atol=1e-5, rtol=1e-5)
    stage = tmp_path / "stages" / "rvq.pt"
    kmm_main([*run, "--steps", "2", "--stage", str(stage)])  # resumes at step 1, does not initialise again
    assert torch.load(out / "state.pt", weights_only=False)["step"] == 2
    assert load_rvq(out / "rvq.pt")[1]["steps"] == shipped["rvq_steps"] + 2
    # the stage: float16, and the next kmm-rvq --init starts from it with the lineage's steps
    staged = torch.load(stage, weights_only=False)
    assert {v.dtype for v in staged["state_dict"].values() if v.is_floating_point()} == {torch.float16}
    assert init_rvq(RVQVAE(RVQConfig()), stage) == shipped["rvq_steps"] + 2

    # --decoder-only: encoder and codebooks (EMA statistics included) stay bit for bit, so
    # every clip keeps its codes; the decoder moves
    dec = tmp_path / "dec"
    run = ["kmm-rvq", "--data", str(data), "--out", str(dec), "--batch", "2", "--lr", "1e-3", "--steps", "2"]
    kmm_main([*run, "--init", str(WEIGHTS / "kmm.pt"), "--decoder-only"])
    tuned, meta = load_rvq(dec / "rvq.pt")
    # the shipped decoder's own decoder-only steps carry over, so a chain of such runs adds up
    assert meta["decoder_only_steps"] == shipped["rvq_decoder_only_steps"] + 2
    for part in ("encoder", "quantizer"):
        a, b = getattr(tuned, part).state_dict(), getattr(fresh, part).state_dict()
        assert a.keys() == b.keys() and all(torch.equal(a[k], b[k]) for k in a)
    assert any(not torch.equal(v, fresh.decoder.state_dict()[k]) for k, v in tuned.decoder.state_dict().items())
    with pytest.raises(SystemExit, match="--init"):
        kmm_main([*run, "--decoder-only"])

    # swap-decoder ships the tuned decoder with the shipped generator; a run whose encoder
    # moved (the plain rvq run above) is refused
    kmm_main(["kmm-swap-decoder", "--rvq", str(dec), "--out", str(tmp_path / "kmm.pt")])
    swapped = torch.load(tmp_path / "kmm.pt", weights_only=False)
    original = torch.load(WEIGHTS / "kmm.pt", weights_only=False)
    assert all(torch.equal(v, original["generator"][k]) for k, v in swapped["generator"].items())
    assert torch.equal(swapped["rvq"]["decoder.0.weight"], tuned.state_dict()["decoder.0.weight"].half())
    assert (
        swapped["meta"]["rvq_decoder_only_steps"] == shipped["rvq_decoder_only_steps"] + 2
        and swapped["meta"]["steps"] == original["meta"]["steps"]
    )
    with pytest.raises(SystemExit, match="only the decoder"):
        kmm_main(["kmm-swap-decoder", "--rvq", str(out), "--out", str(tmp_path / "bad.pt")])


def test_generator_cli_stops_at_a_step_of_its_schedule_and_continues_shipped_weights(tmp_path):
    """--stop-at ends a run early on the schedule of --steps (and a rerun resumes there);
    --init starts from the shipped generator and counts its steps in the checkpoint; --stage
    writes a float16 kmm.pt that the next run --init's; a tokenised corpus cached from other
    clips (a smoke run's --limit) is refused."""
    from motion_core.inference.checkpoints import WEIGHTS
    from motion_core.train.__main__ import main as kmm_main
    from motion_core.train.caches import StaleCache, corpus_fingerprint, file_fingerprint, write_cache

    corpus = _tiny_corpus_and_tokeniser(tmp_path)
    rvq = tmp_path / "rvq"
    data = _toy_data(12)
    data["empty"] = np.zeros(384, np.float32)
    # the tokenised corpus the generator stage caches, here toy codes under the corpus's fingerprint
    write_cache(rvq / "tokens.npz", data, corpus_fingerprint(corpus) + file_fingerprint(rvq / "rvq.pt"))
    out = tmp_path / "gen"
    args = ["kmm-generator", "--data", str(corpus), "--rvq", str(rvq), "--out", str(out), "--steps", "10"]
    args += ["--batch", "4", "--save-every", "1", "--init", str(WEIGHTS / "kmm.pt")]
    kmm_main([*args, "--stop-at", "2"])
    shipped_steps = torch.load(WEIGHTS / "kmm.pt", map_location="cpu", weights_only=False)["meta"]["steps"]
    assert torch.load(out / "state.pt", weights_only=False)["step"] == 2
    meta = torch.load(out / "kmm.pt", weights_only=False)["meta"]
    assert meta["steps"] == shipped_steps + 2 and meta["init"]["steps"] == shipped_steps
    # a resume keeps its run's network and recipe: an ablation arm is not switched mid-run
    with pytest.raises(SystemExit, match="network config was"):
        kmm_main([*args, "--stop-at", "3", "--mask", "random"])
    with pytest.raises(SystemExit, match=r"--pair-prob was 0\.5, now 0\.9"):
        kmm_main([*args, "--stop-at", "3", "--pair-prob", "0.9"])
    stage = tmp_path / "stages" / "kmm.pt"
    kmm_main([*args, "--stop-at", "3", "--stage", str(stage)])  # resumes at step 2
    assert torch.load(out / "state.pt", weights_only=False)["step"] == 3
    assert torch.load(out / "kmm.pt", weights_only=False)["meta"]["steps"] == shipped_steps + 3
    # the stage: float16 as shipped, and the next run's --init goes on from it with the lineage's steps
    staged = torch.load(stage, weights_only=False)
    assert {v.dtype for v in staged["generator"].values() if v.is_floating_point()} == {torch.float16}
    nxt = ["kmm-generator", "--data", str(corpus), "--rvq", str(rvq), "--out", str(tmp_path / "gen2")]
    kmm_main([*nxt, "--steps", "1", "--batch", "4", "--save-every", "1", "--init", str(stage)])
    assert torch.load(tmp_path / "gen2" / "kmm.pt", weights_only=False)["meta"]["steps"] == shipped_steps + 4
    # rerun at its stop (as to --ship a finished run): no step is taken, and the checkpoint
    # keeps the run's last logged losses instead of an empty record
    kmm_main([*args, "--stop-at", "3"])
    meta = torch.load(out / "kmm.pt", weights_only=False)["meta"]
    last = json.loads((out / "result.json").read_text())["log"][-1]
    assert meta["steps"] == shipped_steps + 3 and last["step"] == 3
    assert meta["final"] and meta["final"]["acc_base"] == last["acc_base"]
    # the cache of the whole split is not a cache of its first 3 clips (it used to be read as one)
    with pytest.raises(StaleCache, match=r"tokens\.npz was built from another corpus, --limit or tokeniser"):
        kmm_main([*args[:5], "--out", str(tmp_path / "smoke"), "--steps", "1", "--limit", "3"])


def _tiny_corpus_and_tokeniser(tmp_path):
    """A built corpus of 11 procedural clips in TMP/corpus (returned) and the shipped KMM's
    tokeniser extracted as a run in TMP/rvq, for the generator CLI to train on."""
    from motion_core.corpus.__main__ import main as corpus_main
    from motion_core.inference.checkpoints import WEIGHTS, extract_rvq

    data = tmp_path / "corpus"
    args = ["build", str(data), "--train", "6", "--val", "2", "--test", "3"]
    args += ["--seq-train", "0", "--seq-val", "0", "--seq-test", "0", "--workers", "1"]
    assert corpus_main(args) == 0
    extract_rvq(WEIGHTS / "kmm.pt", tmp_path / "rvq")
    return data


def test_generator_width_and_depth_are_options_that_scoring_follows(tmp_path):
    """`train kmm-generator --d-model/--layers` trains a generator of another size; its
    training state and its kmm.pt both record the size, so `kmm_ablation` can rebuild and
    score it (it used to assume the default size)."""
    from motion_core.eval.tables import kmm_ablation
    from motion_core.inference.checkpoints import WEIGHTS, generator_config
    from motion_core.train.__main__ import main as kmm_main

    data = _tiny_corpus_and_tokeniser(tmp_path)
    out = tmp_path / "gen"
    run = ["kmm-generator", "--data", str(data), "--rvq", str(tmp_path / "rvq"), "--out", str(out)]
    kmm_main([*run, "--steps", "1", "--batch", "2", "--d-model", "32", "--layers", "1", "--save-every", "1"])
    for path in (out / "state.pt", out / "kmm.pt"):
        cfg = generator_config(path)
        assert (cfg.d_model, cfg.layers) == (32, 1)
    assert generator_config(WEIGHTS / "kmm.pt").d_model == KMMConfig().d_model
    res = kmm_ablation([f"state={out / 'state.pt'}", f"ck={out / 'kmm.pt'}"], tmp_path / "rvq", data, n=2)
    assert res["state"]["steps"] == 1 and res["ck"]["steps"] == 1
    assert res["state"]["pass_rate"] == res["ck"]["pass_rate"]


def test_word_pooling_starts_as_the_sentence_generator_and_reads_words_within_their_mask():
    """``word_pool`` adds a learned pooling of token embeddings to each segment's vector: its
    output starts at zero, so a generator fine-tuned with words begins exactly where the one
    without them stood; once trained it reads the words, and only the unmasked ones."""
    torch.manual_seed(0)
    plain = KMMGenerator(KMMConfig(codebook_size=16, d_model=32, layers=1)).eval()
    pooled = KMMGenerator(KMMConfig(codebook_size=16, d_model=32, layers=1, word_pool=True)).eval()
    missing, unexpected = pooled.load_state_dict(plain.state_dict(), strict=False)
    assert not unexpected and missing and all(k.startswith("word_") for k in missing)
    sent, words = torch.randn(3, 384), torch.randn(3, 7, 384)
    mask = torch.ones(3, 7, dtype=torch.bool)
    mask[1, 4:] = False
    assert torch.equal(pooled.text_vectors(sent, words, mask), plain.text_vectors(sent))
    with pytest.raises(ValueError, match="token embeddings"):
        pooled.text_vectors(sent)
    texts, empty = torch.randn(2, 384), torch.randn(384)
    w, m = torch.randn(3, 5, 384), torch.ones(3, 5, dtype=torch.bool)
    g = lambda: torch.Generator().manual_seed(7)  # noqa: E731
    before = plain.generate(texts, empty, [5, 6], g())
    assert torch.equal(before, pooled.generate(texts, empty, [5, 6], g(), words=(w, m)))

    torch.nn.init.normal_(pooled.word_out[-1].weight)  # as if trained: the words now count
    v = pooled.text_vectors(sent, words, mask)
    other = words.clone()
    # another word, not a shifted one: the pooling's LayerNorm removes a constant shift, so
    # "+= 1.0" left the output equal up to rounding and the check passed or failed by it
    other[0, 2] = torch.randn(384, generator=torch.Generator().manual_seed(1))
    assert not torch.allclose(pooled.text_vectors(sent, other, mask)[0], v[0])
    padded = words.clone()
    padded[1, 4:] = 100.0  # behind the mask
    assert torch.allclose(pooled.text_vectors(sent, padded, mask), v)


def test_generator_with_word_pooling_trains_from_one_without_and_generates(tmp_path):
    """`train kmm-generator --word-pool --init SHIPPED`: the caption tokens are cached beside the
    tokens, the shipped (sentence-only) weights load with the word weights left at zero output,
    and the result generates through the public API's path."""
    from motion_core.eval.tables import kmm_ablation
    from motion_core.inference.checkpoints import WEIGHTS, generator_config
    from motion_core.train.__main__ import main as kmm_main

    data = _tiny_corpus_and_tokeniser(tmp_path)
    out = tmp_path / "gen"
    run = ["kmm-generator", "--data", str(data), "--rvq", str(tmp_path / "rvq"), "--out", str(out), "--word-pool"]
    kmm_main([*run, "--steps", "2", "--batch", "2", "--save-every", "1", "--init", str(WEIGHTS / "kmm.pt")])
    words = np.load(tmp_path / "rvq" / "words.npz")
    assert words["tokens"].shape[0] == words["mask"].shape[0] == words["index"].max() + 2  # + the empty text
    assert generator_config(out / "kmm.pt").word_pool
    assert generator_config(out / "kmm.pt").phase  # kept from the shipped --init without --phase
    ck = torch.load(out / "kmm.pt", weights_only=False)
    assert any(k.startswith("word_") for k in ck["generator"])
    res = kmm_ablation([f"words={out / 'kmm.pt'}"], tmp_path / "rvq", data, n=2)
    assert res["words"]["steps"] == ck["meta"]["steps"] and 0 <= res["words"]["pass_rate"] <= 1


def test_segment_phase_places_each_token_in_its_own_segment():
    """Two segments of 3 and 2 tokens and a padding token: p = (i + 1/2) / span restarts at
    each segment, the last feature is log(span) / log(64), padding reads zero."""
    ids = torch.tensor([[0, 0, 0, 1, 1, 0]])
    valid = torch.tensor([[True, True, True, True, True, False]])
    f = segment_phase(ids, valid, freqs=2)
    assert f.shape == (1, 6, 5)
    p = torch.tensor([1 / 6, 3 / 6, 5 / 6, 1 / 4, 3 / 4])
    span = torch.tensor([3.0, 3, 3, 2, 2])
    sin, cos = (torch.stack([fn(k * torch.pi * p) for k in (1, 2)], -1) for fn in (torch.sin, torch.cos))
    want = torch.cat([sin, cos, (span.log() / np.log(64))[:, None]], -1)
    assert torch.allclose(f[0, :5], want, atol=1e-6)
    assert torch.equal(f[0, 5], torch.zeros(5))
    # batch-wide segment ids (as training batches number them): each row's spans are its own
    two = segment_phase(torch.tensor([[0, 0, 0, 1, 1], [2, 2, 3, 3, 3]]), torch.ones(2, 5, dtype=torch.bool), 2)
    assert torch.allclose(two[0], want, atol=1e-6)
    assert torch.allclose(two[1, 2:], want[:3], atol=1e-6)


def test_phase_term_starts_at_zero_and_then_changes_what_is_drawn():
    """``phase`` adds a projection of each token's segment phase, zero at first: a generator
    fine-tuned with it starts exactly where the one without stood (same codes, one segment or
    a timeline, and in a batch); once trained the phase changes the draws."""
    torch.manual_seed(0)
    plain = KMMGenerator(KMMConfig(codebook_size=16, d_model=32, layers=1)).eval()
    phased = KMMGenerator(KMMConfig(codebook_size=16, d_model=32, layers=1, phase=True)).eval()
    missing, unexpected = phased.load_state_dict(plain.state_dict(), strict=False)
    assert not unexpected and sorted(missing) == ["phase_proj.bias", "phase_proj.weight"]
    texts, empty = torch.randn(3, 384), torch.randn(384)
    g = lambda: torch.Generator().manual_seed(7)  # noqa: E731
    for kw in ({}, {"guidance": 2.0}):
        assert torch.equal(
            plain.generate(texts, empty, [5, 6, 4], g(), **kw), phased.generate(texts, empty, [5, 6, 4], g(), **kw)
        )
    assert torch.equal(plain.generate_batch(texts, empty, 9, g()), phased.generate_batch(texts, empty, 9, g()))
    with pytest.raises(ValueError, match="seg_ids"):
        phased.hidden(
            torch.zeros(1, 4, 6, dtype=torch.long),
            torch.ones(1, 4, dtype=torch.bool),
            torch.ones(1, 4, dtype=torch.bool),
            torch.zeros(1, 4, 32),
        )
    torch.nn.init.normal_(phased.phase_proj.weight, std=3.0)  # as if trained
    assert not torch.equal(plain.generate(texts, empty, [5, 6, 4], g()), phased.generate(texts, empty, [5, 6, 4], g()))


def test_generator_with_phase_trains_from_the_shipped_one_and_generates(tmp_path):
    """`train kmm-generator --phase --init SHIPPED`: the shipped weights load with the phase
    projection at zero, the config records the option, and scoring follows it."""
    from motion_core.eval.tables import kmm_ablation
    from motion_core.inference.checkpoints import WEIGHTS, generator_config
    from motion_core.train.__main__ import main as kmm_main

    data = _tiny_corpus_and_tokeniser(tmp_path)
    out = tmp_path / "gen"
    run = ["kmm-generator", "--data", str(data), "--rvq", str(tmp_path / "rvq"), "--out", str(out), "--phase"]
    kmm_main([*run, "--steps", "2", "--batch", "2", "--save-every", "1", "--init", str(WEIGHTS / "kmm.pt")])
    assert generator_config(out / "kmm.pt").phase
    ck = torch.load(out / "kmm.pt", weights_only=False)
    assert ck["generator"]["phase_proj.weight"].abs().sum() > 0  # two steps moved it off zero
    res = kmm_ablation([f"phase={out / 'kmm.pt'}"], tmp_path / "rvq", data, n=2)
    assert res["phase"]["steps"] == ck["meta"]["steps"] and 0 <= res["phase"]["pass_rate"] <= 1


def test_a_tokeniser_stage_goes_on_with_the_loss_weights_it_was_trained_with(tmp_path):
    """`kmm-rvq --set position_weight=12` is recorded in the stage, and the next stage's
    --init carries it (the VAE's stages do the same); only loss weights may be set, since a
    field that reshapes the network would no longer fit the --init's weights."""
    from motion_core.inference import checkpoints
    from motion_core.train.kmm import rvq_config

    heavier = rvq_config(None, ["position_weight=12"])
    assert heavier.position_weight == 12.0 and RVQConfig().position_weight == 4.0
    stage = tmp_path / "rvq.pt"
    checkpoints.ship(stage, RVQVAE(heavier), {"kind": "rvq", "config": heavier.to_dict(), "steps": 3})
    assert rvq_config(str(stage), []).position_weight == 12.0
    assert rvq_config(str(stage), ["root_weight=2"]) == RVQConfig(position_weight=12.0, root_weight=2.0)
    # a training state records its config at the top; a kmm.pt its tokeniser's as meta's rvq_config
    state = tmp_path / "state.pt"
    checkpoints.write_state(state, model={}, config=RVQConfig(position_weight=7.0).to_dict())
    assert rvq_config(str(state), []).position_weight == 7.0
    kmm = tmp_path / "kmm.pt"
    torch.save({"rvq": {}, "generator": {}, "meta": {"rvq_config": RVQConfig(foot_weight=5.0).to_dict()}}, kmm)
    assert rvq_config(str(kmm), []).foot_weight == 5.0
    shipped = checkpoints.read(checkpoints.WEIGHTS / "kmm.pt")["meta"]["rvq_config"]
    assert rvq_config(str(checkpoints.WEIGHTS / "kmm.pt"), []) == RVQConfig(**shipped)
    with pytest.raises(SystemExit, match="quantizers=2: the tokeniser's --set takes a loss weight"):
        rvq_config(None, ["quantizers=2"])
    with pytest.raises(SystemExit, match="--set: "):
        rvq_config(None, ["position_weight=heavy"])


def test_detail_weights_weigh_the_head_hands_and_feet_positions_up():
    """``upper_detail_weight`` multiplies the position weight of the head, neck, elbows and
    wrists, ``foot_weight`` that of the ankles and feet; at 1 the weights are the shipped ones."""
    from motion_core.body.features import HML_LAYOUT
    from motion_core.body.skeleton import HUMANML3D
    from motion_core.models.conv1d import feature_weights

    def position(w, name):
        start = HML_LAYOUT.ric.start + 3 * (HUMANML3D.index(name) - 1)
        return w[start : start + 3]

    # written out, so that an index slip in the code and in this test cannot agree: after the 4
    # root features, joint j's three (j = 1..21); the head is joint 15, the left foot joint 10
    assert HML_LAYOUT.ric.start == 4 and HUMANML3D.index("head") == 15 and HUMANML3D.index("left_foot") == 10

    plain = feature_weights(263, 5.0, 4.0)
    assert torch.equal(plain, feature_weights(263, 5.0, 4.0, None, 1.0, 1.0))
    w = feature_weights(263, 5.0, 4.0, None, 3.0, 2.0)
    assert abs(float(w.mean()) - 1.0) < 1e-5
    knee = float(position(w, "left_knee")[0])
    assert torch.allclose(w[46:49], torch.full((3,), 3 * knee)) and torch.allclose(w[31:34], torch.full((3,), 2 * knee))
    assert torch.allclose(w[43:46], torch.full((3,), knee))  # the right collar (joint 14) is not weighed up
    assert torch.allclose(position(w, "head"), torch.full((3,), 3 * knee))
    assert torch.allclose(position(w, "right_wrist"), torch.full((3,), 3 * knee))
    assert torch.allclose(position(w, "left_foot"), torch.full((3,), 2 * knee))
    assert float(w[0]) == pytest.approx(knee * 5.0 / 4.0)  # the root's weight keeps its ratio to the positions
    model = RVQVAE(RVQConfig(upper_detail_weight=3.0, foot_weight=2.0))
    assert torch.allclose(model.feature_weights(), w)
