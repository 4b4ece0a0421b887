"""The latent denoiser kinds, one table entry each: config class, builder, shipped config.

A checkpoint's ``meta["kind"]`` names its entry; training (``train WHAT``) and loading
(``inference.checkpoints``) both go through this table, so a new denoiser is one entry.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..nn.ssm import SSMConfig
from .denoisers import LatentDenoiser, MotionMambaConfig, TransformerConfig, motion_mamba_denoiser, transformer_denoiser
from .ftmomamba import FTMoMambaConfig, ftmomamba_denoiser


def _motion_mamba_config(d: dict) -> MotionMambaConfig:
    d = dict(d)
    d["htm_ssm"] = SSMConfig(**d["htm_ssm"])
    d["bsm_ssm"] = SSMConfig(**d["bsm_ssm"])
    return MotionMambaConfig(**d)


@dataclass(frozen=True)
class DenoiserKind:
    build: Callable[[Any], LatentDenoiser]
    shipped: Callable[[], Any]  # the config of the shipped checkpoint
    from_dict: Callable[[dict], Any]  # a checkpoint's config dict -> config


# sized so that 50 guided DDIM steps fit the 2-core CPU budget
DENOISERS: dict[str, DenoiserKind] = {
    "motion_mamba": DenoiserKind(
        motion_mamba_denoiser,
        lambda: MotionMambaConfig(
            levels=3, htm_ssm=SSMConfig(expand=0.5, d_state=8), bsm_ssm=SSMConfig(expand=2.0, d_state=4)
        ),
        _motion_mamba_config,
    ),
    # one FTMamba block per stage (the paper: two) to stay near Motion Mamba's CPU cost; the
    # prefix tokens broadcast to every latent token (see its module docstring)
    "ftmomamba": DenoiserKind(
        ftmomamba_denoiser,
        lambda: FTMoMambaConfig(layers_per_stage=1, cond="broadcast"),
        lambda d: FTMoMambaConfig(**d),  # its __post_init__ rebuilds the SSMConfig from a dict
    ),
    "baseline": DenoiserKind(
        transformer_denoiser, lambda: TransformerConfig(levels=1, ff=1024), lambda d: TransformerConfig(**d)
    ),
}


DenoiserConfig = MotionMambaConfig | TransformerConfig | FTMoMambaConfig  # any latent denoiser's config


def default_config(kind: str) -> DenoiserConfig:
    """The config of the shipped checkpoint of denoiser ``kind``."""
    return DENOISERS[kind].shipped()


def build_denoiser(kind: str, cfg) -> LatentDenoiser:
    return DENOISERS[kind].build(cfg)


def config_from_dict(kind: str, d: dict):
    return DENOISERS[kind].from_dict(d)
