"""Real motion capture: the Bandai Namco Research motion data sets (BVH, 3,076 clips).

CC BY-NC 4.0: anything derived from these clips is for non-commercial use, with attribution
to Bandai Namco Research Inc. (arXiv 2306.08861). The archive is unpacked into a cache
directory, never into the repository.

* ``unpack_archive`` / ``bvh_files``: the archive and its clips;
* ``parse_name``: ``dataset-N_{content}_{style}_{id}.bvh`` -> ClipName;
* ``import_clip``: BVH -> retargeted HumanML3D joints (``retarget.retarget``);
* ``check_directions``: the side and turn a clip's label claims, measured on the motion
  (which wrist rises, the sign of the heading change, the walking direction);
* ``VERIFIER_LABELS``: the corpus verifier's labels for the contents it covers;
* ``clip_texts``: several natural sentences per (content, style, measured side).

``python -m motion_core.data.mocap check ARCHIVE --out results/mocap_check.json`` imports every
clip and reports import time, realism figures and verifier agreement.
"""

from __future__ import annotations

import argparse
import fcntl
import json
import os
import platform
import subprocess
import time
from collections import Counter, defaultdict
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from ..formats.bvh import read_bvh
from ..formats.retarget import BANDAI_NAMCO, retarget
from ..verify.rules import RAISED_VS_SHOULDER, Measures

LICENCE = (
    "Bandai Namco Research Motion datasets 1 and 2, CC BY-NC 4.0, (c) Bandai Namco Research Inc. "
    "(arXiv 2306.08861): non-commercial use only, with attribution"
)


