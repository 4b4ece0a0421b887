"""Read a whole prompt: its clauses in the order they happen, which corpus action each asks
for (or that the models do not know it), and a timeline plan of the user's own words.

    r = read_prompt("A person walks forward while waving, then picks up a box. Before sitting down, he bows.")
    [c.kind for c in r.clauses]      # ['walk', 'wave', 'unknown', 'bow', 'sit_down']
    r.unknown_parts[0].message       # "The models have not learned 'picks up a box' (nearest: ...)"
    r.plan()                         # [Segment('A person walks forward while waving', 4.1), ...]
    check_prompt(text)               # the warning to show before generation

How it reads (rules over a small parse, no model download, no network):

1. *Split.* The text is cut into pieces at sentence ends, commas and joining words
   (``lexicon.SEQUENCE_WORDS`` "then", "after that", "and", "finally"...; ``TOGETHER_WORDS``
   "while", "as he"...; "before", "after", "until"). A piece that says no action (", slowly",
   "and to the left", "starting with the left foot") joins the clause before it; after "and",
   a comma or "as" a piece must start with a verb to be a clause of its own, so "walks
   forward and backward" stays one clause. Joining words and pronouns never become clauses.
2. *Order.* "While" / "as" / "at the same time" make a clause run together with the previous
   one; "Before B, A" and "A after B" put B second / first, so clauses come in the order
   they happen.
3. *Classify.* Each clause's normalised words are matched against the lexicon: first the
   specific unknown actions (``lexicon.UNKNOWN``: "picks up", "push ups", "climbs stairs"),
   then the corpus's kinds (``lexicon.KINDS``, most specific first), then the weak unknowns
   (touch, hold, lean...), then any verb of bodily motion (``lexicon.MOTION_VERBS``): a clause
   with a motion verb that matches no kind is unknown, named by its own words. "Stops" /
   "stands still" after an action is its end, not a clause. Side, direction, angle and count
   are read only for kinds whose catalogue variants take them.
4. *Nearest known action.* For an unknown clause, the frozen sentence encoder's nearest
   phrasebook caption (``prompt_guide``) names the closest kind, worded by the lexicon's title
   ("reach forward with the right hand").
5. *Plan.* One segment per sequential clause, together-clauses in the same segment; its text
   is the user's own words for those clauses (with the sentence's subject in front when the
   clause has none), its seconds from the shipped length estimator.

The warning (:func:`check_prompt`) fires when any clause is unknown, when no clause names an
action, or when the phrasebook finds the whole prompt unfamiliar (gibberish, unrelated
sentences: ``prompt_guide``'s calibrated threshold).
"""

from __future__ import annotations

import itertools
import re
from dataclasses import asdict, dataclass, field
from functools import cache, cached_property

from . import lexicon as lx

UNKNOWN = "unknown"


# ------------------------------------------------------------------------------ normalising
def _word_map(mapping: dict[str, object]) -> re.Pattern:
    keys = sorted(mapping, key=len, reverse=True)
    return re.compile(r"\b(?:" + "|".join(re.escape(k) for k in keys) + r")\b")


_SPELL = _word_map(lx.SPELLING)
_NUM = _word_map(lx.NUMBERS)
_CCW = re.compile(r"\b(?:counter ?clock ?wise|anti ?clock ?wise|contra ?clock ?wise)\b")
_CW = re.compile(r"\bclock ?wise\b")


def normalise(text: str) -> str:
    """Lower case, hyphens and slashes as spaces, only letters, digits and spaces; a few
    misspellings fixed; number words as digits; counter-clockwise as ``ccw``, clockwise as
    ``cw``; "leftwards" as "to the left"."""
    t = text.lower().replace("’", "'")
    t = re.sub(r"[-_/]", " ", t)
    t = re.sub(r"[^a-z0-9' ]+", " ", t)
    t = " ".join(t.split())
    t = _SPELL.sub(lambda m: lx.SPELLING[m.group(0)], t)
    t = _NUM.sub(lambda m: str(lx.NUMBERS[m.group(0)]), t)
    t = re.sub(r"\b(\d+) and a half\b", r"\1", t)
    t = _CCW.sub("ccw", t)
    t = _CW.sub("cw", t)
    t = re.sub(r"\b(left|right)(?:wards?|ward)\b", r"to the \1", t)
    return t


# ---------------------------------------------------------------------------------- results
@dataclass(frozen=True)
class Clause:
    """One action the prompt asks for.

    kind: a corpus kind (``corpus.actions.CATALOGUE`` or ``mocap:...``) or ``"unknown"``.
    unknown: for an unknown clause, the action's name (``lexicon.UNKNOWN``'s, e.g. "pick up",
    or the clause's own words when it is named by no entry).
    words: the clause's words, cut from the user's text (``text[start:end]``), never rewritten.
    with_previous: runs together with the clause before it ("walks while waving").
    """

    kind: str
    words: str
    start: int
    end: int
    with_previous: bool = False
    side: str | None = None
    direction: str | None = None
    count: int | None = None
    angle: int | None = None
    speed: str | None = None
    amplitude: str | None = None
    unknown: str | None = None

    @property
    def known(self) -> bool:
        return self.kind != UNKNOWN

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class UnknownPart:
    """A clause the models cannot do, with the nearest known action for people."""

    words: str  # the user's words for it (without the subject)
    name: str  # what it asks for
    nearest_kind: str | None
    nearest: str | None  # the nearest known action, e.g. "reach forward with the right hand"

    @property
    def message(self) -> str:
        near = f" (nearest: {self.nearest})" if self.nearest else ""
        return f"The models have not learned '{self.words}'{near}"

    def to_dict(self) -> dict:
        return {**asdict(self), "message": self.message}


