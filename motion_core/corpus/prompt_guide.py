"""What the models know, in words: the training corpus's action kinds with an example each,
the nearest known phrasings of a prompt, and a warning for a prompt far from all of them.

The "phrasebook" is a few thousand unique training captions generated from the corpus's own
catalogues (``corpus.actions.CATALOGUE`` with ``corpus.text`` templates for the procedural
clips, ``mocap.clip_texts`` for the motion-capture clips), with their sentence embeddings from
the frozen text encoder the models use, stored as float16 in ``motion_core/data/phrasebook.npz``
(built by ``python -m motion_core.corpus.prompt_guide build``; no data set is read at run time).

A prompt is "unfamiliar" when its best cosine similarity to any phrasebook caption is below
a threshold calibrated by ``python -m motion_core.corpus.prompt_guide calibrate`` on held-out
paraphrases (familiar) against unrelated sentences and gibberish (unfamiliar); the threshold
is written into the phrasebook and its precision/recall into results/prompt_warning.json.
"""

from __future__ import annotations

import argparse
import json
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

PHRASEBOOK = Path(__file__).resolve().parents[1] / "data" / "phrasebook.npz"
CAPTIONS_PER_KIND = 120  # procedural kinds; every motion-capture caption is kept


@dataclass(frozen=True)
class ActionKind:
    kind: str  # the catalogue's name, e.g. "jump_up" or "mocap:dance-long"
    title: str  # for people: "jump up"
    example: str  # one training caption of it
    source: str  # "procedural" | "motion capture"


# Motion-capture actions the procedural catalogue lacks, with a title for people (the
# others, e.g. walk or bow, are listed once under their procedural kind)
MOCAP_ONLY = {
    "bye": "wave goodbye",
    "guide": "show the way",
    "call": "beckon",
    "respond": "gesture in reply",
    "slash": "slash with a sword",
    "dance-long": "dance",
}


def action_kinds() -> list[ActionKind]:
    """Every action kind of the training corpus, with one example caption (deterministic)."""
    from ..data.mocap import clip_texts
    from .actions import CATALOGUE, Spec
    from .text import WHO, captions_for

    out = []
    for kind, entry in CATALOGUE.items():
        variant = dict(entry["variants"][0])
        if entry.get("count"):
            variant["count"] = entry["count"][0] + 1
        example = captions_for(Spec(kind=kind, **variant), np.random.default_rng(7), n=1)[0]
        who = next((w for w in sorted(WHO, key=len, reverse=True) if example.startswith(w + " ")), None)
        if who:  # every example with the same subject, so the list reads as a list of actions
            example = "a person" + example[len(who) :]
        out.append(ActionKind(kind, kind.replace("_", " "), example, "procedural"))
    for content, title in MOCAP_ONLY.items():
        out.append(ActionKind(f"mocap:{content}", title, clip_texts(content, "normal")[0], "motion capture"))
    return out


def phrasebook_captions(per_kind: int = CAPTIONS_PER_KIND, seed: int = 0) -> tuple[list[str], list[str]]:
    """(captions, their kinds): unique training captions from both catalogues."""
    from ..data.mocap import _ACTION_TEXTS, _STYLE, clip_texts
    from .actions import CATALOGUE, sample_spec
    from .text import captions_for

    rng = np.random.default_rng(seed)
    seen: set[str] = set()
    captions, kinds = [], []
    for kind in CATALOGUE:
        got = 0
        for _ in range(per_kind * 20):
            for c in captions_for(sample_spec(rng, kind), rng, n=3):
                if c not in seen and got < per_kind:
                    seen.add(c)
                    captions.append(c)
                    kinds.append(kind)
                    got += 1
            if got >= per_kind:
                break
    for content in _ACTION_TEXTS:
        for style in _STYLE:
            for side in (None, "left", "right") if content == "bye" else (None,):
                for c in clip_texts(content, style, side):
                    if c not in seen:
                        seen.add(c)
                        captions.append(c)
                        kinds.append(f"mocap:{content}")
    return captions, kinds


def _encode(texts: list[str]) -> np.ndarray:
    from ..nn.text import get_text_encoder

    return get_text_encoder().encode(list(texts)).numpy().astype(np.float32)


