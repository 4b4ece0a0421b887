"""The method registry: the one list of generators the core offers and the app shows.

Each entry names its display name, a one-line description, how to build its network and
which shipped checkpoint holds its weights. ``methods()`` lists the entries whose
checkpoints are present; ``load_method`` loads one once per process and shares it.
"""

from __future__ import annotations

import copy
import dataclasses
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from .diffusion import Diffusion, DiffusionConfig
from .features import Normalizer
from .models.denoisers import (
    LatentDenoiser,
    MotionMambaConfig,
    TransformerConfig,
    motion_mamba_denoiser,
    transformer_denoiser,
)
from .models.ftmomamba import FTMoMambaConfig, ftmomamba_denoiser
from .models.kmm import KMMConfig, KMMGenerator
from .models.rvq import RVQVAE, RVQConfig
from .models.vae import MotionVAE, VAEConfig
from .ssm import SSMConfig

WEIGHTS = Path(__file__).parent / "weights"


@dataclass(frozen=True)
class MethodInfo:
    name: str
    display_name: str
    description: str
    checkpoint: str
    max_seconds: float = 10.0  # per segment; longer timelines are composed from segments
    family: str = "diffusion"  # "diffusion" (shared VAE + denoiser) or "masked" (KMM: own tokeniser)
    # sampling defaults: DDIM steps and CFG scale (diffusion); decoding passes and CFG on
    # the base codes (masked, MoMask's ~10 passes and scale ~4)
    default_steps: int = 50
    default_guidance: float = 7.5
    steps_label: str = "sampling steps (DDIM)"

    @property
    def available(self) -> bool:
        own = (WEIGHTS / self.checkpoint).is_file()
        return own and (self.family != "diffusion" or (WEIGHTS / "vae.pt").is_file())


REGISTRY: dict[str, MethodInfo] = {
    m.name: m
    for m in (
        MethodInfo(
            "motion_mamba",
            "Motion Mamba",
            "Latent diffusion with a U-Net of hierarchical temporal (HTM) and bidirectional spatial (BSM) "
            "Mamba blocks (Zhang et al. 2024).",
            "motion_mamba.pt",
        ),
        MethodInfo(
            "kmm",
            "KMM",
            "Masked generation of residual-VQ motion tokens by a bidirectional Mamba, key frames chosen by "
            "density peaks, text-motion contrastive alignment; one sequence for the whole timeline, "
            "boundaries in-filled (Zhang et al. 2024).",
            "kmm.pt",
            family="masked",
            # 4 passes, not MoMask's 10: on 200 test prompts 10 / 6 / 4 passes gave 33.0 / 32.0 /
            # 32.5% verifier passes and 47.7 / 53.5 / 55.8% direction accuracy, while a 10 s
            # timeline took 237 / 171 / 140 ms (2026-11-23, one thread, the other core busy)
            default_steps=4,
            # scale 1 (plain conditional sampling, no unconditional pass), not MoMask's 4: on the
            # same 200 prompts scales 0 / 0.5 / 1 / 1.5 / 2 / 3 / 4 / 7 gave 9.5 / 41 / 50 / 47 /
            # 43.5 / 34 / 32.5 / 26% verifier passes (50 / 45% for 1 / 2 with other seeds), and
            # direction accuracy did not rise above scale 1's 53-55% either (2026-11-23); on the
            # 4,900-step generator scales 1 / 1.5 / 2 gave 60.5 / 55.0 / 54.5% passes, on the
            # 5,700-step one 1 / 1.5 gave 67.0 / 63.5%, on the 9,900-step one 70.0 / 68.5% (direction
            # 83.7 / 86.0%: within the noise of 86 prompts, and 1 needs half the work)
            default_guidance=1.0,
            steps_label="decoding passes (masked)",
        ),
        MethodInfo(
            "ftmomamba",
            "FTMoMamba",
            "The same latent diffusion with a U-Net of FTMamba blocks: frequency bands (DWT) injected into the "
            "state matrix A (FreqSSM) and the sentence embedding into the output matrix C (TextSSM) "
            "(Li et al. 2024).",
            "ftmomamba.pt",
        ),
        MethodInfo(
            "baseline",
            "Transformer baseline (MLD-style)",
            "The same latent diffusion with an MLD-style skip-transformer denoiser; the reference for every "
            "speed and quality claim.",
            "baseline.pt",
        ),
    )
}


