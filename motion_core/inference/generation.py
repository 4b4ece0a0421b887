"""Public generation API: a timeline of (text, seconds) segments -> one continuous motion.

    motion = generate([("a person walks forward", 4.0), ("then waves", 3.0)], method="motion_mamba", seed=0)
    motion.joints  # (T, 22, 3) float32 metres, 20 fps

Diffusion methods generate each segment on its own (one latent per segment, its own
text, its length) and join them by blending an overlap: every segment but the last is
generated ``overlap`` frames longer, the next segment is moved rigidly so that its first
frame stands where (and faces where) the previous one is at its boundary, and the
overlap's joint positions are cross-faded with a smoothstep weight. The weight's zero
slope at both ends makes the joined curve continuous in position and in velocity.
"""

from __future__ import annotations

import itertools
import time
from dataclasses import dataclass, field

import numpy as np
import torch

from .features import facing_angles, features_to_joints, rotate_y
from .ik import rigidify
from .keyframes import density_peaks, select_keyframes
from .registry import MaskedTokenMethod, UnknownMethod, get_info, load_method
from .skeleton import HUMANML3D
from .text import get_text_encoder

FPS = 20
MAX_TEXT_CHARS = 300
MAX_SEGMENTS = 10
MIN_SECONDS, MAX_SECONDS, MAX_TOTAL_SECONDS = 1.0, 10.0, 60.0


class InputError(ValueError):
    """A request a user can get wrong: the message says what to change."""


@dataclass
class Motion:
    joints: np.ndarray  # (T, 22, 3) float32, metres, y up, facing +z at frame 0
    fps: int
    segments: list[tuple[int, int, str]]  # (start_frame, end_frame exclusive, text)
    method: str
    seed: int
    timings: dict[str, float] = field(default_factory=dict)
    keyframes: list[int] | None = None  # KMM only
    density: dict | None = None  # KMM only

    @property
    def frames(self) -> int:
        return int(self.joints.shape[0])

    @property
    def seconds(self) -> float:
        return self.frames / self.fps


def validate(segments: list[tuple[str, float]], method: str) -> list[tuple[str, int]]:
    """Check a timeline; returns (text, frames) pairs or raises InputError / UnknownMethod."""
    get_info(method)
    if not segments:
        raise InputError("the timeline is empty: add at least one segment with a text and a duration")
    if len(segments) > MAX_SEGMENTS:
        raise InputError(f"too many segments: {len(segments)} (at most {MAX_SEGMENTS})")
    out, total = [], 0.0
    for i, seg in enumerate(segments, 1):
        try:
            text, seconds = seg
            seconds = float(seconds)
        except (TypeError, ValueError):
            raise InputError(f"segment {i}: expected a text and a duration in seconds") from None
        text = (text or "").strip() if isinstance(text, str) else ""
        if not text:
            raise InputError(f"segment {i}: the text is empty; describe the motion in words")
        if len(text) > MAX_TEXT_CHARS:
            raise InputError(f"segment {i}: the text has {len(text)} characters (at most {MAX_TEXT_CHARS})")
        if not (MIN_SECONDS <= seconds <= MAX_SECONDS) or not np.isfinite(seconds):
            raise InputError(f"segment {i}: duration {seconds:g} s is outside {MIN_SECONDS:g}-{MAX_SECONDS:g} s")
        total += seconds
        out.append((text, round(seconds * FPS)))
    if total > MAX_TOTAL_SECONDS:
        raise InputError(f"the timeline lasts {total:g} s (at most {MAX_TOTAL_SECONDS:g} s in all)")
    return out


def _smoothstep(n: int) -> np.ndarray:
    s = (np.arange(n) + 0.5) / n
    return s * s * (3 - 2 * s)


