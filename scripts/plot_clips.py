"""Draw a few clips as skeleton strips (used for docs/ pictures and for eyeballing)."""

from __future__ import annotations

import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from motion_core.body.skeleton import HUMANML3D


def draw_strip(
    ax,
    joints: np.ndarray,
    title: str,
    n_poses: int = 6,
    color: str = "tab:blue",
    spread: float | None = None,
    front: bool = False,
    idx: np.ndarray | None = None,
) -> None:
    """Side view (z forward to the right, y up) of n_poses poses spread along x for legibility
    (by ``spread`` metres; by default 0.9, or the body's length when it lies along the floor).
    ``idx``: which frames (default: evenly in time)."""
    T = len(joints)
    if idx is None:
        idx = np.linspace(0, T - 1, n_poses).round().astype(int)
    n_poses = len(idx)
    if spread is None and front:
        spread = 0.9 + float(np.abs(joints[:, 0, 0] - joints[0, 0, 0]).max())
    if spread is None:
        length = (joints[..., 2].max(-1) - joints[..., 2].min(-1)).max()
        spread = max(0.9, float(length) + 0.25)
    for k, t in enumerate(idx):
        p = joints[t].copy()
        if front:  # seen from in front: the body's left (+x) on the right, sideways travel kept
            p[:, 2] = p[:, 0] - joints[0, 0, 0] + k * spread
        else:
            p[:, 2] = p[:, 2] - joints[t, 0, 2] + k * spread
        # colour left limbs darker so left/right can be told apart
        for par, ch in HUMANML3D.bones():
            name = HUMANML3D.joint_names[ch]
            c = "tab:red" if name.startswith("left") else color
            ax.plot(
                [p[par, 2], p[ch, 2]], [p[par, 1], p[ch, 1]], color=c, lw=1.6, alpha=0.35 + 0.65 * (k + 1) / n_poses
            )
    ax.axhline(0, color="0.6", lw=0.8)
    ax.set_aspect("equal")
    ax.set_xlim(-0.6 - (spread - 0.9), (n_poses - 1) * spread + 0.6 + 0.3 * (spread - 0.9))
    ax.set_ylim(-0.05, max(1.0, min(2.0, float(joints[..., 1].max()) + 0.15)))
    ax.set_title(title, fontsize=8)
    ax.axis("off")


def draw_top(ax, joints: np.ndarray) -> None:
    """Top view of the pelvis path and both feet."""
    ax.plot(joints[:, 0, 0], joints[:, 0, 2], color="k", lw=1)
    ax.plot(joints[:, 10, 0], joints[:, 10, 2], ".", color="tab:red", ms=2)
    ax.plot(joints[:, 11, 0], joints[:, 11, 2], ".", color="tab:blue", ms=2)
    ax.set_aspect("equal")
    ax.invert_xaxis()  # +x is the body's left: draw it on the left when looking from above/behind
    ax.tick_params(labelsize=6)


def draw_front(ax, pose: np.ndarray, x0: float, scale: float = 1.0) -> None:
    """One pose seen from the front (the body's left on the picture's right), placed at x0."""
    p = pose - pose[0] * np.array([1.0, 0.0, 1.0])
    for par, ch in HUMANML3D.bones():
        c = "tab:red" if HUMANML3D.joint_names[ch].startswith("left") else "tab:blue"
        ax.plot([x0 + p[par, 0] * scale, x0 + p[ch, 0] * scale], [p[par, 1], p[ch, 1]], color=c, lw=1.6)


# kinds whose motion reads best from in front (sideways travel, arms out to the sides, a swing
# across the body)
FRONT_VIEW = {
    "jump_sideways",
    "arm_circles",
    "hands_on_hips",
    "cross_arms",
    "salute",
    "scratch_head",
    "spin",
    "dodge",
    "play_guitar",
    "play_violin",
    "golf_swing",
    "tennis_forehand",
    "dribble",
    "walk_a_line",
    "look_around",
    "shrug",
}
SHEET_KINDS = 22  # kinds per contact sheet (11 rows of two): docs/new-kinds.png, docs/new-kinds-2.png, ...


def front_view(spec) -> bool:
    """Whether a clip reads best from in front: its kind's, or its own sideways direction."""
    return spec.kind in FRONT_VIEW or (spec.kind == "being_pushed" and spec.direction in ("left", "right"))


