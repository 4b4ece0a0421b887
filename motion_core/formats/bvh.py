"""BVH (Biovision hierarchy) reading, forward kinematics, unit detection, resampling and writing.

One module serves three users: our BVH export (a generated motion, 22 HumanML3D joints), a
user's BVH upload, and the import of real motion capture (the Bandai Namco clips). BVH
conventions followed here, which the format leaves to readers:

* A joint's local transform is ``T @ R`` with ``T`` its translation and ``R`` the product of its
  rotation channels in file order (``Zrotation Xrotation Yrotation`` means ``Rz @ Rx @ Ry``,
  intrinsic, degrees).
* Position channels, where a joint has them, *replace* its OFFSET for that frame (the root
  always; the Bandai Namco files give every joint six channels whose positions equal the
  offsets). Joints without position channels use their OFFSET.
* BVH has no unit field. ``detect_unit`` guesses it from the figure's height in the first
  frame (see there); callers may pass the unit explicitly.
"""

from __future__ import annotations

import io
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..body.ik import RigFit, fit_rig
from ..body.skeleton import HUMANML3D, Skeleton

POSITION_CHANNELS = ("Xposition", "Yposition", "Zposition")
ROTATION_CHANNELS = ("Xrotation", "Yrotation", "Zrotation")
UNITS_TO_M = {"m": 1.0, "cm": 0.01, "mm": 0.001, "inch": 0.0254}


class BvhError(ValueError):
    """A BVH file that cannot be read (the message names the file and the problem)."""