@dataclass(frozen=True)
class Segment:
    """One timeline segment: the user's own words for one sequential clause and any clauses
    that run together with it, and the seconds the length estimator gives them."""

    text: str
    seconds: float
    kinds: tuple[str, ...]
    known: bool

    def to_dict(self) -> dict:
        return {"text": self.text, "seconds": self.seconds, "kinds": list(self.kinds), "known": self.known}


@dataclass(frozen=True)
class Reading:
    text: str
    clauses: tuple[Clause, ...]
    subject: str | None = None  # the sentence's subject in the user's words ("A person")

    @property
    def fully_known(self) -> bool:
        """Every clause a known kind (and at least one clause)."""
        return bool(self.clauses) and all(c.known for c in self.clauses)

    @cached_property
    def unknown_parts(self) -> tuple[UnknownPart, ...]:
        """The clauses the models cannot do, each with its nearest known action."""
        unknown = [c for c in self.clauses if not c.known]
        if not unknown:
            return ()
        ask = [c for c in unknown if lx.NEAREST.get(c.unknown or "") is None]
        near = dict(zip((id(c) for c in ask), _nearest([self._with_subject(c.words) for c in ask]), strict=True))
        out = []
        for c in unknown:
            kind = lx.NEAREST.get(c.unknown or "")
            if kind is not None:
                det = {"side": c.side} if c.side and _takes().get(kind, {}).get("side") else {}
                title: str | None = _title(kind, det)
            else:
                kind, title = near[id(c)]
            out.append(UnknownPart(_without_subject(c.words), c.unknown or _without_subject(c.words), kind, title))
        return tuple(out)

    def groups(self) -> list[list[Clause]]:
        """The clauses grouped into segments: each sequential clause with its together-clauses."""
        out: list[list[Clause]] = []
        for c in self.clauses:
            if c.with_previous and out:
                out[-1].append(c)
            else:
                out.append([c])
        return out

    def segment_texts(self) -> list[str]:
        texts = []
        for g in self.groups():
            ordered = sorted(g, key=lambda c: c.start)
            contiguous = all(_only_joiners(self.text[a.end : b.start]) for a, b in itertools.pairwise(ordered))
            if contiguous:
                words = self.text[ordered[0].start : ordered[-1].end]
            else:
                words = " while ".join(c.words for c in g)
            texts.append(self._with_subject(words))
        return texts

    def plan(self) -> list[Segment]:
        """One segment per sequential clause: (the user's words, seconds from the shipped length
        estimator). Together-clauses share their segment."""
        groups = self.groups()
        if not groups:
            return []
        from ..inference.length import estimate_seconds

        texts = self.segment_texts()
        secs = estimate_seconds(texts)
        return [
            Segment(t, float(s), tuple(c.kind for c in g), all(c.known for c in g))
            for t, s, g in zip(texts, secs, groups, strict=True)
        ]

    def _with_subject(self, words: str) -> str:
        if not self.subject or _has_subject(words):
            return words
        return f"{self.subject} {words}"

    def to_dict(self, plan: bool = False) -> dict:
        out = {
            "text": self.text,
            "subject": self.subject,
            "clauses": [c.to_dict() for c in self.clauses],
            "fully_known": self.fully_known,
            "unknown_parts": [u.to_dict() for u in self.unknown_parts],
        }
        if plan:
            out["plan"] = [s.to_dict() for s in self.plan()]
        return out


@dataclass(frozen=True)
class PromptCheck:
    """What to tell the user before generating: ``warn`` and its ``messages``."""

    text: str
    warn: bool
    messages: tuple[str, ...]
    unknown_parts: tuple[UnknownPart, ...]
    unfamiliar: bool  # the phrasebook finds the whole prompt unlike any training caption
    no_action: bool  # no clause names an action
    reading: Reading = field(repr=False)

    def to_dict(self) -> dict:
        return {
            "text": self.text,
            "warn": self.warn,
            "messages": list(self.messages),
            "unknown_parts": [u.to_dict() for u in self.unknown_parts],
            "unfamiliar": self.unfamiliar,
            "no_action": self.no_action,
            "clauses": [c.to_dict() for c in self.reading.clauses],
        }


# ---------------------------------------------------------------------------------- splitting
_TOKEN = re.compile(r"\d+(?:[.,]\d+)+|[A-Za-z0-9]+(?:['’][A-Za-z]+)?|[.,;:!?()]")
_STOP = {".", ";", "!", "?", "(", ")"}
_COMMA = {",", ":"}
# joining phrases (as token tuples) -> marker
_JOINERS: dict[tuple[str, ...], str] = {}
for _w in lx.SEQUENCE_WORDS:
    _JOINERS[tuple(_w.split())] = "and" if _w == "and" else "seq"
for _w in lx.TOGETHER_WORDS:
    _JOINERS[tuple(_w.split()[:1] if _w.startswith("as ") else _w.split())] = (
        "while" if _w.split()[0] in ("while", "whilst", "as") else "with"
    )
