"""Plotly figures of a generated motion: KMM's density peaks, or speed and foot contact."""

from __future__ import annotations

import html

import numpy as np
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from motion_core import Motion
from motion_core.body.features import joints_to_features

# One line each, above the plot: what it shows, in words.
DENSITY_NOTE = (
    "Key frames (magenta) are the motion tokens with the highest gamma = d·S:<br>"
    "density d = how many tokens look alike, distance S = how far the nearest denser token is."
)
KINEMATICS_NOTE = "How fast the body moves over the floor, and when each foot is planted (1 = on the floor)."
TOP_MARGIN = 92  # room for the one-line note and, under it, the segments' titles


def _note(fig: go.Figure, text: str) -> None:
    fig.update_layout(
        title={
            "text": text,
            "font": {"size": 12},
            "x": 0.01,
            "xanchor": "left",
            "y": 1.0,
            "yanchor": "top",
            "pad": {"t": 12},
        }
    )


def _segment_lines(fig: go.Figure, motion: Motion, rows: int) -> None:
    for start, _, _ in motion.segments[1:]:
        for r in range(1, rows + 1):
            fig.add_vline(x=start / motion.fps, line_dash="dash", line_color="#555", row=r, col=1)
    for start, end, text in motion.segments:
        # plotly renders a subset of HTML in annotation text: escape the user's words
        short = html.escape(text if len(text) < 40 else text[:37] + "…")
        fig.add_annotation(
            x=(start + end) / 2 / motion.fps,
            y=1.0,
            yref="paper",
            text=short,
            showarrow=False,
            font={"size": 10},
            yanchor="bottom",
        )


def density_figure(motion: Motion) -> go.Figure:
    """KMM: per-token density d, distance S and gamma over time; key frames highlighted."""
    d = motion.density or {}
    t = np.asarray(d.get("frame", []), dtype=float) / motion.fps
    fig = make_subplots(rows=3, cols=1, shared_xaxes=True, vertical_spacing=0.05)
    key = set(int(k) for k in (d.get("selected_tokens") or []))
    for r, (name, label) in enumerate((("d", "density d"), ("S", "distance S"), ("gamma", "gamma = d·S")), 1):
        y = np.asarray(d.get(name, []), dtype=float)
        fig.add_trace(go.Scatter(x=t, y=y, mode="lines+markers", name=label, marker={"size": 4}), row=r, col=1)
        sel = [i for i in range(len(y)) if i in key]
        fig.add_trace(
            go.Scatter(
                x=t[sel],
                y=y[sel],
                mode="markers",
                name="key frames" if r == 1 else None,
                showlegend=r == 1,
                marker={"size": 10, "color": "#c2185b", "symbol": "diamond"},
            ),
            row=r,
            col=1,
        )
        fig.update_yaxes(title_text=label, row=r, col=1)
    _segment_lines(fig, motion, 3)
    fig.update_xaxes(title_text="time (s)", row=3, col=1)
    fig.update_layout(
        height=460, margin={"l": 50, "r": 10, "t": TOP_MARGIN, "b": 40}, legend={"orientation": "h", "y": -0.2}
    )
    _note(fig, DENSITY_NOTE)
    return fig


def kinematics_figure(motion: Motion) -> go.Figure:
    """Diffusion methods: root speed and foot contacts per frame (they have no key frames)."""
    j = np.asarray(motion.joints, dtype=np.float64)
    t = np.arange(len(j)) / motion.fps
    vel = np.linalg.norm(np.diff(j[:, 0, [0, 2]], axis=0), axis=-1) * motion.fps
    speed = np.concatenate([vel[:1], vel])
    contacts = joints_to_features(j)[:, -4:]  # (T-1, 4): left ankle/foot, right ankle/foot
    left = np.concatenate([contacts[:, :2].max(axis=1), contacts[-1:, :2].max(axis=1)])
    right = np.concatenate([contacts[:, 2:].max(axis=1), contacts[-1:, 2:].max(axis=1)])
    fig = make_subplots(rows=2, cols=1, shared_xaxes=True, vertical_spacing=0.08, row_heights=[0.6, 0.4])
    fig.add_trace(go.Scatter(x=t, y=speed, name="root speed (m/s)", line={"color": "#4e79a7"}), row=1, col=1)
    for y, name, colour in ((left + 0.05, "left", "#3b6fd8"), (right * 0.9, "right", "#d84a3b")):
        line = {"shape": "hv", "color": colour}
        fig.add_trace(go.Scatter(x=t, y=y, name=f"{name} foot contact", line=line), row=2, col=1)
    fig.update_yaxes(title_text="m/s", row=1, col=1)
    # a fixed range: with both feet planted throughout, the automatic one spanned 0.9-1.05 and
    # drew the right foot's contact line (at 0.9) on the axis, where it read as "never"
    fig.update_yaxes(title_text="contact", tickvals=[0, 1], range=[-0.15, 1.2], row=2, col=1)
    fig.update_xaxes(title_text="time (s)", row=2, col=1)
    _segment_lines(fig, motion, 2)
    fig.update_layout(
        height=380,
        margin={"l": 50, "r": 10, "t": TOP_MARGIN, "b": 40},
        legend={"orientation": "h", "y": -0.25},
    )
    _note(fig, KINEMATICS_NOTE + " (Key frames and density are KMM's.)")
    return fig


def motion_figure(motion: Motion) -> go.Figure:
    return density_figure(motion) if motion.density else kinematics_figure(motion)


__all__ = ["density_figure", "kinematics_figure", "motion_figure"]
