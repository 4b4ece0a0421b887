"""The method registry: the one table of generators the core offers and the app shows.

Each entry names its display name, a one-line description, the class that loads and
samples it (a ``base.Method``) and which shipped checkpoint holds its weights; adding a
method is one module with its class plus one entry here. ``methods()`` lists the entries
whose checkpoints are present; ``load_method`` loads one once per process and shares it.
"""

from __future__ import annotations

import copy
import dataclasses
import functools
import threading
import warnings
from pathlib import Path

import torch

from ..nn.allocator import keep_freed_memory
from .base import Method, MethodInfo, UnknownMethod
from .checkpoints import WEIGHTS, distilled_from, read, read_float32
from .latent_diffusion import LatentDiffusionMethod
from .masked import MaskedTokenMethod
from .samplers import student_kind

# 5 DDIM steps, not MLD's 50, for the three diffusion methods: trained on the x_0 target,
# they predict the clean latent at every step. At each method's guidance scale (below), on
# the 349 validation prompts pooled, 5 steps pass within a point of the best of 3-10 steps
# (Motion Mamba's 2026-11-26 weights 91.7% against 90.3% at 10, FTMoMamba 90.8 / 91.1, the baseline 94.6 / 94.6)
# at half the network calls of 10; 3 steps lose 11 points for Motion Mamba
# (results/ddim_steps_val_scales.json; 10 steps until 2026-11-26, results/ddim_steps_val.json)
DIFFUSION_STEPS = 5
# Classifier-free guidance scales of the diffusion methods, each its best on the 349
# validation prompts pooled (200 procedural + 149 real, 10 steps, seed 0, the floor rule of
# body.ground; results/guidance_val.json), swept over 1-10. The 7.5 all three used before
# (MLD's) was chosen for the first denoisers; for the trained temporal-latent ones it
# over-guides: Motion Mamba 79.4% pooled at 7.5, 90.3% at 4 (88.5-90.0% anywhere in 1-4).
# Motion Mamba's 3.0 (4.0 until 2026-11-29) was rechosen at today's 5 steps over four seeds:
# 91.5 / 91.7 / 91.7 / 89.6% pooled at 2 / 2.5 / 3 / 4 (docs/training-log.md, 2026-11-29),
# and it shipped with a student distilled at 3, so the fast sampler folds in the same scale
GUIDANCE = {"motion_mamba": 3.0, "ftmomamba": 2.0, "baseline": 3.0}

# a method samples with its "fast" distilled student by default where, on the validation
# prompts its distillation scored (``train lcm`` records both samplers' pass rates in the
# student's meta), the student passed within this many of the teacher's: the fast sampler rule
FAST_DEFAULT_MARGIN = 0.02

REGISTRY: dict[str, MethodInfo] = {
    m.name: m
    for m in (
        MethodInfo(
            "motion_mamba",
            "Motion Mamba",
            "Latent diffusion with a U-Net of hierarchical temporal (HTM) and bidirectional spatial (BSM) "
            "Mamba blocks (Zhang et al. 2024).",
            "motion_mamba.pt",
            LatentDiffusionMethod,
            needs=("vae.pt",),
            student="motion_mamba_fast.pt",
            default_steps=DIFFUSION_STEPS,
            default_guidance=GUIDANCE["motion_mamba"],
        ),
        MethodInfo(
            "kmm",
            "KMM",
            "Masked generation of residual-VQ motion tokens by a bidirectional Mamba, key frames chosen by "
            "density peaks, text-motion contrastive alignment; one sequence for the whole timeline, "
            "boundaries in-filled (Zhang et al. 2024).",
            "kmm.pt",
            MaskedTokenMethod,
            # 4 passes, not MoMask's 10: on the validation prompts fewer passes lost no verifier
            # passes and gained direction accuracy, at well under half the time per timeline
            default_steps=4,
            # scale 1 (plain conditional sampling, no unconditional pass), not MoMask's 4: on the
            # validation prompts larger scales passed fewer prompts and were no better at
            # direction, and scale 1 needs half the work (figures: docs/training-log.md)
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
            LatentDiffusionMethod,
            needs=("vae.pt",),
            student="ftmomamba_fast.pt",
            default_steps=DIFFUSION_STEPS,
            default_guidance=GUIDANCE["ftmomamba"],
        ),
        MethodInfo(
            "baseline",
            "Transformer baseline (MLD-style)",
            "The same latent diffusion with an MLD-style skip-transformer denoiser; the reference for every "
            "speed and quality claim.",
            "baseline.pt",
            LatentDiffusionMethod,
            needs=("vae.pt",),
            student="baseline_fast.pt",
            default_steps=DIFFUSION_STEPS,
            default_guidance=GUIDANCE["baseline"],
        ),
    )
}