_JOINERS.update(
    {
        ("and", "at", "the", "same", "time"): "with",
        ("at", "the", "same", "time", "as"): "with",
        ("as", "well", "as"): "and",
        ("as",): "as",
        ("after", "a", "while"): "seq",
        ("after", "some", "time"): "seq",
        ("while",): "while",
        ("whilst",): "while",
        ("before",): "before",
        ("after",): "after",
        ("until",): "until",
        ("till",): "until",
        ("but",): "and",
        ("or",): "or",
        ("and", "proceeds", "to"): "seq",
        ("proceeds", "to"): "seq",
        ("goes", "on", "to"): "seq",
        ("and", "continues", "to"): "seq",
        ("and", "starts", "to"): "seq",
        ("in", "order", "to"): "until",
        ("so", "that"): "until",
    }
)
_NOT_JOINERS = {("after", "a"), ("before", "the"), ("after", "the"), ("as", "if"), ("as", "though")}
_MAXJ = max(len(k) for k in _JOINERS)
_ADVERB = re.compile(r"\w+ly|also|still|now|just|again|back|once|immediately|quickly|then|too|even|first")
_DETERMINERS = {"a", "an", "the", "this", "that", "some"}


@dataclass
class _Piece:
    start: int
    end: int
    markers: set[str]
    sentence: int
    tokens: list[str]
    text: str = ""


def _pieces(text: str) -> list[_Piece]:
    toks = [(m.group(0).lower().replace("’", "'"), m.start(), m.end()) for m in _TOKEN.finditer(text)]
    pieces: list[_Piece] = []
    cur: list[tuple[str, int, int]] = []
    markers: set[str] = set()
    sentence = 0

    def flush() -> None:
        nonlocal cur, markers
        if cur:
            pieces.append(_Piece(cur[0][1], cur[-1][2], markers, sentence, [t[0] for t in cur]))
            markers = set()
        cur = []

    i = 0
    while i < len(toks):
        w = toks[i][0]
        if w in _STOP:
            flush()
            markers = set()
            sentence += 1
            i += 1
            continue
        if w in _COMMA:
            flush()
            markers.add("comma")
            i += 1
            continue
        hit = None
        for n in range(min(_MAXJ, len(toks) - i), 0, -1):
            key = tuple(t[0] for t in toks[i : i + n])
            if key == ("and",) and tuple(t[0] for t in toks[i : i + 3]) == ("and", "a", "half"):
                break  # "three and a half steps"
            if key in _JOINERS and (n > 1 or tuple(t[0] for t in toks[i : i + 2]) not in _NOT_JOINERS):
                hit = (n, _JOINERS[key])
                break
        if hit:
            flush()
            markers.add(hit[1])
            i += hit[0]
            continue
        cur.append(toks[i])
        i += 1
    flush()
    for p in pieces:
        p.text = text[p.start : p.end]
    return pieces


# ----------------------------------------------------------------------------- classifying
_STRONG_UNKNOWN = lx.STRONG_PATTERNS
_WEAK_UNKNOWN = lx.WEAK_PATTERNS
_ALL_VERBS = set(lx.MOTION_VERBS) | {v for k in lx.KINDS for v in k.verbs if v.isalpha()}
_MOTION = re.compile(r"\b" + lx.forms(*sorted(_ALL_VERBS)) + r"\b")
_AUX = re.compile(r"\b" + lx.forms(*[a for a in lx.AUXILIARY if " " not in a]) + r"\b")
_SUBJECT = set(lx.SUBJECT_WORDS)


@dataclass(frozen=True)
class _Reading:
    kind: str | None  # a kind, "unknown", "rest" or None (no action)
    unknown: str | None = None
    details: tuple = ()


_MANNER = re.compile(r"\b(?:like|as if|as though|similar to|imitating a|in the style of)\b.*$")


def _classify(norm: str) -> _Reading:
    """What a normalised clause asks for. Manner ("like a drunk", "as if ...") is read only when
    the rest of the clause names no action."""
    bare = _MANNER.sub("", norm).strip()
    if bare and bare != norm:
        got = _classify_words(bare)
        if got.kind not in (None, "rest"):
            return got
    return _classify_words(norm)


_IN_THE_AIR = re.compile(r"\b(?:in the air|mid ?air|while jumping)\b")
_RUN = re.compile(r"\b" + lx.forms("run", "ran", "jog", "sprint") + r"\b")


def _classify_words(norm: str) -> _Reading:
    if (m := lx.REST_PATTERN.match(norm)) is not None and m.start() == 0 and not norm.startswith("stand"):
        return _Reading("rest")  # "stops after five steps": the end of what came before
    if _ARMS_DOWN.match(norm) and re.search(
        r"\b(?:lower|lowers|lowering|lowered|drop|drops|dropping|dropped|sink|down)\b", norm
    ):
        return _Reading("rest")
    for name, pat in _STRONG_UNKNOWN:
        if pat.search(norm):
            return _Reading(UNKNOWN, name, tuple(_details(UNKNOWN, norm, name).items()))
    for entry in lx.KINDS:
        if entry.pattern.search(norm):
            kind = entry.kind
            if kind == "turn" and (m := _RUN.search(norm)):  # "runs in a curve": run's variants turn
                kind = "jog" if m.group(0).startswith("jog") else "run"
            if kind in ("turn", "turn_around") and _IN_THE_AIR.search(norm):
                return _Reading(UNKNOWN, "turn in the air")
            return _Reading(kind, None, tuple(_details(kind, norm).items()))
    for name, pat in _WEAK_UNKNOWN:
        if pat.search(norm):
            return _Reading(UNKNOWN, name, tuple(_details(UNKNOWN, norm, name).items()))
    if lx.REST_PATTERN.search(norm):
        return _Reading("rest")
    if _MOTION.search(norm):
        return _Reading(UNKNOWN, None, tuple(_details(UNKNOWN, norm).items()))
    return _Reading(None)