def build(out: Path = PHRASEBOOK, threshold: float | None = None) -> dict:
    captions, kinds = phrasebook_captions()
    emb = _encode(captions)
    _save(out, captions, kinds, emb, threshold)
    return {"captions": len(captions), "bytes": out.stat().st_size}


def _save(out: Path, captions, kinds, emb: np.ndarray, threshold: float | None) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(
        out,
        captions=np.array(captions),
        kinds=np.array(kinds),
        embeddings=emb.astype(np.float16),
        threshold=np.float64(np.nan if threshold is None else threshold),
    )


@dataclass(frozen=True)
class Match:
    caption: str
    kind: str
    similarity: float


@dataclass(frozen=True)
class Guidance:
    text: str
    nearest: list[Match]
    best: float  # the highest similarity to any known caption
    threshold: float
    unfamiliar: bool  # best < threshold: the models were not trained on anything like it


class Phrasebook:
    def __init__(self, path: Path = PHRASEBOOK) -> None:
        with np.load(path) as z:
            self.captions = [str(c) for c in z["captions"]]
            self.kinds = [str(k) for k in z["kinds"]]
            self.embeddings = z["embeddings"].astype(np.float32)
            self.threshold = float(z["threshold"])
        if not np.isfinite(self.threshold):
            raise ValueError(
                f"{path} has no calibrated threshold: run python -m motion_core.corpus.prompt_guide calibrate"
            )

    def similarities(self, texts: list[str]) -> np.ndarray:
        """(N, captions) cosine similarities (the encoder's embeddings are unit length)."""
        return _encode(texts) @ self.embeddings.T

    def best(self, texts: list[str]) -> np.ndarray:
        return self.similarities(texts).max(axis=1) if texts else np.zeros(0)

    def guide(self, text: str, k: int = 3) -> Guidance:
        """The k nearest known phrasings of ``text`` (distinct kinds first) and whether it is unfamiliar."""
        text = " ".join((text or "").split())
        if not text:
            return Guidance(text, [], 0.0, self.threshold, False)
        sims = self.similarities([text])[0]
        order = np.argsort(-sims)
        picked, kinds = [], set()
        for i in order[:50]:  # prefer different kinds, so the suggestions are alternatives
            if self.kinds[i] not in kinds:
                picked.append(i)
                kinds.add(self.kinds[i])
            if len(picked) == k:
                break
        nearest = [Match(self.captions[i], self.kinds[i], float(sims[i])) for i in picked]
        best = float(sims[order[0]])
        return Guidance(text, nearest, best, self.threshold, best < self.threshold)


_shared: Phrasebook | None = None
_lock = threading.Lock()


def get_phrasebook() -> Phrasebook:
    global _shared
    with _lock:
        if _shared is None:
            _shared = Phrasebook()
        return _shared


