"""Every checkpoint read and write of the project, and the float16 <-> float32 conversion.

Formats (all ``torch.save`` dicts):

* shipped weights (``motion_core/weights/*.pt``): floating tensors in float16, half the size;
  loading casts them back to float32. VAE and denoisers: {"state_dict", "meta"}; KMM:
  {"generator", "rvq", "meta"}; a VAE's meta names its ``arch`` (``VAE_ARCHS``, "transformer"
  when absent: the VAEs before the temporal one); the evaluator: {"state_dict", "config", "mean", "std", "meta"}.
* a training run's result (``OUT/vae.pt``, ``OUT/<kind>.pt``, ``OUT/rvq.pt``, ``OUT/kmm.pt``):
  the same layout in float32.
* a distilled student (shipped as ``motion_core/weights/<kind>_fast.pt``; a run's
  ``OUT/<kind>_lcm.pt`` or ``OUT/<kind>_guidance.pt``): {"state_dict", "meta"} like its
  teacher's, the state dict a ``GuidedStudent``'s ("net." the teacher's architecture,
  "w_embed." the guidance embedding), the meta the teacher's config and kind plus
  "teacher" and its kind's settings: "consistency" (``ConsistencyConfig``) or
  "guidance_distillation" (``GuidanceDistillConfig``); see ``samplers.student_kind``.
* a training state (``OUT/state.pt``): {"model", "opt", "step", "rng", ...}, written
  atomically so that a kill mid-save never leaves a broken file.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import torch

from ..body.features import Normalizer
from ..models.consistency import GuidedStudent
from ..models.conv_vae import ConvMotionVAE, ConvVAEConfig
from ..models.kmm import KMMConfig, KMMGenerator
from ..models.latent_denoisers import build_denoiser, config_from_dict
from ..models.length import LengthConfig, LengthEstimator
from ..models.rvq import RVQVAE, RVQConfig
from ..models.vae import MotionVAE, VAEConfig
from .base import WEIGHTS

__all__ = ["WEIGHTS"]  # re-exported: the trainers ship into it


# ------------------------------------------------------------------ raw reads and writes


def read(path: str | Path) -> dict:
    """A checkpoint's dict, tensors on the CPU."""
    return torch.load(Path(path), map_location="cpu", weights_only=False)


def read_state(path: str | Path) -> dict:
    """A training state, to resume a run: tensors on the CPU (a state saved on a GPU resumes
    anywhere; load_state_dict moves them to the parameters' device)."""
    return torch.load(Path(path), map_location="cpu", weights_only=False)


def write(path: str | Path, checkpoint: dict) -> None:
    torch.save(checkpoint, Path(path))


def write_state(path: Path, **state) -> None:
    """A resumable training state, atomically: a kill mid-save never leaves a broken file."""
    tmp = path.with_suffix(".tmp")
    torch.save(state, tmp)
    tmp.replace(path)


def float16_state(sd: dict) -> dict:
    """A state dict as shipped: floating tensors in float16 (half the size; inference casts
    back to float32), integer buffers as they are."""
    # on the CPU: a network trained on a GPU ships the same file as one trained here
    return {k: (v.detach().cpu().half() if v.is_floating_point() else v.cpu()) for k, v in sd.items()}


def float32_state(sd: dict) -> dict:
    """A state dict with float16 tensors (as shipped) made float32 again."""
    return {k: v.float() if v.is_floating_point() else v for k, v in sd.items()}


def save_run(path: Path, model: torch.nn.Module, meta: dict) -> None:
    """A training run's result: float32 weights and the meta that rebuilds the model."""
    torch.save({"state_dict": {k: v.detach().cpu() for k, v in model.state_dict().items()}, "meta": meta}, path)


def ship(path: Path, model: torch.nn.Module, meta: dict) -> None:
    """Inference checkpoint: float16 weights and the configs needed to rebuild the model."""
    path.parent.mkdir(parents=True, exist_ok=True)
    # through a temporary file and a rename: a process reading the weights folder (a running
    # demo lists students by reading them) never sees half a file, and a symlinked entry is
    # replaced, not written through to the file it points at
    tmp = path.with_name(path.name + ".tmp")
    torch.save({"state_dict": float16_state(model.state_dict()), "meta": meta}, tmp)
    tmp.replace(path)


# ------------------------------------------------------------------ VAE and latent denoisers


def read_float32(path: str | Path) -> dict:
    """A {"state_dict", "meta"} checkpoint (shipped or a run's) with a float32 state dict."""
    ck = read(path)
    ck["state_dict"] = float32_state(ck["state_dict"])
    return ck


# the VAE architectures a checkpoint's meta["arch"] may name: (model class, config class)
VAE_ARCHS: dict[str, tuple[type, type]] = {
    "transformer": (MotionVAE, VAEConfig),
    "conv": (ConvMotionVAE, ConvVAEConfig),
}
AnyVAE = MotionVAE | ConvMotionVAE