def _looks_like_a_verb(norm: str) -> bool:
    """After a subject, a word in -s or -ing that is no auxiliary ("a person wobbles"): a verb
    the lexicon does not list, so an action the models do not know."""
    words = [w for w in norm.split() if not _ADVERB.fullmatch(w)]
    if not words or _AUX.fullmatch(words[0]):
        words = words[1:]
    return bool(words) and bool(re.fullmatch(r"[a-z]{3,}(?:[^s']s|ing)", words[0])) and not _AUX.fullmatch(words[0])


def _starts_with_verb(norm: str) -> bool:
    """Does the piece begin, after its subject, pronouns and adverbs, with a verb (or a phrase
    of the lexicon)?"""
    words = norm.split()
    i = 0
    while i < len(words) and (
        words[i] in _SUBJECT
        or words[i] in lx.PRONOUNS
        or words[i] in _DETERMINERS
        or _ADVERB.fullmatch(words[i])
        or _AUX.fullmatch(words[i])
        or words[i] in ("to", "not", "again")
    ):
        i += 1
    rest = " ".join(words[i:])
    if not rest:
        return False
    first = words[i]
    if _MOTION.fullmatch(first) or lx.REST_PATTERN.match(rest) or first.endswith("ing"):
        return True
    if any((m := p.search(rest)) is not None and m.start() == 0 for _, p in lx.UNKNOWN_PATTERNS):
        return True
    return any(
        (m := k.pattern.search(rest)) is not None and m.start() == 0 and _MOTION.search(m.group(0)) for k in lx.KINDS
    )


# "then to the right", "and another two steps": a clause whose verb is the previous one's
_ELLIPSIS = re.compile(r"^(?:(?:\d+|a|one|another|1)\s+(?:\w+\s+)?steps?\b|(?:\w+\s+){0,2}to the (?:left|right)\b)")
# lowering the arms after raising them, "lets them sink": the end of the action
_ARMS_DOWN = re.compile(
    r"^(?:\w+ly )?" + lx.forms("lower", "drop", "let", "bring", "brought", "put", "take", "took") + r" (?:\w+ ){0,3}"
    r"(?:arms?|hands?|them|it)\b(?: \w+){0,3}? ?(?:down|sink|again|to (?:his|her|its|their|the) sides?)?$"
)


@cache
def _takes() -> dict[str, dict[str, object]]:
    """What each kind's catalogue entry takes: side / direction / angle values, count, speed, amplitude."""
    from .actions import CATALOGUE

    out: dict[str, dict[str, object]] = {}
    for kind, c in CATALOGUE.items():
        vals: dict[str, set] = {"side": set(), "direction": set(), "angle": set()}
        for v in c["variants"]:
            for k in vals:
                if k in v:
                    vals[k].add(v[k])
        out[kind] = {**vals, "count": bool(c.get("count")), "speed": bool(c.get("speed")), "amp": bool(c.get("amp"))}
    out["mocap:bye"] = {
        "side": {"left", "right", "both"},
        "direction": set(),
        "angle": set(),
        "count": False,
        "speed": False,
        "amp": False,
    }
    return out


_LR = r"(left|right)"
_LR_WAY = r"(left|right)\b(?! (?:foot|feet|leg|legs|hand|hands|arm|arms|knee|knees|food|fist|shoulder|heel|toe))"
_COUNTED = (
    r"steps?|strides?|circles?|rounds?|laps?|jumps?|kicks?|punch(?:es)?|squats?|claps?|waves?|hops?|"
    r"jumping jacks?|repetitions?|reps?|times?|jabs?|lunges?"
)


_LOCOMOTION = {"walk", "jog", "run", "walk_backward", "sidestep", "turn", "circle", "turn_around"}
_LIMB_WORD = r"(?:hand|hands|arm|arms|leg|legs|foot|feet|knee|knees|fist|fists|shoulder|elbow|wrist|heel|hip|toe)"


def _side(n: str, allowed: set | None) -> str | None:
    """The limb the words name: left / right / both ("both arms", "his hands", "the knees")."""
    lr = re.search(rf"\b{_LR} (?:\w+ )?{_LIMB_WORD}\b", n) or re.search(rf"\b{_LIMB_WORD} (?:\w+ )?{_LR}\b", n)
    if lr is None and not re.search(rf"\b{_LR} side\b|\bto the {_LR}\b|\b(?:from|on) the {_LR}\b", n):
        lr = re.search(rf"\b{_LR}\b", n)
    both = re.search(r"\bboth\b|\b2 (?:hands|arms|legs|feet)\b|\b(?:hands|arms|knees|fists)\b", n)
    if both and not (lr and re.search(rf"\b{_LR} (?:\w+ )?(?:hand|arm|leg|foot|knee|fist)\b(?!s)", n)):
        side = "both"
    else:
        side = lr.group(1) if lr else None
    return side if side and (allowed is None or side in allowed) else None


