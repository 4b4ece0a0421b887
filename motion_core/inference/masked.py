"""KMM: masked generation of residual-VQ motion tokens by a bidirectional Mamba.

The whole timeline is one token sequence: segment i gets the tokens between
round(F_{i-1}/4) and round(F_i/4), F the cumulative frame counts, so token spans follow
the requested durations to within 2 frames; the decoded motion is cut to exactly
sum(frames). ``steps`` = decoding passes, ``guidance`` = classifier-free guidance on the
base codes (defaults in the registry).
"""

from __future__ import annotations

import copy
import dataclasses
import itertools
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from ..body.features import Normalizer, features_to_joints
from ..body.ik import rigidify
from ..models.keyframes import density_peaks, select_keyframes
from ..models.kmm import KMMGenerator
from ..models.rvq import RVQVAE
from ..nn.text import get_text_encoder
from . import checkpoints
from .base import FPS, MethodInfo, Motion, Plan, batch_motions, finish_total, on_floor, segment_bounds, sync


@dataclass
class MaskedTokenMethod:
    """A loaded KMM: its residual VQ-VAE tokeniser, the masked generator, feature statistics."""

    info: MethodInfo
    rvq: RVQVAE
    generator: KMMGenerator
    normalizer: Normalizer
    meta: dict
    load_seconds: float

    @classmethod
    def load(cls, info: MethodInfo, path: Path) -> MaskedTokenMethod:
        t0 = time.perf_counter()
        rvq, gen, norm, meta = checkpoints.load_kmm(path)
        return cls(info, rvq, gen, norm, meta, time.perf_counter() - t0)

    def to(self, device: torch.device) -> MaskedTokenMethod:
        return dataclasses.replace(
            self, rvq=copy.deepcopy(self.rvq).to(device), generator=copy.deepcopy(self.generator).to(device)
        )

    def denoiser_params(self, sampler: str | None = None) -> int:
        """The generator's parameters (named as the diffusion methods' for the bench table)."""
        return sum(p.numel() for p in self.generator.parameters())

    def autoencoder_params(self) -> int:
        """The tokeniser's parameters (its own, instead of the shared VAE)."""
        return sum(p.numel() for p in self.rvq.parameters())

    def _words(self, texts: list[str], dev: torch.device) -> tuple[torch.Tensor, torch.Tensor] | None:
        """Token embeddings (N + 1, L, D) and mask of ``texts`` and the empty text, for a
        generator that pools words; None for one that reads sentence embeddings only."""
        if not self.generator.cfg.word_pool:
            return None
        tokens, mask = get_text_encoder().encode_words([*texts, ""])
        return tokens.to(dev), mask.to(dev)

    @torch.no_grad()
    def sample(
        self,
        plan: Plan,
        seed: int,
        *,
        steps: int | None = None,
        guidance: float | None = None,
        overlap: int = 0,  # unused: one sequence has no joins
        progress=None,
        rigid: bool = True,
        sampler: str = "quality",  # KMM has its masked decoding only
        timings: dict[str, float],
        device: torch.device | None = None,
    ) -> Motion:
        """The whole plan as one token sequence, with its key frames and token density."""
        dev = device or torch.device("cpu")
        t0 = time.perf_counter()
        enc = get_text_encoder()
        texts = enc.encode([t for t, _ in plan] + [""]).to(dev)
        words = self._words([t for t, _ in plan], dev)
        timings["text"] = time.perf_counter() - t0
        if progress:
            progress(0.0, f"{len(plan)} segment(s) as one sequence")
        per_token = self.rvq.cfg.downsample
        cum = np.cumsum([n for _, n in plan])
        edges = np.concatenate([[0], np.maximum(1, np.round(cum / per_token).astype(int))])
        seg_tokens = [max(1, int(b - a)) for a, b in itertools.pairwise(edges)]
        total = int(cum[-1])
        g = torch.Generator(device=dev).manual_seed(int(seed))
        t1 = time.perf_counter()
        info = self.info
        codes = self.generator.generate(
            texts[:-1],
            texts[-1],
            seg_tokens,
            g,
            iterations=steps or info.default_steps,
            guidance=info.default_guidance if guidance is None else guidance,
            words=words,
        )
        sync(dev)
        t2 = time.perf_counter()
        feats = self.rvq.decode(codes[None])[0].cpu()
        if feats.shape[0] < total:  # rounding left the sequence a few frames short: hold the last pose
            feats = torch.cat([feats, feats[-1:].expand(total - feats.shape[0], -1)])
        joints = features_to_joints(self.normalizer.denormalize(feats[:total])).numpy()
        t3 = time.perf_counter()
        if rigid:
            joints = rigidify(joints)
        joints = on_floor(joints)
        # key frames and density on the generated tokens' latents (the sum of their code vectors)
        latents = self.rvq.quantizer.lookup(codes[None])[0].cpu().numpy()
        d, S, gamma = density_peaks(latents)
        keys = select_keyframes(latents, self.generator.cfg.keyframe_ratio)
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
        finish_total(timings)
        if progress:
            progress(1.0, "done")
        keyframes = [int(centre[k]) for k in keys]
        return Motion(joints, FPS, segment_bounds(plan), info.name, seed, timings, keyframes, density)

    @torch.no_grad()
    def sample_batch(
        self,
        texts: list[str],
        frames: int,
        seed: int,
        *,
        steps: int | None = None,
        guidance: float | None = None,
        rigid: bool = True,
        timings: dict[str, float],
        device: torch.device,
        sampler: str = "quality",  # KMM has its masked decoding only
    ) -> list[Motion]:
        """One token sequence per text, decoded together; rows share one random stream."""
        dev, n = device, frames
        t0 = time.perf_counter()
        emb = get_text_encoder().encode([*texts, ""]).to(dev)
        cond, empty = emb[:-1], emb[-1:]
        words = self._words(texts, dev)
        timings["text"] = time.perf_counter() - t0
        t1 = time.perf_counter()
        per_token = self.rvq.cfg.downsample
        g = torch.Generator(device=dev).manual_seed(int(seed))
        codes = self.generator.generate_batch(
            cond,
            empty[0],
            max(1, round(n / per_token)),
            g,
            iterations=steps or self.info.default_steps,
            guidance=self.info.default_guidance if guidance is None else guidance,
            words=words,
        )
        sync(dev)
        t2 = time.perf_counter()
        feats = self.rvq.decode(codes).cpu()
        if feats.shape[1] < n:  # as in a timeline: hold the last pose for the rounding's frames
            feats = torch.cat([feats, feats[:, -1:].expand(-1, n - feats.shape[1], -1)], dim=1)
        joints = features_to_joints(self.normalizer.denormalize(feats[:, :n])).numpy()
        t3 = time.perf_counter()
        out = batch_motions(joints, texts, n, self.info.name, seed, rigid, timings)
        timings.update(denoise=t2 - t1, decode=t3 - t2, join=time.perf_counter() - t3)
        finish_total(timings)
        return out