_BUILTIN = frozenset(REGISTRY)


def sampling_scale(kind: str, fallback: float) -> float:
    """The guidance scale a method samples at by default (a trainer's ``kind`` is the
    method's name); ``fallback`` for a kind that is no registered method."""
    return REGISTRY[kind].default_guidance if kind in REGISTRY else fallback


def methods() -> list[dict]:
    """The available methods: name, display name, description, per-segment limit, sampling
    defaults, the samplers each offers ("quality"; "fast" where a distilled student ships),
    its default sampler, and each sampler's settings (``sampler_options``)."""
    return [
        {
            "name": m.name,
            "display_name": m.display_name,
            "description": m.description,
            "max_seconds": m.max_seconds,
            "default_steps": m.default_steps,
            "default_guidance": m.default_guidance,
            "steps_label": m.steps_label,
            "samplers": list(samplers(m)),
            "default_sampler": default_sampler(m),
            "sampler_options": sampler_options(m),
        }
        for m in REGISTRY.values()
        if m.available
    ]


@functools.lru_cache(maxsize=32)
def _student_meta(student: str, student_mtime: int, teacher: str, teacher_mtime: int) -> dict | None:
    # keyed on both files' mtimes: a student or teacher shipped while the process runs is
    # read afresh. A file that cannot be read leaves the method without "fast", not the
    # whole listing broken
    try:
        meta = read(student)["meta"]
        student_kind(meta)  # a file of no known student kind is no student
        return meta if distilled_from(meta, read_float32(teacher)["state_dict"]) else None
    except Exception as e:  # a damaged or foreign file: any failure to read it means "no student"
        warnings.warn(f"{student} cannot be read as a distilled student ({e}): no 'fast' sampler", stacklevel=2)
        return None


def student_meta(info: MethodInfo) -> dict | None:
    """The meta of the method's distilled student (``train lcm`` or ``train guidance``); None
    where none ships,
    where it was distilled from other weights than the method's, or where the method was
    loaded in this process without it (a student shipped after loading waits for a restart:
    what is offered is what ``generate`` can run)."""
    student, teacher = info.student_file, WEIGHTS / info.checkpoint
    if student is None or not teacher.is_file():
        return None
    loaded = _LOADED.get(info.name)
    if loaded is not None and "fast" not in getattr(loaded, "samplers", {}):
        return None
    meta = _student_meta(str(student), student.stat().st_mtime_ns, str(teacher), teacher.stat().st_mtime_ns)
    return copy.deepcopy(meta) if meta is not None else None  # the cached dict stays as read


def samplers(info: MethodInfo) -> tuple[str, ...]:
    """The samplers a method offers: its own ("quality"), and "fast" where a distilled
    student of its weights ships."""
    return ("quality", "fast") if student_meta(info) is not None else ("quality",)


def default_sampler(info: MethodInfo) -> str:
    """ "fast" where the student's recorded validation pass rate is within
    ``FAST_DEFAULT_MARGIN`` of its teacher's sampler's, else "quality" (also where the
    distillation recorded no validation: no evidence, no switch)."""
    meta = student_meta(info)
    val = (meta or {}).get("validation") or {}
    fast, quality = val.get("fast"), val.get("quality")
    if fast is None or quality is None:
        return "quality"
    # rounded: rates are counts over the prompts, and 0.14 - 0.12 is 0.020000000000000018 in floats
    return "fast" if round(quality["pass_rate"] - fast["pass_rate"], 9) <= FAST_DEFAULT_MARGIN else "quality"