def _direction(n: str, dirs: set) -> str | None:
    """The way the words say (only direction words count)."""
    d = None
    if dirs == {"backward"}:
        return "backward"
    if {"cw", "ccw"} & dirs:
        if re.search(r"\bccw\b", n):
            return "ccw"
        if re.search(r"\bcw\b", n):
            return "cw"
        m = re.search(rf"\b{_LR_WAY}", n)
        return ("ccw" if m.group(1) == "left" else "cw") if m else None
    if m := re.search(rf"\bdiagonal\w*(?: \w+){{0,3}} {_LR}\b|\b{_LR} diagonal", n):
        side = m.group(1) or m.group(2)
        d = f"forward-{side}" if f"forward-{side}" in dirs else side
    elif m := re.search(rf"\bforwards? and (?:\w+ )?(?:to the )?{_LR}\b", n):
        side = m.group(1)
        d = f"forward-{side}" if f"forward-{side}" in dirs else side
    elif m := re.search(rf"\b{_LR_WAY}", n):
        d = m.group(1)
    elif re.search(r"\bccw\b", n):
        d = "left"
    elif re.search(r"\bcw\b", n):
        d = "right"
    elif re.search(r"\bbackwards?\b|\bin reverse\b|\bto the (?:back|rear)\b", n):
        d = "backward"
    elif re.search(r"\bforwards?\b|\bahead\b|\bstraight\b|\bto the front\b", n):
        d = "forward"
    return d if d in dirs else None


def _count(n: str) -> int | None:
    """Repetitions the words give: "twice", "3 times", "4 steps", "a step", "3 kicks"."""
    if m := re.search(r"\b(once|twice|thrice)\b", n):
        return lx.COUNT_WORDS[m.group(1)]
    if m := re.search(rf"\b(\d+) (?:\w+ )?(?:{_COUNTED})\b", n):
        return int(m.group(1))
    if re.search(r"\b(?:a|1|single) (?:\w+ )?(?:step|jump|kick|punch|hop|squat|wave)\b(?!s)", n):
        return 1
    return None


def _details(kind: str, n: str, unknown: str | None = None) -> dict:
    """Side, direction, count, angle, speed and amplitude where the words give them, for the
    fields the kind's catalogue entry takes (an unknown action: side and direction)."""
    t = _takes().get(kind)
    out: dict[str, object] = {}
    if kind == UNKNOWN:
        if unknown == "being pushed":  # the way the push moves the body
            if m := re.search(rf"\bfrom (?:the |his |her |its |their )?{_LR}\b", n):
                out["direction"] = "left" if m.group(1) == "right" else "right"
            elif re.search(r"\bfrom (?:the )?(?:behind|back|rear)\b", n):
                out["direction"] = "forward"
            elif re.search(r"\bfrom (?:the )?front\b|\bpushed back|\bbackwards?\b", n):
                out["direction"] = "backward"
            if m := re.search(rf"\b{_LR} shoulder\b", n):
                out["side"] = m.group(1)
            return out
        if side := _side(n, {"left", "right", "both"}) if re.search(rf"\b{_LIMB_WORD}\b", n) else None:
            out["side"] = side
        elif d := _direction(n, {"forward", "backward", "left", "right"}):
            out["direction"] = d
        return out
    if t is None:
        if kind == "mocap:bye" and (side := _side(n, {"left", "right", "both"})):
            out["side"] = side
        return out
    if t["side"] and (side := _side(n, t["side"] | ({"both"} if kind == "kneel" else set()))):
        out["side"] = side
    if t["direction"]:
        dirs = set(t["direction"])
        if kind in ("turn", "turn_around"):
            dirs |= {"left", "right"}
        if d := _direction(n, dirs):
            out["direction"] = d
    if kind in ("turn", "turn_around"):
        if m := re.search(r"\b(\d+) ?(?:degrees?|deg)\b", n):
            out["angle"] = int(m.group(1))
        elif re.search(r"\bquarter\b", n):
            out["angle"] = 90
        elif re.search(r"\bhalf\b|\baround\b|\bu turn\b|\babout (?:face|turn)\b", n):
            out["angle"] = 180
    if (c := _count(n)) is not None and (t["count"] or kind in _LOCOMOTION):
        out["count"] = c
    if re.search(r"\bslow\w*|\bleisurely\b|\bcasual\w*", n):
        out["speed"] = "slow"
    elif re.search(r"\bfast\w*|\bquick\w*|\bbrisk\w*|\brapid\w*|\bhurr\w*|\bsprint\w*", n):
        out["speed"] = "fast"
    if t["amp"] and re.search(r"\bhigh\b", n):
        out["amplitude"] = "high"
    return out


def _has_subject(words: str) -> bool:
    toks = normalise(words).split()
    for w in toks[:4]:
        if w in _SUBJECT:
            return True
        if w not in _DETERMINERS and not re.fullmatch(r"\w+(?:ly|ed|y)|old|young|tall|big|small|little", w):
            return False
    return False


_SUBJECT_RE = re.compile(
    r"^\s*(?:(?:a|an|the|this|that|some|our|my)\s+(?:[A-Za-z]+\s+){0,2}?)?(?:" + "|".join(lx.SUBJECT_WORDS) + r")\b\s*",
    re.IGNORECASE,
)


def _subject_of(words: str) -> str | None:
    """The clause's leading subject ("A person", "the tired man", "he"), or None."""
    m = _SUBJECT_RE.match(words)
    return m.group(0).strip() if m else None


def _without_subject(words: str) -> str:
    subject = _subject_of(words)
    rest = words[len(words) - len(words.lstrip()) + len(subject) :].strip() if subject else words.strip()
    rest = re.sub(r"^(?:is|are|was)\s+", "", rest, flags=re.IGNORECASE)
    return rest or words.strip()


def _only_joiners(gap: str) -> bool:
    words = [w for w in _TOKEN.findall(gap.lower()) if w not in _COMMA]
    return len(words) <= 4


# --------------------------------------------------------------------------------- reading
@dataclass
class _Draft:
    start: int
    end: int
    sentence: int
    markers: set[str]
    cls: _Reading
    norm: str
    first_in_sentence: bool
    extra: list[tuple[int, int]] = field(default_factory=list)  # merged spans not classified


