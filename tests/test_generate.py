"""The public generation API on the shipped checkpoints: inputs, determinism, joins."""

from __future__ import annotations

import time

import numpy as np
import pytest

import motion_core
from motion_core import InputError, UnknownMethod
from motion_core.body.skeleton import HUMANML3D
from motion_core.inference.generation import validate
from motion_core.inference.latent_diffusion import join_segments
from motion_core.inference.registry import _LOADED, REGISTRY, load_method


def test_methods_lists_every_shipped_method():
    names = {m["name"] for m in motion_core.methods()}
    assert names == set(REGISTRY) == {"motion_mamba", "kmm", "ftmomamba", "baseline"}
    for m in motion_core.methods():
        assert m["display_name"] and m["description"]


@pytest.mark.parametrize(
    ("segments", "method", "message"),
    [
        ([], "motion_mamba", "empty"),
        ([("   ", 3.0)], "motion_mamba", "text is empty"),
        ([("walk" * 80, 3.0)], "motion_mamba", "at most 300"),
        ([("walk", 0.5)], "motion_mamba", "outside 1-10 s"),
        ([("walk", 11)], "motion_mamba", "outside 1-10 s"),
        ([("walk", 3.0)] * 11, "motion_mamba", "too many segments"),
        ([("walk", 10.0)] * 7, "motion_mamba", "at most 60 s"),
        ([("walk", "soon")], "motion_mamba", "expected a text and a duration"),
    ],
)
def test_bad_timelines_get_clear_messages(segments, method, message):
    with pytest.raises(InputError, match=message):
        validate(segments, method)


def test_unknown_method_names_the_available_ones():
    with pytest.raises(UnknownMethod, match="motion_mamba"):
        motion_core.generate([("walk", 2.0)], method="nope")


def test_checkpoints_are_small_and_load_fast():
    for name in REGISTRY:
        info = REGISTRY[name]
        from motion_core.inference.checkpoints import WEIGHTS

        assert (WEIGHTS / info.checkpoint).stat().st_size < 20 * 2**20
        _LOADED.pop(name, None)
        t0 = time.perf_counter()
        load_method(name)
        assert time.perf_counter() - t0 < 2.0
    assert (WEIGHTS / "vae.pt").stat().st_size < 20 * 2**20


@pytest.mark.parametrize("spec", ["motion_mamba", "motion_mamba:fast", "kmm", "ftmomamba", "baseline"])
def test_generate_is_deterministic_and_well_formed(spec):
    method, _, sampler = spec.partition(":")
    kw = {"sampler": "fast"} if sampler else {"sampler": "quality", "steps": 10}
    segs = [("a person walks forward", 2.5), ("a person waves with the right hand", 2.0)]
    a = motion_core.generate(segs, method=method, seed=3, **kw)
    b = motion_core.generate(segs, method=method, seed=3, **kw)
    c = motion_core.generate(segs, method=method, seed=4, **kw)
    assert a.joints.shape == (90, 22, 3) and a.joints.dtype == np.float32
    assert a.fps == 20 and a.method == method
    assert a.segments == [(0, 50, segs[0][0]), (50, 90, segs[1][0])]
    assert np.array_equal(a.joints, b.joints)
    assert not np.array_equal(a.joints, c.joints)
    assert {"text", "denoise", "decode", "total"} <= set(a.timings)
    assert np.isfinite(a.joints).all()
    feet = [i for pair in HUMANML3D.feet for i in pair]
    assert abs(a.joints[:, feet, 1].min()) < 1e-6  # standing on the floor
    bones = np.linalg.norm(a.joints[:, 1:] - a.joints[:, HUMANML3D.parents[1:]], axis=-1)
    assert np.abs(bones.mean(0) - HUMANML3D.bone_lengths[1:]).max() < 0.05


def test_join_is_continuous_in_position_and_velocity():
    t = np.arange(60, dtype=np.float64)
    base = np.zeros((60, 22, 3))
    a = base + np.stack([np.zeros_like(t), np.ones_like(t), 0.05 * t], -1)[:, None]  # walks +z
    b = base + np.stack([np.zeros_like(t), np.ones_like(t), 0.02 * t], -1)[:, None]
    # give both a body so the facing is defined (+z)
    for m in (a, b):
        m[:, 2, 0] -= 0.1  # right hip at -x
        m[:, 1, 0] += 0.1
        m[:, 17, 0] -= 0.2
        m[:, 16, 0] += 0.2
    out = join_segments([a, b], [50, 40], overlap=10).astype(np.float64)
    assert out.shape == (90, 22, 3)
    root = out[:, 0, 2]
    v = np.diff(root)
    # velocity moves from 0.05 to 0.02 m/frame spread over the overlap: a hard cut would
    # change it by 0.03 in one frame; the smoothstep blend's largest one-frame change is ~1/3 of that
    assert np.abs(np.diff(v)).max() < 0.4 * 0.03
    assert abs(v[:45].mean() - 0.05) < 1e-6 and abs(v[-20:].mean() - 0.02) < 1e-6


