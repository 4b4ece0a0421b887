"""The Advanced panel's sampler picker: which samplers a method offers ("quality": its own;
"fast": a distilled consistency student, where one ships), and the steps and guidance
sliders each one sets. All of it read from ``motion_core.methods()``."""

from __future__ import annotations

import json
from typing import Any

import gradio as gr

import motion_core
from motion_core.inference.registry import FAST_DEFAULT_MARGIN

GUIDANCE_LABEL = "guidance scale"
FIXED_SCALE_CLASS = "mms-fixed-scale"
# the page's CSS for a scale that cannot change: the number alone, no track or reset button
FIXED_SCALE_CSS = (
    f".{FIXED_SCALE_CLASS} .slider_input_container, .{FIXED_SCALE_CLASS} .reset-button {{ display: none; }}"
)


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
        f"follows the validation prompts within {100 * FAST_DEFAULT_MARGIN:g} points of quality. Validation "
        "prompts are a set of their own, used to choose these settings; the figure beside the method above "
        "is on the test prompts, so the two differ"
        if len(names) > 1
        else None,
    }


def choice_key(choice: dict[str, Any]) -> str:
    """What a sampler picker shows (``sampler_choice``'s kwargs) as a comparable string: a
    method pick that would show the same leaves the picker alone (``ui.on_method``)."""
    return json.dumps(choice, sort_keys=True, default=list)


def _label(option: dict, name: str) -> str:
    rate = option.get("validation_pass_rate")
    return option.get("label", name) + (f" · follows {rate:.0%} of validation prompts" if rate is not None else "")


def slider_settings(
    info: dict, sampler: str, guidance: float | None = None, steps: int | None = None
) -> tuple[dict[str, Any], dict[str, Any]]:
    """(guidance, steps) slider settings for ``sampler`` of a method: the steps and guidance
    range it accepts, at ``guidance`` / ``steps`` (None: the sampler's defaults: the method's
    guidance and steps for "quality", the student's for "fast")."""
    opt = info["sampler_options"][sampler]
    lo, hi = opt["guidance"]
    label = info["steps_label"] if sampler == "quality" else opt.get("steps_label", "steps (distilled student)")
    g = guidance if guidance is not None else opt["default_guidance"]
    k = steps if steps is not None else opt["steps"]
    if hi > lo:
        scale = {
            "minimum": lo,
            "maximum": hi,
            "value": g,
            "interactive": True,
            "info": None,
            "label": GUIDANCE_LABEL,
            "elem_classes": [],
        }
    else:
        # a student of one scale (Motion Mamba's: 3) takes that scale alone (the registry's
        # range is [3, 3]). A slider cannot span 3-3 (gradio refuses minimum == maximum):
        # its track, which would read "3 to 3.5", is hidden (CSS, FIXED_SCALE_CLASS) and the
        # scale shows as a fixed number
        scale = {
            "minimum": lo,
            "maximum": lo + 0.5,
            "value": lo,
            "interactive": False,
            "info": f"fixed: this student was distilled for guidance {lo:g} alone",
            "label": f"{GUIDANCE_LABEL}: {lo:g}",
            "elem_classes": [FIXED_SCALE_CLASS],
        }
    return (
        scale,
        {"minimum": 1, "maximum": opt["max_steps"], "value": k, "label": label},
    )


def sampler_sliders(
    info: dict, sampler: str, guidance: float | None = None, steps: int | None = None
) -> tuple[Any, Any]:
    """``slider_settings`` as (guidance, steps) slider updates."""
    g, s = slider_settings(info, sampler, guidance, steps)
    return gr.Slider(**g), gr.Slider(**s)


def offered(method: str, sampler: str | None) -> str | None:
    """The page's sampler choice for ``method``, None (its default) where the method does not
    offer it: the radio may still hold a choice made for another method."""
    info = next((m for m in motion_core.methods() if m["name"] == method), None)
    return sampler if info is not None and sampler in info["samplers"] else None