def read_prompt(text: str) -> Reading:
    """The prompt's clauses in the order they happen; see the module's docstring."""
    text = text or ""
    drafts: list[_Draft] = []
    for p in _pieces(text):
        norm = normalise(_without_subject(p.text))
        cls = _classify(norm)
        if cls.kind is None and _subject_of(p.text) and _looks_like_a_verb(norm):
            cls = _Reading(UNKNOWN, None, tuple(_details(UNKNOWN, norm).items()))
        prev = drafts[-1] if drafts and drafts[-1].sentence == p.sentence else None
        if (
            prev is not None
            and prev.cls.kind not in (None, "rest")
            and p.markers & {"seq", "and", "comma"}
            and not _starts_with_verb(norm)
            and _ELLIPSIS.match(norm)
        ):
            # the previous clause's action again, with these words' own details
            kind = prev.cls.kind
            again = _classify(norm).kind
            if kind in _LOCOMOTION and again in _LOCOMOTION:
                kind = again
            if kind == UNKNOWN:
                cls = _Reading(UNKNOWN, prev.cls.unknown, tuple(_details(UNKNOWN, norm, prev.cls.unknown).items()))
            else:
                cls = _Reading(kind, None, tuple(_details(kind, norm).items()))
            drafts.append(_Draft(p.start, p.end, p.sentence, set(p.markers) | {"seq"}, cls, norm, False))
            continue
        soft = not (p.markers & {"seq", "with", "while", "before", "after"}) and bool(
            p.markers & {"and", "comma", "as", "or"}
        )
        joins = prev is not None and (
            cls.kind is None
            or "until" in p.markers
            or "or" in p.markers
            or (soft and not _starts_with_verb(norm))
            or (cls.kind == "rest" and prev.cls.kind not in (None, "rest"))
        )
        if joins and prev is not None:
            prev.end = p.end
            generic = prev.cls.kind is None or (prev.cls.kind == UNKNOWN and prev.cls.unknown is None)
            hedge = bool(p.markers & {"until", "or"})
            if cls.kind is not None and not hedge and cls.kind != "rest" and generic:
                prev.norm = f"{prev.norm} {norm}"
                prev.cls = _classify(prev.norm)
            elif not hedge and cls.kind not in ("rest",):
                prev.norm = f"{prev.norm} {norm}"
                # the merged words refine the clause they join: its details (side, count), or a more
                # specific way of moving ("walks a quarter, left-sided circle")
                if prev.cls.kind not in (None, UNKNOWN, "rest"):
                    kind = prev.cls.kind
                    again = _classify(prev.norm).kind
                    if (
                        "and" not in p.markers
                        and kind in _LOCOMOTION
                        and again in _LOCOMOTION
                        and _kind_rank(again) < _kind_rank(kind)
                    ):
                        kind = again
                    prev.cls = _Reading(kind, None, tuple(_details(kind, prev.norm).items()))
                    if kind in ("turn", "turn_around") and _IN_THE_AIR.search(prev.norm):
                        prev.cls = _Reading(UNKNOWN, "turn in the air")
            continue
        # a leading piece with no action (a bare subject) joins the next one
        if prev is not None and prev.cls.kind is None:
            prev.end = p.end
            prev.norm = f"{prev.norm} {norm}"
            prev.cls = cls
            prev.markers |= p.markers
            continue
        drafts.append(_Draft(p.start, p.end, p.sentence, set(p.markers), cls, norm, prev is None))
    # a rest clause alone in its sentence with no action anywhere is an unknown ("stand still")
    has_action = any(d.cls.kind not in (None, "rest") for d in drafts)
    clauses_d = [d for d in drafts if d.cls.kind is not None and (d.cls.kind != "rest" or not has_action)]
    clauses_d = _merge_corpus_phrasings(clauses_d)
    subject = None
    for d in drafts:
        if (subject := _subject_of(text[d.start : d.end])) is not None:
            break
    posture = _starting_posture(subject)
    clauses: list[Clause] = []
    for d, together in _merge_together(_order(_drop_glances(clauses_d))):
        start, end = _trim(text, d.start, d.end)
        words = text[start:end]
        det = dict(d.cls.details)
        together = together and bool(clauses)
        kind = d.cls.kind
        if kind == "rest":
            clauses.append(Clause(UNKNOWN, words, start, end, together, unknown="stand still"))
        elif kind == UNKNOWN:
            clauses.append(
                Clause(UNKNOWN, words, start, end, together, unknown=d.cls.unknown or _without_subject(words), **det)
            )
        else:
            moved = any(c.kind in ("kneel", "sit_down", "lie_down", "stand_up", "get_up") for c in clauses)
            here = posture or _starting_posture(text[: d.start] + " " + text[d.start : d.end].split(" stand")[0])
            if kind in ("stand_up", "get_up") and here == "kneeling" and not moved:
                clauses.append(Clause(UNKNOWN, words, start, end, together, unknown="stand up from kneeling"))
                continue
            if kind == "stand_up" and here == "lying" and not moved:
                kind = "get_up"
            clauses.append(Clause(kind, words, start, end, together, **_fit(kind, det)))
    return Reading(text, tuple(_after_neighbours(clauses)), subject)


def _drop_glances(drafts: list[_Draft]) -> list[_Draft]:
    """A glance while doing something ("while looking at his feet") is the action's manner,
    not a step of its own."""
    out = []
    for i, d in enumerate(drafts):
        if d.cls.kind == UNKNOWN and d.cls.unknown == "look around" and d.markers & {"while", "with"}:
            near = [x for x in drafts[max(0, i - 1) : i + 2] if x is not d and x.sentence == d.sentence]
            if any(x.cls.kind not in (None, "rest", UNKNOWN) for x in near):
                continue
        out.append(d)
    return out


