"""How often real captions ask for stairs, steps and platforms, and how they phrase it.

    python tools/stairs_captions.py [../shared/captions/kitml-annotations.json]

Counts the KIT Motion-Language captions (the 2,883 original motions; the mirrored ``M`` keys,
whose text only swaps left and right, are left out) that match each phrasing, as captions
and as motions, and prints every matching caption once.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
STAIRS = r"(stairs?|staircases?|steps)"
WALK = r"\b(walk(s|ing)?|wakling)"  # (one caption spells it "wakling")
PHRASINGS = {
    "walks up stairs": rf"{WALK} (up (and down )?(the |some |a )?{STAIRS}|(\w+ )?upstairs)",
    "walks down stairs": (
        rf"{WALK} ((up and )?down (the |some |a |on )?{STAIRS}|(\w+ )?downstairs)|upstairs and then downstairs"
    ),
    "goes up / down stairs": rf"\bgo(es|ing)? ((up|down) (the |some )?{STAIRS}|upstairs|downstairs)",
    "climbs stairs": rf"\bclimb(s|ing)? (up )?(the |some |a )?{STAIRS}",
    "steps up onto": (
        r"\bstep(s|ping)? (up )?on(to)? (a |the )?(low |small )?(platform|step|box|higher ground|stairs)"
        r"|\bstepping onto higher ground"
    ),
    "steps over": r"\bstep(s|ping)? over\b",
    "any stair word (stair, stairs, staircase, upstairs, downstairs)": r"stair",
}


def count(path: Path) -> dict:
    data = json.loads(path.read_text())
    motions = {k: [a["text"] for a in v["annotations"]] for k, v in data.items() if not k.startswith("M")}
    out = {"motions": len(motions), "captions": sum(len(v) for v in motions.values()), "phrasings": {}}
    for name, pattern in PHRASINGS.items():
        rx = re.compile(pattern, re.I)
        hits = [(k, t) for k, texts in motions.items() for t in texts if rx.search(t)]
        out["phrasings"][name] = {
            "captions": len(hits),
            "motions": len({k for k, _ in hits}),
            "examples": sorted({t for _, t in hits}),
        }
    return out


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    path = Path(argv[0]) if argv else REPO.parent / "shared" / "captions" / "kitml-annotations.json"
    res = count(path)
    print(f"{res['captions']} captions of {res['motions']} motions (KIT-ML, mirrored keys left out)")
    for name, r in res["phrasings"].items():
        print(f"\n{name}: {r['captions']} captions, {r['motions']} motions")
        for t in r["examples"]:
            print(f"    {t}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