def test_kmm_returns_key_frames_and_density_on_its_tokens():
    segs = [("a person walks forward", 3.0), ("a person turns left", 2.1), ("a person jumps", 2.0)]
    m = motion_core.generate(segs, method="kmm", seed=1)
    assert m.frames == 60 + 42 + 40 and m.segments[1] == (60, 102, segs[1][0])
    d = m.density
    n_tok = -(-m.frames // d["frames_per_token"])
    assert d["frames_per_token"] == 4
    for key in ("d", "S", "gamma", "frame"):
        assert len(d[key]) == n_tok
    assert np.allclose(np.asarray(d["gamma"]), np.asarray(d["d"]) * np.asarray(d["S"]))
    sel = d["selected_tokens"]
    assert len(sel) == int(np.ceil(0.3 * n_tok))  # the paper's 30% ratio
    # the selected tokens are those of highest gamma; key frames are their centre frames
    gamma = np.asarray(d["gamma"])
    assert gamma[sel].min() >= np.sort(gamma)[-len(sel)]
    assert m.keyframes == [d["frame"][k] for k in sel]
    assert all(0 <= k < m.frames for k in m.keyframes)
    # diffusion methods carry neither
    other = motion_core.generate(segs[:1], method="baseline", seed=1, steps=5)
    assert other.keyframes is None and other.density is None


def test_kmm_timeline_is_one_sequence_with_per_segment_texts():
    """Changing one segment's text changes that span most; the timeline is generated as one
    sequence, so the boundary tokens may change too, but the far segment stays close.
    Without the foot lock: it moves the legs by what the floor and the plants make of each
    motion, which is the post-processing's doing, not the generator's."""
    a = motion_core.generate(
        [("a person walks forward", 4.0), ("a person jumps", 4.0)], method="kmm", seed=2, foot_lock=False
    )
    b = motion_core.generate(
        [("a person walks forward", 4.0), ("a person waves with the left hand", 4.0)],
        method="kmm",
        seed=2,
        foot_lock=False,
    )
    rel_a, rel_b = a.joints - a.joints[:, :1], b.joints - b.joints[:, :1]
    first = np.abs(rel_a[:60] - rel_b[:60]).mean()
    second = np.abs(rel_a[80:] - rel_b[80:]).mean()
    assert second > first


@pytest.mark.parametrize("spec", ["motion_mamba", "motion_mamba:fast", "kmm", "ftmomamba", "baseline"])
def test_generate_batch_of_one_equals_generate_and_batches_are_reproducible(spec):
    from motion_core import generate_batch

    method, _, sampler = spec.partition(":")
    kw = {"sampler": "fast"} if sampler else {"sampler": "quality", "steps": 5}
    text = "a person walks forward and waves with the right hand"
    single = motion_core.generate([(text, 3.0)], method=method, seed=5, **kw)
    (one,) = generate_batch([text], 3.0, method=method, seed=5, **kw)
    assert np.array_equal(one.joints, single.joints)
    assert one.segments == [(0, 60, text)] and one.method == method
    texts = ["a person jumps up", text, "a person turns left"]
    a = generate_batch(texts, 3.0, method=method, seed=5, **kw)
    b = generate_batch(texts, 3.0, method=method, seed=5, **kw)
    assert [m.segments[0][2] for m in a] == texts
    for x, y in zip(a, b, strict=True):
        assert x.joints.shape == (60, 22, 3) and np.array_equal(x.joints, y.joints)
        assert np.isfinite(x.joints).all()
    assert not np.array_equal(a[0].joints, a[2].joints)  # each row is its own sample
    assert load_method(method, "cpu") is load_method(method)  # the CPU needs no copy


def test_generate_batch_rejects_what_generate_rejects():
    from motion_core import generate_batch

    with pytest.raises(InputError, match="no texts"):
        generate_batch([], 2.0, method="baseline")
    with pytest.raises(InputError, match="text is empty"):
        generate_batch(["a person walks", " "], 2.0, method="baseline")
    with pytest.raises(InputError, match="outside"):
        generate_batch(["a person walks"], 30.0, method="kmm")
    with pytest.raises(UnknownMethod):
        generate_batch(["a person walks"], 2.0, method="nope")


def test_a_bare_cuda_device_names_the_current_one(monkeypatch):
    """A bare "cuda" and "cuda:0" must key one device copy of a method, not two (no GPU:
    only the name is resolved)."""
    import torch

    from motion_core.inference.registry import canonical_device

    monkeypatch.setattr(torch.cuda, "current_device", lambda: 1)
    assert canonical_device("cuda") == torch.device("cuda", 1)
    assert canonical_device("cuda:0") == torch.device("cuda", 0)
    assert canonical_device(None) == canonical_device("cpu") == torch.device("cpu")


@pytest.mark.parametrize("method", ["motion_mamba", "baseline"])
def test_a_diffusion_method_samples_its_registry_steps_by_default(method):
    # the registry's DDIM steps (chosen on validation prompts), not the scheduler's 50. Named
    # "quality": Motion Mamba's default sampler is its student (next test)
    from motion_core.inference.registry import DIFFUSION_STEPS, GUIDANCE

    info = {m["name"]: m for m in motion_core.methods()}[method]
    assert info["default_steps"] == DIFFUSION_STEPS == 5
    assert info["default_guidance"] == GUIDANCE[method]
    segs = [("a person jumps up", 2.0)]
    default = motion_core.generate(segs, method=method, seed=1, sampler="quality")
    explicit = motion_core.generate(segs, method=method, seed=1, sampler="quality", steps=5, guidance=GUIDANCE[method])
    assert np.array_equal(default.joints, explicit.joints)
    # the registry's scale is the one sampled with, not the checkpoint's diffusion config's
    # (7.5): until 2026-11-26 generate() sampled at the latter whatever methods() listed
    q = {"sampler": "quality"}
    old_scale = motion_core.generate(segs, method=method, seed=1, steps=5, guidance=7.5, **q)
    assert not np.array_equal(default.joints, old_scale.joints)
    for other in (10, 50):
        assert not np.array_equal(
            default.joints, motion_core.generate(segs, method=method, seed=1, steps=other, **q).joints
        )
    batch = motion_core.generate_batch(["a person jumps up"], 2.0, method=method, seed=1, **q)
    assert np.array_equal(
        batch[0].joints,
        motion_core.generate_batch(
            ["a person jumps up"], 2.0, method=method, seed=1, steps=5, guidance=GUIDANCE[method], **q
        )[0].joints,
    )


def test_motion_mambas_default_sampler_is_its_student_and_a_ddim_step_count_says_so():
    """Since 2026-11-27 Motion Mamba's student is within 2 points of its teacher on the
    validation prompts, so a bare generate() samples with it; DDIM's step counts then ask
    for the quality sampler by name, and the message says so."""
    info = {m["name"]: m for m in motion_core.methods()}["motion_mamba"]
    assert info["default_sampler"] == "fast"
    segs = [("a person jumps up", 2.0)]
    default = motion_core.generate(segs, method="motion_mamba", seed=1)
    assert default.sampler == "fast"
    assert np.array_equal(
        default.joints, motion_core.generate(segs, method="motion_mamba", seed=1, sampler="fast").joints
    )
    with pytest.raises(InputError, match="sampler='quality' takes up to 100 DDIM steps"):
        motion_core.generate(segs, method="motion_mamba", seed=1, steps=10)


@pytest.mark.parametrize("spec", ["motion_mamba:quality", "motion_mamba:fast", "ftmomamba:quality", "baseline:fast"])
def test_a_timelines_segments_sampled_as_one_batch_equal_each_sampled_alone(spec):
    """A timeline's segments are one batch, each row with its own text, length and noise
    stream (one generator per row): each row equals that segment sampled by itself, up to
    the float rounding of batched matrix products."""
    import torch

    from motion_core.nn.text import get_text_encoder

    method, _, sampler = spec.partition(":")
    m = load_method(method)
    texts = ["a person walks forward", "a person jumps up", "a person waves with the right hand"]
    emb = get_text_encoder().encode([*texts, ""])
    cond, empty = emb[:-1], emb[-1:]
    frames = torch.tensor([110, 60, 200])
    draw = m.draw(sampler, None, None)
    steps, guidance = m.steps_for(sampler, None), m.guidance_for(sampler, None)
    shape = tuple(m.vae.latent_shape)

    def gen(i: int):
        return torch.Generator().manual_seed(7000 + i)

    batched = draw(cond, empty, frames, (3, *shape), [gen(i) for i in range(3)], steps, guidance, "cpu")
    for i in range(3):
        alone = draw(cond[i : i + 1], empty, frames[i : i + 1], (1, *shape), gen(i), steps, guidance, "cpu")
        torch.testing.assert_close(batched[i : i + 1], alone, atol=1e-5, rtol=0)
    assert not torch.allclose(batched[0], batched[1])


def test_noise_drawn_with_one_generator_per_row_is_each_rows_own_stream():
    import torch

    from motion_core.nn.diffusion import randn_rows

    rows = randn_rows((3, 4, 2), [torch.Generator().manual_seed(s) for s in (1, 2, 3)])
    for i, s in enumerate((1, 2, 3)):
        assert torch.equal(rows[i : i + 1], torch.randn((1, 4, 2), generator=torch.Generator().manual_seed(s)))
    one = randn_rows((3, 4, 2), torch.Generator().manual_seed(1))
    assert torch.equal(one, torch.randn((3, 4, 2), generator=torch.Generator().manual_seed(1)))
    with pytest.raises(ValueError, match="2 generators for a batch of 3"):
        randn_rows((3, 4, 2), [torch.Generator(), torch.Generator()])
