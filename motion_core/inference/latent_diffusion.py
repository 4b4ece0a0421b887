"""Latent diffusion methods (Motion Mamba, FTMoMamba, the transformer baseline): a shared
VAE, a text-conditioned latent denoiser, DDIM with classifier-free guidance.

A timeline is generated as one batch of segments (one latent per segment, its own text, its
length, its own noise stream) and joined by blending an overlap: every segment but the last is generated
``overlap`` frames longer, the next segment is moved rigidly so that its first frame stands
where (and faces where) the previous one is at its boundary, and the overlap's joint
positions are cross-faded with a smoothstep weight. The weight's zero slope at both ends
makes the joined curve continuous in position and in velocity.
"""

from __future__ import annotations

import copy
import dataclasses
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from ..body.features import Normalizer, facing_angles, features_to_joints, rotate_y
from ..body.ik import rigidify
from ..body.skeleton import HUMANML3D
from ..models.consistency import GuidedStudent
from ..models.denoisers import LatentDenoiser
from ..nn.diffusion import Diffusion, DiffusionConfig
from ..nn.text import get_text_encoder
from . import checkpoints
from .base import FPS, InputError, MethodInfo, Motion, Plan, batch_motions, finish_total, on_floor, segment_bounds, sync
from .samplers import GuidedDDIM, LatentSampler, StudentKind, student_kind

_VAE: dict[str, tuple[checkpoints.AnyVAE, Normalizer]] = {}


def shared_vae(path: str | Path | None = None) -> tuple[checkpoints.AnyVAE, Normalizer]:
    """The shipped VAE (or the VAE checkpoint at ``path``, e.g. a stage that an arm's denoiser
    was trained on) and its feature statistics, loaded once per process."""
    key = str(Path(path).resolve()) if path is not None else "vae"
    if key not in _VAE:
        vae, meta = checkpoints.load_vae(Path(path) if path is not None else checkpoints.WEIGHTS / "vae.pt")
        _VAE[key] = (vae, checkpoints.vae_normalizer(meta))
    return _VAE[key]


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
        # (the last frame we have when this segment got no overlap frames: no blend then)
        b = min(end, len(out) - 1)
        f_here = facing_angles(out[b : b + 1], HUMANML3D, smooth=False)[0]
        f_next = facing_angles(nxt[:1], HUMANML3D, smooth=False)[0]
        anchor = nxt[0, 0] * np.array([1.0, 0.0, 1.0])
        nxt = rotate_y(nxt - anchor, f_here - f_next) + out[b, 0] * np.array([1.0, 0.0, 1.0])
        w = min(overlap, len(out) - end, len(nxt))
        s = _smoothstep(w)[:, None, None]
        blend = (1 - s) * out[end : end + w] + s * nxt[:w]
        out = np.concatenate([out[:end], blend, nxt[w:]], axis=0)
        end += n
    return out[:end].astype(np.float32)


