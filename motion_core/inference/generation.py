"""Public generation API: a timeline of (text, seconds) segments -> one continuous motion.

    motion = generate([("a person walks forward", 4.0), ("then waves", 3.0)], method="motion_mamba", seed=0)
    motion.joints  # (T, 22, 3) float32 metres, 20 fps

``generate`` checks the timeline, asks the registry for the method and lets it sample; how
a method turns a timeline into one motion is its own (``latent_diffusion``: segment by
segment, joined; ``masked``: one token sequence).
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import torch

from ..body.footlock import lock_feet
from .base import (
    FPS,
    MAX_SECONDS,
    MAX_SEGMENTS,
    MAX_TEXT_CHARS,
    MAX_TOTAL_SECONDS,
    MIN_SECONDS,
    InputError,
    Motion,
    Plan,
)
from .length import estimate_seconds
from .registry import default_sampler, get_info, load_method, samplers


def validate(segments: list[tuple[str, float | None]], method: str) -> Plan:
    """Check a timeline; returns (text, frames) pairs or raises InputError / UnknownMethod.
    A segment whose seconds are None gets the length estimator's duration for its text."""
    get_info(method)
    if not segments:
        raise InputError("the timeline is empty: add at least one segment with a text and a duration")
    if len(segments) > MAX_SEGMENTS:
        raise InputError(f"too many segments: {len(segments)} (at most {MAX_SEGMENTS})")
    out, total = [], 0.0
    for i, seg in enumerate(segments, 1):
        try:
            text, seconds = seg
            text = (text or "").strip() if isinstance(text, str) else ""
            if seconds is None and text and len(text) <= MAX_TEXT_CHARS:
                seconds = estimate_seconds([text])[0]
            seconds = float(seconds)
        except (TypeError, ValueError):
            raise InputError(f"segment {i}: expected a text and a duration in seconds") from None
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
    foot_lock: bool = True,
    sampler: str | None = None,
) -> Motion:
    """Generate one continuous motion for a timeline of (text, seconds) segments.

    ``steps``: DDIM steps or decoding passes (default: the method's, see ``methods()``);
    ``guidance``: classifier-free guidance scale (default: the method's); ``overlap``:
    frames blended at a join of separately generated segments; ``progress``: optional
    callable(fraction, message); ``rigid``: put the result on rigid bones (``ik.rigidify``;
    decoders' bones stretch by centimetres); ``device``: where the networks run (default the
    CPU; "cuda" on a GPU), decoding to joints stays on the CPU; ``foot_lock``: hold planted
    feet in place (``body.footlock``: knees, ankles and toes move, nothing else). A segment's
    seconds may be None: the length estimator picks them from its text. ``sampler``: "quality"
    (the method's own sampler) or "fast" (its distilled few-step student, where one ships;
    ``methods()`` lists each method's samplers); default the method's. Same inputs and seed
    give the same motion.
    """
    plan = validate(segments, method)
    sampler = choose_sampler(method, sampler)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    dev = torch.device(device or "cpu")
    m = load_method(method, dev)
    timings["load"] = time.perf_counter() - t0
    motion = m.sample(
        plan,
        int(seed),
        steps=steps,
        guidance=guidance,
        overlap=overlap,
        progress=progress,
        rigid=rigid,
        timings=timings,
        device=dev,
        sampler=sampler,
    )
    return lock_motion_feet(motion) if foot_lock else motion


def choose_sampler(method: str, sampler: str | None) -> str:
    """``sampler`` checked against the method's (None: its default); InputError otherwise."""
    info = get_info(method)
    if sampler is None:
        return default_sampler(info)
    offered = samplers(info)
    if sampler not in offered:
        choices = " or ".join(repr(s) for s in offered)
        raise InputError(f"{info.display_name} has no {sampler!r} sampler; choose {choices}")
    return sampler


def method_spec(spec: str) -> tuple[str, str]:
    """An evaluation's method, "NAME" or "NAME:SAMPLER" ("motion_mamba:fast") -> (name,
    sampler). A bare name takes the method's default sampler as it is now, so a table
    records which sampler it measured rather than whatever the default becomes later.
    InputError for an unknown method or a sampler it lacks."""
    name, _, sampler = spec.partition(":")
    validate([("x", 1.0)], name)
    return name, choose_sampler(name, sampler or None)


def row_name(name: str, sampler: str) -> str:
    """A results table's row for a method's sampler: the bare name for "quality" (its own
    sampler), "NAME:SAMPLER" otherwise. Keyed by what ran, not by what was asked: a bare
    "motion_mamba" runs its default, the student, and is written as "motion_mamba:fast"."""
    return name if sampler == "quality" else f"{name}:{sampler}"


def lock_motion_feet(motion: Motion) -> Motion:
    """The motion with its planted feet held in place (its timings gain "foot_lock")."""
    t = time.perf_counter()
    joints = lock_feet(motion.joints).joints.astype(np.float32)
    took = time.perf_counter() - t
    timings = {**motion.timings, "foot_lock": took, "total": motion.timings.get("total", 0.0) + took}
    return dataclasses.replace(motion, joints=joints, timings=timings)


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
    foot_lock: bool = True,
    sampler: str | None = None,
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
    sampler = choose_sampler(method, sampler)
    timings: dict[str, float] = {}
    t0 = time.perf_counter()
    m = load_method(method, device)
    dev = torch.device(device or "cpu")
    timings["load"] = time.perf_counter() - t0
    motions = m.sample_batch(
        [t for t, _ in plan],
        plan[0][1],
        int(seed),
        steps=steps,
        guidance=guidance,
        rigid=rigid,
        timings=timings,
        device=dev,
        sampler=sampler,
    )
    return [lock_motion_feet(x) for x in motions] if foot_lock else motions


__all__ = ["generate", "generate_batch", "validate"]
