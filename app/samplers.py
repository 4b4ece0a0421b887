"""The Advanced panel's sampler picker: which samplers a method offers ("quality": its own;
"fast": a distilled consistency student, where one ships), and the steps and guidance
sliders each one sets. All of it read from ``motion_core.methods()``."""

from __future__ import annotations

from typing import Any

import gradio as gr

import motion_core


def sampler_choice(info: dict) -> dict[str, Any]:
    """Keyword arguments for the sampler Radio of a method's listing (``methods()`` entry):
    its samplers' labels, its default, visible only where there is a choice to make."""
    options = info.get("sampler_options") or {}
    names = info.get("samplers") or ["quality"]
    return {
        "choices": [(_label(options.get(n, {}), n), n) for n in names],
        "value": info.get("default_sampler", "quality"),
        "visible": len(names) > 1,
        "info": "the fast one is a student distilled to sample in a few steps; it is the default where it "
        "follows the validation prompts within 2 points of quality"
        if len(names) > 1
        else None,
    }


def _label(option: dict, name: str) -> str:
    rate = option.get("validation_pass_rate")
    return option.get("label", name) + (f" · follows {rate:.0%} of validation prompts" if rate is not None else "")


def sampler_sliders(
    info: dict, sampler: str, guidance: float | None = None, steps: int | None = None
) -> tuple[Any, Any]:
    """(guidance, steps) slider updates for ``sampler`` of a method: the steps and guidance
    range it accepts, at ``guidance`` / ``steps`` (None: the method's default guidance and the
    sampler's default steps)."""
    opt = info["sampler_options"][sampler]
    lo, hi = opt["guidance"]
    label = info["steps_label"] if sampler == "quality" else "consistency steps (distilled student)"
    return (
        gr.Slider(
            minimum=lo,
            maximum=hi,
            value=guidance if guidance is not None else min(max(info["default_guidance"], lo), hi),
        ),
        gr.Slider(minimum=1, maximum=opt["max_steps"], value=steps if steps is not None else opt["steps"], label=label),
    )


def offered(method: str, sampler: str | None) -> str | None:
    """The page's sampler choice for ``method``, None (its default) where the method does not
    offer it: the radio may still hold a choice made for another method."""
    info = next((m for m in motion_core.methods() if m["name"] == method), None)
    return sampler if info is not None and sampler in info["samplers"] else None