def join_segments(parts: list[np.ndarray], lengths: list[int], overlap: int) -> np.ndarray:
    """Chain segment motions (each (T_i, 22, 3), all but the last ``overlap`` frames longer
    than ``lengths[i]``) into one (sum(lengths), 22, 3) motion; see the module docstring."""
    out = parts[0].astype(np.float64)
    end = lengths[0]
    for part, n in zip(parts[1:], lengths[1:], strict=True):
        nxt = part.astype(np.float64)
        # rigid move: next segment's frame 0 root and heading onto ours at the boundary frame
        f_here = facing_angles(out[end : end + 1], HUMANML3D, smooth=False)[0]
        f_next = facing_angles(nxt[:1], HUMANML3D, smooth=False)[0]
        anchor = nxt[0, 0] * np.array([1.0, 0.0, 1.0])
        nxt = rotate_y(nxt - anchor, f_here - f_next) + out[end, 0] * np.array([1.0, 0.0, 1.0])
        w = min(overlap, len(out) - end, len(nxt))
        s = _smoothstep(w)[:, None, None]
        blend = (1 - s) * out[end : end + w] + s * nxt[:w]
        out = np.concatenate([out[:end], blend, nxt[w:]], axis=0)
        end += n
    return out[:end].astype(np.float32)


def _floor(joints: np.ndarray) -> np.ndarray:
    """Put the lowest foot point over the clip on y = 0 (generated roots drift a little)."""
    feet = [i for pair in HUMANML3D.feet for i in pair]
    return joints - np.array([0.0, joints[:, feet, 1].min(), 0.0], dtype=joints.dtype)


@torch.no_grad()
def generate(
    segments: list[tuple[str, float]],
    method: str = "motion_mamba",
    seed: int = 0,
    steps: int | None = None,
    guidance: float | None = None,
    overlap: int = 10,
    progress=None,
    rigid: bool = True,
    device: torch.device | str | None = None,
) -> Motion:
    """Generate one continuous motion for a timeline of (text, seconds) segments.

    ``steps``: DDIM steps (default 50); ``guidance``: classifier-free guidance scale
    (default 7.5); ``progress``: optional callable(fraction, message); ``rigid``: put the
    result on rigid bones (``ik.rigidify``; the decoder's bones stretch by centimetres);
    ``device``: where the networks run (default the CPU; "cuda" on a GPU), decoding to
    joints and joining stay on the CPU. Same inputs and seed give the same motion.
    """
    plan = validate(segments, method)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    dev = torch.device(device or "cpu")
    m = load_method(method, dev)
    timings["load"] = time.perf_counter() - t0
    if isinstance(m, MaskedTokenMethod):
        return _generate_masked(plan, m, int(seed), steps, guidance, progress, rigid, timings, dev)
    t0 = time.perf_counter()
    enc = get_text_encoder()
    texts = enc.encode([t for t, _ in plan] + [""]).to(dev)
    timings["text"] = time.perf_counter() - t0
    cond, empty = texts[:-1], texts[-1:]
    parts, lengths = [], []
    t_denoise = t_decode = 0.0
    for i, (_, n) in enumerate(plan):
        if progress:
            progress(i / len(plan), f"segment {i + 1} of {len(plan)}")
        n_gen = n + (overlap if i + 1 < len(plan) else 0)
        g = torch.Generator().manual_seed(int(seed) * 1000 + i)
        frames = torch.tensor([n_gen], device=dev)
        c = cond[i : i + 1]

        def eps_fn(x, t, guided, c=c, frames=frames):
            if guided:
                return m.denoiser(x, t, torch.cat([c, empty]), torch.cat([frames, frames]))
            return m.denoiser(x, t, c, frames)

        t1 = time.perf_counter()
        z = m.diffusion.sample(eps_fn, (1, *m.vae.latent_shape), g, steps, guidance, device=dev)
        _sync(dev)
        t2 = time.perf_counter()
        feats = m.normalizer.denormalize(m.vae.decode(z * m.latent_scale, n_gen)[0, :n_gen].cpu())
        joints = features_to_joints(feats).numpy()
        t_decode += time.perf_counter() - t2
        t_denoise += t2 - t1
        parts.append(joints)
        lengths.append(n)
    t0 = time.perf_counter()
    joints = join_segments(parts, lengths, overlap)
    if rigid:
        joints = rigidify(joints)
    joints = _floor(joints)
    timings.update(denoise=t_denoise, decode=t_decode, join=time.perf_counter() - t0)
    timings["total"] = sum(v for k, v in timings.items() if k != "load")
    bounds, start = [], 0
    for (text, _), n in zip(plan, lengths, strict=True):
        bounds.append((start, start + n, text))
        start += n
    if progress:
        progress(1.0, "done")
    return Motion(joints, FPS, bounds, method, int(seed), timings)


