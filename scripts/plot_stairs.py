"""Draw the stairs kinds: poses over the steps in side view, and the feet's heights in time.

``python scripts/plot_stairs.py [--out docs/stairs.png] [--seed 0]``: one row per kind
(walk_upstairs, walk_downstairs, step_up_onto). Left: poses in the world's side view (forward
to the right, as the clip travels), with the boxes ``motion_core.body.terrain.steps`` finds
under the feet. Right: the toes' heights, the surface found under each foot, and the pelvis.
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Rectangle

from motion_core.body.features import canonicalize, features_to_joints, joints_to_features
from motion_core.body.ground import ground
from motion_core.body.skeleton import HUMANML3D
from motion_core.body.terrain import steps, surface
from motion_core.corpus import sample_clip
from motion_core.corpus.kinds import stairs  # noqa: F401  (registers the kinds)

KINDS = ("walk_upstairs", "walk_downstairs", "step_up_onto")
L_TOE, R_TOE = HUMANML3D.index("left_foot"), HUMANML3D.index("right_foot")


def clip_joints(kind: str, seed: int) -> tuple[np.ndarray, dict]:
    """A clip of ``kind`` as the corpus stores it (through the features) and stood on the
    ground as generated motions are (``body.ground``)."""
    clip, spec = sample_clip(np.random.default_rng(seed), kind)
    j = ground(canonicalize(features_to_joints(joints_to_features(clip.joints))))
    return j, spec.labels()


def draw_boxes(ax, j: np.ndarray) -> None:
    for box in steps(j):
        # seen from the side: the box's depth runs along the travel (here +z)
        c, d = box["center"], box["depth"]
        along = c[1] * np.cos(box["yaw"]) + c[0] * np.sin(box["yaw"])
        ax.add_patch(Rectangle((along - d / 2, 0), d, box["top"], fc="0.82", ec="0.45", lw=0.8))
    ax.axhline(0, color="0.45", lw=0.8)


def draw_pose(ax, p: np.ndarray, alpha: float = 1.0) -> None:
    for par, ch in HUMANML3D.bones():
        c = "tab:red" if HUMANML3D.joint_names[ch].startswith("left") else "tab:blue"
        ax.plot([p[par, 2], p[ch, 2]], [p[par, 1], p[ch, 1]], color=c, lw=1.4, alpha=alpha)


def draw_side(ax, j: np.ndarray, title: str, n_poses: int = 9) -> None:
    """Poses in place over the whole clip."""
    draw_boxes(ax, j)
    idx = np.linspace(0, len(j) - 1, n_poses).round().astype(int)
    for k, t in enumerate(idx):
        draw_pose(ax, j[t], 0.25 + 0.75 * (k + 1) / n_poses)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=8)
    ax.tick_params(labelsize=6)


def draw_frames(axes, j: np.ndarray) -> None:
    """One pose a panel, 1.2 m around the pelvis, at evenly spread times."""
    idx = np.linspace(0, len(j) - 1, len(axes) + 2).round().astype(int)[1:-1]
    top = float(j[..., 1].max()) + 0.05
    for ax, t in zip(axes, idx, strict=True):
        draw_boxes(ax, j)
        draw_pose(ax, j[t])
        z = float(j[t, 0, 2])
        ax.set_xlim(z - 0.6, z + 0.6)
        ax.set_ylim(-0.05, top)
        ax.set_aspect("equal")
        ax.set_title(f"{t / 20:.2f} s", fontsize=7)
        ax.axis("off")


def draw_heights(ax, j: np.ndarray) -> None:
    t = np.arange(len(j)) / 20.0
    surf = surface(j)
    ax.plot(t, j[:, L_TOE, 1], color="tab:red", lw=1, label="left toe")
    ax.plot(t, j[:, R_TOE, 1], color="tab:blue", lw=1, label="right toe")
    if surf is not None:
        ax.plot(t, surf[:, 0], color="tab:red", lw=2, alpha=0.3, label="ground under left")
        ax.plot(t, surf[:, 1], color="tab:blue", lw=2, alpha=0.3, label="ground under right")
    ax.plot(t, j[:, 0, 1] - 0.8, color="k", lw=1, label="pelvis - 0.8 m")
    ax.set_xlabel("s", fontsize=7)
    ax.tick_params(labelsize=6)
    ax.legend(fontsize=5, loc="upper left")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="docs/stairs.png")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--kinds", nargs="*", default=list(KINDS))
    a = ap.parse_args(argv)
    n = len(a.kinds)
    fig = plt.figure(figsize=(16, 3.3 * n))
    grid = fig.add_gridspec(n, 9, width_ratios=[2.4, 1, 1, 1, 1, 1, 1, 0.2, 2.0])
    for row, kind in enumerate(a.kinds):
        j, labels = clip_joints(kind, a.seed)
        extra = ", ".join(f"{k} {v}" for k, v in labels.items() if k in ("count", "side"))
        draw_side(fig.add_subplot(grid[row, 0]), j, f"{kind} ({extra})" if extra else kind)
        draw_frames([fig.add_subplot(grid[row, c]) for c in range(1, 7)], j)
        draw_heights(fig.add_subplot(grid[row, 8]), j)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(a.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