@dataclass
class LatentDiffusionMethod:
    """A loaded diffusion method: VAE, denoiser, scheduler, feature statistics, and its
    samplers by name (``inference/samplers.py``): "quality", guided DDIM on the denoiser,
    and "fast", its distilled student (a consistency or a guidance-distilled one), where one
    ships (``MethodInfo.student``)."""

    info: MethodInfo
    vae: checkpoints.AnyVAE
    denoiser: LatentDenoiser
    diffusion: Diffusion
    normalizer: Normalizer
    latent_scale: float
    load_seconds: float
    student: GuidedStudent | None = None
    student_kind: StudentKind | None = None

    @property
    def samplers(self) -> dict[str, LatentSampler]:
        out: dict[str, LatentSampler] = {"quality": GuidedDDIM(self.denoiser, self.diffusion)}
        if self.student is not None and self.student_kind is not None:
            out["fast"] = self.student_kind.sampler(self.student, self.diffusion)
        return out

    @classmethod
    def load(
        cls, info: MethodInfo, path: Path, ck: dict | None = None, vae_path: str | Path | None = None
    ) -> LatentDiffusionMethod:
        """The method of the denoiser checkpoint at ``path`` (``ck``: already read) on the shipped
        VAE, or on the VAE checkpoint ``vae_path`` (an arm's)."""
        t0 = time.perf_counter()
        vae, norm = shared_vae(vae_path)
        ck = ck if ck is not None else checkpoints.read_float32(path)
        meta = ck["meta"]
        if meta.get("vae_steps") != getattr(vae, "steps", None):
            # a denoiser only makes sense on the latents of the VAE it was trained on
            raise RuntimeError(
                f"{path.name} was trained on a VAE of {meta.get('vae_steps')} steps but "
                f"{Path(vae_path).name if vae_path else 'weights/vae.pt'} has {getattr(vae, 'steps', None)}: "
                "ship them together"
            )
        den = checkpoints.load_denoiser(ck, meta.get("kind", info.name))
        # the schedule and prediction target the denoiser was trained with (checkpoints that
        # record none were trained on epsilon, DiffusionConfig's default)
        diffusion = Diffusion(DiffusionConfig(**meta.get("diffusion", {})))
        student, kind = cls._load_student(info, ck["state_dict"])
        return cls(
            info,
            vae,
            den.eval(),
            diffusion,
            norm,
            meta["latent_scale"],
            time.perf_counter() - t0,
            student,
            kind,
        )

    @staticmethod
    def _load_student(info: MethodInfo, teacher_weights: dict) -> tuple[GuidedStudent | None, StudentKind | None]:
        """The method's student and its kind, if one ships. One distilled from other weights
        than this teacher's (its fingerprint, ``checkpoints.weights_fingerprint``) is left
        out with a warning: its latents would not match, and the teacher's own sampler
        still works."""
        if info.student_file is None:
            return None, None
        ck = checkpoints.read_float32(info.student_file)
        meta = ck["meta"]
        if not checkpoints.distilled_from(meta, teacher_weights):
            warnings.warn(
                f"{info.student} was distilled from other weights than {info.checkpoint}: its 'fast' sampler is "
                "left out (distil it again from the shipped teacher)",
                stacklevel=3,
            )
            return None, None
        return checkpoints.load_student(ck).eval(), student_kind(meta)

    def steps_for(self, sampler: str, steps: int | None) -> int | None:
        """The request's steps, or the default: the registry's DDIM steps for "quality", the
        student's own for "fast" (None: the sampler's)."""
        if steps is not None or sampler != "quality":
            return steps
        return self.info.default_steps

    def guidance_for(self, sampler: str, guidance: float | None) -> float | None:
        """The request's guidance scale, or the default: the registry's for "quality" (the
        checkpoint's diffusion config keeps the scale it was trained beside, not the one
        chosen for sampling), the student's own for "fast" (None)."""
        if guidance is not None or sampler != "quality":
            return guidance
        return self.info.default_guidance

    def draw(self, sampler: str, steps: int | None, guidance: float | None) -> LatentSampler:
        """The named sampler, with the request's steps and guidance checked against it."""
        samplers = self.samplers
        if sampler not in samplers:
            raise InputError(
                f"{self.info.display_name} has no {sampler!r} sampler loaded (a student shipped after the method "
                "was loaded needs a restart); choose " + " or ".join(repr(s) for s in samplers)
            )
        if sampler == "fast" and self.student_kind is not None:
            self.student_kind.check(steps, guidance)
        return samplers[sampler]

    def to(self, device: torch.device) -> LatentDiffusionMethod:
        moved = {"vae": self.vae, "denoiser": self.denoiser, "student": self.student}
        return dataclasses.replace(self, **{k: copy.deepcopy(v).to(device) for k, v in moved.items() if v is not None})

    def denoiser_params(self, sampler: str | None = None) -> int:
        """The teacher's, or for "fast" its student's: a student may be a smaller network
        (``train lcm --student-from``), and the w-embedding is its own."""
        net = self.student if sampler == "fast" and self.student is not None else self.denoiser
        return sum(p.numel() for p in net.parameters())

    def autoencoder_params(self) -> int:
        """The shared VAE's parameters."""
        return sum(p.numel() for p in self.vae.parameters())

    @torch.no_grad()
    def sample(
        self,
        plan: Plan,
        seed: int,
        *,
        steps: int | None = None,
        guidance: float | None = None,
        overlap: int = 10,
        progress=None,
        rigid: bool = True,
        timings: dict[str, float],
        device: torch.device,
        sampler: str = "quality",
    ) -> Motion:
        """Each segment from its own latent (seed * 1000 + i), joined; see the module docstring.

        The segments are one batch (row i: segment i's text, length and noise stream): a
        denoiser call costs about the same for one row as for six here, so a timeline costs
        the sampler's calls once, not once per segment. Each row draws its noise from its
        own generator, so a segment's motion is the one it would get sampled alone (up to
        float rounding of the batched matrix products)."""
        dev = device
        draw = self.draw(sampler, steps, guidance)
        steps = self.steps_for(sampler, steps)
        guidance = self.guidance_for(sampler, guidance)
        t0 = time.perf_counter()
        enc = get_text_encoder()
        texts = enc.encode([t for t, _ in plan] + [""]).to(dev)
        timings["text"] = time.perf_counter() - t0
        cond, empty = texts[:-1], texts[-1:]
        if progress:
            progress(0.0, f"{len(plan)} segment{'s' if len(plan) != 1 else ''}")
        lengths = [n for _, n in plan]
        # a latent decodes to at most vae.longest frames: a temporal VAE of max_frames 200
        # gives a 10 s segment no overlap frames, and join_segments then cuts without a blend
        n_gen = [
            min(n + (overlap if i + 1 < len(plan) else 0), max(n, self.vae.longest)) for i, n in enumerate(lengths)
        ]
        gens = [torch.Generator().manual_seed(int(seed) * 1000 + i) for i in range(len(plan))]
        frames = torch.tensor(n_gen, device=dev)
        t1 = time.perf_counter()
        z = draw(cond, empty, frames, (len(plan), *self.vae.latent_shape), gens, steps, guidance, dev)
        sync(dev)
        t2 = time.perf_counter()
        feats = self.normalizer.denormalize(self.vae.decode(z * self.latent_scale, frames).cpu())
        parts = [features_to_joints(feats[i, :n]).numpy() for i, n in enumerate(n_gen)]
        timings.update(denoise=t2 - t1, decode=time.perf_counter() - t2)
        t0 = time.perf_counter()
        joints = join_segments(parts, lengths, overlap)
        if rigid:
            joints = rigidify(joints)
        joints = on_floor(joints)
        timings["join"] = time.perf_counter() - t0
        finish_total(timings)
        if progress:
            progress(1.0, "done")
        return Motion(joints, FPS, segment_bounds(plan), self.info.name, int(seed), timings, sampler=sampler)

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
        sampler: str = "quality",
    ) -> list[Motion]:
        """Row b's start noise is the b-th draw of one stream seeded ``seed * 1000``."""
        dev, n, b = device, frames, len(texts)
        t0 = time.perf_counter()
        emb = get_text_encoder().encode([*texts, ""]).to(dev)
        cond, empty = emb[:-1], emb[-1:]
        timings["text"] = time.perf_counter() - t0
        t1 = time.perf_counter()
        g = torch.Generator().manual_seed(int(seed) * 1000)
        lengths = torch.full((b,), n, device=dev)
        draw = self.draw(sampler, steps, guidance)
        steps, guidance = self.steps_for(sampler, steps), self.guidance_for(sampler, guidance)
        z = draw(cond, empty, lengths, (b, *self.vae.latent_shape), g, steps, guidance, dev)
        sync(dev)
        t2 = time.perf_counter()
        feats = self.vae.decode(z * self.latent_scale, n).cpu()
        joints = features_to_joints(self.normalizer.denormalize(feats[:, :n])).numpy()
        t3 = time.perf_counter()
        out = batch_motions(joints, texts, n, self.info.name, seed, rigid, timings, sampler)
        timings.update(denoise=t2 - t1, decode=t3 - t2, join=time.perf_counter() - t3)
        finish_total(timings)
        return out