def unpack_archive(archive: str | Path, cache_dir: str | Path) -> Path:
    """Unpack ``archive`` (.tar.xz) into ``cache_dir`` once; returns ``cache_dir``.

    A marker file records a finished unpack, so an interrupted one is redone.
    """
    archive, cache = Path(archive), Path(cache_dir)
    marker = cache / ".unpacked"
    stamp = f"{archive.name} {archive.stat().st_size}"
    if marker.is_file() and marker.read_text() == stamp:
        return cache
    cache.mkdir(parents=True, exist_ok=True)
    # processes that unpack at once (parallel test workers) take turns: the one that waited
    # finds the marker and reads nothing half-written
    with open(cache.parent / f"{cache.name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (marker.is_file() and marker.read_text() == stamp):
            # the system tar (xz in C) unpacks the 550 MB in ~10 s; Python's tarfile takes minutes
            subprocess.run(["tar", "xJf", str(archive), "-C", str(cache)], check=True)
            marker.write_text(stamp)
    return cache


def bvh_files(root: str | Path) -> list[Path]:
    """All clips under an unpacked archive, sorted by name."""
    return sorted(Path(root).glob("Bandai-Namco-Research-Motiondataset-*/data/*.bvh"))


@dataclass(frozen=True)
class ClipName:
    dataset: int
    content: str
    style: str
    take: str

    @property
    def clip_id(self) -> str:
        return f"bn{self.dataset}_{self.content}_{self.style}_{self.take}"


def parse_name(path: str | Path) -> ClipName:
    stem = Path(path).stem
    parts = stem.split("_")
    if len(parts) != 4 or not parts[0].startswith("dataset-"):
        raise ValueError(f"not a Bandai Namco clip name: {stem}")
    return ClipName(int(parts[0].split("-")[1]), parts[1], parts[2], parts[3])


# The corpus verifier's labels for the contents it covers (wave / raise with left /
# right / both, turn left / right, walk, run). dash is a fast run.
VERIFIER_LABELS: dict[str, dict] = {
    "walk": {"kind": "walk", "direction": "forward"},
    "run": {"kind": "run", "direction": "forward"},
    "dash": {"kind": "run", "direction": "forward"},
    "walk-turn-left": {"kind": "turn", "direction": "left"},
    "walk-turn-right": {"kind": "turn", "direction": "right"},
    "wave-left-hand": {"kind": "wave", "side": "left"},
    "wave-right-hand": {"kind": "wave", "side": "right"},
    "wave-both-hands": {"kind": "wave", "side": "both"},
    "raise-up-left-hand": {"kind": "raise_arm", "side": "left"},
    "raise-up-right-hand": {"kind": "raise_arm", "side": "right"},
    "raise-up-both-hands": {"kind": "raise_arm", "side": "both"},
}

# What a label claims about direction, checked on the motion by ``check_directions``.
CLAIMED_SIDE = {
    "wave-left-hand": "left",
    "wave-right-hand": "right",
    "wave-both-hands": "both",
    "raise-up-left-hand": "left",
    "raise-up-right-hand": "right",
    "raise-up-both-hands": "both",
    "byebye": "both",
}
CLAIMED_TURN = {"walk-turn-left": "left", "walk-turn-right": "right"}
CLAIMED_HEADING = {"walk": "forward", "run": "forward", "dash": "forward", "walk-back": "backward",
                   "walk-left": "left", "walk-right": "right"}  # fmt: skip


@dataclass
class DirectionCheck:
    claimed: str | None
    measured: str | None
    agrees: bool
    measures: dict[str, float]


def _raised_side(m: Measures, raised: float = RAISED_VS_SHOULDER, margin: float = 0.1) -> str:
    """Which wrist rises: 'left', 'right', 'both' (both within ``margin`` of each other and
    no lower than 10 cm under their shoulders, the verifier's wave threshold) or 'neither'."""
    hi = {s: float(m.wrist_above_shoulder(s).max()) for s in ("left", "right")}
    up = [s for s in ("left", "right") if hi[s] > raised]
    if not up:
        return "neither"
    if len(up) == 2 and abs(hi["left"] - hi["right"]) < margin:
        return "both"
    return "left" if hi["left"] > hi["right"] else "right"


def check_directions(joints: np.ndarray, content: str) -> DirectionCheck:
    """The side / turn / heading the content claims against what the motion shows."""
    m = Measures(joints)
    ms = {"turn_deg": m.turn_deg(), "disp_angle_deg": m.disp_angle_deg()}
    ms.update({f"{s}_wrist_above_shoulder": float(m.wrist_above_shoulder(s).max()) for s in ("left", "right")})
    if content in CLAIMED_SIDE:
        claimed, measured = CLAIMED_SIDE[content], _raised_side(m)
    elif content in CLAIMED_TURN:
        claimed, measured = CLAIMED_TURN[content], "left" if ms["turn_deg"] > 0 else "right"
    elif content in CLAIMED_HEADING:
        a = ms["disp_angle_deg"]
        claimed = CLAIMED_HEADING[content]
        if claimed in ("left", "right"):  # diagonal walks (set 1): drifting 10+ degrees to that side
            measured = "left" if a > 10 else "right" if a < -10 else "forward"
        else:  # within 35 degrees counts as straight, as in the verifier's direction checks
            measured = "forward" if abs(a) < 35 else "backward" if abs(a) > 145 else "left" if a > 0 else "right"
    else:
        return DirectionCheck(None, None, True, ms)
    return DirectionCheck(claimed, measured, claimed == measured, ms)


# ------------------------------------------------------------------ texts

_ACTION_TEXTS: dict[str, list[str]] = {
    "walk": ["walks forward", "walks straight ahead", "takes a walk forward"],
    "run": ["runs forward", "jogs straight ahead", "runs ahead"],
    "dash": ["sprints forward", "dashes ahead at full speed", "runs forward very fast"],
    "walk-back": ["walks backwards", "steps backwards several times", "walks back without turning around"],
    "walk-left": ["walks diagonally forward to the left", "walks forward, drifting to the left"],
    "walk-right": ["walks diagonally forward to the right", "walks forward, drifting to the right"],
    "walk-turn-left": [
        "walks forward and turns left",
        "walks and makes a left turn",
        "turns to the left while walking",
    ],
    "walk-turn-right": [
        "walks forward and turns right",
        "walks and makes a right turn",
        "turns to the right while walking",
    ],
    "wave-left-hand": ["waves with the left hand", "raises the left hand and waves", "waves the left arm"],
    "wave-right-hand": ["waves with the right hand", "raises the right hand and waves", "waves the right arm"],
    "wave-both-hands": ["waves with both hands", "raises both arms and waves", "waves both hands in the air"],
    "raise-up-left-hand": ["raises the left hand", "lifts the left arm up high", "puts the left hand up"],
    "raise-up-right-hand": ["raises the right hand", "lifts the right arm up high", "puts the right hand up"],
    "raise-up-both-hands": ["raises both hands", "lifts both arms up high", "puts both hands up in the air"],
    "bow": ["bows", "bows politely", "bends forward in a bow"],
    "bye": ["waves goodbye with one hand", "says goodbye with a wave", "waves goodbye"],
    "byebye": ["waves goodbye with both hands", "waves both hands to say goodbye"],
    "guide": ["gestures to show the way", "points the way with the hand", "guides someone with a hand gesture"],
    "respond": ["responds with a gesture", "answers with a small gesture"],
    "call": ["calls someone over with a hand gesture", "beckons someone to come"],
    "punch": ["punches", "throws punches", "punches forward"],
    "kick": ["kicks", "throws a kick", "kicks with the leg"],
    "slash": ["slashes with a sword", "swings a sword", "makes slashing motions"],
    "dance-long": ["dances", "dances energetically", "performs a dance"],
    "dance-short": ["dances", "does a short dance", "performs a short dance"],
}

# style -> (subject that carries the style, or None, manner phrase that carries it)
_STYLE: dict[str, tuple[str | None, str]] = {
    "normal": (None, ""),
    "active": ("an energetic person", ", full of energy"),
    "elderly": ("an elderly person", " like an old person"),
    "old": ("an elderly person", " like an old person"),
    "exhausted": ("an exhausted person", ", looking exhausted"),
    "tired": ("a tired person", ", looking tired"),
    "feminine": (None, " in a feminine way"),
    "masculine": (None, " in a masculine way"),
    "masculinity": (None, " in a masculine way"),
    "youthful": ("a young person", " in a youthful way"),
    "childish": ("a child-like person", " in a childish way"),
    "happy": ("a happy person", ", looking happy"),
    "sad": ("a sad person", ", looking sad"),
    "angry": ("an angry person", ", looking angry"),
    "proud": ("a proud person", ", looking proud"),
    "not-confident": ("an unsure person", ", without confidence"),
    "musical": (None, " in a theatrical, musical way"),
    "giant": (None, " with big, heavy movements like a giant"),
    "chimpira": (None, " with a swaggering, thuggish attitude"),
}


def clip_texts(content: str, style: str, measured_side: str | None = None) -> list[str]:
    """Natural sentences for a clip. ``measured_side`` words one-handed 'bye' by the hand
    that actually waves."""
    actions = list(_ACTION_TEXTS.get(content, [content.replace("-", " ")]))
    if content == "bye" and measured_side in ("left", "right"):
        actions = [f"waves goodbye with the {measured_side} hand", f"says goodbye, waving the {measured_side} hand"]
    subject, manner = _STYLE.get(style, (None, f" in a {style.replace('-', ' ')} way"))
    out = [f"a person {actions[0]}{manner}", f"someone {actions[1 % len(actions)]}{manner}"]
    if subject:
        out.append(f"{subject} {actions[2 % len(actions)]}")
    else:
        out.append(f"the person {actions[2 % len(actions)]}{manner}")
    return out


# ------------------------------------------------------------------ import


@dataclass
class ImportedClip:
    name: ClipName
    joints: np.ndarray  # (T, 22, 3) canonical, metres, 20 fps
    source_frames: int
    source_fps: float
    directions: DirectionCheck


def import_clip(path: str | Path) -> ImportedClip:
    name = parse_name(path)
    bvh = read_bvh(path)
    joints = retarget(bvh, BANDAI_NAMCO)
    return ImportedClip(name, joints, bvh.n_frames, bvh.fps, check_directions(joints, name.content))


def check_archive(root: Path, out: Path | None = None) -> dict:
    """Import every clip; time it; realism figures; verifier agreement; direction checks."""
    from ..verify.realism import BOUNDS, realism
    from ..verify.rules import verify

    files = bvh_files(root)
    t0 = time.perf_counter()
    per_content: dict[str, Counter] = defaultdict(Counter)
    disagree, verifier_fail = [], []
    figures: dict[str, list[float]] = defaultdict(list)
    frames = 0
    t_import = 0.0
    for f in files:
        t1 = time.perf_counter()
        clip = import_clip(f)
        t_import += time.perf_counter() - t1
        frames += len(clip.joints)
        r = realism(clip.joints)
        for k in ("bone_dev_m", "foot_slide_m", "penetration_m", "max_joint_speed_ms"):
            figures[k].append(float(getattr(r, k)))
        c = clip.name.content
        if not clip.directions.agrees:
            disagree.append({"clip": f.name, **asdict(clip.directions)})
        if c in VERIFIER_LABELS:
            v = verify(clip.joints, VERIFIER_LABELS[c])
            per_content[c]["clips"] += 1
            per_content[c]["pass"] += int(v.passed)
            if not v.passed:
                failed = [k for k, ok in v.checks.items() if not ok]
                per_content[c].update(f"fail:{k}" for k in failed)
                verifier_fail.append({"clip": f.name, "failed": failed, "measures": v.measures})
    covered = sum(c["clips"] for c in per_content.values())
    passed = sum(c["pass"] for c in per_content.values())
    q = {k: {"median": float(np.median(v)), "p95": float(np.percentile(v, 95)), "worst": float(max(v, key=abs))}
         for k, v in figures.items()}  # fmt: skip
    report = {
        "clips": len(files),
        "frames_20fps": frames,
        "hours": frames / 20 / 3600,
        "import_seconds": t_import,
        "wall_seconds": time.perf_counter() - t0,
        "realism": q,
        "corpus_bounds": BOUNDS,
        "verifier": {
            "clips": covered,
            "passed": passed,
            "agreement": passed / max(covered, 1),
            "per_content": {k: dict(v) for k, v in sorted(per_content.items())},
            "failures": verifier_fail,
        },
        "direction_disagreements": disagree,
        "licence": LICENCE,
        "machine": f"{os.cpu_count()} CPUs, {platform.machine()}, Python {platform.python_version()}",
        "command": "python -m motion_core.data.mocap check ARCHIVE --out OUT",
    }
    if out:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps(report, indent=1))
    return report


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m motion_core.data.mocap")
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("check", help="import every clip of the archive and report")
    c.add_argument("archive", help="bandai-namco-motion.tar.xz")
    c.add_argument("--cache", default=".cache/bandai-namco", help="where to unpack (outside git)")
    c.add_argument("--out", default="results/mocap_check.json")
    args = ap.parse_args(argv)
    root = unpack_archive(args.archive, args.cache)
    rep = check_archive(root, Path(args.out))
    v = rep["verifier"]
    print(
        f"{rep['clips']} clips, {rep['hours']:.2f} h, imported in {rep['import_seconds']:.0f} s; "
        f"verifier agrees on {v['passed']}/{v['clips']} ({100 * v['agreement']:.1f}%); "
        f"{len(rep['direction_disagreements'])} direction disagreements"
    )
    print(json.dumps({k: v for k, v in v["per_content"].items()}, indent=1))


if __name__ == "__main__":
    main()