_BACK = re.compile(r"\b(?:back|returns?|returning|returned)\b")
_REVERSE = re.compile(r"\b(?:backwards?|reverse|rear)\b")
_OTHER = {"left": "right", "right": "left"}


def _after_neighbours(clauses: list[Clause]) -> list[Clause]:
    """What "back" means depends on the clause before: after a sidestep, going back is a
    sidestep the other way; between forward walks, a step back is a walk backwards; after a
    turn, walking back is walking (the way the body now faces)."""
    out: list[Clause] = []
    for c in clauses:
        prev = out[-1] if out else None
        n = normalise(c.words)
        if prev is not None and c.kind in ("walk", "walk_backward") and _BACK.search(n):
            if prev.kind == "sidestep":
                direction = _OTHER.get(prev.direction or "") if c.direction is None else c.direction
                c = Clause("sidestep", c.words, c.start, c.end, c.with_previous, direction=direction, count=c.count)
            elif prev.kind in ("turn", "turn_around") and c.kind == "walk_backward" and not _REVERSE.search(n):
                c = Clause("walk", c.words, c.start, c.end, c.with_previous, count=c.count, speed=c.speed)
            elif (
                prev.kind == "walk"
                and c.kind == "walk"
                and re.search(r"\b(?:go|goes|went|move|moves|moved|step|steps|stepped)\b(?: \w+)? back\b", n)
                and not re.search(r"\bback (?:to|on|onto|into|in)\b", n)
            ):
                c = Clause(
                    "walk_backward",
                    c.words,
                    c.start,
                    c.end,
                    c.with_previous,
                    direction="backward",
                    count=c.count,
                    speed=c.speed,
                )
        out.append(c)
    return out


def _fit(kind: str, det: dict) -> dict:
    """Details re-read for a kind that changed in a merge (only the fields it takes)."""
    t = _takes().get(kind)
    if t is None:
        return {k: v for k, v in det.items() if k == "side"}
    keep = {"speed", "count"}
    keep |= {"side"} if t["side"] else set()
    keep |= {"direction"} if t["direction"] else set()
    keep |= {"angle"} if kind in ("turn", "turn_around") else set()
    keep |= {"amplitude"} if t["amp"] else set()
    return {k: v for k, v in det.items() if k in keep}


def _starting_posture(subject: str | None) -> str | None:
    """ "A kneeling person ...", "a person lying on the floor ...": where the motion starts."""
    n = normalise(subject or "")
    if re.search(r"\bkneel|\b(?:on|from) (?:his|her|its|their|the|both|2) knees\b", n):
        return "kneeling"
    if re.search(r"\b(?:lying|laying)\b", n):
        return "lying"
    return None


def _kind_rank(kind: str) -> int:
    return next((i for i, k in enumerate(lx.KINDS) if k.kind == kind), len(lx.KINDS))


def _remake(d: _Draft, other: _Draft, kind: str) -> _Draft:
    norm = f"{d.norm} {other.norm}"
    start, end = min(d.start, other.start), max(d.end, other.end)
    return _Draft(
        start,
        end,
        d.sentence,
        d.markers,
        _Reading(kind, None, tuple(_details(kind, norm).items())),
        norm,
        d.first_in_sentence,
    )


def _merge_corpus_phrasings(drafts: list[_Draft]) -> list[_Draft]:
    """The corpus's own phrasings of one kind that read as two clauses (``lexicon.AND_PHRASINGS``:
    "walks and turns left" is one ``turn``; with "then" or a comma it stays two), and a bare "turns" followed by "walks
    back" (a ``turn_around``)."""
    out: list[_Draft] = []
    for d in drafts:
        prev = out[-1] if out else None
        if (
            prev is not None
            and prev.sentence == d.sentence
            and (prev.cls.kind, d.cls.kind) in lx.AND_PHRASINGS
            and d.markers == {"and"}
        ):
            out[-1] = _remake(prev, d, lx.AND_PHRASINGS[(prev.cls.kind, d.cls.kind)])
            continue
        if (
            prev is not None
            and prev.cls.kind == "turn"
            and d.cls.kind == "walk"
            and re.search(r"\bback\b", d.norm)
            and dict(prev.cls.details).get("angle") in (None, 180)
        ):
            prev.cls = _Reading("turn_around", None, tuple(_details("turn_around", prev.norm).items()))
        out.append(d)
    return out


def _merge_together(items: list[tuple[_Draft, bool]]) -> list[tuple[_Draft, bool]]:
    """Two ways of moving at once are one kind: "walks while turning right" is one ``turn``,
    "walks backwards while drifting left" one ``walk_backward`` (the more specific kind wins);
    turning during a jump is "turn in the air", which the corpus lacks."""
    out: list[tuple[_Draft, bool]] = []
    for d, together in items:
        if together and out:
            prev, ptog = out[-1]
            a, b = prev.cls.kind, d.cls.kind
            if a in _LOCOMOTION and b in _LOCOMOTION:
                kind = min((a, b), key=_kind_rank)
                if {a, b} == {"walk", "turn_around"} or {a, b} == {"walk", "turn"}:
                    kind = "turn"
                out[-1] = (_remake(prev, d, kind), ptog)
                continue
            if {a, b} <= {"jump_up", "jump_forward", "turn", "turn_around"} and a != b:
                jump, turn = (prev, d) if a.startswith("jump") else (d, prev)
                turn.cls = _Reading(UNKNOWN, "turn in the air", ())
                out[-1] = (jump, ptog)
                out.append((turn, True))
                continue
        out.append((d, together))
    return out