@torch.no_grad()
def generate_batch(
    texts: list[str],
    seconds: float,
    method: str = "motion_mamba",
    seed: int = 0,
    steps: int | None = None,
    guidance: float | None = None,
    device: torch.device | str | None = None,
    rigid: bool = True,
) -> list[Motion]:
    """One single-segment motion per text, all ``seconds`` long, sampled as one batch on
    ``device`` (default the CPU; "cuda" on a GPU). For throughput (``bench --batch``) and
    batched evaluation; the app's timelines go through ``generate``.

    A batch of one equals ``generate([(texts[0], seconds)], method, seed)``; in a larger batch
    the rows share one random stream (row b's start noise is the b-th draw), so a row's
    motion depends on its batch, and a batch is reproducible as a whole. The networks run
    on ``device``; decoding to joints, ``rigid`` and the floor step on the CPU.
    """
    if not texts:
        raise InputError("no texts to generate")
    plan = [validate([(t, seconds)], method)[0] for t in texts]
    n = plan[0][1]
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    m = load_method(method, device)
    dev = torch.device(device or "cpu")
    timings["load"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    emb = get_text_encoder().encode([t for t, _ in plan] + [""]).to(dev)
    cond, empty = emb[:-1], emb[-1:]
    words = _words(m, [t for t, _ in plan], dev) if isinstance(m, MaskedTokenMethod) else None
    timings["text"] = time.perf_counter() - t0
    b = len(plan)
    t1 = time.perf_counter()
    if isinstance(m, MaskedTokenMethod):
        per_token = m.rvq.cfg.downsample
        g = torch.Generator(device=dev).manual_seed(int(seed))
        codes = m.generator.generate_batch(
            cond,
            empty[0],
            max(1, round(n / per_token)),
            g,
            iterations=steps or m.info.default_steps,
            guidance=m.info.default_guidance if guidance is None else guidance,
            words=words,
        )
        _sync(dev)
        t2 = time.perf_counter()
        feats = m.rvq.decode(codes).cpu()
        if feats.shape[1] < n:  # as in a timeline: hold the last pose for the rounding's frames
            feats = torch.cat([feats, feats[:, -1:].expand(-1, n - feats.shape[1], -1)], dim=1)
    else:
        g = torch.Generator().manual_seed(int(seed) * 1000)
        frames = torch.full((b,), n, device=dev)

        def eps_fn(x, t, guided):
            if guided:
                return m.denoiser(x, t, torch.cat([cond, empty.expand(b, -1)]), torch.cat([frames, frames]))
            return m.denoiser(x, t, cond, frames)

        z = m.diffusion.sample(eps_fn, (b, *m.vae.latent_shape), g, steps, guidance, device=dev)
        _sync(dev)
        t2 = time.perf_counter()
        feats = m.vae.decode(z * m.latent_scale, n).cpu()
    joints = features_to_joints(m.normalizer.denormalize(feats[:, :n])).numpy()
    t3 = time.perf_counter()
    out = []
    for text_joints, (text, _) in zip(joints, plan, strict=True):
        j = rigidify(text_joints) if rigid else text_joints
        out.append(Motion(_floor(j), FPS, [(0, n, text)], m.info.name, int(seed), timings))
    timings.update(denoise=t2 - t1, decode=t3 - t2, join=time.perf_counter() - t3)
    timings["total"] = sum(v for k, v in timings.items() if k != "load")
    return out


def _sync(dev: torch.device) -> None:
    """Wait for queued GPU work, so a stage's time is its own (CUDA calls return early)."""
    if dev.type == "cuda":
        torch.cuda.synchronize(dev)


def _bounds(plan: list[tuple[str, int]]) -> list[tuple[int, int, str]]:
    out, start = [], 0
    for text, n in plan:
        out.append((start, start + n, text))
        start += n
    return out


def _words(m: MaskedTokenMethod, texts: list[str], dev: torch.device) -> tuple[torch.Tensor, torch.Tensor] | None:
    """Token embeddings (N + 1, L, D) and mask of ``texts`` and the empty text, for a KMM
    generator that pools words; None for one that reads sentence embeddings only."""
    if not m.generator.cfg.word_pool:
        return None
    tokens, mask = get_text_encoder().encode_words([*texts, ""])
    return tokens.to(dev), mask.to(dev)


def _generate_masked(
    plan, m: MaskedTokenMethod, seed, steps, guidance, progress, rigid, timings, dev: torch.device | None = None
) -> Motion:
    """KMM: the whole timeline as one token sequence (see ``models.kmm.KMMGenerator.generate``).

    Segment i gets the tokens between round(F_{i-1}/4) and round(F_i/4), F the cumulative
    frame counts, so token spans follow the requested durations to within 2 frames; the
    decoded motion is cut to exactly sum(frames). ``steps`` = decoding passes (default 4, registry),
    ``guidance`` = classifier-free guidance on the base codes (default 1: none, see the registry).
    """
    dev = dev or torch.device("cpu")
    t0 = time.perf_counter()
    enc = get_text_encoder()
    texts = enc.encode([t for t, _ in plan] + [""]).to(dev)
    words = _words(m, [t for t, _ in plan], dev)
    timings["text"] = time.perf_counter() - t0
    if progress:
        progress(0.0, f"{len(plan)} segment(s) as one sequence")
    per_token = m.rvq.cfg.downsample
    cum = np.cumsum([n for _, n in plan])
    edges = np.concatenate([[0], np.maximum(1, np.round(cum / per_token).astype(int))])
    seg_tokens = [max(1, int(b - a)) for a, b in itertools.pairwise(edges)]
    total = int(cum[-1])
    g = torch.Generator(device=dev).manual_seed(int(seed))
    t1 = time.perf_counter()
    info = m.info
    codes = m.generator.generate(
        texts[:-1],
        texts[-1],
        seg_tokens,
        g,
        iterations=steps or info.default_steps,
        guidance=info.default_guidance if guidance is None else guidance,
        words=words,
    )
    _sync(dev)
    t2 = time.perf_counter()
    feats = m.rvq.decode(codes[None])[0].cpu()
    if feats.shape[0] < total:  # rounding left the sequence a few frames short: hold the last pose
        feats = torch.cat([feats, feats[-1:].expand(total - feats.shape[0], -1)])
    joints = features_to_joints(m.normalizer.denormalize(feats[:total])).numpy()
    t3 = time.perf_counter()
    if rigid:
        joints = rigidify(joints)
    joints = _floor(joints)
    # key frames and density on the generated tokens' latents (the sum of their code vectors)
    latents = m.rvq.quantizer.lookup(codes[None])[0].cpu().numpy()
    d, S, gamma = density_peaks(latents)
    keys = select_keyframes(latents, m.generator.cfg.keyframe_ratio)
    centre = np.minimum(np.arange(len(latents)) * per_token + per_token // 2, total - 1)
    density = {
        "frame": centre.tolist(),
        "d": d.tolist(),
        "S": S.tolist(),
        "gamma": gamma.tolist(),
        "selected_tokens": keys.tolist(),
        "frames_per_token": per_token,
    }
    timings.update(denoise=t2 - t1, decode=t3 - t2, join=time.perf_counter() - t3)
    timings["total"] = sum(v for k, v in timings.items() if k != "load")
    if progress:
        progress(1.0, "done")
    return Motion(joints, FPS, _bounds(plan), m.info.name, seed, timings, [int(centre[k]) for k in keys], density)


__all__ = ["InputError", "Motion", "UnknownMethod", "generate", "generate_batch", "validate"]
