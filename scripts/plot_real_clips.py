"""docs/real-vs-procedural.png: real Bandai Namco clips after retargeting, next to the same
action from the procedural corpus (front or side view strips, and a top view).

    python scripts/plot_real_clips.py --archive ../shared/data/bandai-namco-motion.tar.xz
"""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from plot_clips import draw_strip, draw_top

from motion_core.body.features import canonicalize
from motion_core.body.skeleton import HUMANML3D
from motion_core.corpus.compose import sample_clip
from motion_core.corpus.text import captions_for
from motion_core.data.mocap import bvh_files, clip_texts, import_clip, unpack_archive

# (Bandai content, procedural labels to look for, view)
ACTIONS = [
    ("walk", {"kind": "walk", "direction": "forward"}, "side"),
    ("walk-turn-right", {"kind": "turn", "direction": "right"}, "side"),
    ("wave-left-hand", {"kind": "wave", "side": "left"}, "front"),
    ("raise-up-both-hands", {"kind": "raise_arm", "side": "both"}, "front"),
]


def draw_front(ax, joints: np.ndarray, title: str, n_poses: int = 6) -> None:
    """Front view (the body's left on the viewer's right, y up), poses spread in time."""
    idx = np.linspace(0, len(joints) - 1, n_poses).round().astype(int)
    for k, t in enumerate(idx):
        p = joints[t] - joints[t, 0] * np.array([1.0, 0.0, 1.0])
        x = p[:, 0] + k * 0.9
        for par, ch in HUMANML3D.bones():
            c = "tab:red" if HUMANML3D.joint_names[ch].startswith("left") else "tab:blue"
            ax.plot([x[par], x[ch]], [p[par, 1], p[ch, 1]], color=c, lw=1.6, alpha=0.35 + 0.65 * (k + 1) / n_poses)
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlim(-0.6, (n_poses - 1) * 0.9 + 0.6)
    ax.set_ylim(-0.05, 2.0)
    ax.set_title(title, fontsize=8)
    ax.axis("off")


def procedural(labels: dict, seed: int = 0) -> tuple[np.ndarray, str]:
    rng = np.random.default_rng(seed)
    for _ in range(500):
        clip, spec = sample_clip(rng, labels["kind"])
        if all(spec.labels().get(k) == v for k, v in labels.items()):
            return canonicalize(clip.joints), captions_for(spec, np.random.default_rng(0), 1)[0]
    raise RuntimeError(f"no procedural clip with {labels}")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--archive", default="../shared/data/bandai-namco-motion.tar.xz")
    ap.add_argument("--cache", default=".cache/bandai-namco")
    ap.add_argument("--out", default="docs/real-vs-procedural.png")
    a = ap.parse_args()
    files = bvh_files(unpack_archive(a.archive, a.cache))
    fig, axes = plt.subplots(
        len(ACTIONS), 4, figsize=(16, 2.1 * len(ACTIONS)), gridspec_kw={"width_ratios": [5, 1, 5, 1]}
    )
    for row, (content, labels, view) in zip(axes, ACTIONS, strict=True):
        path = next(f for f in files if f"_{content}_normal_" in f.name)
        real = import_clip(path)
        draw = draw_front if view == "front" else draw_strip
        draw(row[0], real.joints, f"REAL {path.stem}: '{clip_texts(content, 'normal')[0]}'")
        draw_top(row[1], real.joints)
        j, cap = procedural(labels)
        draw(row[2], j, f"PROCEDURAL: '{cap}'")
        draw_top(row[3], j)
    fig.suptitle(
        "Left: real motion capture (Bandai Namco Research, CC BY-NC 4.0) retargeted to the HumanML3D skeleton. "
        "Right: the procedural corpus.\nStrips: poses in time, left to right (side view for walks, front view for "
        "arms, the body's left on the viewer's right); red = left limbs. Small panels: top view of pelvis and toes.",
        fontsize=8,
    )
    fig.tight_layout()
    fig.savefig(a.out, dpi=100)
    print("wrote", a.out)


if __name__ == "__main__":
    main()