def _order(drafts: list[_Draft]) -> list[tuple[_Draft, bool]]:
    """Drafts in the order they happen, each with whether it runs with the previous one.

    "X while Y": the ongoing Y first, X with it. "While Y, X": the same. "X at the same time
    Y": X, Y with it. "Before B, A" and "A after B": A / B first."""
    together = {"with", "while"}
    items = [[d, bool(d.markers & together) and not d.first_in_sentence] for d in drafts]
    for i, (d, _) in enumerate(items):
        if (
            d.first_in_sentence
            and d.markers & together
            and i + 1 < len(items)
            and items[i + 1][0].sentence == d.sentence
        ):
            items[i + 1][1] = True
    i = 0
    while i < len(items):
        d = items[i][0]
        nxt = items[i + 1][0] if i + 1 < len(items) else None
        same = i > 0 and items[i - 1][0].sentence == d.sentence
        if "while" in d.markers and not d.first_in_sentence and same and not items[i - 1][1]:
            items[i - 1], items[i] = [d, False], [items[i - 1][0], True]
        elif "before" in d.markers and d.first_in_sentence and nxt is not None and nxt.sentence == d.sentence:
            # "Before B, A": A (with its together-clauses) happens first
            j = i + 1
            while j + 1 < len(items) and items[j + 1][1] and items[j + 1][0].sentence == d.sentence:
                j += 1
            block = items[i + 1 : j + 1]
            block[0][1] = False
            items[i : j + 1] = [*block, [d, False]]
            i = j + 1
            continue
        elif "after" in d.markers and not d.first_in_sentence and same:
            # "A after B": B happens first
            items[i - 1], items[i] = [d, False], [items[i - 1][0], False]
        i += 1
    return [(d, w) for d, w in items]


def _trim(text: str, start: int, end: int) -> tuple[int, int]:
    """The span without leading joining words and trailing punctuation."""
    span = text[start:end]
    lead = re.match(
        r"^(?:\s|,|and\b|then\b|but\b|after that\b|afterwards\b|finally\b|next\b|while\b|whilst\b|before\b|after\b)*",
        span,
        re.IGNORECASE,
    )
    s = start + (lead.end() if lead else 0)
    e = end
    while e > s and text[e - 1] in " ,.;:!?":
        e -= 1
    return s, e


# --------------------------------------------------------------------------- nearest action
def _title(kind: str, details: dict) -> str:
    entry = next((k for k in lx.KINDS if k.kind == kind), None)
    title = entry.title if entry else kind.replace("_", " ")
    side = details.get("side")
    direction = details.get("direction")
    direction = {"cw": "clockwise", "ccw": "counter-clockwise"}.get(direction, direction)
    if direction and direction.startswith("forward-"):
        direction = "diagonally " + direction.split("-")[1]
    if side:
        title = title.replace("{side}", "both" if side == "both" else side)
        if side == "both":
            title = re.sub(r"\bthe both (\w+?)s?\b", r"both \1s", title)
    else:
        title = title.replace("the {side}", "one").replace("to the {side}", "")
    if direction:
        title = title.replace(
            "{direction}",
            direction
            if direction in ("forward", "backward", "clockwise", "counter-clockwise")
            or direction.startswith("diagonally")
            else f"to the {direction}",
        )
    else:
        title = re.sub(r"\s*(?:to the )?\{direction\}", "", title)
    return title.replace("{side}", "").replace("{direction}", "").strip()


def _nearest(texts: list[str]) -> list[tuple[str | None, str | None]]:
    """For each text, the nearest known action (kind, a phrase for people): the phrasebook's
    nearest training caption, read by the reader itself."""
    if not texts:
        return []
    from .prompt_guide import get_phrasebook

    book = get_phrasebook()
    out: list[tuple[str | None, str | None]] = []
    for row in book.similarities(texts):
        out.append(_known_action(book.captions[int(row.argmax())]))
    return out


def _known_action(caption: str) -> tuple[str | None, str | None]:
    c = next((c for c in read_prompt(caption).clauses if c.known), None)
    if c is None:
        return None, None
    return c.kind, _title(c.kind, {"side": c.side, "direction": c.direction})


def check_prompt(text: str) -> PromptCheck:
    """The warning before generation: which parts of the prompt the models do not know (with
    the nearest known action), or that nothing in it is an action they know."""
    from .prompt_guide import get_phrasebook

    reading = read_prompt(text)
    flat = " ".join((text or "").split())
    guide = get_phrasebook().guide(flat) if flat else None
    unfamiliar = bool(guide and guide.unfamiliar)
    parts = reading.unknown_parts
    no_action = not reading.clauses
    nothing_known = not any(c.known for c in reading.clauses)
    if unfamiliar and nothing_known:
        parts = ()  # unlike anything the models know, as a whole: say so rather than name parts
    messages = [u.message for u in parts]
    if (no_action or unfamiliar) and not parts and flat:
        near = _known_action(guide.nearest[0].caption)[1] if guide and guide.nearest else None
        hint = f" (nearest: {near})" if near else ""
        messages.append(f"The models have not learned anything like '{flat}'{hint}")
    warn = bool(flat) and (bool(parts) or no_action or unfamiliar)
    return PromptCheck(text, warn, tuple(messages), parts, unfamiliar, no_action and bool(flat), reading)
