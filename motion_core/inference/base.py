"""What every method shares: the Motion it returns, the request limits, the registry entry
(``MethodInfo``) and the ``Method`` protocol a method family implements.

A plan is the validated timeline: (text, frames) pairs at ``FPS``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

import numpy as np
import torch

from ..body.ground import ground
from ..body.ik import rigidify

# the shipped checkpoints; MMS_WEIGHTS_DIR points the core (and the trainers' --ship) at
# another folder of the same files, e.g. one holding a student that does not ship yet
WEIGHTS = Path(os.environ.get("MMS_WEIGHTS_DIR") or Path(__file__).resolve().parents[1] / "weights").resolve()

FPS = 20
MAX_TEXT_CHARS = 300
MAX_SEGMENTS = 10
MIN_SECONDS, MAX_SECONDS, MAX_TOTAL_SECONDS = 1.0, 10.0, 60.0

Plan = list[tuple[str, int]]  # (text, frames) per segment


class InputError(ValueError):
    """A request a user can get wrong: the message says what to change."""


class UnknownMethod(ValueError):
    pass


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
    sampler: str = "quality"  # which of the method's samplers drew it ("quality" / "fast")

    @property
    def frames(self) -> int:
        return int(self.joints.shape[0])

    @property
    def seconds(self) -> float:
        return self.frames / self.fps


class Method(Protocol):
    """A loaded method: its networks and statistics, able to sample motions.

    ``sample`` turns a whole plan into one continuous Motion; ``sample_batch`` one
    single-segment Motion per text, all ``frames`` long, sampled together. Both add their
    stage times to ``timings`` ("text", "denoise", "decode", "join", "total"). ``sampler``
    names one of ``registry.samplers(info)`` ("quality": the method's own sampler; "fast": a
    distilled few-step one, where shipped); ``generate`` checks it first."""

    info: MethodInfo
    load_seconds: float

    @classmethod
    def load(cls, info: MethodInfo, path: Path) -> Method: ...

    def to(self, device: torch.device) -> Method:
        """A copy with its networks on ``device`` (decoding to joints stays on the CPU)."""
        ...

    def denoiser_params(self, sampler: str | None = None) -> int:
        """Parameters of the network that runs at every sampling step of ``sampler`` (None:
        the method's own network)."""
        ...

    def autoencoder_params(self) -> int:
        """Parameters of the network that maps between motions and what is sampled."""
        ...

    def sample(
        self,
        plan: Plan,
        seed: int,
        *,
        steps: int | None,
        guidance: float | None,
        overlap: int,
        progress,
        rigid: bool,
        timings: dict[str, float],
        device: torch.device,
        sampler: str,
    ) -> Motion: ...

    def sample_batch(
        self,
        texts: list[str],
        frames: int,
        seed: int,
        *,
        steps: int | None,
        guidance: float | None,
        rigid: bool,
        timings: dict[str, float],
        device: torch.device,
        sampler: str,
    ) -> list[Motion]: ...


@dataclass(frozen=True)
class MethodInfo:
    """A registry entry: how a method is shown, which class loads it from which checkpoint."""

    name: str
    display_name: str
    description: str
    checkpoint: str  # under motion_core/weights/ (or an absolute path: an ablation arm)
    method: type  # the class implementing ``Method``
    needs: tuple[str, ...] = ()  # other shipped files it loads (the diffusion methods' VAE)
    max_seconds: float = 10.0  # per segment; longer timelines are composed from segments
    # sampling defaults: DDIM steps and CFG scale (diffusion); decoding passes and CFG on
    # the base codes (masked)
    default_steps: int = 50
    default_guidance: float = 7.5
    steps_label: str = "sampling steps (DDIM)"
    # a student distilled from the method's sampler (``train lcm``: consistency; ``train
    # guidance``: guidance-distilled), under motion_core/weights/ as <kind>_fast.pt; the
    # "fast" sampler exists where that file does (which one is the
    # default: ``registry.default_sampler``)
    student: str | None = None

    @property
    def available(self) -> bool:
        return all((WEIGHTS / f).is_file() for f in (self.checkpoint, *self.needs))

    @property
    def student_file(self) -> Path | None:
        """The distilled student's file where one is present (``registry.samplers`` also
        checks it was distilled from this method's weights)."""
        if self.student is None or not (WEIGHTS / self.student).is_file():
            return None
        return WEIGHTS / self.student


def on_floor(joints: np.ndarray) -> np.ndarray:
    """Stand the motion on the floor frame by frame (``body.ground``): generated roots and
    legs drift vertically by centimetres, so one shift for the whole clip leaves stance
    feet hovering. (T, J, 3) -> (T, J, 3)."""
    return ground(joints)


def sync(dev: torch.device) -> None:
    """Wait for queued GPU work, so a stage's time is its own (CUDA calls return early)."""
    if dev.type == "cuda":
        torch.cuda.synchronize(dev)


def segment_bounds(plan: Plan) -> list[tuple[int, int, str]]:
    """(start frame, end frame exclusive, text) of each segment of a plan."""
    out, start = [], 0
    for text, n in plan:
        out.append((start, start + n, text))
        start += n
    return out


def finish_total(timings: dict[str, float]) -> None:
    timings["total"] = sum(v for k, v in timings.items() if k != "load")


def batch_motions(
    joints: np.ndarray,
    texts: list[str],
    frames: int,
    name: str,
    seed: int,
    rigid: bool,
    timings: dict[str, float],
    sampler: str = "quality",
) -> list[Motion]:
    """Joints (B, frames, 22, 3) -> one single-segment Motion per text: on rigid bones when
    ``rigid``, standing on the floor; the Motions share ``timings``."""
    out = []
    for text_joints, text in zip(joints, texts, strict=True):
        j = rigidify(text_joints) if rigid else text_joints
        out.append(Motion(on_floor(j), FPS, [(0, frames, text)], name, int(seed), timings, sampler=sampler))
    return out