def build_vae(arch: str, config: dict) -> AnyVAE:
    """A fresh VAE of architecture ``arch`` from a config dict."""
    if arch not in VAE_ARCHS:
        raise ValueError(f"unknown VAE arch {arch!r}; one of {sorted(VAE_ARCHS)}")
    model_cls, cfg_cls = VAE_ARCHS[arch]
    return model_cls(cfg_cls(**config))


def vae_arch(vae: AnyVAE) -> str:
    return next(a for a, (cls, _) in VAE_ARCHS.items() if isinstance(vae, cls))


def load_vae(path: str | Path) -> tuple[AnyVAE, dict]:
    """A VAE checkpoint (a training run's or the shipped float16 one) in eval mode, and its meta."""
    ck = read_float32(path)
    vae = build_vae(ck["meta"].get("arch", "transformer"), ck["meta"]["config"])
    vae.load_state_dict(ck["state_dict"])
    vae.steps = ck["meta"].get("steps")
    return vae.eval(), ck["meta"]


def vae_normalizer(meta: dict) -> Normalizer:
    """The feature statistics a VAE was trained with (its checkpoint's meta)."""
    return Normalizer(np.asarray(meta["mean"]), np.asarray(meta["std"]))


def load_denoiser(ck: dict, kind: str):
    """The latent denoiser of a ``read_float32`` checkpoint, built from its recorded config."""
    den = build_denoiser(kind, config_from_dict(kind, ck["meta"]["config"]))
    den.load_state_dict(ck["state_dict"])
    return den


def weights_fingerprint(state_dict: dict) -> str:
    """sha256 of a network's weights as shipped (float16), key by key in order: a float32
    run checkpoint and its shipped float16 copy share it."""
    h = hashlib.sha256()
    for k, v in sorted(float16_state(state_dict).items()):
        h.update(k.encode())
        h.update(v.detach().cpu().contiguous().numpy().tobytes())
    return h.hexdigest()


def distilled_from(student_meta: dict, teacher_state: dict) -> bool:
    """Whether a student (its meta) was distilled from these teacher weights: a student of
    other weights would start from latents its teacher never made."""
    return student_meta.get("teacher", {}).get("fingerprint") == weights_fingerprint(teacher_state)


def load_student(ck: dict) -> GuidedStudent:
    """The distilled student (either kind) of a ``read_float32`` checkpoint (see the formats above)."""
    kind = ck["meta"]["kind"]
    student = GuidedStudent(build_denoiser(kind, config_from_dict(kind, ck["meta"]["config"])))
    student.load_state_dict(ck["state_dict"])
    return student


# ------------------------------------------------------------------ KMM: tokeniser and generator


def load_kmm(path: str | Path) -> tuple[RVQVAE, KMMGenerator, Normalizer, dict]:
    """A shipped kmm.pt: tokeniser and generator in eval mode, feature statistics, meta."""
    ck = read(path)
    meta = ck["meta"]
    rvq = RVQVAE(RVQConfig(**meta["rvq_config"]))
    rvq.load_state_dict(float32_state(ck["rvq"]))
    gen = KMMGenerator(KMMConfig(**meta["config"]))
    gen.load_state_dict(float32_state(ck["generator"]))
    return rvq.eval(), gen.eval(), vae_normalizer(meta), meta


def save_kmm(path: Path, generator: KMMGenerator, rvq: RVQVAE, meta: dict, half: bool = False) -> None:
    """A kmm.pt: generator, tokeniser and meta (``half``: float16, as shipped)."""
    ck = {"generator": generator.state_dict(), "rvq": rvq.state_dict()}
    if half:
        ck = {k: float16_state(sd) for k, sd in ck.items()}
        path.parent.mkdir(parents=True, exist_ok=True)
    torch.save({**ck, "meta": meta}, path)


def load_rvq(path: str | Path) -> tuple[RVQVAE, dict]:
    ck = read(path)
    model = RVQVAE(RVQConfig(**ck["meta"]["config"]))
    model.load_state_dict(float32_state(ck["state_dict"]))
    return model.eval(), ck["meta"]


def init_rvq(model: RVQVAE, path: str | Path) -> int:
    """Load tokeniser weights from a shipped kmm.pt ("rvq"), an rvq.pt or a training state;
    the codebooks' EMA statistics come along, so training goes on where those weights stood.
    Returns the steps they had been trained for."""
    ck = read(path)
    sd = ck.get("rvq") or ck.get("state_dict") or ck["model"]
    model.load_state_dict(float32_state(sd))
    if "rvq" in ck:
        return int(ck["meta"]["rvq_steps"])
    return int(ck["meta"]["steps"] if "meta" in ck else ck["step"])


def rvq_config_of(path: str | Path) -> RVQConfig | None:
    """The tokeniser config recorded with the weights at ``path``, in the forms ``init_rvq``
    reads: a shipped kmm.pt (meta's rvq_config), an rvq.pt or a stage (meta's config) or a
    training state (its config); None where none is recorded."""
    ck = read(path)
    meta = ck.get("meta", {})
    if "rvq" in ck:
        recorded = meta.get("rvq_config")
    elif "meta" in ck:
        recorded = meta.get("config") if meta.get("kind") == "rvq" else None
    else:
        recorded = ck.get("config")
    return RVQConfig(**recorded) if recorded else None