# ---------------------------------------------------------------------------- calibration
# Familiar: people's own wordings of actions the corpus has, none a template's output.
PARAPHRASES = [
    "a guy strolls ahead casually",
    "somebody lifts their right arm up",
    "a woman hops on one leg",
    "the man crouches down and stands back up",
    "someone does star jumps",
    "a person sits on a chair",
    "a person lies down on the floor",
    "someone gets up off the ground",
    "the woman bends at the waist to greet",
    "a man jabs forward with his fist",
    "a person kicks a ball with the left foot",
    "someone claps a few times",
    "a person throws something overhand",
    "a person stretches the arms above the head",
    "someone jogs slowly forward",
    "a man sprints as fast as he can",
    "a person backs up a few steps",
    "the person shuffles to the side",
    "someone spins around",
    "a woman walks around in circles",
    "a person kneels on one knee",
    "someone lunges forward with the right leg",
    "a person leaps forward",
    "a person jumps straight up",
    "someone steps over a box",
    "a person reaches out for something on the left",
    "a man greets someone by waving his hand",
    "a person waves goodbye",
    "someone dances happily",
    "a person swings a sword around",
    "someone beckons a friend to come closer",
    "a person points the way",
    "an old man walks slowly",
    "a tired woman trudges forward",
    "a happy kid skips along",
    "a person raises both hands in the air",
    "someone waves with both arms",
    "the person squats three times",
    "a person turns left while walking",
    "someone walks and turns to the right",
    "a person jumps up and down",
    "a person punches with the left hand twice",
    "someone kicks high with the right leg",
    "a person walks diagonally to the right",
    "a man steps to the left",
    "the person turns around and walks back",
    "someone stands up from sitting",
    "a person bows deeply",
    "someone sits down slowly",
    "a person raises the left hand and waves",
    "a woman claps her hands",
    "a person jogs in place",
    "someone jumps forward twice",
    "a man reaches up high with the right hand",
    "a person lies on the ground",
    "a person runs and then stops",
    "someone walks proudly forward",
    "an angry man stomps ahead",
    "a figure makes a half turn",
    "a person does a lunge",
]
# Unfamiliar: sentences about other things, and gibberish.
UNRELATED = [
    "the stock market fell sharply today",
    "please pass the salt",
    "what is the capital of france",
    "the cake needs another ten minutes in the oven",
    "my laptop battery is almost empty",
    "the meeting was moved to thursday",
    "rain is expected later this evening",
    "photosynthesis converts light",
    "the invoice is attached to this email",
    "a red car parked on the street",
    "the museum opens at nine",
    "quantum computers use qubits",
    "the soup tastes a little salty",
    "this book has four hundred pages",
    "the train to berlin is delayed",
    "a cup of coffee on the table",
    "the password must contain a number",
    "the river flooded the valley",
    "sunflowers grow in the summer",
    "the orchestra played a symphony",
    "an apple a day keeps the doctor away",
    "the printer is out of paper",
    "the volcano erupted last year",
    "she bought three tomatoes and an onion",
    "the wifi network is down",
    "interest rates will rise",
    "the moon orbits the earth",
    "a blue vase full of flowers",
    "the recipe calls for two eggs",
    "my phone number changed",
    "the election results are in",
    "a painting of a quiet harbour",
    "the database query timed out",
    "tax returns are due in april",
    "the glacier is melting",
    "a sandwich with cheese and ham",
    "the concert tickets sold out",
    "the bridge was built in 1890",
    "an email about the quarterly report",
    "the dog food is in the cupboard",
    "a history of the roman empire",
    "the kettle is boiling",
    "chapter three explains the theorem",
    "the shop closes early on sundays",
    "a spreadsheet of monthly expenses",
    "the plants need watering",
    "the contract expires next month",
    "the sky is clear tonight",
    "a bowl of noodles",
    "the software update failed",
]


# Not used to calibrate: motions the corpus does not have. The warning is not meant to catch
# these (they are sentences about a person moving); how many it does is reported as a limit.
UNKNOWN_ACTIONS = [
    "someone does a cartwheel",
    "a person swims the breaststroke",
    "a man plays the guitar",
    "a person rides a bicycle",
    "someone climbs a ladder",
    "a woman juggles three balls",
    "a person picks up a box from the floor",
    "someone skips rope",
    "a person does a handstand",
    "a man does push-ups",
    "someone crawls on hands and knees",
    "a person brushes their teeth",
    "someone types on a keyboard",
    "a person drinks from a cup",
    "a man rows a boat",
    "a person does a backflip",
    "someone skates on ice",
    "a woman plays tennis",
    "a person shovels snow",
    "someone drives a car",
]


def gibberish(n: int, seed: int = 0) -> list[str]:
    """Random letter strings shaped like words, and keyboard mashing (seeded)."""
    rng = np.random.default_rng(seed)
    letters = np.array(list("abcdefghijklmnopqrstuvwxyz"))
    out = ["asdf qwer zxcv", "qwertyuiop", "jkl jkl jkl", "xxxxxx yyyy", "zzzz zzzz", "lorem ipsum dolor sit amet"]
    while len(out) < n:
        words = ["".join(rng.choice(letters, int(rng.integers(2, 9)))) for _ in range(int(rng.integers(1, 6)))]
        out.append(" ".join(words))
    return out[:n]


def calibration_sets() -> dict[str, list[str]]:
    """Even items calibrate the threshold, odd items test it."""
    unfamiliar = UNRELATED + gibberish(len(UNRELATED))
    return {
        "familiar_cal": PARAPHRASES[0::2],
        "familiar_test": PARAPHRASES[1::2],
        "unfamiliar_cal": unfamiliar[0::2],
        "unfamiliar_test": unfamiliar[1::2],
    }