_BUILTIN = frozenset(REGISTRY)


def default_config(name: str) -> MotionMambaConfig | TransformerConfig | FTMoMambaConfig:
    """Configurations of the shipped checkpoints; sized so that 50 guided DDIM steps fit the
    2-core CPU budget (see README, 'Motion Mamba on a CPU')."""
    if name == "motion_mamba":
        return MotionMambaConfig(
            levels=3, htm_ssm=SSMConfig(expand=0.5, d_state=8), bsm_ssm=SSMConfig(expand=2.0, d_state=4)
        )
    if name == "baseline":
        return TransformerConfig(levels=1, ff=1024)
    if name == "ftmomamba":
        # one FTMamba block per stage (the paper: two) to stay near Motion Mamba's CPU cost
        return FTMoMambaConfig(layers_per_stage=1)
    raise KeyError(name)


def override_config(cfg, assignments: list[str]):
    """A copy of a denoiser config with "field=value" assignments applied (the ablation arms,
    e.g. ``htm_order=flat``, ``bsm=single``, ``freq=off``, ``transform=fft``); values take
    the type of the field's current value. Unknown fields are an error naming the known ones."""
    known = {f.name for f in dataclasses.fields(cfg)}
    changes: dict = {}
    for item in assignments:
        key, sep, value = item.partition("=")
        if not sep or key not in known:
            raise ValueError(f"bad override {item!r}: expected FIELD=VALUE with FIELD one of {sorted(known)}")
        cur = getattr(cfg, key)
        if isinstance(cur, bool):
            changes[key] = value.lower() in ("1", "true", "yes", "on")
        elif isinstance(cur, (int, float, str)):
            changes[key] = type(cur)(value)
        else:
            raise ValueError(f"{key} cannot be set from the command line")
    return dataclasses.replace(cfg, **changes)  # the configs' __post_init__ checks the values


def build_denoiser(name: str, cfg) -> LatentDenoiser:
    if name == "motion_mamba":
        return motion_mamba_denoiser(cfg)
    if name == "baseline":
        return transformer_denoiser(cfg)
    if name == "ftmomamba":
        return ftmomamba_denoiser(cfg)
    raise KeyError(name)


def _config_from_dict(name: str, d: dict):
    if name == "motion_mamba":
        d = dict(d)
        d["htm_ssm"] = SSMConfig(**d["htm_ssm"])
        d["bsm_ssm"] = SSMConfig(**d["bsm_ssm"])
        return MotionMambaConfig(**d)
    if name == "ftmomamba":
        return FTMoMambaConfig(**d)  # its __post_init__ rebuilds the SSMConfig from a dict
    return TransformerConfig(**d)


class UnknownMethod(ValueError):
    pass


def methods() -> list[dict]:
    """The available methods: name, display name, description, per-segment limit, sampling defaults."""
    return [
        {
            "name": m.name,
            "display_name": m.display_name,
            "description": m.description,
            "max_seconds": m.max_seconds,
            "default_steps": m.default_steps,
            "default_guidance": m.default_guidance,
            "steps_label": m.steps_label,
        }
        for m in REGISTRY.values()
        if m.available
    ]


def get_info(name: str) -> MethodInfo:
    if name not in REGISTRY or not REGISTRY[name].available:
        known = ", ".join(m["name"] for m in methods()) or "none"
        raise UnknownMethod(f"unknown method {name!r}; available: {known}")
    return REGISTRY[name]