def decoder_only_steps(path: str | Path) -> int:
    """The decoder-only steps already in the tokeniser weights at ``path`` (a shipped kmm.pt,
    an rvq.pt or a training state, which records none)."""
    meta = read(path).get("meta", {})
    return int(meta.get("rvq_decoder_only_steps", meta.get("decoder_only_steps", 0)) or 0)


def _generator_state(ck: dict) -> dict:
    """The generator's weights in a shipped kmm.pt ("generator") or a training state ("model")."""
    return ck["generator"] if "generator" in ck else ck["model"]


def _generator_config_of(ck: dict) -> KMMConfig:
    cfg = ck["meta"]["config"] if "meta" in ck else ck.get("config")
    if cfg:
        return KMMConfig(**cfg)
    # a state saved before configs were recorded: the defaults, and the phase term if its weights are there
    return KMMConfig(phase="phase_proj.weight" in _generator_state(ck))


def _load_generator_weights(model: KMMGenerator, ck: dict, path: str | Path) -> int:
    missing, unexpected = model.load_state_dict(float32_state(_generator_state(ck)), strict=False)
    if unexpected or any(not k.startswith(("word_", "phase_")) for k in missing):
        raise RuntimeError(f"{path} does not fit this generator: missing {missing}, unexpected {unexpected}")
    return int(ck["meta"]["steps"] if "meta" in ck else ck["step"])


def generator_config(path: str | Path) -> KMMConfig:
    """The network config of a generator checkpoint: a shipped kmm.pt's meta, or a training
    state's own record (states saved before widths became options hold none: the defaults)."""
    return _generator_config_of(read(path))


def init_generator(model: KMMGenerator, path: str | Path) -> int:
    """Load generator weights from a shipped kmm.pt ("generator") or a training state ("model");
    returns the steps those weights had been trained for. A generator with word pooling may
    start from one without: its word weights keep their initialisation (a zero output)."""
    return _load_generator_weights(model, read(path), path)


def load_generator(path: str | Path) -> tuple[KMMGenerator, int]:
    """A generator checkpoint (kmm.pt or training state) read once: the network at its own
    config, in eval mode, and the steps it was trained for."""
    ck = read(path)
    model = KMMGenerator(_generator_config_of(ck))
    steps = _load_generator_weights(model, ck, path)
    return model.eval(), steps


def extract_rvq(shipped: str | Path, out: str | Path) -> Path:
    """Write the tokeniser inside a shipped kmm.pt (float16) as ``out/rvq.pt`` in float32,
    in the format ``train kmm-rvq`` writes; the float16 rounding is the one the demo decodes with."""
    ck = read(shipped)
    meta = ck["meta"]
    rvq_meta = {
        "kind": "rvq",
        "config": meta["rvq_config"],
        "steps": meta["rvq_steps"],
        "decoder_only_steps": meta.get("rvq_decoder_only_steps", 0),
        "data": meta.get("data"),
        "test_500": meta.get("rvq_test_500"),
        "mean": meta["mean"],
        "std": meta["std"],
        "extracted_from": str(shipped),
    }
    sd = float32_state(ck["rvq"])
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    torch.save({"state_dict": sd, "meta": rvq_meta}, out / "rvq.pt")
    return out / "rvq.pt"


def swap_decoder(shipped: str | Path, rvq_run: str | Path, out: str | Path) -> Path:
    """Write ``out`` (a kmm.pt): the shipped KMM with the decoder of a ``kmm-rvq --decoder-only``
    run. Refused unless the run's encoder and codebooks equal the shipped ones, since any
    other change would give the generator codes it was not trained on."""
    ck = read(shipped)
    tuned, rvq_meta = load_rvq(Path(rvq_run) / "rvq.pt")
    new = tuned.state_dict()
    for name, v in ck["rvq"].items():
        if not name.startswith("decoder.") and not torch.equal(v, new[name].to(v.dtype)):
            raise SystemExit(f"{rvq_run}: {name} differs from {shipped}; only the decoder may change")
    half = float16_state(new)
    meta = {
        **ck["meta"],
        "rvq_steps": rvq_meta["steps"],
        "rvq_decoder_only_steps": rvq_meta.get("decoder_only_steps", 0),
        "rvq_test_500": rvq_meta.get("test_500"),
    }
    torch.save({**ck, "rvq": half, "meta": meta}, Path(out))
    return Path(out)


# ------------------------------------------------------------------ length estimator


def load_length(path: str | Path) -> LengthEstimator:
    """The length estimator as shipped ({"state_dict", "meta"}), in float32, eval mode."""
    ck = read(path)
    model = LengthEstimator(LengthConfig(**ck["meta"]["config"]))
    model.load_state_dict(float32_state(ck["state_dict"]))
    return model.eval()