def motion_frames(joints: np.ndarray, n: int) -> np.ndarray:
    """n frames from first to last, evenly spaced in how much the body moves (joint speed, body
    travel left out) with a third of the weight on time: a quick shove or stomp gets its poses."""
    local = joints - joints[:, :1] * np.array([1.0, 0.0, 1.0])
    speed = np.linalg.norm(np.diff(local, axis=0), axis=-1).mean(-1)
    w = speed + 0.5 * speed.mean()
    cum = np.concatenate([[0.0], np.cumsum(w)])
    return np.searchsorted(cum, np.linspace(0, cum[-1], n)).clip(0, len(joints) - 1)


def sheet_paths(n_kinds: int, first: str = "docs/new-kinds.png") -> list[str]:
    """The contact sheets' files for n_kinds kinds, SHEET_KINDS each: docs/new-kinds.png, then
    docs/new-kinds-2.png, docs/new-kinds-3.png, ..."""
    stem = first[: -len(".png")]
    return [first if i == 0 else f"{stem}-{i + 1}.png" for i in range((n_kinds + SHEET_KINDS - 1) // SHEET_KINDS)]


def staged_sheet(out: str, seed: int, kinds: list[str] | None = None, part: tuple[int, int] = (1, 1)) -> None:
    """A contact sheet of staged kinds (motion_core.corpus.kinds, not trained on yet): per kind
    one clip, seven poses (spaced by how much the body moves) in side (or front) view with the
    floor line, and the pose furthest
    from the first one again from the other view (right, boxed). ``part``: (this sheet, sheets)."""
    from motion_core.body.features import canonicalize
    from motion_core.corpus.compose import sample_clip
    from motion_core.corpus.kinds import REGISTRY, staged_kinds
    from motion_core.corpus.text import captions_for

    kinds = kinds or staged_kinds()
    cols = 2
    rows = (len(kinds) + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(20, 2.3 * rows), squeeze=False)
    for ax in axes.flat[len(kinds) :]:
        ax.axis("off")
    for ax, kind in zip(axes.flat, kinds, strict=False):
        clip, spec = sample_clip(np.random.default_rng([seed, 5]), kind)
        j = canonicalize(clip.joints)
        cap = captions_for(spec, np.random.default_rng(seed), 1)[0]
        front = front_view(spec)
        view = "front view" if front else "side view"
        draw_strip(ax, j, f"{kind} ({view}): {cap}  ({len(j) / clip.fps:.1f} s)", front=front, idx=motion_frames(j, 7))
        if REGISTRY[kind].owns_clip:
            continue
        # the pose furthest from the first, from the other side (boxed, at the right)
        key = int(np.linalg.norm(j - j[:1], axis=-1).sum(-1).argmax())
        x_lo, x_hi = ax.get_xlim()
        x0 = x_hi + 0.55
        if front:
            p = j[key] - j[key, 0] * np.array([1.0, 0.0, 1.0])
            for par, ch in HUMANML3D.bones():
                c = "tab:red" if HUMANML3D.joint_names[ch].startswith("left") else "tab:blue"
                ax.plot([x0 + p[par, 2], x0 + p[ch, 2]], [p[par, 1], p[ch, 1]], color=c, lw=1.6)
        else:
            draw_front(ax, j[key], x0)
        ax.add_patch(plt.Rectangle((x0 - 0.5, -0.03), 1.0, ax.get_ylim()[1] - 0.02, fill=False, lw=0.6, ec="0.6"))
        ax.text(x0, ax.get_ylim()[1] - 0.05, "side" if front else "front", ha="center", va="top", fontsize=6)
        ax.set_xlim(x_lo, x0 + 0.55)
    sheet = f" (sheet {part[0]} of {part[1]})" if part[1] > 1 else ""
    fig.suptitle(
        f"Staged kinds{sheet} (procedural, not yet trained on). Poses left to right in time, closer where it moves "
        "fast; side view: the body faces right; front view: the body's left on the right; red = the body's left "
        "limbs; grey line = the floor. Boxed: the pose furthest from the first, from the other view.",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0, 1, 0.985))
    fig.savefig(out, dpi=80)
    print("wrote", out)


def chain_sheet(out: str, seed: int, n: int = 8) -> None:
    """Chains (corpus/chain.py: two or three actions under one sentence), with the staged kinds:
    per chain its first caption, four poses of each action (spaced by how much the body moves
    within it), and a grey bar under each action's poses."""
    from motion_core.body.features import canonicalize
    from motion_core.corpus.chain import chain_captions, sample_chain
    from motion_core.corpus.kinds import all_kinds

    fig, axes = plt.subplots(n, 1, figsize=(20, 2.4 * n), squeeze=False)
    for i, ax in enumerate(axes[:, 0]):
        rng = np.random.default_rng([seed, 7, i])
        comp = sample_chain(rng, 2 + i % 2, all_kinds())
        j = canonicalize(comp.joints)
        specs = [sp for _, _, sp in comp.segments]
        cap = chain_captions(specs, rng, 1)[0]
        idx = np.concatenate([a + motion_frames(j[a:b], 4) for a, b, _ in comp.segments])
        names = " -> ".join(sp.kind for sp in specs)
        draw_strip(ax, j, f"{names}: {cap}  ({len(j) / comp.fps:.1f} s)", idx=idx, spread=0.9)
        for k, (_, _, sp) in enumerate(comp.segments):
            x0 = 0.9 * 4 * k - 0.4
            ax.plot([x0, x0 + 0.9 * 4 - 0.2], [-0.06, -0.06], color="0.5", lw=3)
            ax.text(x0 + 1.7, -0.16, sp.kind, ha="center", va="top", fontsize=8)
        ax.set_ylim(-0.3, ax.get_ylim()[1])
    fig.suptitle(
        "Chains: two or three actions in one clip under one sentence (with the staged kinds). Four poses per "
        "action, left to right in time; side view, the body faces right; red = the body's left limbs.",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0, 1, 0.985))
    fig.savefig(out, dpi=80)
    print("wrote", out)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=None)
    ap.add_argument("--kinds", default=None, help="comma-separated (default: ten built-in kinds, or every staged one)")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument(
        "--staged",
        action="store_true",
        help=f"contact sheets of every staged kind, {SHEET_KINDS} a sheet (docs/new-kinds.png, docs/new-kinds-2.png)",
    )
    ap.add_argument("--chains", type=int, default=0, help="a sheet of this many chains (docs/chains.png)")
    a = ap.parse_args()
    if a.chains:
        chain_sheet(a.out or "docs/chains.png", a.seed, a.chains)
        return
    if a.staged:
        if a.kinds:  # just these, on one sheet
            staged_sheet(a.out or "docs/new-kinds.png", a.seed, a.kinds.split(","))
            return
        from motion_core.corpus.kinds import staged_kinds

        kinds = staged_kinds()
        paths = sheet_paths(len(kinds), a.out or "docs/new-kinds.png")
        for i, path in enumerate(paths):
            staged_sheet(path, a.seed, kinds[i * SHEET_KINDS : (i + 1) * SHEET_KINDS], (i + 1, len(paths)))
        return
    a.out = a.out or "docs/corpus-clips.png"
    a.kinds = a.kinds or "walk,run,wave,kick,jump_forward,squat,sit_down,lie_down,kneel,jumping_jacks"
    from motion_core.body.features import canonicalize
    from motion_core.corpus.compose import sample_clip

    kinds = a.kinds.split(",")
    rng = np.random.default_rng(a.seed)
    fig, axes = plt.subplots(len(kinds), 2, figsize=(11, 1.9 * len(kinds)), gridspec_kw={"width_ratios": [5, 1]})
    for row, kind in zip(np.atleast_2d(axes), kinds, strict=True):
        clip, spec = sample_clip(rng, kind)
        j = canonicalize(clip.joints)
        from motion_core.corpus.text import captions_for

        cap = captions_for(spec, np.random.default_rng(0), 1)[0]
        draw_strip(row[0], j, f"{cap}  ({len(j) / clip.fps:.1f} s)")
        draw_top(row[1], j)
    fig.suptitle(
        "Built-in corpus (procedural): side view, poses spread left to right in time; red = the body's left "
        "limbs.  Right: top view of the pelvis path and toes (x mirrored so the body's left is on the left).",
        fontsize=8,
    )
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print("wrote", a.out)


if __name__ == "__main__":
    main()