def _load(path: Path) -> dict:
    ck = torch.load(path, map_location="cpu", weights_only=False)
    ck["state_dict"] = {k: v.float() if v.is_floating_point() else v for k, v in ck["state_dict"].items()}
    return ck


def load_vae(path: str | Path) -> tuple[MotionVAE, dict]:
    """A VAE checkpoint (a training run's or the shipped float16 one) in eval mode, and its meta."""
    ck = _load(Path(path))
    vae = MotionVAE(VAEConfig(**ck["meta"]["config"]))
    vae.load_state_dict(ck["state_dict"])
    vae.steps = ck["meta"].get("steps")
    return vae.eval(), ck["meta"]


@dataclass
class LatentDiffusionMethod:
    """A loaded diffusion method: VAE, denoiser, scheduler, feature statistics."""

    info: MethodInfo
    vae: MotionVAE
    denoiser: LatentDenoiser
    diffusion: Diffusion
    normalizer: Normalizer
    latent_scale: float
    load_seconds: float

    def denoiser_params(self) -> int:
        return sum(p.numel() for p in self.denoiser.parameters())


@dataclass
class MaskedTokenMethod:
    """A loaded KMM: its residual VQ-VAE tokeniser, the masked generator, feature statistics."""

    info: MethodInfo
    rvq: RVQVAE
    generator: KMMGenerator
    normalizer: Normalizer
    meta: dict
    load_seconds: float

    def denoiser_params(self) -> int:
        """The generator's parameters (named as the diffusion methods' for the bench table)."""
        return sum(p.numel() for p in self.generator.parameters())


def _load_kmm(info: MethodInfo) -> MaskedTokenMethod:
    t0 = time.perf_counter()
    ck = torch.load(WEIGHTS / info.checkpoint, map_location="cpu", weights_only=False)
    meta = ck["meta"]

    def f32(sd: dict) -> dict:
        return {k: v.float() if v.is_floating_point() else v for k, v in sd.items()}

    rvq = RVQVAE(RVQConfig(**meta["rvq_config"]))
    rvq.load_state_dict(f32(ck["rvq"]))
    gen = KMMGenerator(KMMConfig(**meta["config"]))
    gen.load_state_dict(f32(ck["generator"]))
    norm = Normalizer(np.asarray(meta["mean"]), np.asarray(meta["std"]))
    return MaskedTokenMethod(info, rvq.eval(), gen.eval(), norm, meta, time.perf_counter() - t0)


_LOCK = threading.Lock()
_LOADED: dict[str, LatentDiffusionMethod | MaskedTokenMethod] = {}
_VAE: dict[str, tuple[MotionVAE, Normalizer]] = {}


def shared_vae() -> tuple[MotionVAE, Normalizer]:
    """The shipped VAE and its feature statistics, loaded once per process."""
    if "vae" not in _VAE:
        vae, meta = load_vae(WEIGHTS / "vae.pt")
        _VAE["vae"] = (vae, Normalizer(np.asarray(meta["mean"]), np.asarray(meta["std"])))
    return _VAE["vae"]


def _load_diffusion(info: MethodInfo, path: Path, ck: dict | None = None) -> LatentDiffusionMethod:
    """A diffusion method from its denoiser checkpoint at ``path`` (``ck``: already loaded)."""
    t0 = time.perf_counter()
    vae, norm = shared_vae()
    ck = ck if ck is not None else _load(path)
    meta = ck["meta"]
    if meta.get("vae_steps") != getattr(vae, "steps", None):
        # a denoiser only makes sense on the latents of the VAE it was trained on
        raise RuntimeError(
            f"{path.name} was trained on a VAE of {meta.get('vae_steps')} steps but "
            f"weights/vae.pt has {getattr(vae, 'steps', None)}: ship them together"
        )
    kind = meta.get("kind", info.name)
    den = build_denoiser(kind, _config_from_dict(kind, meta["config"]))
    den.load_state_dict(ck["state_dict"])
    # the schedule and prediction target the denoiser was trained with (checkpoints from
    # before the target was recorded were all trained on epsilon)
    diffusion = Diffusion(DiffusionConfig(**meta.get("diffusion", {})))
    return LatentDiffusionMethod(info, vae, den.eval(), diffusion, norm, meta["latent_scale"], time.perf_counter() - t0)


