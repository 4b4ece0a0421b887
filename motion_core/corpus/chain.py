"""Two or three actions in one clip under one sentence: "walks forward, then sits down".

A third of real captions chain actions in one sentence (yardstick/README.md: 20-25% of the
KIT-ML samples are multi-action). A timeline of single-action segments cannot follow such a
sentence as one segment, so the corpus holds clips of such chains with one caption that
names every action in order. The connectives are the ones real captions use most
("then", "and then", ", then", "and", "first ... then", "after that"); the three-action forms
add the list form ("A, B and then C").

Which kinds can chain: those that start and end standing on the flat floor (a floor kind
owns its whole clip, holding an object is a posture that spans its clip, and stairs need
their terrain), plus the built-in posture pairs, which chain as sample_sequence does
(sit down -> stand up, lie down -> get up).
"""

from __future__ import annotations

import numpy as np

from .actions import CATALOGUE, POSTURE, REGISTERED, Spec, duration_of, sample_spec
from .compose import Composed, compose
from .text import WHO, captions_for

CHAIN_SECONDS = 10.0  # a chain fits the models' window (196 frames, like a single clip)
TWO = ("{a}, then {b}", "{a} and then {b}", "{a}, and then {b}", "{a} then {b}", "{a} and {b}", "{a}, after that {b}")
FIRST = ("{who} first {a}, then {b}", "{who} first {a} and then {b}")
THREE = ("{a}, {b} and then {c}", "{a}, then {b}, then {c}", "{a}, {b}, and then {c}", "{a}, then {b} and {c}")
LEAVES = {"sit_down": "stand_up", "lie_down": "get_up"}


def chain_kinds(kinds: list[str] | None = None) -> list[str]:
    """The kinds (of ``kinds``, default CATALOGUE) a chain may draw freely: standing at both
    ends on flat ground. stand_up / get_up come only after the action that leaves that posture."""
    pool = list(CATALOGUE) if kinds is None else kinds
    out = []
    for k in pool:
        if k in ("stand_up", "get_up"):
            continue
        if k in REGISTERED:
            kind = REGISTERED[k]
            if kind.posture != ("standing", "standing") or kind.family == "stairs":
                continue
        out.append(k)
    return out


def sample_chain_specs(rng: np.random.Generator, n: int, kinds: list[str] | None = None) -> list[Spec]:
    """n actions in sequence, no kind twice in a row; a sit down (lie down) is followed by the
    stand up (get up) that leaves it, which counts as one of the n."""
    pool = chain_kinds(kinds)
    specs: list[Spec] = []
    while len(specs) < n:
        if specs and specs[-1].kind in LEAVES:
            specs.append(Spec(LEAVES[specs[-1].kind]))
            continue
        spec = sample_spec(rng, pool[int(rng.integers(len(pool)))])
        if specs and spec.kind == specs[-1].kind:
            continue
        if spec.kind in LEAVES and len(specs) == n - 1:
            continue  # no room for the way back up
        specs.append(spec)
    return specs


def sample_chain(rng: np.random.Generator, n: int, kinds: list[str] | None = None) -> Composed:
    """One clip of n (2 or 3) actions in sequence, at most CHAIN_SECONDS with lead-in and tail;
    segments carry each action's frames."""
    specs = sample_chain_specs(rng, n, kinds)
    lead, tail = rng.uniform(0.2, 0.5), rng.uniform(0.2, 0.5)
    durs = [duration_of(s, rng) for s in specs]
    room = CHAIN_SECONDS - lead - tail
    if sum(durs) > room:
        # Shrink proportionally, but no action below 70% of its shortest catalogue duration.
        scale = room / sum(durs)
        durs = [max(d * scale, 0.7 * _shortest(s)) for s, d in zip(specs, durs, strict=True)]
    plan = list(zip(specs, durs, strict=True))
    assert POSTURE.get(specs[-1].kind, ("", "standing"))[1] == "standing"
    return compose(plan, rng, lead, tail)


def _shortest(spec: Spec) -> float:
    c = CATALOGUE[spec.kind] if spec.kind in CATALOGUE else REGISTERED[spec.kind].catalogue
    return float(c["dur"][0])


def _subject_and_predicate(caption: str) -> tuple[str, str] | None:
    """("a person", "walks forward") when the caption starts with its subject, else None."""
    for who in sorted(WHO, key=len, reverse=True):
        if caption.startswith(who + " "):
            return who, caption[len(who) + 1 :]
    return None


def _predicate(spec: Spec, rng: np.random.Generator) -> str:
    """The action as a verb phrase without its subject ("sits down on a chair")."""
    caps = captions_for(spec, rng, 6)
    split = [sp for c in caps if (sp := _subject_and_predicate(c)) is not None]
    if split:
        return split[int(rng.integers(len(split)))][1]
    # Every template opens with a setting ("from kneeling, a person stands up"): keep what
    # follows its subject.
    c = caps[int(rng.integers(len(caps)))]
    for who in sorted(WHO, key=len, reverse=True):
        if f" {who} " in f" {c} ":
            return c.split(f"{who} ", 1)[1]
    return c


def chain_caption(specs: list[Spec], rng: np.random.Generator) -> str:
    """One sentence naming every action of the chain in order."""
    who = WHO[int(rng.integers(len(WHO)))]
    parts = [_predicate(s, rng) for s in specs]
    if len(specs) == 2:
        if rng.random() < 0.2:
            tpl = FIRST[int(rng.integers(len(FIRST)))]
            return tpl.format(who=who, a=parts[0], b=parts[1])
        tpl = TWO[int(rng.integers(len(TWO)))]
        return tpl.format(a=f"{who} {parts[0]}", b=parts[1])
    if len(specs) == 3:
        tpl = THREE[int(rng.integers(len(THREE)))]
        return tpl.format(a=f"{who} {parts[0]}", b=parts[1], c=parts[2])
    raise ValueError(f"a chain names two or three actions, not {len(specs)}")


def chain_captions(specs: list[Spec], rng: np.random.Generator, n: int = 3) -> list[str]:
    """n distinct sentences (fewer if they run out) for one chain."""
    out: list[str] = []
    for _ in range(n * 4):
        c = chain_caption(specs, rng)
        if c not in out:
            out.append(c)
        if len(out) == n:
            break
    return out


def chain_labels(comp: Composed) -> dict:
    """The verifier's labels for a chain clip: its actions in order, with their true frames."""
    return {
        "kind": "chain",
        "actions": [spec.labels() for _, _, spec in comp.segments],
        "frames": [[a, b] for a, b, _ in comp.segments],
    }