def _warning_figures(fam: np.ndarray, unf: np.ndarray, thr: float) -> dict:
    """Precision and recall of the warning (warned = best similarity below ``thr``)."""
    tp = int((unf < thr).sum())
    fp = int((fam < thr).sum())
    fn = int((unf >= thr).sum())
    return {
        "precision": tp / (tp + fp) if tp + fp else 1.0,
        "recall": tp / (tp + fn) if tp + fn else 1.0,
        "warned_familiar": fp,
        "familiar": len(fam),
        "warned_unfamiliar": tp,
        "unfamiliar": len(unf),
    }


def calibrate(path: Path = PHRASEBOOK, report: Path | None = None) -> dict:
    """Pick the threshold that best separates the calibration halves (the highest F1 of the
    warning, ties to the middle of the gap), store it and report both halves' figures."""
    book = Phrasebook.__new__(Phrasebook)
    with np.load(path) as z:
        captions, kinds, emb = [str(c) for c in z["captions"]], [str(k) for k in z["kinds"]], z["embeddings"]
    book.captions, book.kinds, book.embeddings, book.threshold = captions, kinds, emb.astype(np.float32), np.nan
    sets = calibration_sets()
    best = {k: book.best(v) for k, v in sets.items()}
    fam, unf = best["familiar_cal"], best["unfamiliar_cal"]
    cands = np.unique(np.concatenate([fam, unf]))
    mids = (cands[:-1] + cands[1:]) / 2

    def f1(t: float) -> float:
        r = _warning_figures(fam, unf, t)
        return 2 * r["precision"] * r["recall"] / (r["precision"] + r["recall"] or 1)

    scores = np.array([f1(t) for t in mids])
    top = mids[scores >= scores.max() - 1e-12]
    thr = round(float(np.median(top)), 3)
    _save(path, captions, kinds, emb.astype(np.float32), thr)
    result = {
        "threshold": thr,
        "note": "warned = the prompt's best similarity is below the threshold; precision = warned prompts that "
        "are unfamiliar, recall = unfamiliar prompts warned; 'test' = the held-out halves",
        "phrasebook_captions": len(captions),
        "encoder": "all-MiniLM-L6-v2 (frozen), cosine similarity to the nearest phrasebook caption",
        "calibration": _warning_figures(fam, unf, thr),
        "test": _warning_figures(best["familiar_test"], best["unfamiliar_test"], thr),
        "unknown_actions_warned": _warning_figures(np.zeros(0), book.best(UNKNOWN_ACTIONS), thr)["recall"],
        "best_similarity": {
            k: {"min": float(v.min()), "median": float(np.median(v)), "max": float(v.max())} for k, v in best.items()
        },
        "missed_or_wrong_on_test": {
            "warned_familiar": [
                t for t, s in zip(sets["familiar_test"], best["familiar_test"], strict=True) if s < thr
            ],
            "unwarned_unfamiliar": [
                t for t, s in zip(sets["unfamiliar_test"], best["unfamiliar_test"], strict=True) if s >= thr
            ],
        },
        "command": (
            "python -m motion_core.corpus.prompt_guide build && python -m motion_core.corpus.prompt_guide calibrate"
        ),
    }
    if report is not None:
        report.parent.mkdir(parents=True, exist_ok=True)
        report.write_text(json.dumps(result, indent=1) + "\n")
    return result


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m motion_core.corpus.prompt_guide", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    b = sub.add_parser("build", help="write the phrasebook (captions and their embeddings)")
    b.add_argument("--out", type=Path, default=PHRASEBOOK)
    c = sub.add_parser("calibrate", help="calibrate the unfamiliar-prompt threshold; report precision/recall")
    c.add_argument("--phrasebook", type=Path, default=PHRASEBOOK)
    c.add_argument("--report", type=Path, default=Path("results/prompt_warning.json"))
    g = sub.add_parser("guide", help="the nearest known phrasings of a prompt")
    g.add_argument("text")
    args = ap.parse_args(argv)
    if args.cmd == "build":
        print(json.dumps(build(args.out)))
    elif args.cmd == "calibrate":
        r = calibrate(args.phrasebook, args.report)
        print(json.dumps({k: r[k] for k in ("threshold", "calibration", "test")}, indent=1))
    else:
        gd = get_phrasebook().guide(args.text)
        print(f"best {gd.best:.3f} (threshold {gd.threshold:.3f}){' UNFAMILIAR' if gd.unfamiliar else ''}")
        for m in gd.nearest:
            print(f"  {m.similarity:.3f}  {m.caption}  [{m.kind}]")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