def register_arm(name: str, path: str | Path) -> MethodInfo:
    """Make a training run's denoiser (``train motion_mamba|ftmomamba|baseline --out RUN``,
    e.g. an ablation arm trained with ``--set``) a method of this process under ``name``, on
    the shipped VAE, so every table and ``generate`` take it like a shipped one. ``path``:
    the run directory or its checkpoint file."""
    path = Path(path).resolve()
    if path.is_dir():
        found = [path / f"{k}.pt" for k in ("motion_mamba", "ftmomamba", "baseline") if (path / f"{k}.pt").is_file()]
        if len(found) != 1:
            raise FileNotFoundError(f"{path}: expected one of motion_mamba.pt, ftmomamba.pt, baseline.pt")
        path = found[0]
    if name in REGISTRY:
        raise ValueError(f"{name!r} is already a method; pick another arm name")
    ck = _load(path)
    base = REGISTRY[ck["meta"]["kind"]]
    info = dataclasses.replace(base, name=name, display_name=f"{base.display_name} [{name}]", checkpoint=str(path))
    method = _load_diffusion(info, path, ck)
    with _LOCK:
        REGISTRY[name] = info
        _LOADED[name] = method
    return info


def unregister_arm(name: str) -> None:
    """Forget an arm ``register_arm`` added (the shipped methods cannot be removed)."""
    if name in _BUILTIN:
        raise ValueError(f"{name!r} is a shipped method, not an arm")
    with _LOCK:
        REGISTRY.pop(name, None)
        _LOADED.pop(name, None)
        for key in [k for k in _ON_DEVICE if k.startswith(f"{name}@")]:
            del _ON_DEVICE[key]


def canonical_device(device: torch.device | str | None) -> torch.device:
    """``device`` with its index filled in: "cuda" names the current CUDA device, so that
    "cuda" and "cuda:0" key one copy of a method, not two."""
    dev = torch.device(device or "cpu")
    if dev.type == "cuda" and dev.index is None:
        dev = torch.device("cuda", torch.cuda.current_device())
    return dev


def load_method(name: str, device: torch.device | str | None = None) -> LatentDiffusionMethod | MaskedTokenMethod:
    """Load a method's checkpoints once per process (thread-safe) and return it; with a
    ``device`` other than the CPU, a copy of its networks on that device (also kept)."""
    info = get_info(name)
    with _LOCK:
        if name not in _LOADED and info.family == "masked":
            _LOADED[name] = _load_kmm(info)
        if name not in _LOADED:
            _LOADED[name] = _load_diffusion(info, WEIGHTS / info.checkpoint)
        dev = canonical_device(device)
        if dev.type == "cpu":
            return _LOADED[name]
        key = f"{name}@{dev}"
        if key not in _ON_DEVICE:
            _ON_DEVICE[key] = _to_device(_LOADED[name], dev)
        return _ON_DEVICE[key]


_ON_DEVICE: dict[str, LatentDiffusionMethod | MaskedTokenMethod] = {}


def _to_device(m: LatentDiffusionMethod | MaskedTokenMethod, dev: torch.device):
    """A copy of a loaded method with its networks on ``dev`` (the feature statistics stay
    numpy: decoding ends on the CPU)."""
    if isinstance(m, MaskedTokenMethod):
        return dataclasses.replace(m, rvq=copy.deepcopy(m.rvq).to(dev), generator=copy.deepcopy(m.generator).to(dev))
    return dataclasses.replace(m, vae=copy.deepcopy(m.vae).to(dev), denoiser=copy.deepcopy(m.denoiser).to(dev))