def sampler_options(info: MethodInfo) -> dict[str, dict]:
    """Per sampler the method offers: its default steps, the steps and guidance it accepts,
    a label for a picker, and (where recorded) its validation pass rate."""
    out = {
        "quality": {
            "steps": info.default_steps,
            "max_steps": 100,
            "guidance": [1.0, 15.0],
            "default_guidance": info.default_guidance,
            "label": f"quality: {info.default_steps} {info.steps_label}",
        }
    }
    meta = student_meta(info)
    if meta is not None:
        val = meta.get("validation") or {}
        out["fast"] = student_kind(meta).options()
        for name in ("quality", "fast"):
            if name in val:
                out[name]["validation_pass_rate"] = float(val[name]["pass_rate"])
    return out


def get_info(name: str) -> MethodInfo:
    if name not in REGISTRY or not REGISTRY[name].available:
        known = ", ".join(m["name"] for m in methods()) or "none"
        raise UnknownMethod(f"unknown method {name!r}; available: {known}")
    return REGISTRY[name]


_LOCK = threading.Lock()
_LOADED: dict[str, Method] = {}
_ON_DEVICE: dict[str, Method] = {}


def register_arm(
    name: str, path: str | Path, student: str | Path | None = None, vae: str | Path | None = None
) -> MethodInfo:
    """Make a training run's network a method of this process under ``name``, so every table
    and ``generate`` take it like a shipped one: a denoiser (``train motion_mamba|ftmomamba|
    baseline --out RUN``, e.g. an ablation arm trained with ``--set``) on the shipped VAE or on
    ``vae`` (the VAE checkpoint it was trained on, e.g. a stage), or a KMM ``kmm.pt`` (a
    ``kmm-generator`` run's or stage, with its own tokeniser). ``path``: the run directory or its
    checkpoint file; ``student``: a student distilled from the denoiser (``train lcm|guidance
    --teacher PATH``), its "fast" sampler."""
    path = Path(path).resolve()
    if path.is_dir():
        kinds = ("motion_mamba", "ftmomamba", "baseline", "kmm")
        found = [path / f"{k}.pt" for k in kinds if (path / f"{k}.pt").is_file()]
        if len(found) != 1:
            raise FileNotFoundError(f"{path}: expected one of {', '.join(k + '.pt' for k in kinds)}")
        path = found[0]
    if name in REGISTRY:
        raise ValueError(f"{name!r} is already a method; pick another arm name")
    ck = read_float32(path) if "rvq" not in read(path) else None
    base = REGISTRY[ck["meta"]["kind"] if ck is not None else "kmm"]
    info = dataclasses.replace(
        base,
        name=name,
        display_name=f"{base.display_name} [{name}]",
        checkpoint=str(path),
        student=str(Path(student).resolve()) if student else None,
    )
    if ck is None:
        if student or vae:
            raise ValueError("a KMM arm has its own tokeniser and no student: give it neither")
        method: Method = MaskedTokenMethod.load(info, path)
    else:
        method = LatentDiffusionMethod.load(info, path, ck, vae)
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


def load_method(name: str, device: torch.device | str | None = None) -> Method:
    """Load a method's checkpoints once per process (thread-safe) and return it; with a
    ``device`` other than the CPU, a copy of its networks on that device (also kept)."""
    info = get_info(name)
    keep_freed_memory()  # sampling's mid-sized tensors reuse the heap (allocator.py)
    with _LOCK:
        if name not in _LOADED:
            _LOADED[name] = info.method.load(info, WEIGHTS / info.checkpoint)
        dev = canonical_device(device)
        if dev.type == "cpu":
            return _LOADED[name]
        key = f"{name}@{dev}"
        if key not in _ON_DEVICE:
            _ON_DEVICE[key] = _LOADED[name].to(dev)
        return _ON_DEVICE[key]
