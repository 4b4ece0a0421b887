"""Gradio Blocks of the demo."""

from __future__ import annotations

import gradio as gr

from motion_core import HUMANML3D

TITLE = "Motion Mamba Studio"


def build_demo() -> gr.Blocks:
    """The demo page. Models, timeline and viewer arrive with the app issue."""
    with gr.Blocks(title=TITLE) as demo:
        gr.Markdown(
            f"# {TITLE}\n"
            "Text to 3D human motion with selective state space models (Motion Mamba, KMM, FTMoMamba).\n\n"
            f"Skeleton: {HUMANML3D.n_joints} joints, {HUMANML3D.feature_dim}-dim HumanML3D features, "
            f"{HUMANML3D.fps:g} fps."
        )
    return demo