@dataclass
class Bvh:
    """A parsed BVH file.

    Attributes:
        names: (J,) joint names in file order (parents precede children).
        parents: (J,) parent index per joint, -1 for the root.
        offsets: (J, 3) OFFSET of each joint, file units.
        channels: per joint, its channel names in file order.
        end_sites: joint index -> (3,) End Site offset.
        frame_time: seconds per frame.
        motion: (F, C) channel values, C = total channel count.
    """

    names: list[str]
    parents: list[int]
    offsets: np.ndarray
    channels: list[tuple[str, ...]]
    frame_time: float
    motion: np.ndarray
    end_sites: dict[int, np.ndarray] = field(default_factory=dict)

    @property
    def n_frames(self) -> int:
        return int(self.motion.shape[0])

    @property
    def fps(self) -> float:
        return 1.0 / self.frame_time

    def _columns(self) -> list[int]:
        starts, c = [], 0
        for ch in self.channels:
            starts.append(c)
            c += len(ch)
        return starts

    def local_transforms(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-frame local rotations (F, J, 3, 3) and translations (F, J, 3), file units."""
        F, J = self.n_frames, len(self.names)
        rot = np.tile(np.eye(3), (F, J, 1, 1))
        trans = np.tile(self.offsets[None], (F, 1, 1)).astype(np.float64)
        for j, (ch, start) in enumerate(zip(self.channels, self._columns(), strict=True)):
            rot_order, rot_cols = "", []
            for k, name in enumerate(ch):
                if name in POSITION_CHANNELS:
                    trans[:, j, POSITION_CHANNELS.index(name)] = self.motion[:, start + k]
                else:
                    rot_order += name[0].upper()
                    rot_cols.append(start + k)
            if rot_order:
                rot[:, j] = Rotation.from_euler(rot_order, self.motion[:, rot_cols], degrees=True).as_matrix()
        return rot, trans

    def global_transforms(self) -> tuple[np.ndarray, np.ndarray]:
        """Forward kinematics: global rotations (F, J, 3, 3) and positions (F, J, 3), file units."""
        rot, trans = self.local_transforms()
        g_rot = np.empty_like(rot)
        g_pos = np.empty_like(trans)
        for j, p in enumerate(self.parents):
            if p < 0:
                g_rot[:, j], g_pos[:, j] = rot[:, j], trans[:, j]
            else:
                g_rot[:, j] = g_rot[:, p] @ rot[:, j]
                g_pos[:, j] = g_pos[:, p] + np.einsum("fij,fj->fi", g_rot[:, p], trans[:, j])
        return g_rot, g_pos

    def positions(self) -> np.ndarray:
        """(F, J, 3) global joint positions in file units."""
        return self.global_transforms()[1]


_TOKEN = re.compile(r"\S+")


def parse_bvh(text: str, source: str = "<string>") -> Bvh:
    """Parse BVH text. Raises BvhError naming ``source`` on any malformed input."""
    toks = _TOKEN.findall(text)
    pos = 0

    def take() -> str:
        nonlocal pos
        if pos >= len(toks):
            raise BvhError(f"{source}: unexpected end of file")
        pos += 1
        return toks[pos - 1]

    def expect(word: str) -> None:
        got = take()
        if got.upper() != word.upper():
            raise BvhError(f"{source}: expected {word!r}, found {got!r}")

    def floats(n: int) -> np.ndarray:
        try:
            return np.array([float(take()) for _ in range(n)])
        except ValueError as e:
            raise BvhError(f"{source}: bad number ({e})") from None

    names: list[str] = []
    parents: list[int] = []
    offsets: list[np.ndarray] = []
    channels: list[tuple[str, ...]] = []
    end_sites: dict[int, np.ndarray] = {}

    expect("HIERARCHY")
    head = take()
    if head.upper() != "ROOT":
        raise BvhError(f"{source}: expected ROOT, found {head!r}")
    stack: list[int] = []
    kind = "ROOT"
    while True:
        if kind in ("ROOT", "JOINT"):
            name = take()
            expect("{")
            j = len(names)
            names.append(name)
            parents.append(stack[-1] if stack else -1)
            expect("OFFSET")
            offsets.append(floats(3))
            word = take()
            if word.upper() == "CHANNELS":
                try:
                    n = int(take())
                except ValueError:
                    raise BvhError(f"{source}: bad channel count for joint {name!r}") from None
                ch = tuple(take() for _ in range(n))
                bad = [c for c in ch if c not in POSITION_CHANNELS + ROTATION_CHANNELS]
                if bad:
                    raise BvhError(f"{source}: joint {name!r} has unknown channels {bad}")
                channels.append(ch)
            else:
                channels.append(())
                pos -= 1
            stack.append(j)
        elif kind == "END":
            expect("Site")
            expect("{")
            expect("OFFSET")
            end_sites[stack[-1]] = floats(3)
            expect("}")
        elif kind == "}":
            if not stack:
                raise BvhError(f"{source}: unbalanced '}}'")
            stack.pop()
            if not stack:
                break
        else:
            raise BvhError(f"{source}: unexpected {kind!r} in HIERARCHY")
        kind = take().upper()
    expect("MOTION")
    expect("Frames:")
    try:
        n_frames = int(take())
        expect("Frame")
        expect("Time:")
        frame_time = float(take())
    except ValueError:
        raise BvhError(f"{source}: bad Frames/Frame Time header") from None
    if frame_time <= 0:
        raise BvhError(f"{source}: Frame Time must be positive, got {frame_time}")
    n_ch = sum(len(c) for c in channels)
    rest = toks[pos:]
    if len(rest) < n_frames * n_ch:
        raise BvhError(f"{source}: {n_frames} frames of {n_ch} channels announced, {len(rest)} values found")
    try:
        motion = np.array(rest[: n_frames * n_ch], dtype=np.float64).reshape(n_frames, n_ch)
    except ValueError as e:
        raise BvhError(f"{source}: bad number in MOTION ({e})") from None
    if n_frames == 0:
        raise BvhError(f"{source}: no frames")
    return Bvh(names, parents, np.array(offsets), channels, frame_time, motion, end_sites)


def read_bvh(path: str | Path) -> Bvh:
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8", errors="replace")
    except OSError as e:
        raise BvhError(f"{path}: cannot read ({e.strerror})") from None
    return parse_bvh(text, source=path.name)


def detect_unit(bvh: Bvh) -> str:
    """Guess the length unit from the figure's height (max - min y over joints) in frame 0.

    A person's joints span roughly 0.8-2 m (lying down: less, hence the wide bands): a span
    under 3 reads as metres, 30-300 as centimetres, over 300 as millimetres. A span of 3-30
    fits none of them and is refused; pass the unit explicitly then.
    """
    first = Bvh(bvh.names, bvh.parents, bvh.offsets, bvh.channels, bvh.frame_time, bvh.motion[:1], bvh.end_sites)
    p = first.positions()[0]
    span = float(p[:, 1].max() - p[:, 1].min())
    if span < 3:
        return "m"
    if 30 <= span <= 300:
        return "cm"
    if span > 300:
        return "mm"
    raise BvhError(f"cannot tell the unit of a figure {span:.1f} units tall; pass unit= explicitly")


def resample(x: np.ndarray, src_fps: float, dst_fps: float) -> np.ndarray:
    """Linear resampling along axis 0: (F, ...) at src_fps -> (F', ...) at dst_fps, same span."""
    if abs(src_fps - dst_fps) < 1e-9:
        return x.copy()
    n = x.shape[0]
    duration = (n - 1) / src_fps
    m = int(np.floor(duration * dst_fps + 1e-9)) + 1
    t = np.arange(m) / dst_fps * src_fps
    i0 = np.clip(np.floor(t).astype(int), 0, n - 1)
    i1 = np.clip(i0 + 1, 0, n - 1)
    w = (t - i0).reshape(-1, *([1] * (x.ndim - 1)))
    return x[i0] * (1 - w) + x[i1] * w


def bvh_positions_m(bvh: Bvh, fps: float | None = None, unit: str | None = None) -> np.ndarray:
    """(F', J, 3) joint positions in metres, resampled to ``fps`` when given."""
    unit = unit or detect_unit(bvh)
    if unit not in UNITS_TO_M:
        raise BvhError(f"unknown unit {unit!r}; one of {sorted(UNITS_TO_M)}")
    pos = bvh.positions() * UNITS_TO_M[unit]
    return resample(pos, bvh.fps, fps) if fps else pos


# --------------------------------------------------------------------------- writing


def joints_to_bvh(
    joints: np.ndarray,
    fps: float,
    skeleton: Skeleton = HUMANML3D,
    unit: str = "cm",
    rotation_order: str = "ZYX",
    fit: RigFit | None = None,
) -> Bvh:
    """A BVH of a joint-position motion on ``skeleton``: rotation channels, root position.

    Args:
        joints: (T, J, 3) global positions in metres, y up.
        fps: frame rate of ``joints``.
        unit: the unit written to the file (centimetres by default, as most tools expect).
    The rotations come from ``ik.fit_rig`` (see there for how exact they are); ``fit`` is
    that fit where the caller has it already. The file lists joints depth first, so read it
    back by joint name, not by index.
    """
    if fit is None:
        fit = fit_rig(joints, skeleton)
    T, J = fit.local_rot.shape[:2]
    scale = 1.0 / UNITS_TO_M[unit]
    euler = Rotation.from_matrix(fit.local_rot.reshape(-1, 3, 3)).as_euler(rotation_order, degrees=True)
    euler = euler.reshape(T, J, 3)
    rot_channels = tuple(f"{a}rotation" for a in rotation_order)
    cols, channels = [], []
    for j, p in enumerate(skeleton.parents):
        if p < 0:
            channels.append(POSITION_CHANNELS + rot_channels)
            cols.append(fit.root_pos * scale)
        else:
            channels.append(rot_channels)
        cols.append(euler[:, j])
    off = fit.offsets * scale
    off[0] = fit.root_pos[0] * scale
    return Bvh(
        names=list(skeleton.joint_names),
        parents=list(skeleton.parents),
        offsets=off,
        channels=channels,
        frame_time=1.0 / fps,
        motion=np.concatenate(cols, axis=1),
        end_sites={j: e * scale for j, e in fit.end_sites.items()},
    )


def format_bvh(bvh: Bvh, precision: int = 6) -> str:
    """BVH text of ``bvh`` (tabs, one frame per line).

    Joints are written depth first, as the format requires, whatever their order in ``bvh``;
    reading the text back gives the same joints in that file order.
    """
    out = io.StringIO()
    children: list[list[int]] = [[] for _ in bvh.names]
    for c, p in enumerate(bvh.parents):
        if p >= 0:
            children[p].append(c)

    zero = f"{0.0:.{precision}f}"  # what a value that rounds to zero from below is written as

    def num(v: float) -> str:
        s = f"{v:.{precision}f}"
        return zero if s.strip("-0.") == "" else s

    order: list[int] = []  # the file lists joints depth first; MOTION columns follow that order

    def write(j: int, depth: int) -> None:
        order.append(j)
        ind = "\t" * depth
        kind = "ROOT" if bvh.parents[j] < 0 else "JOINT"
        out.write(f"{ind}{kind} {bvh.names[j]}\n{ind}{{\n")
        out.write(f"{ind}\tOFFSET {' '.join(num(v) for v in bvh.offsets[j])}\n")
        if bvh.channels[j]:
            out.write(f"{ind}\tCHANNELS {len(bvh.channels[j])} {' '.join(bvh.channels[j])}\n")
        for c in children[j]:
            write(c, depth + 1)
        if j in bvh.end_sites:
            out.write(f"{ind}\tEnd Site\n{ind}\t{{\n")
            out.write(f"{ind}\t\tOFFSET {' '.join(num(v) for v in bvh.end_sites[j])}\n{ind}\t}}\n")
        out.write(f"{ind}}}\n")

    out.write("HIERARCHY\n")
    write(bvh.parents.index(-1), 0)
    out.write(f"MOTION\nFrames: {bvh.n_frames}\nFrame Time: {bvh.frame_time:.8f}\n")
    starts = bvh._columns()
    cols = [starts[j] + k for j in order for k in range(len(bvh.channels[j]))]
    # one %-format per frame (C speed; num() per value was half of an export's time), then
    # negative zeros written as num() writes them
    row = " ".join([f"%.{precision}f"] * len(cols))
    text = "\n".join(row % tuple(r) for r in bvh.motion[:, cols].tolist())
    out.write(re.sub(rf"(?<![^ \n])-{re.escape(zero)}(?![^ \n])", zero, text))
    if len(bvh.motion):
        out.write("\n")
    return out.getvalue()


def write_bvh(path: str | Path, bvh: Bvh) -> Path:
    path = Path(path)
    path.write_text(format_bvh(bvh), encoding="utf-8")
    return path
