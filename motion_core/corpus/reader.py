"""Read a whole prompt: its clauses in the order they happen, which corpus action each asks
for (or that the models do not know it), and a timeline plan of the user's own words.

    r = read_prompt("A person walks forward while waving, then picks up a box. Before sitting down, he bows.")
    [c.kind for c in r.clauses]      # ['wave', 'walk', 'unknown', 'bow', 'sit_down']
    r.unknown_parts[0].message       # "The models have not learned 'picks up a box' (nearest: ...)"
    r.plan()                         # [Segment('A person walks forward while waving', 5.8), ...]
    check_prompt(text)               # the warning to show before generation

How it reads (rules over a small parse, no model download, no network; docs/prompt-reader.md
lists every rule):

1. *Split.* The text is cut into pieces at sentence ends, commas and joining words
   (``lexicon.SEQUENCE_WORDS`` "then", "after that", "and"...; ``TOGETHER_WORDS`` "while",
   "meanwhile", "during that"...; ``CAUSE_WORDS`` "due to", "because of"; "before", "after",
   "until"), and inside a piece where a second clause starts with no joining word
   (:func:`_split_points`: a second finite verb, a new subject with its verb, a finite verb
   after a participle in the subject, "to" with a verb of purpose, an -ing after a whole verb
   phrase). A piece that says no action joins the clause before it; after "and", a comma or
   "as" a piece must start with a verb to be a clause of its own, unless it repeats the
   previous clause's verb with a way, a side or a count ("then backward", "one back", "and
   forward again" after "walks forward"; a way joined by "and" only when it is the opposite).
2. *Order.* "While", "at the same time", "meanwhile", "by doing" make a clause run together
   with the previous one; "Before B, A", "A after B" and "A because of B" put B second /
   first, so clauses come in the order they happen.
3. *Classify.* Each clause's normalised words are matched against the lexicon: first the
   specific unknown actions (``lexicon.STRONG``: "picks up", "push ups", "climbs stairs"),
   then the corpus's kinds (``lexicon.KINDS``, most specific first), then the weak unknowns
   (``lexicon.WEAK``: touch, hold, lean...), then any verb of bodily motion
   (``lexicon.MOTION_VERBS``): a clause with a motion verb that matches no kind is unknown,
   named by its own words. "Stops" after an action, landing after a jump and recovering
   after a push are its end, not clauses. Side, direction, angle and count are read only for
   kinds whose catalogue variants take them.
4. *Nearest known action.* For an unknown clause, ``lexicon.NEAREST`` or the frozen sentence
   encoder's nearest phrasebook caption (``prompt_guide``) names the closest kind, worded by
   the lexicon's title ("reach forward with the right hand").
5. *Plan.* One segment per sequential clause, together-clauses in the same segment; its text
   is the user's own words for those clauses, with a left-out verb put back from the clause it
   repeats and the clause's sentence's subject in front when the words have none (a gerund or
   bare verb after it inflected: "sitting down" -> "he sits down"); its seconds from the
   shipped length estimator.

The warning (:func:`check_prompt`) fires when any clause is unknown, when no clause names an
action, or when the phrasebook finds the whole prompt unfamiliar (gibberish, unrelated
sentences: ``prompt_guide``'s calibrated threshold).
"""

from __future__ import annotations

import itertools
import re
from dataclasses import asdict, dataclass, field, replace
from functools import cache, cached_property, lru_cache

from . import lexicon as lx
from .spelling import correct, correct_word

UNKNOWN = "unknown"


# ------------------------------------------------------------------------------ normalising
def _word_map(mapping: dict[str, object]) -> re.Pattern:
    keys = sorted(mapping, key=len, reverse=True)
    return re.compile(r"\b(?:" + "|".join(re.escape(k) for k in keys) + r")\b")


_SPELL = _word_map(lx.SPELLING)
_NUM = _word_map(lx.NUMBERS)
_CCW = re.compile(r"\b(?:counter ?clock ?wise|anti ?clock ?wise|contra ?clock ?wise|against (?:the )?clock ?wise)\b")
_CW = re.compile(r"\bclock ?wise\b")
# the seams of words run together: "CasualWalk", "TPose", "Walk8", "Kicking001"
_RUN_TOGETHER = re.compile(r"(?<=[a-z])(?=[A-Z])|(?<=[A-Z])(?=[A-Z][a-z])|(?<=[A-Za-z])(?=\d)|(?<=\d)(?=[A-Za-z])")


@lru_cache(maxsize=8192)
def normalise(text: str) -> str:
    """Lower case, hyphens and slashes as spaces, only letters, digits and spaces; misspelt
    motion words put right (``spelling``) and a few seen misspellings fixed; number words as
    digits; counter-clockwise (or "against the clockwise") as ``ccw``, clockwise as ``cw``;
    "leftwards" as "to the left"; words run together in CamelCase or with digits ("DrunkWalk",
    "Walk8", as trial names are written) apart."""
    t = _RUN_TOGETHER.sub(" ", text).lower().replace("’", "'")
    t = re.sub(r"(\w)-like\b", r"\1like", t)  # "ballet-like": one word, no manner clause
    t = re.sub(r"[-_/]", " ", t)
    t = re.sub(r"[^a-z0-9' ]+", " ", t)
    t = correct(" ".join(t.split()))
    t = _SPELL.sub(lambda m: lx.SPELLING[m.group(0)], t)
    t = _NUM.sub(lambda m: str(lx.NUMBERS[m.group(0)]), t)
    t = re.sub(r"\b(\d+) and a half\b", r"\1", t)
    t = _CCW.sub("ccw", t)
    t = _CW.sub("cw", t)
    t = re.sub(r"\b(left|right)(?:wards?|ward)\b(?= (?:circle|curve|turn|bend|arc|loop|half|quarter))", r"\1", t)
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
    restored: for a clause whose words leave out the verb they share with the clause before
    ("then backward" after "runs forward"), its words with that verb, as the user wrote it, put
    back ("runs backward"); None otherwise. The plan uses it.
    subject: the subject its words leave out, in the user's words (its sentence's, else the
    text's first), or None when its words have one.
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
    restored: str | None = None
    subject: str | None = None

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


_PLURAL = {"they", "people", "persons", "men", "women", "humans", "we", "you"}


def _finite(words: str, plural: bool = False) -> str:
    """A clause that starts with a gerund or a bare verb ("Before sitting down", "to pick up a
    coin"), as the verb after a subject: "sitting down" -> "sits down", "being pushed" -> "is
    pushed", "pick up" -> "picks up". Other words are left as they are."""
    m = re.match(r"\s*([A-Za-z]+)\b", words)
    if m is None:
        return words
    w = m.group(1).lower()
    if w in _ING_TO_THIRD:
        base = _ING[w]
        new = {"be": "are"}.get(base, base) if plural else _ING_TO_THIRD[w]
    elif w in _BASE and not plural and w not in _THIRD:
        new = _INFLECTED[w][1]
    else:
        return words
    return words[: m.start(1)] + new + words[m.end(1) :]


def _has_verb(words: str) -> bool:
    return any(w.lower() in _VERB_FORMS or w.lower() in _AUX_WORDS for w in _TOKEN.findall(words))


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
        """Each segment's text: the user's words for its clauses (the span from the first to the
        last when only joining words lie between them), a left-out verb put back ("runs
        backward" for "then backward"), and the subject in front when the words have none; a
        gerund then becomes the verb it names ("sitting down" -> "he sits down")."""
        texts = []
        for g in self.groups():
            ordered = sorted(g, key=lambda c: c.start)
            contiguous = all(_only_joiners(self.text[a.end : b.start]) for a, b in itertools.pairwise(ordered))
            if len(g) == 1 and g[0].restored:
                words = g[0].restored
            elif contiguous:
                start = ordered[0].start
                if len(g) > 1 and (m := re.search(r"\b(?:while|whilst|as|when)\s+$", self.text[:start], re.I)):
                    start = m.start()  # "While walking, he waves": the user's own sentence
                words = self.text[start : ordered[-1].end]
            else:
                words = " while ".join(c.words for c in g)
            if len(g) > 1 and contiguous and any(c.subject is None for c in ordered[1:]):
                texts.append(words)  # a later clause has its own subject: the words are a sentence
            else:
                texts.append(self._with_subject(words, ordered[0].subject))
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

    def _with_subject(self, words: str, subject: str | None = None) -> str:
        subject = subject or self.subject
        if not subject or _has_subject(words) or not _has_verb(words):
            return words  # "three steps" (after "After three steps"): no verb to give a subject
        plural = subject.lower().split()[-1] in _PLURAL
        return f"{subject} {_finite(words, plural)}"

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
# a word: lower case with one capital before it, or capitals alone, so that words run together in
# CamelCase ("DrunkWalk") are two tokens, as normalise reads them
_TOKEN = re.compile(r"\d+(?:[.,]\d+)+|\d+|[A-Z]?[a-z]+(?:['’][A-Za-z]+)?|[A-Z]+(?![a-z])(?:['’][A-Za-z]+)?|[.,;:!?()]")
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
for _w in lx.CAUSE_WORDS:
    _JOINERS[tuple(_w.split())] = "cause"
_JOINERS.update(
    {
        ("and", "at", "the", "same", "time"): "with",
        ("at", "the", "same", "time", "as"): "while",
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
        ("in", "order", "to"): "purpose",
        ("so", "as", "to"): "purpose",
        ("so", "that"): "until",
    }
)
_NOT_JOINERS = {("after", "a"), ("before", "the"), ("after", "the"), ("as", "if"), ("as", "though")}
# nouns of an action: "after a little hop", "before a deep bow" join as "after" / "before" do
_ACTION_NOUNS = {
    "hop", "jump", "turn", "kick", "punch", "squat", "bow", "push", "spin", "wave", "throw", "stumble",
    "sprint", "run", "jog", "walk", "lunge", "clap", "stretch", "dance", "pirouette", "somersault",
}  # fmt: skip
_MAXJ = max(len(k) for k in _JOINERS)
_DURATION_BEFORE = {"a", "short", "little", "long", "brief", "good", "small", "quite"}
_ADVERB = re.compile(
    r"\w+ly|also|still|now|just|again|back|once|immediately|quickly|then|too|even|first|therefore|thus|hence|"
    r"afterwards|soon|suddenly|slowly"
)
_DETERMINERS = {"a", "an", "the", "this", "that", "some"}
# where a "the" is a misspelt "then" (see _pieces): after a walk's last word, before an object or a way
_THE_TYPO_AFTER = {"step", "steps", "forward", "forwards", "ahead", "straight", "back", "backwards", "around",
                   "left", "right", "away", "down", "up"}  # fmt: skip
_THE_TYPO_BEFORE = {"a", "an", "the", "his", "her", "their", "its", "some", "around", "back", "left", "right",
                    "to", "up", "down", "again"}  # fmt: skip

# ------------------------------------------------------------------ verb forms, for splitting
_REST_VERBS = ("stop", "halt", "pause", "wait", "rest", "freeze", "froze")
_VERB_BASES = {v for v in {*lx.MOTION_VERBS, *(v for k in lx.KINDS for v in k.verbs)} if v.isalpha()} | set(_REST_VERBS)
_INFLECTED = {b: lx.inflect(b) for b in _VERB_BASES}
_THIRD = {f[1] for f in _INFLECTED.values()} | {"goes", "does"}  # walks, turns, goes: a finite verb
_ING = {f[3]: b for b, f in _INFLECTED.items()} | {"lying": "lie", "laying": "lay", "being": "be", "getting": "get"}
_ING_TO_THIRD = {
    ing: {"be": "is", "lie": "lies", "lay": "lays"}.get(b) or _INFLECTED.get(b, lx.inflect(b))[1]
    for ing, b in _ING.items()
}
_BASE = set(_VERB_BASES)
_AUX_WORDS = {"is", "are", "was", "were", "be", "been", "being", "has", "have", "had", "can", "could", "will",
              "would", "may", "might", "should", "must", "do", "did"}  # fmt: skip
_LIGHT = set(lx.LIGHT_VERBS) | {lx.inflect(v)[1] for v in lx.LIGHT_VERBS if v.isalpha()}
_TO_COMPLEMENT = set(lx.TO_COMPLEMENT)
_NUMBER_WORDS = {w for k in lx.NUMBERS for w in k.split()}
# words that open a noun phrase: a verb-looking word after them is its head noun ("a few steps")
_NP_OPEN = (
    {"a", "an", "the", "this", "that", "these", "those", "some", "any", "each", "every", "another", "other", "no"}
    | set(lx.PRONOUNS) - {"he", "she", "they", "it", "him", "them", "himself", "herself", "itself"}
    | {
        "my",
        "your",
        "our",
        "few",
        "several",
        "many",
        "more",
        "most",
        "multiple",
        "couple",
        "number",
        "lot",
        "lots",
        "series",
        "pair",
        "both",
        "all",
        "half",
        "quarter",
        "of",
        "to",
        "for",
        "with",
        "in",
        "on",
        "at",
        "by",
        "from",
        "into",
        "onto",
        "about",
        "like",
        "than",
        "as",
        "per",
        "without",
        "toward",
        "towards",
        "during",
        "via",
        "upon",
        "within",
        "near",
    }
    | _NUMBER_WORDS
)
# words that keep a noun phrase open before its head ("a few small running steps")
_ADJECTIVES = {
    "small", "big", "large", "long", "short", "quick", "slow", "fast", "little", "huge", "tiny", "high", "low",
    "single", "double", "sharp", "wide", "light", "heavy", "first", "second", "third", "last", "next", "final",
    "left", "right", "side", "forward", "backward", "sideways", "lateral", "diagonal", "full", "whole",
    "complete", "brief", "gentle", "slight", "deep", "giant", "normal", "regular", "consecutive", "rapid",
    "powerful", "strong", "soft", "hard", "tall", "additional", "further", "same", "different", "few", "couple",
    "quarter", "half", "very", "rather", "quite", "straight", "sudden", "awkward", "careful", "narrow", "simple",
    "odd", "strange", "weird", "funny", "good", "bad", "great", "steady", "extra", "bigger", "smaller", "larger",
    "longer", "shorter", "faster", "slower", "wider", "greater", "quicker", "higher", "lower",
}  # fmt: skip
_SUBJECT_NOUNS = set(lx.SUBJECT_WORDS) - set(lx.PRONOUNS)
_SUBJECT_WORDS = set(lx.SUBJECT_WORDS)


def _adjective(w: str) -> bool:
    if w.endswith("thing"):
        return False  # "something" is a noun
    return w in _ADJECTIVES or w.isdigit() or bool(re.fullmatch(r"\w{3,}(?:ing|ed|al|ful|ous|ive|ic|ish)", w))


# words after which an -ing form is no participle of its own ("starts walking", "is walking", "as if carrying")
_NO_ADJUNCT = (
    _NP_OPEN
    | _AUX_WORDS
    | _LIGHT
    | _TO_COMPLEMENT
    | {"if", "though", "like", "and", "or", "not", "without", "while", "keeps", "kept", "stops", "quits", "finishes",
       "ends", "resumes", "practices", "goes", "comes", "avoids", "gets", "got", "then"}
)  # fmt: skip
_ING_NOT_ACTION = {"starting", "beginning", "continuing", "trying", "keeping", "going", "getting", "being", "using",
                   "facing", "ending", "finishing", "stopping", "having", "leading", "following"}  # fmt: skip


def _third_after(toks: list[str], j: int) -> bool:
    """A finite action verb (not an auxiliary: "the place he was coming from") after adverbs."""
    while j < len(toks) and _ADVERB.fullmatch(toks[j]):
        j += 1
    return j < len(toks) and toks[j] in _THIRD


def _split_points(toks: list[str]) -> list[tuple[int, str]]:
    """Where one piece holds two clauses with no joining word: a second finite verb after a
    complete verb phrase ("walks forward turns around"), a new subject with its verb ("after
    three steps a woman sits down"), a finite verb after a participle in the subject ("a person
    getting shoved stumbles"), and "to" with a verb of purpose ("turns around to walk back").
    Returns (token index, marker) pairs."""
    out: list[tuple[int, str]] = []
    seen = finite = np_open = single = False
    # a verb phrase is complete (its object's head or its way was read): a bare verb after it can only
    # be the next clause with its -s left off ("walks two steps turn around")
    complete = False
    plural = any(t in _PLURAL for t in toks)

    def verb_after(j: int) -> bool:
        while j < len(toks) and _ADVERB.fullmatch(toks[j]):
            j += 1
        return j < len(toks) and (toks[j] in _THIRD or toks[j] in _AUX_WORDS - {"do", "did", "be", "been"})

    for i, w in enumerate(toks):
        prev = toks[i - 1] if i else ""
        if w == "like" or (w in ("if", "though") and prev == "as"):
            break  # what follows is a comparison, not a clause: "punches like he is boxing"
        was_complete, complete = complete, False
        if (
            was_complete
            and finite
            and not plural
            and w in _BASE
            and w not in _THIRD
            and (i + 1 >= len(toks) or toks[i + 1] not in ("by", "of", "and", "or"))
        ):
            out.append((i, "list"))
            np_open, single = w in _LIGHT, False
            continue
        if was_complete and (w in _WAY_WORDS or _ADVERB.fullmatch(w)):
            complete = True  # "two steps forward turn left": the way belongs to the phrase before
        # a new subject and its verb: "... a woman sits down", "... he turns"
        if i and prev not in _NP_OPEN and prev not in ("who", "that", "which"):
            if w in ("a", "an", "the", "this", "that") and i + 1 < len(toks) and toks[i + 1] in _SUBJECT_NOUNS:
                if verb_after(i + 2):
                    out.append((i, "list"))
                    seen = finite = np_open = False
                    continue
            elif (w in _SUBJECT_NOUNS or w in ("he", "she", "they")) and seen and _third_after(toks, i + 1):
                out.append((i, "list"))
                seen = finite = np_open = False
                continue
        if w in _THIRD:
            if not seen:
                seen = finite = True
                np_open, single = w in _LIGHT, False
            elif prev == "another" and i >= 2 and toks[i - 2] in ("to", "from", "into"):
                out.append((i, "list"))  # "from one point to another turns": the pronoun, then the verb
                finite = True
                np_open, single = w in _LIGHT, False
            elif (
                (np_open and not (single and prev in _BASE))
                or prev in _NP_OPEN
                or prev[:1].isdigit()
                or prev in (_AUX_WORDS | {"not", "who", "which", "and", "or"})
                # the object of a preposition: "walks down steps", "jumps over steps"
                or (w in _STEP_NOUNS and prev in _STEP_PREPOSITIONS)
            ):
                np_open = False  # the head noun of a phrase: "takes a few steps", "some dance steps"
                complete = finite
            else:
                out.append((i, "list" if finite else "participle"))
                finite = True
                np_open, single = w in _LIGHT, False
            continue
        if w in _ING:
            if np_open:
                continue  # "a running jump"
            if finite and prev not in _NO_ADJUNCT and w not in _ING_NOT_ACTION and _ING[w] not in _LIGHT:
                out.append((i, "adjunct"))  # "walks forward holding a cup": at the same time
                np_open, single = _ING[w] in _LIGHT, False
                continue
            seen = True
            # "is doing punches", "practicing waltz steps"; a gerund with no subject before it may
            # be a noun's modifier ("jumping twists")
            bare = not any(t in _SUBJECT_WORDS or t in ("is", "are", "was", "were") for t in toks[:i])
            np_open, single = _ING[w] in _LIGHT or bare, False
            continue
        if (
            w in ("is", "gets", "got", "was")
            and finite
            and prev not in _NP_OPEN
            and prev not in _AUX_WORDS | {"who", "that", "which", "and", "or", "then", "it", "he", "she"}
            and i + 1 < len(toks)
            and toks[i + 1] in _DONE_TO
        ):
            out.append((i, "list"))  # "walks forward is pushed back": a missing "and" before a new predicate
            continue
        if w in ("is", "are", "was", "gets", "got") and seen and not finite and prev not in _NP_OPEN:
            out.append((i, "participle"))  # "the person walking forward is pushed"
            finite = True
            continue
        if (
            w == "to"
            and seen
            and i + 1 < len(toks)
            and toks[i + 1] in _BASE
            and prev not in _TO_COMPLEMENT
            and not (prev in ("comes", "come", "came", "coming") and toks[i + 1] in _REST_VERBS)  # "comes to rest"
        ):
            if i + 2 >= len(toks) or toks[i + 2] not in ("of", "the"):
                out.append((i, "purpose"))
                np_open = False
                continue
        if w in _NP_OPEN or w[:1].isdigit():
            np_open = True
            single = w in ("a", "an", "one", "each", "every", "another")  # "a step turns": the noun was "step"
        elif np_open and (w in _BASE or w in _BODY_NOUNS or w in _ACTIVITY_NOUNS):
            pass  # a noun before the head: "some dance steps", "a jump kick", "does knee bends", "floor exercises"
        elif np_open and i + 1 < len(toks) and toks[i + 1] in _STEP_NOUNS:
            pass  # any word before a step noun modifies it: "a few recovery steps", "two stork steps"
        elif w in ("left", "right", "front", "back", "side") and i >= 2 and toks[i - 2] in _NP_OPEN:
            np_open = False  # the head of "to the left", "from his right"
            # not "a slight right curve"; "three steps back" keeps the step noun's completeness
            complete = complete or (finite and prev in ("the", "his", "her", "its", "their"))
        elif np_open and _adjective(w):
            pass
        else:
            np_open = False
    return out


# nouns that name a sport or a kind of training before the noun of what is done ("floor exercises",
# "some warmup fitness exercises", "karate kicks"): not verbs, so the plural after them is the head
_ACTIVITY_NOUNS = {"floor", "fitness", "warmup", "warm", "karate", "ballet", "yoga", "gym", "aerobic", "aerobics",
                   "martial", "kung", "fu", "tai", "chi", "training", "workout", "cardio", "sport", "sports",
                   "gymnastic", "gymnastics", "exercise", "stretching", "boxing", "kickboxing", "taekwondo",
                   "judo", "fighting", "fight", "combat", "tennis", "golf", "soccer", "football", "basketball",
                   "baseball", "volleyball", "swimming", "breathing", "relaxation", "balance"}  # fmt: skip
# past participles of what is done to the body ("is pushed", "gets hit")
_DONE_TO = {"pushed", "shoved", "hit", "bumped", "knocked", "struck", "pulled", "dragged", "stopped", "tripped",
            "punched", "kicked", "nudged", "blocked", "grabbed", "caught", "thrown", "jostled"}  # fmt: skip
_BODY_NOUNS = {"knee", "arm", "leg", "hand", "head", "hip", "toe", "foot", "shoulder", "elbow", "wrist", "neck",
               "torso", "body", "trunk", "waist", "heel"}  # fmt: skip
# one movement done both ways, not two clauses; "to the left and right" names both ways of one verb
_WAY_WORDS = {"forward", "forwards", "ahead", "back", "backward", "backwards", "left", "right", "straight", "away",
              "sideways", "around", "on"}  # fmt: skip
_PAIRS = {("up", "down"), ("back", "forth"), ("to", "fro"), ("in", "out"), ("round", "round"), ("over", "over"),
          ("left", "right"), ("right", "left")}  # fmt: skip
# words after which "than" compares (besides any word in -er: "faster than", "further than")
_COMPARATIVE = {"more", "less", "rather", "other", "fewer", "else", "longer", "much"}
_STEPS_AHEAD = re.compile(
    r"(?:a few|few|some|several|a couple of|couple of|a number of|many|\d+|"
    + "|".join(sorted(lx.NUMBERS, key=len, reverse=True))
    + r"|a|one) (?:\w+ )?(?:steps?|strides?|paces?)\b"
)


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
    # "anf" is "and", "tehn" is "then", "wakling" is "walking" (``spelling``)
    toks = [(lx.JOIN_TYPOS.get(w) or correct_word(w), a, b) for w, a, b in toks]
    # "and than walks", ", than turns": no comparison follows "and" or a comma, so "than" is "then"
    toks = [
        ("then" if w == "than" and k and toks[k - 1][0] in ("and", ",", ";") else w, a, b)
        for k, (w, a, b) in enumerate(toks)
    ]
    pieces: list[_Piece] = []
    cur: list[tuple[str, int, int]] = []
    markers: set[str] = set()
    sentence = 0

    def flush() -> None:
        nonlocal cur, markers
        if cur:
            pieces.extend(_split_piece(cur, markers, sentence, text))
            markers = set()
        cur = []

    i = 0
    while i < len(toks):
        w = toks[i][0]
        nxt = toks[i + 1][0] if i + 1 < len(toks) else ""
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
        # a determiner cannot stand before a finite verb: "turns around a walks back" is "and walks"
        # "an" before a consonant is never the article ("turns around an moves back", "an crawling")
        an_typo = (
            w == "an" and cur and nxt[:1] not in ("a", "e", "i", "o", "u", "h", "") and (nxt in _THIRD or nxt in _ING)
        )
        # "the" straight after a joining word or a walk's way, before a verb with its object or way, is a
        # misspelt "then": "and the takes a turn", "a few steps the turn 180 degrees"
        after = toks[i + 2][0] if i + 2 < len(toks) else ""
        to_a_side = after == "to" and [t[0] for t in toks[i + 3 : i + 5]] in (["the", "left"], ["the", "right"])
        the_typo = (
            w == "the"
            and (cur[-1][0] in _THE_TYPO_AFTER if cur else bool(markers & {"and", "comma"}))
            and (nxt in _THIRD or nxt in _BASE)
            # "the turns" may be a noun, but not before a way or an angle: "the turns left 180 degrees",
            # "and the turns to the right"
            and (
                nxt not in ("steps", "step", "turns")
                or after in ("left", "right", "around")
                or after[:1].isdigit()
                or to_a_side
            )
            and (after in _THE_TYPO_BEFORE or after[:1].isdigit())
        )
        if an_typo or the_typo:
            flush()
            markers.add("seq" if the_typo else "and")
            i += 1
            continue
        # "than" with no comparative before it is a misspelt "then": "is walking and than walking back",
        # "walks forward than rotates" ("faster than", "more than two" stay comparisons)
        than_typo = w == "than" and not (cur and (cur[-1][0] in _COMPARATIVE or cur[-1][0].endswith("er")))
        if (w in ("a", "an") and cur and nxt in _THIRD and nxt not in ("steps", "turns")) or than_typo:
            flush()
            markers.add("and" if w != "than" else "seq")
            i += 1
            continue
        # "during walking forward", "when walking": the same as "while"; "..., when he steps aside" (an
        # event that interrupts what went before) and "When he reaches the wall, he turns" are in the
        # order of the text
        if w in ("during", "when") and (nxt in _ING or (w == "during" and re.fullmatch(r"[a-z]{3,}ing", nxt))):
            flush()
            markers.add("while")
            i += 1
            continue
        if w == "when" and (cur or markers) and nxt in _SUBJECT_WORDS | {"a", "the"}:
            flush()
            markers.add("seq")
            i += 1
            continue
        # "by stepping sideways": the means, done with the clause before
        if w == "by" and cur and (nxt in _ING or re.fullmatch(r"[a-z]{3,}ing", nxt)):
            flush()
            markers.add("by")
            i += 1
            continue
        # "up and down", "back and forth": one movement, not two clauses
        if w == "and" and cur and (cur[-1][0], nxt) in _PAIRS:
            cur.append(toks[i])
            i += 1
            continue
        # "one slow and three fast steps", "a large and a small step": two sizes of one noun, one clause
        sizes = len(cur) > 1 and _sizes_of_steps([t[0] for t in cur[-2:]], [t[0] for t in toks[i + 1 : i + 5]])
        if w == "and" and sizes:
            cur.append(toks[i])
            i += 1
            continue
        # "after a few steps", "before 3 steps": the steps are a walk of their own, or the length of
        # the walk before them (``read_prompt``)
        steps = _STEPS_AHEAD.match(" ".join(t[0] for t in toks[i + 1 : i + 6])) if w in ("after", "before") else None
        if steps:
            flush()
            markers.add(w)
            i += 1
            # a verb straight after the steps starts the next clause, in the order of the text: "walks
            # forward and after a few steps turns around" (one piece, it was put before the walk)
            n = len(steps.group(0).split())
            if i + n < len(toks) and (toks[i + n][0] in _THIRD or toks[i + n][0] in _BASE):
                cur.extend(toks[i : i + n])
                i += n
                flush()
                markers.add("seq")
            continue
        hit = None
        for n in range(min(_MAXJ, len(toks) - i), 0, -1):
            key = tuple(t[0] for t in toks[i : i + n])
            if key == ("and",) and tuple(t[0] for t in toks[i : i + 3]) == ("and", "a", "half"):
                break  # "three and a half steps"
            if key == ("while",) and cur and cur[-1][0] in _DURATION_BEFORE:
                break  # "sits there for a short while": a stretch of time, not the joining word
            if key in _JOINERS and (
                n > 1
                or tuple(t[0] for t in toks[i : i + 2]) not in _NOT_JOINERS
                or (key in (("after",), ("before",)) and any(t[0] in _ACTION_NOUNS for t in toks[i + 2 : i + 5]))
            ):
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
    pieces = _join_light_verbs(pieces)
    for p in pieces:
        p.text = text[p.start : p.end]
    return pieces


_STEP_NOUNS = {"step", "steps", "stride", "strides", "pace", "paces"}
_STEP_PREPOSITIONS = {"up", "down", "over", "onto", "on", "off", "from", "into", "across", "of", "with", "by"}
# sizes and speeds of a step; ways ("left", "side") are left out: "to the left and two steps right" is two
_SIZES = _ADJECTIVES - _WAY_WORDS - {"left", "right", "side", "lateral", "diagonal", "sideways", "first", "second",
                                     "third", "last", "next", "final", "same", "different"}  # fmt: skip


def _size(w: str) -> bool:
    return w in _SIZES or w.isdigit() or w in _NUMBER_WORDS


def _sizes_of_steps(before: list[str], after: list[str]) -> bool:
    """ "and" between two sizes of one step noun: an article or number and a size before it,
    then articles, numbers and sizes up to the noun ("one slow and three fast steps", "3 bigger
    and 1 smaller steps"); "walks fast and two steps back" is two clauses."""
    counted = before[0] in ("a", "an") or before[0].isdigit() or before[0] in _NUMBER_WORDS
    if not (counted and before[1] in _SIZES):
        return False
    j = 0
    while j < len(after) and (after[j] in ("a", "an") or _size(after[j])):
        j += 1
    sized = any(not (w.isdigit() or w in _NUMBER_WORDS or w in ("a", "an")) for w in after[:j])
    return sized and j < len(after) and after[j] in _STEP_NOUNS


def _imperative_split_points(
    toks: list[str], slashed: frozenset[int] | set[int] = frozenset()
) -> list[tuple[int, str]]:
    """Where a piece with no subject and no finite verb, written as commands or as a trial's name
    ("walk forward turn 90 degrees left walk forward", "Run Jump Stop Run", "Punch Kick"),
    starts its next clause: at each later bare verb of motion, once a verb has been
    read before it, that does not stand in a noun phrase (after a determiner, a number, an
    adjective, "to" or a preposition) and is not a step noun after a verb ("dance steps"). The
    finite-verb scan (:func:`_split_points`) finds none of these. Not at a verb after a slash
    (``slashed``: "run/jog" names one action two ways), nor at a turn or a kick straight after a
    jump ("jump turn": one move)."""
    if not toks or any(t in _SUBJECT_WORDS or t in _THIRD or t in _AUX_WORDS for t in toks):
        return []
    if toks[0] in _NP_OPEN or toks[0] in _DETERMINERS or toks[0][:1].isdigit():
        return []
    out: list[tuple[int, str]] = []
    for i in range(1, len(toks)):
        w, prev = toks[i], toks[i - 1]
        if not any(t in _VERB_BASES for t in toks[:i]):
            continue  # "Basketball Jump Shot": a noun before the first verb is no clause
        nxt = toks[i + 1] if i + 1 < len(toks) else ""
        if w not in _VERB_BASES or w in _LIGHT or nxt == "of":
            continue
        if prev in _NP_OPEN or prev in _DETERMINERS or prev in _TO_COMPLEMENT or prev in ("to", "and", "or"):
            continue
        if prev[:1].isdigit() or prev in _NUMBER_WORDS or prev in _STEP_PREPOSITIONS:
            continue
        if _adjective(prev) and prev not in _WAY_WORDS:  # "a quick walk"; "forward turn" is a new verb
            continue
        if w in _STEP_NOUNS and prev in _VERB_BASES:
            continue
        if i in slashed or (prev in ("jump", "hop", "leap") and w in ("turn", "twist", "spin", "rotate", "kick")):
            continue
        if i >= 2 and toks[i - 2] in ("with", "without", "using", "for", "of", "by"):
            continue  # "kneel down with hand support": a compound noun in a manner phrase
        out.append((i, "list"))
    return out


def _split_piece(cur: list[tuple[str, int, int]], markers: set[str], sentence: int, text: str = "") -> list[_Piece]:
    words = [t[0] for t in cur]
    slashed = {i for i in range(1, len(cur)) if text[cur[i - 1][2] : cur[i][1]].strip() == "/"}
    cuts = _split_points(words) or _imperative_split_points(words, slashed)
    out: list[_Piece] = []
    bounds = [(0, set(markers))]
    for i, marker in cuts:
        bounds.append((i + (1 if marker == "purpose" else 0), {marker}))
    for k, (a, m) in enumerate(bounds):
        b = cuts[k][0] if k < len(cuts) else len(cur)
        if b > a:
            part = cur[a:b]
            out.append(_Piece(part[0][1], part[-1][2], m, sentence, [t[0] for t in part]))
    return out


_LIGHT_ONLY = {"gets", "get", "got", "getting", "is", "are", "was", "were", "be", "being", "been"}


def _join_light_verbs(pieces: list[_Piece]) -> list[_Piece]:
    """A piece that is only a light verb ("gets" in "and gets then pushed") is one clause with
    the piece after it."""
    out: list[_Piece] = []
    i = 0
    while i < len(pieces):
        p = pieces[i]
        rest = [w for w in p.tokens if w not in _SUBJECT_NOUNS and w not in _DETERMINERS]
        nxt = pieces[i + 1] if i + 1 < len(pieces) else None
        if rest and all(w in _LIGHT_ONLY for w in rest) and nxt is not None and nxt.sentence == p.sentence:
            out.append(_Piece(p.start, nxt.end, p.markers, p.sentence, p.tokens + nxt.tokens))
            i += 2
            continue
        out.append(p)
        i += 1
    return out


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


_MANNER = re.compile(r"\b(?:like|as if|as though|similar to|imitating a|in the style of|resembl\w*)\b.*$")


@lru_cache(maxsize=8192)
def _classify(norm: str, lowering: bool = True) -> _Reading:
    """What a normalised clause asks for. Manner ("like a drunk", "as if ...") is read only when
    the rest of the clause names no action. ``lowering=False``: "puts it down" is not the end of
    a raised arm (the "it" is an object)."""
    norm = _ATTRIBUTIVE.sub(r"\1", norm)
    norm = _POINT_NOUN.sub(r"\1 place", norm)
    bare = _MANNER.sub("", norm).strip()
    if bare and bare != norm:
        got = _classify_words(bare, lowering)
        if got.kind not in (None, "rest") and not (got.kind == UNKNOWN and got.unknown is None):
            return got
        # "makes motions as if opening a door": a motion named only by what it is like
        like = _classify_words(norm[len(bare) :].strip(), lowering)
        if got.kind == UNKNOWN and got.unknown is None and like.kind not in (None, "rest"):
            return like
        if got.kind not in (None, "rest"):
            return got
    return _classify_words(norm, lowering)


_IN_THE_AIR = re.compile(r"\b(?:in the air|in air|mid ?air|while jumping)\b")
_RUN = re.compile(r"\b" + lx.forms("run", "ran", "jog", "sprint") + r"\b")
# "the raised left arm", "his bent knee": a participle before a noun names a state, not an action
_ATTRIBUTIVE = re.compile(r"\b(the|his|her|its|their|a|an|both) (?:raised|lifted|bent|lowered|stretched)\b")
# "to a certain point", "the starting point": the noun, not the gesture
_POINT_NOUN = re.compile(
    r"\b(a|an|the|this|that|some|one|\d+|another|each|every)((?: (?!points?\b)[a-z]+){0,2}) points?\b"
)
_OSCILLATION = re.compile(r"\bup and down\b|\bback and forth\b|\bto and fro\b")
_ARM_VERB = re.compile(
    r"\b"
    + lx.forms("raise", "lift", "hold", "held", "put", "stick", "stretch", "extend", "spread", "move", "bring", "throw")
    + r"\b|\bt pose\b"
)
_RAISE_VERB = re.compile(r"\b" + lx.forms("raise", "lift", "move", "bring", "brought", "put") + r"\b")
# "reaches flat ground", "reaches the wall": reaching a place is arriving, not reaching out
_ARRIVE = re.compile(
    r"\breach\w* (?:the |a |an |his |her |its |their )?(?:\w+ )?(?:ground|floor|destination|end|point|goal|wall|"
    r"door|top|bottom|place|position|spot|area|corner|room|line|mark|target|start\w*|finish)\b"
)
_PREPARE = re.compile(
    r"^(?:\w+ly )?(?:(?:is|are) )?(?:gets?|getting|got) ready\b|^(?:\w+ly )?prepar\w* (?:to|for|him|her|it|the)"
)
_FORWARD_ONLY = re.compile(r"\b(?:forwards?|ahead|front)\b")


def _classify_words(norm: str, lowering: bool = True) -> _Reading:
    if (m := lx.REST_PATTERN.match(norm)) is not None and m.start() == 0 and not norm.startswith("stand"):
        return _Reading("rest")  # "stops after five steps": the end of what came before
    if (
        lowering
        and _ARMS_DOWN.match(norm)
        and not re.search(r"\bup\b", norm)
        and re.search(r"\b(?:lower|lowers|lowering|lowered|drop|drops|dropping|dropped|sink|down|ground|floor)\b", norm)
    ):
        return _Reading("rest")
    for name, pat in _STRONG_UNKNOWN:
        if pat.search(norm):
            if name == "turn 360 degrees" and _IN_THE_AIR.search(norm):
                return _Reading(UNKNOWN, "turn in the air", tuple(_details(UNKNOWN, norm, "turn in the air").items()))
            if name == "turn 360 degrees" and re.search(r"\bwalk\w*\b", norm):
                return _Reading("circle", None, tuple(_details("circle", norm).items()))  # walked round
            return _Reading(UNKNOWN, name, tuple(_details(UNKNOWN, norm, name).items()))
    for i, entry in enumerate(lx.KINDS):
        if entry.pattern.search(norm):
            kind = entry.kind
            if kind == "raise_arm" and not _ARM_VERB.search(norm):
                # "claps his hands above his head": the arms' position, the clap is the action
                later = next((k.kind for k in lx.KINDS[i + 1 :] if k.pattern.search(norm)), None)
                if later is not None:
                    kind = later
            if kind == "turn" and (m := _RUN.search(norm)):  # "runs in a curve": run's variants turn
                kind = "jog" if m.group(0).startswith("jog") else "run"
            if kind in ("turn", "turn_around") and _IN_THE_AIR.search(norm):
                return _Reading(UNKNOWN, "turn in the air")
            if kind == "raise_arm" and _OSCILLATION.search(norm) and not _RAISE_VERB.search(norm):
                # bouncing or shaking a hand up and down is a movement of its own; raising and lowering
                # it is the raise
                return _Reading(UNKNOWN, "move hand up and down", tuple(_details(UNKNOWN, norm).items()))
            if kind == "sidestep" and (
                re.search(r"\bdiagonal\w*", norm)
                or (_FORWARD_ONLY.search(norm) and not re.search(r"\bside\w*|\blateral\w*|\bcrab", norm))
            ):
                kind = "walk"  # a diagonal step, a shuffle forward: walking, not stepping sideways
            if kind == "turn_around" and re.search(r"\b90\b|\bquarter\b", norm):
                kind = "turn"  # a quarter turn on the spot
            if kind == "circle" and re.search(rf"\b{_LIMB_WORD}\b", norm) and not re.search(r"\bwalk|\bstep", norm):
                return _Reading(UNKNOWN, "arm circles", tuple(_details(UNKNOWN, norm, "arm circles").items()))
            if kind == "circle" and re.search(r"(?<!3 )\b(?:quarter|half|90|180)\b(?: \w+){0,3} circl", norm):
                kind = "turn"  # a part of a circle is a turn ("a quarter left circle")
            if kind == "reach" and _ARRIVE.search(norm):
                return _Reading("rest")  # "reaches the wall": arriving, the end of a walk
            return _Reading(kind, None, tuple(_details(kind, norm).items()))
    for name, pat in _WEAK_UNKNOWN:
        if pat.search(norm):
            return _Reading(UNKNOWN, name, tuple(_details(UNKNOWN, norm, name).items()))
    if lx.REST_PATTERN.search(norm):
        return _Reading("rest")
    if re.search(r"\bobstacles?\b", norm):
        return _Reading(UNKNOWN, "walk around an obstacle")  # no verb of stepping or jumping over it
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
        or (words[i] == "on" and i and _AUX.fullmatch(words[i - 1]))  # "keeps on walking"
    ):
        i += 1
    rest = " ".join(words[i:])
    if not rest:
        return False
    first = words[i]
    if _MOTION.fullmatch(first) or lx.REST_PATTERN.match(rest) or first in _ING:
        return True
    if _ASPECT.fullmatch(first) and any(w in _ING for w in words[i + 1 : i + 3]):
        return True  # "keeps on walking", "starts running": the gerund is the verb
    after = words[i + 1 : i + 3]
    if re.fullmatch(r"[a-z]{4,}[^s']s", first) and (
        (after[:1] == ["to"] and after[1:2] and after[1] in _BASE) or (after[:1] and after[0] in _ING)
    ):
        return True  # a verb the lexicon lacks (or misspelt) before "to walk" / "walking"
    if any((m := p.search(rest)) is not None and m.start() == 0 for _, p in lx.UNKNOWN_PATTERNS):
        return True
    return any(
        (m := k.pattern.search(rest)) is not None and m.start() == 0 and _MOTION.search(m.group(0)) for k in lx.KINDS
    )


_ASPECT = re.compile(lx.forms(*lx.ASPECT_VERBS))

# "then to the right", "and another two steps": a clause whose verb is the previous one's
_ELLIPSIS = re.compile(r"^(?:(?:\d+|a|one|another|1)\s+(?:\w+\s+)?steps?\b|(?:\w+\s+){0,2}to the (?:left|right)\b)")
# lowering the arms after raising them, "lets them sink": the end of the action
_ARMS_DOWN = re.compile(
    r"^(?:\w+ly )?"
    + lx.forms("lower", "drop", "let", "bring", "brought", "put", "take", "took", "set", "place", "move")
    + r" (?:\w+ ){0,3}?(?:arms?|hands?|legs?|foot|feet|them|it)\b(?: \w+){0,3}?"
    r"(?: ?(?:back|down|sink|again|to (?:the|his|her|its|their) (?:sides?|ground|floor)))*$"
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
    """The way the words say (only direction words count; "starting with the right" is a leg)."""
    d = None
    n = re.sub(rf"\b(?:starting|beginning|leading|starts|begins) with (?:the |his |her |its |their )?{_LR}\b", "", n)
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


def _count(n: str, kind: str | None = None) -> int | None:
    """Repetitions the words give: "twice", "3 times", "4 steps", "a step", "3 kicks"; for a
    circle, circles only ("a full circle" is 1, "in 8 steps" is no count)."""
    if m := re.search(r"\b(once|twice|thrice)\b", n):
        return lx.COUNT_WORDS[m.group(1)]
    if kind == "circle":
        if m := re.search(r"\b(\d+) (?:\w+ )?(?:circles?|rounds?|laps?|loops?|times)\b", n):
            return int(m.group(1))
        if re.search(
            r"\b(?:full|whole|complete|entire|one|1)\b(?: \w+)? (?:circle|round|loop|lap)\b|\bcomplet\w* the circle", n
        ):
            return 1
        return None
    if m := re.search(rf"\b(\d+) (?:\w+ )?(?:{_COUNTED})\b", n):
        return int(m.group(1))
    if re.search(r"\b(?:a|1|single) (?:\w+ )?(?:step|jump|kick|punch|hop|squat|wave)\b(?!s)", n):
        return 1
    return None


def _angle(n: str) -> int | None:
    """Degrees the words give for a turn: the number, a quarter (90), half, around, a U-turn (180)."""
    if m := re.search(r"\b(\d+) ?(?:degrees?|deg)\b", n):
        return int(m.group(1))
    if re.search(r"\b(?:full|whole|complete) (?:turn|spin|rotation)", n):
        return 360
    if re.search(r"\bquarter\b", n):
        return 90
    if re.search(r"\bhalf\b|\baround\b|\bu turn\b|\babout (?:face|turn)\b|\bto the back\b", n):
        return 180
    if m := re.search(r"\b(\d+) (?:turn|spin)", n):
        return int(m.group(1))
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
            elif m := re.search(
                rf"\b(?:pushed|shoved|knocked|nudged|bumped)(?: \w+)? (?:to|towards?) "
                rf"(?:the |his |her |its |their )?(?:{_LR}|front)\b",
                n,
            ):
                out["direction"] = m.group(1) or "forward"  # "pushed to the left": the body moves left
            if m := re.search(rf"\b{_LR} shoulder\b", n):
                out["side"] = m.group(1)
            return out
        if unknown and re.match(r"(?:jump|turn|walk|run|stumble|dodge|recovery|crawl|skip|limp|climb|step)", unknown):
            # a movement of the whole body: its way (and a turn's angle), not a limb
            if d := _direction(n, {"forward", "backward", "left", "right"}):
                out["direction"] = d
            elif re.search(r"\bccw\b", n):
                out["direction"] = "left"
            elif re.search(r"\bcw\b", n):
                out["direction"] = "right"
            if unknown.startswith("turn") and (angle := _angle(n)):
                out["angle"] = angle
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
    if (kind in ("turn", "turn_around") or t["angle"]) and (angle := _angle(n)):
        out["angle"] = angle
    if (c := _count(n, kind)) is not None and (t["count"] or kind in _LOCOMOTION):
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
    verb: tuple[str, str] | None = None  # the verb it shares with the clause before (user's, normalised)
    restored: str | None = None  # its words with that verb put back, for the plan


_WALKING = {"walk", "jog", "run", "walk_backward", "sidestep", "circle"}
# actions that go on while another happens: a participle of one in the subject runs with the main verb
_DURATIVE = _WALKING | {"turn", "mocap:dance-long"}
_DURATIVE_UNKNOWN = {"hold", "carry", "limp", "sneak", "walk in a slalom", "walk on a slope", "walk up a slope",
                     "walk down a slope", "run in a circle", "crawl"}  # fmt: skip
# actions of the arms that can go with walking ("walks forward, waving")
_UPPER = {"wave", "clap", "punch", "raise_arm", "reach", "throw", "mocap:bye", "mocap:call", "mocap:guide",
          "mocap:respond"}  # fmt: skip
_OBJECT_ACTIONS = {"pick up", "carry", "lift an object overhead", "hold", "pass object between hands", "put down",
                   "pull an object", "push", "handle an object", "catch"}  # fmt: skip
_PERTURBED = {"being pushed", "stumble"}
_STRIKES = {"punch", "kick", "throw"}
# what a guard or a wind-up reads as alone: a raised or held arm, or an action the lexicon names
_GUARD_KINDS = {UNKNOWN, "raise_arm", "reach", "punch", "stretch"}
_GUARD = re.compile(
    r"\b(?:cover|guard|defen[cs]e|defensive|protect\w*|stance|wind(?:s|ing)? up|wound up|wind-?up|"
    r"strikes? out|(?:boxing|fighting|fight|combat|ready|starting|attack) (?:position|pose|manner|way|style)|"
    # raised fists, or the striking arm drawn back (the wind-up of a throw or a punch)
    r"fists?|(?:arm|hand|fist)s? (?:back|backwards?|behind)|(?:boxing|fighting) (?:guard|stance))\b"
)
# both hands placed (held, put, moved) with no action named: "moves the hands together", "puts his hands back"
_HANDS = re.compile(r"\b(?:hold\w*|held|put\w*|mov\w+|lift\w*|rais\w+|bring\w*|brought) (?:\w+ )?hands\b")
_BALANCING = re.compile(
    r"\b(?:balanc\w*|counterbalanc\w*|recover\w*|correct\w*|compensat\w*|stabili[sz]\w*|steady\w*)\b"
)
_TO_A_SIDE = re.compile(r"\bto (?:the |his |her |its |their )?(left|right)\b")
_RETURN_TO_START = re.compile(
    r"^(?:\w+ly |then |and |after |before )*(?:return\w*|recover\w*|(?!walk|run|jog|sprint)\w+ back) "
    r"(?:\w+ )?(?:to|into|in) "
    r"(?:the |his |her |its |their )?(?:\w+ )?(?:initial|original|starting|start|first|previous|old|former|"
    r"normal|upright|neutral) ?(?:position|point|place|spot|pose|posture|stance|location)?\b"
)
# coming back onto the feet: the end of an action done on the hands or the floor ("goes into a
# handstand and comes back on his feet")
_BACK_ON_FEET = re.compile(r"^(?:\w+ly |then |and )*\w+ back (?:on|onto|to) (?:his |her |its |their |the )?feet\b")
_TO_A_PATH = re.compile(r"\b(?:line|path|track|route|course|direction|way|lane|trajectory)\b")
# an aim that is no movement of its own: "steps to the right to avoid something"
_AIM = re.compile(r"^(?:avoid|evade|dodge|escape|keep|regain|gain|maintain|prevent|not)\b")
# actions after which a held thing is a new state ("picks up a box and holds it"), not the same action
_TAKES_HOLD = {"pick up", "lift an object overhead", "put down", "catch", "carry"}
_BRACING = re.compile(
    r"^(?:\w+ly )?(?:bend\w*|bent|flex\w*) (?:\w+ )?knees?(?: \w+ly)?$|^(?:\w+ly )?(?:lean\w*|bend\w*|bent) "
    r"(?:(?:a bit|a little|slightly|the upper body|his upper body|her upper body|their upper body) )?forwards?$"
)
_PERTURB = re.compile(r"\b(?:push|shove|hit|bump|blow|force|nudge|impact|collision|knock)\w*\b")
_CONTINUE = re.compile(rf"^(?:(?:\w+ly|then|also|just|and) )*{lx.CONTINUE}$")
_RECOVER = re.compile(rf"^(?:(?:\w+ly|then|also|just|and|tries to|trying to|attempts to) )*{lx.RECOVER}\b")
_HEDGE = re.compile(r"^(?:and |but )?(?:it |this |that )?(?:looks|seems|seemed|looked|appears|appeared) "
                    r"(?:like|as if|as though|that|to be)\b")  # fmt: skip
_JUMP_TURN = re.compile(r"\b(?:turn\w*|spin\w*|rotat\w*|twist\w*|pirouett\w*|twirl\w*|\d+ ?degrees?|ccw|cw)\b")
_WAY = (
    r"(?P<way>back(?:wards?)?|forwards?|ahead|straight|sideways|the other way|in the (?:other|opposite) direction|"
    r"(?:to (?:the |his |her |its |their )?)?(?:left|right|front|rear)\b"
    r"(?! (?:foot|feet|leg|legs|hand|hands|arm|arms|knee|knees|fist|shoulder|heel|toe|side)\b))"
)
_WAY_ELLIPSIS = re.compile(
    r"^(?:again )?(?:(?:\d+|a|another|a few|few|some|several|a couple of|couple of|a little|a bit)\s+"
    r"(?:(?:small|big|large|long|short|quick|slow|more|little)\s+)?(?:steps?|strides?|paces?|meters?|metres?|bit)?\s*)?"
    + _WAY
)
_CURVE_WAY = re.compile(
    r"^(?:(?:to|towards|toward|on) (?:the |his |her |its |their )?)?(?:left|right)(?: side| hand side)?$"
    r"|^(?:cw|ccw)$"
)
_PARTICIPLE_FIRST = re.compile(r"(?:\w+ly )?\w+ing\b")
_STEP_WORD = re.compile(r"\b(?:steps?|strides?|paces?)\b")
_STEP_COUNT_ONLY = re.compile(
    r"^(?:\w+ly )?(?:tak\w+|took|mak\w+|made|do|does|doing|did|with|in) (?:about |only |just )?"
    r"(?:\d+|a few|few|some|several|a couple of|" + "|".join(sorted(lx.NUMBERS, key=len, reverse=True)) + r")"
    r" (?:\w+ )?(?:steps?|strides?|paces?)(?: \w+ly)?$"
)
_SIDE_ELLIPSIS = re.compile(r"^(?:(?:with|on|using) )?(?:the |his |her |its |their )?(?:left|right)(?: \w+)?$")
# how an action is done, said with a verb of its own, is no action: a hand as support ("using the
# right hand as support", "stabilising himself with the left hand"), a guard position of the arms
# during a kick ("getting the arms up in a defence position"), keeping one's balance, and what
# does not happen ("so he does not fall", "without falling")
_DETAIL = re.compile(
    r"^(?:(?:\w+ly|and|then|also|just|while|by) )*(?:"
    r"(?:using|uses|use|with|putting|puts|placing|places|leaning|leans) (?:\w+ ){0,4}"
    r"(?:as (?:an? )?(?:\w+ )?(?:support|help|aid|prop)|for (?:\w+ )?(?:support|balance))\b|"
    r"(?:using|uses) (?:his|her|its|their|the|both|one|a) (?:\w+ )?(?:hands?|arms?)$|"
    r"(?:support|stabili[sz]|steady|steadie|brac)\w* (?:himself|herself|itself|themselves|oneself|his body|"
    r"her body|the body)\b|"
    r"(?:keeps?|keeping|kept|holds?|holding|maintain\w*|finds?|finding) (?:his |her |its |their |the )?balance\b|"
    r"(?:support|carr(?:y|ie)|bear|shift)\w* (?:all |some )?(?:of )?(?:his |her |its |their |the )?(?:body )?weight\b|"
    r"(?:\w+ ){0,6}in (?:an? )?(?:defen[cs]e|defensive|guard|fighting|boxing|combat) "
    r"(?:position|stance|posture|pose)\b|"
    r"(?:(?:he|she|it|they|the \w+) )?(?:does not|doesn't|did not|didn't|do not|don't|not|never|without)\b)"
)
# "and repeats it", "does the same again": the actions said so far happen once more
_OBJ_BACK = (
    r"(?:it|this|that|them|these|those|the same|everything|all|"
    r"the (?:\w+ )?(?:movements?|motions?|sequence|actions?|exercises?|things?|pattern|process|steps?))"
)
_REPEAT = re.compile(
    r"^(?:(?:\w+ly|then|and|also) )*(?:(?:repeats?|repeating|repeated)(?: " + _OBJ_BACK + r")?"
    r"|(?:does|did|doing|do) (?:" + _OBJ_BACK + r"|so)) ?(?:again|once more|one more time|once again)?$"
)
_REPEAT_NEEDS_AGAIN = re.compile(r"^(?:(?:\w+ly|then|and|also) )*(?:does|did|doing|do)\b")
# "stumbles during that", "waves at the same time" (the joining words at the clause's end, where
# no clause follows them): this clause runs with the one before it
_DURING_AFTER = re.compile(
    r"^\s*,?\s*(?:during (?:that|this|it|the \w+)|meanwhile|in the meantime|at the same time|simultaneously|"
    r"while doing (?:so|that|this|it))\s*(?:[.;!?]|$)",
    re.IGNORECASE,
)
# a state the action starts from, said as a clause of its own: "is in a fighting pose and ducks"
_STARTING_STATE = re.compile(
    r"^(?:is |stands |standing |starts |starting )?(?:in|into) (?:an? |the |his |her |its |their )?"
    r"(?:\w+ )?(?:defen[cs]e|defensive|guard|fighting|boxing|combat|fight|starting|ready|neutral) "
    r"(?:position|stance|posture|pose)$"
)
# "as he does so", "while doing this": the clause before runs with the one before it
_DOING_SO = re.compile(
    r"^(?:(?:he|she|it|they|the \w+) )?(?:does|did|do|is doing|are doing|doing) (?:so|this|that|it)$"
)
_PAST_PARTICIPLE = re.compile(r"^(?:\w+ly )?(?:\w{2,}ed|bent|held|spread|kept|hung|shut|outstretched)\b")


def _way(n: str) -> str | None:
    """The way a piece of words says: back, forward, left, right ("left foot" is no way)."""
    n = re.sub(rf"\b(?:starting|beginning|leading|starts|begins) with (?:the |his |her |its |their )?{_LR}\b", "", n)
    if re.search(r"\bback(?:wards?)?\b|\bthe other way\b|\b(?:other|opposite) direction\b|\brear\b", n):
        return "back"
    if m := re.search(rf"\b{_LR_WAY}", n):
        return m.group(1)
    if re.search(r"\bforwards?\b|\bahead\b|\bstraight\b|\bfront\b", n):
        return "forward"
    return None


_VERB_FORMS = (
    {f for fs in _INFLECTED.values() for f in fs} | _LIGHT | set(_ING) | {"ran", "went", "came", "stood", "sat"}
)


def _user_verb(text: str, d: _Draft) -> tuple[str, str] | None:
    """The clause's verb as the user wrote it (with an auxiliary before it: "is walking") and
    normalised: what a clause that leaves its verb out shares with it."""
    if d.verb is not None:
        return d.verb
    span = text[d.start : d.end]
    subject = _subject_of(span)
    off = d.start + (span.index(subject) + len(subject) if subject else 0)
    toks = [(m.group(0), m.start() + off) for m in _TOKEN.finditer(text[off : d.end])]
    aux = None
    for w, _ in toks:
        lw = w.lower()
        if lw in ("is", "are", "was", "were"):
            aux = w
            continue
        if lw in _VERB_FORMS:
            user = f"{aux} {w}" if aux and lw.endswith("ing") else w
            return user, lw
        if not _ADVERB.fullmatch(lw):
            aux = None
    return None


def _ing(verb: str) -> str:
    """walks -> walking, runs -> running, dances -> dancing (a verb as the user wrote it)."""
    lw = verb.lower().split()[-1]
    for f in _INFLECTED.values():
        if lw in f:
            return f[3]
    return lw if lw.endswith("ing") else lw + "ing"


def read_prompt(text: str) -> Reading:
    """The prompt's clauses in the order they happen; see the module's docstring."""
    text = text or ""
    drafts: list[_Draft] = []
    last_was_rest = False
    for p in _pieces(text):
        if _HEDGE.match(normalise(p.text)):
            continue  # "it looks like he got pushed before": the annotator's guess, not an action
        norm = normalise(_without_subject(p.text))
        # "walks a circle (right turn)", "plays the violin. (one stroke)": words in brackets with no
        # verb of their own say how the clause before is done; its words run to the closing bracket
        close = text.find(")", p.end)
        if (
            drafts
            and text[: p.start].rstrip().endswith("(")
            and not _starts_with_verb(norm)
            and not _looks_like_a_verb(norm)
            and close >= 0
            and not text[p.end : close].strip()
        ):
            d = drafts[-1]
            if d.cls.kind in ("circle", "turn", "turn_around"):
                whole = _classify(f"{d.norm} {norm}")
                if whole.kind == d.cls.kind:
                    d.norm, d.cls = f"{d.norm} {norm}", whole
            d.end = close + 1
            continue
        cls = _classify(norm)
        if cls.kind is None and _subject_of(p.text) and _looks_like_a_verb(norm):
            cls = _Reading(UNKNOWN, None, tuple(_details(UNKNOWN, norm).items()))
        if _PREPARE.match(norm) or (_STARTING_STATE.match(norm) and not any(d.sentence == p.sentence for d in drafts)):
            # "getting ready to jump": part of the jump that follows; "is in a fighting pose and
            # ducks": where the action starts (PROTOCOL.md, starting postures)
            cls = _Reading(None)
        prev = drafts[-1] if drafts and drafts[-1].sentence == p.sentence else None
        again = norm.endswith(("again", "more", "time"))
        if drafts and _REPEAT.match(norm) and (again or not _REPEAT_NEEDS_AGAIN.match(norm)):
            last = drafts[-1].sentence
            block = [d for d in drafts if d.sentence == last]
            for k, d0 in enumerate(block):
                drafts.append(
                    replace(d0, markers={"seq"} if k == 0 else set(d0.markers), first_in_sentence=False,
                            sentence=p.sentence, extra=list(d0.extra))
                )  # fmt: skip
            continue
        # two verbs sharing one object ("lifts and lowers their arms"): a verb that needs an object says
        # nothing alone, so it is one clause with the next verb's object
        if (
            prev is not None
            and p.markers == {"and"}
            and prev.norm in _VERB_FORMS
            and prev.cls.kind == UNKNOWN
            and prev.cls.unknown is None
            and norm.split()[0] in _VERB_FORMS
            and len(norm.split()) > 1
        ):
            shared = _classify(f"{prev.norm} {norm.split(' ', 1)[1]}")
            if shared.kind not in (None, "rest", UNKNOWN):
                prev.end, prev.norm, prev.cls = p.end, f"{prev.norm} and {norm}", shared
                continue
        if prev is not None and _DOING_SO.match(norm):
            if len(drafts) > 1 and drafts[-2].sentence == prev.sentence:
                prev.markers.add("with")  # "claps as he does so": at the same time as the clause before
            prev.end = p.end
            continue
        if prev is not None and prev.cls.kind not in (None, "rest") and _DETAIL.match(norm):
            prev.end = p.end  # the way the action before is done, or what does not happen
            continue
        markers = set(p.markers)
        if (
            markers & {"after", "before"}
            and prev is not None
            and (
                prev.cls.kind in _WALKING
                or prev.cls.unknown in _DURATIVE_UNKNOWN
                or last_was_rest
                # "walks forward and is pushed after a couple of steps": the steps of the walk before
                or any(x.sentence == p.sentence and x.cls.kind in _WALKING for x in drafts)
            )
            and cls.kind == "walk"
            and _STEPS_AHEAD.match(norm)
        ):
            prev.end = p.end  # "slows down again after a couple of steps": the steps of that walk
            continue
        rest_before, last_was_rest = last_was_rest, False
        # "steps left, returning to the initial position": back to the start after a sidestep is a
        # sidestep the other way (PROTOCOL.md), whatever verb or joining word says it
        if prev is not None and prev.cls.kind == "sidestep" and _RETURN_TO_START.match(norm):
            back = _OTHER.get(dict(prev.cls.details).get("direction") or "")
            cls = _Reading("sidestep", None, (("direction", back),) if back else ())
            markers = (markers - {"adjunct", "participle", "by", "purpose"}) | {"seq"}
        # "takes a lunge and returns to the initial position", "goes into a handstand and comes back on
        # his feet": the way back ends an action done in place; it is no walk (after a walk it is the
        # walk back, after a sidestep a sidestep back, after sitting or lying down a standing up)
        # (not during a walk: "walks, is pushed and gets back to the original path" walks on)
        if (
            prev is not None
            and prev.cls.kind not in (None, "rest", "sit_down", "lie_down", *_LOCOMOTION)
            and not any(d.cls.kind in _LOCOMOTION for d in drafts)
            and (_RETURN_TO_START.match(norm) or (prev.cls.kind == UNKNOWN and _BACK_ON_FEET.match(norm)))
            and not _TO_A_PATH.search(norm)
        ):
            prev.end = p.end
            continue
        # "gets his cover up and kicks", "winds up and throws": the guard or the wind-up before a
        # strike is the way it starts, not an action of its own (incidental arm posture, PROTOCOL.md)
        if (
            prev is not None
            and markers
            and markers <= {"and", "comma"}
            and cls.kind in _STRIKES
            and (
                (prev.cls.kind in _GUARD_KINDS and _GUARD.search(prev.norm))
                or (prev.cls.kind == UNKNOWN and prev.cls.unknown in (None, "hold") and _HANDS.search(prev.norm))
            )
        ):
            prev.end, prev.norm, prev.cls = p.end, norm, cls
            prev.markers.discard("with")  # a guard held during a walk: the strike still comes after it
            continue
        # context: what the words mean after the clauses before them
        if "cause" in markers and _PERTURB.search(norm) and cls.unknown != "being pushed":
            cls = _Reading(UNKNOWN, "being pushed", tuple(_details(UNKNOWN, norm, "being pushed").items()))
        if (
            (cls.kind == UNKNOWN and cls.unknown in ("recovery step", "balance"))
            or (cls.kind in (None, UNKNOWN) and _RECOVER.match(norm))
        ) and (
            # "recovers in one step": the step is the reaction's own clause (PROTOCOL.md)
            not re.search(r"\bsteps?\b", norm) and any(d.cls.unknown in _PERTURBED for d in drafts)
        ):
            cls = _Reading("rest")  # recovering after a push or a stumble ends the reaction
        perturbed = any(d.cls.unknown in _PERTURBED for d in drafts)
        if perturbed and cls.kind == "walk" and _way(norm) is None and _BALANCING.search(norm):
            # "makes a few steps to gain balance": steps of the reaction with no way named
            cls = _Reading(UNKNOWN, "recovery step", tuple(_details(UNKNOWN, norm, "recovery step").items()))
        elif perturbed and cls.kind == "walk" and (m := _TO_A_SIDE.search(norm)) and _way(norm) != "forward":
            # "recovers and goes back to the left": a step to a side after a push is a sidestep
            cls = _Reading("sidestep", None, (("direction", m.group(1)),))
        if (
            cls.kind == "rest"
            and re.search(r"\b(?:it|them)\b", norm)
            and prev is not None
            and prev.cls.unknown in _OBJECT_ACTIONS
        ):
            cls = _classify(norm, lowering=False)  # "picks up a cup and puts it down": the cup
        if (
            prev is not None
            and prev.cls.kind in _JUMPS
            and (cls.kind in ("turn", "turn_around") or cls.unknown == "turn 360 degrees")
            and (markers == {"and"} or (markers == {"comma"} and re.match(r"\w+ing\b", norm)))
        ):
            # "jumps up and turns 360 degrees", "jumps, turning 90 degrees": the turn is the jump's
            cls = _Reading(UNKNOWN, "turn in the air", tuple(_details(UNKNOWN, norm, "turn in the air").items()))
        if (
            prev is not None
            and (prev.cls.kind in _JUMPS or prev.cls.unknown == "turn in the air")
            and re.match(r"(?:\w+ly )?(?:lands?|landing|landed)\b", norm)
        ):
            cls = _Reading("rest")  # "jumps up and lands", "... before landing": the end of the jump
        if cls.unknown == "turn in the air" and prev is not None and prev.cls.kind in _JUMPS:
            markers.add("with")  # "hops and turns in the air": during the jump
        if cls.unknown in ("look around", "look down") and prev is not None and markers == {"and"} and not rest_before:
            # "crouches and looks around": a glance goes with the body's action (not once it has
            # stopped: "walks, stops and looks around" looks after the walk)
            markers.add("with")
        if prev is not None and _DURING_AFTER.match(text[p.end :]):
            markers = (markers - {"seq"}) | {"with"}
        if "by" in markers:
            markers.discard("by")
            markers.add("seq" if rest_before or prev is None else "with")
        if "participle" in markers:
            markers.discard("participle")
            durative = prev is not None and (
                prev.cls.kind in _DURATIVE or prev.cls.unknown in _DURATIVE_UNKNOWN or cls.unknown == "being pushed"
            )
            markers.add("with" if durative else "seq")
        # said with a walk or a run, leaning forward is the gait's posture and looking down its head's
        # (PROTOCOL.md): "walks leaning forward", "runs, leaning forward", "is walking slowly, looking down"
        leaning = cls.kind == "bow" and bool(_BRACING.match(norm))
        if (
            prev is not None
            and prev.cls.kind in _WALKING
            and (leaning or cls.unknown == "look down")
            and (
                (leaning and markers & {"adjunct", "participle", "while", "with"})
                or (markers == {"comma"} and _PARTICIPLE_FIRST.match(norm))
            )
        ):
            prev.end = p.end
            continue
        if "adjunct" in markers:
            markers.discard("adjunct")
            if prev is not None and (cls.kind in (None, "rest") or cls.kind == prev.cls.kind):
                prev.end = p.end  # "walks forward looking ahead", "is boxing throwing punches": the same clause
                continue
            markers.add("with")
        if "purpose" in markers and prev is not None:
            if cls.kind in (None, "rest") or cls.kind == prev.cls.kind or _AIM.match(norm):
                prev.end = p.end  # an action for the same end, or an aim that is no action: the same clause
                continue
            if cls.unknown == "being pushed":
                markers.add("cause")  # "to recover from a push": the push came first
        # a sidestep "to the front" or at 45 degrees is a step forward, which is a walk
        if cls.kind == "sidestep" and _way(norm) == "forward":
            step = re.sub(r"\bside ?(steps?)\b", r"\1", re.sub(r"\b\d+ ?degrees? ", "", norm))  # a count of steps only
            cls = _Reading("walk", None, tuple(_details("walk", step).items()))
        if prev is not None and prev.cls.kind == "sidestep":
            if re.match(r"(?:\w+ly |then )*(?:cross\w*|crosses)\b", norm) and cls.kind in (None, UNKNOWN):
                prev.end = p.end  # "steps left, then crosses behind with the right foot": one crossing sidestep
                continue
            if cls.kind == "walk" and re.search(r"\b(?:return\w*|back)\b", norm) and _way(norm) in (None, "back"):
                # going back to the start after a sidestep is a sidestep the other way
                back = _OTHER.get(dict(prev.cls.details).get("direction") or "")
                cls = _Reading("sidestep", None, (("direction", back),) if back else ())
        if (
            prev is not None
            and cls.kind == "walk"
            and prev.cls.kind in ("walk", "jog", "run")
            and _way(norm) == "back"
            and _way(prev.norm) != "back"
            and not any(d.cls.kind in ("turn", "turn_around") for d in drafts)
        ):
            # with no turn before it, "walks forward, then walks back" goes back facing the same way
            # (PROTOCOL.md); after a turn the same words are a walk the other way
            cls = _Reading("walk_backward", None, tuple(_details("walk_backward", norm).items()))
        # holding a thing while doing something to it is one action: "holds a cup and wipes it",
        # "plays the violin, holding it under the chin" ("it" is the thing held)
        if prev is not None and prev.cls.unknown not in _TAKES_HOLD and re.search(r"\b(?:it|them)\b", norm):
            if cls.unknown == "hold" and prev.cls.kind == UNKNOWN:
                prev.end = p.end
                continue
            if prev.cls.unknown == "hold" and cls.kind == UNKNOWN and markers & {"and", "comma"}:
                prev.end, prev.norm, prev.cls = p.end, norm, cls
                continue
            # "plays the violin and bows it with the left", "holds a guitar and plays it": what is
            # done to the thing the action before named, with no action of its own named
            if (
                prev.cls.kind == UNKNOWN
                and prev.cls.unknown is not None
                and cls.kind == UNKNOWN
                and cls.unknown is None
                and markers & {"and", "comma", "participle", "adjunct"}
            ):
                prev.end = p.end
                continue
        # holding a part of the body or a pose goes on through the action it is said with
        # (PROTOCOL.md: "holding a body part for the whole motion" is a clause at the same time)
        if (
            prev is not None
            and cls.unknown == "hold"
            and prev.cls.kind not in (None, "rest")
            and prev.cls.unknown not in _TAKES_HOLD
            and markers & {"and", "comma"}
            and not markers & {"seq"}
        ):
            markers.add("with")
        # bending the knees or leaning forward and then jumping or walking: the way of that jump or walk
        if (
            prev is not None
            and markers == {"and"}
            and (cls.kind in _JUMPS or cls.kind in _WALKING)
            and _BRACING.match(prev.norm)
            and prev.cls.kind in ("squat", "bow", UNKNOWN)
        ):
            prev.end, prev.norm, prev.cls = p.end, norm, cls
            continue
        if (
            prev is not None
            and cls.kind == prev.cls.kind
            and cls.kind in ("sit_down", "kneel", "lie_down", "squat")
            and re.search(r"\b(?:there|still|for (?:a|some|\d+)|a while|a moment|that way)\b", norm)
        ):
            prev.end = p.end  # "sits down, sits there for a while": the posture held, not a second action
            continue
        first = next((w for w in norm.split() if not _ADVERB.fullmatch(w)), "")
        if prev is not None and markers == {"comma"} and first in _ING and cls.kind == prev.cls.kind != UNKNOWN:
            prev.end = p.end  # "is boxing, throwing punches": the same action said again
            continue
        if prev is not None and markers == {"comma"} and first in _ING and prev.cls.kind in _WALKING:
            # a participle after a comma runs with a movement it can go with
            if cls.kind == "turn" or cls.kind in _UPPER:
                markers.add("with")
        # "walks in a small circle, to the right": a way after a comma, with no joining word, is the way
        # of the curve before it, not a walk of its own
        if prev is not None and prev.cls.kind in ("circle", "turn") and markers == {"comma"} and _CURVE_WAY.match(norm):
            whole = _classify(f"{prev.norm} {norm}")
            prev.end = p.end
            if whole.kind == prev.cls.kind:
                prev.norm, prev.cls = f"{prev.norm} {norm}", whole
            continue
        # "hops forward, turns around and hops back": back after a half turn is forward again, as a
        # walk back after a turn is a walk (PROTOCOL.md)
        if (
            cls.unknown == "jump backward"
            and _way(norm) == "back"
            and any(d.cls.kind == "turn_around" and d.sentence == p.sentence for d in drafts)
        ):
            cls = _Reading("jump_forward", None, tuple(_details("jump_forward", norm).items()))
        # "walks a quarter circle, taking four steps", "walks fast and does 4 steps": a count of steps
        # with no way of its own is the count of the walk (or curve) before, not a second walk
        if (
            prev is not None
            and cls.kind == "walk"
            and _STEP_COUNT_ONLY.match(norm)
            and (
                (markers == {"comma"} and prev.cls.kind in _LOCOMOTION)
                or (markers == {"and"} and prev.cls.kind in ("walk", "jog", "run", "walk_backward", "sidestep"))
            )
        ):
            prev.end = p.end
            continue
        # a verb left out: "then backward", "one back", "and forward again", "then the right one"
        way = _WAY_ELLIPSIS.match(norm)
        if (
            prev is not None
            and prev.cls.kind not in (None, "rest")
            and markers & {"seq", "and", "comma", "list"}
            and not _starts_with_verb(norm)
            and (
                _ELLIPSIS.match(norm)
                or (way and prev.cls.kind in _LOCOMOTION)
                or (_SIDE_ELLIPSIS.match(norm) and prev.cls.kind not in _LOCOMOTION)
            )
        ):
            pway = "back" if prev.cls.kind == "walk_backward" else _way(prev.norm)
            nway = _way(norm)
            opposite = (
                nway is not None
                and pway is not None
                and nway != pway
                and ("back" in (nway, pway) or {nway, pway} == {"left", "right"})
            )
            counted = _ELLIPSIS.match(norm) and not re.match(r"^(?:\w+ ){0,2}to the (?:left|right)", norm)
            if markers & {"seq", "comma", "list"} or opposite or re.search(r"\bagain\b", norm) or counted:
                verb = _user_verb(text, prev)
                # "does a T-pose, 2 steps forward": steps after an action done in place are a walk
                walked = prev.cls.kind not in _LOCOMOTION and cls.kind in _LOCOMOTION and _STEP_WORD.search(norm)
                if walked:
                    verb = None
                else:
                    cls = _repeat(prev, norm, verb[1] if verb else "", nway)
                d = _Draft(p.start, p.end, p.sentence, markers | {"seq"}, cls, norm, False)
                d.verb = verb
                d.restored = f"{verb[0]} {text[p.start : p.end]}" if verb else None
                drafts.append(d)
                continue
        # "continues", "keeps going", "carries on": the walking before goes on
        if _CONTINUE.match(norm) and prev is not None:
            walked = next((d for d in reversed(drafts) if d.cls.kind in _WALKING), None)
            if walked is None or prev.cls.kind in _WALKING:
                prev.end = p.end
                continue
            verb = _user_verb(text, walked)
            d = _Draft(p.start, p.end, p.sentence, markers | {"seq"}, _Reading(walked.cls.kind), norm, False)
            if verb and not re.search(r"\b\w+ing$", norm):
                d.restored = f"{text[p.start : p.end]} {_ing(verb[0])}"
            drafts.append(d)
            continue
        soft = not (markers & {"seq", "with", "while", "before", "after", "cause", "purpose"}) and bool(
            markers & {"and", "comma", "as", "or", "list"}
        )
        # "as a counterbalance", "as support": a role, not a clause (no verb and no subject of its own)
        role = "as" in markers and (
            norm.split()[:1] in (["a"], ["an"], ["the"])
            or not (_has_subject(p.text) or any(w in _THIRD or w in _ING or w in lx.PRONOUNS for w in norm.split()))
        )
        hedge = "until" in markers or (
            "or" in markers and prev is not None and prev.cls.kind is not None and _starts_with_verb(norm)
        )
        manner = (
            soft
            and prev is not None
            and _PAST_PARTICIPLE.match(norm)
            and (cls.kind in (None, "raise_arm") or (cls.kind == UNKNOWN and cls.unknown is None))
        )
        joins = prev is not None and (
            cls.kind is None
            or hedge
            or manner
            or role
            or (soft and not _starts_with_verb(norm))
            or (cls.kind == "rest" and prev.cls.kind not in (None, "rest"))
        )
        if joins and prev is not None:
            prev.end = p.end
            last_was_rest = cls.kind == "rest"
            generic = prev.cls.kind is None or (prev.cls.kind == UNKNOWN and prev.cls.unknown is None)
            if manner or hedge or role:
                continue
            if cls.kind is not None and cls.kind != "rest" and generic:
                prev.norm = f"{prev.norm} {norm}"
                prev.cls = _classify(prev.norm)
            elif cls.kind not in ("rest",):
                prev.norm = f"{prev.norm} {'and ' if 'and' in markers else ''}{norm}"
                again = _classify(prev.norm)
                # "gets down on his knees and hands": the joined words name a more specific action
                if again.kind == UNKNOWN and again.unknown in _STRONG_NAMES and again.unknown != prev.cls.unknown:
                    prev.cls = again
                # the merged words refine the clause they join: its details (side, count), or a more
                # specific way of moving ("walks a quarter, left-sided circle")
                elif prev.cls.kind not in (None, UNKNOWN, "rest"):
                    kind = prev.cls.kind
                    if (
                        "and" not in markers
                        and kind in _LOCOMOTION
                        and again.kind in _LOCOMOTION
                        and _kind_rank(again.kind) < _kind_rank(kind)
                    ):
                        kind = again.kind
                    prev.cls = _Reading(kind, None, tuple(_details(kind, prev.norm).items()))
                    if kind in ("turn", "turn_around") and _IN_THE_AIR.search(prev.norm):
                        prev.cls = _Reading(UNKNOWN, "turn in the air")
                        if len(drafts) > 1 and drafts[-2].cls.kind in _JUMPS and drafts[-2].sentence == prev.sentence:
                            prev.markers.add("with")  # "jumps and turns left while in the air"
            continue
        # a leading piece with no action (a bare subject) joins the next one
        if prev is not None and prev.cls.kind is None:
            prev.end = p.end
            prev.norm = f"{prev.norm} {norm}"
            prev.cls = cls
            prev.markers |= markers
            continue
        d = _Draft(p.start, p.end, p.sentence, markers, cls, norm, prev is None)
        verb = _user_verb(text, prev) if prev is not None and not _has_verb(p.text) else None
        if verb is not None and verb[1].split()[-1] in _LIGHT:
            # "performs a headstand and a backflip": the second shares the verb
            d.verb, d.restored = verb, f"{verb[0]} {p.text}"
        drafts.append(d)
    # a rest clause alone in its sentence with no action anywhere is an unknown ("stand still")
    has_action = any(d.cls.kind not in (None, "rest") for d in drafts)
    if not has_action:
        for d in drafts:
            # "stops walking" alone: the walk is named, and it ends
            if d.cls.kind == "rest" and (m := _STOPS_DOING.search(d.norm)):
                if (named := _classify(m.group(1))).kind not in (None, "rest", UNKNOWN):
                    d.cls, has_action = named, True
    clauses_d = [d for d in drafts if d.cls.kind is not None and (d.cls.kind != "rest" or not has_action)]
    clauses_d = _merge_corpus_phrasings(clauses_d)
    subjects: dict[int, str] = {}
    for d in drafts:
        if d.sentence not in subjects and (sub := _subject_of(text[d.start : d.end])) is not None:
            subjects[d.sentence] = sub
    subject = subjects[min(subjects)] if subjects else None
    posture = _starting_posture(subject)
    ordered = _merge_together(_turn_between_walks(_order(_drop_glances(clauses_d))))
    if len(ordered) > 1 and (still := _stative(ordered[0][0])) and _getting_up(ordered[1][0]):
        posture = still  # "lies on the floor and gets up": where it starts, not a clause
        ordered = ordered[1:]
    clauses: list[Clause] = []
    fours = False
    for d, together in ordered:
        start, end = _trim(text, d.start, d.end)
        words = text[start:end]
        det = dict(d.cls.details)
        together = together and bool(clauses)
        kind = d.cls.kind
        own = subjects.get(d.sentence, subject)
        extra = {"restored": d.restored, "subject": None if _has_subject(words) else own}
        if kind in _WALKING and fours:
            kind, d.cls = UNKNOWN, _Reading(UNKNOWN, "crawl")  # walking on hands and knees
        if kind == "rest":
            clauses.append(Clause(UNKNOWN, words, start, end, together, unknown="stand still", **extra))
        elif kind == UNKNOWN:
            name = d.cls.unknown or _without_subject(words)
            clauses.append(Clause(UNKNOWN, words, start, end, together, unknown=name, **det, **extra))
        else:
            moved = any(c.kind in ("kneel", "sit_down", "lie_down", "stand_up", "get_up") for c in clauses)
            here = posture or _starting_posture(text[: d.start] + " " + text[d.start : d.end].split(" stand")[0])
            if kind in ("stand_up", "get_up") and here == "kneeling" and not moved:
                clauses.append(Clause(UNKNOWN, words, start, end, together, unknown="stand up from kneeling", **extra))
                fours = False
                continue
            lying = next((c.kind for c in reversed(clauses) if c.kind in _POSTURE_KINDS), None) == "lie_down"
            if kind == "stand_up" and ((here == "lying" and not moved) or lying):
                kind = "get_up"  # getting up after lying down is from the floor
            clauses.append(Clause(kind, words, start, end, together, **_fit(kind, det), **extra))
            if kind in ("jump_up", "jump_forward") and _JUMP_TURN.search(d.norm):
                # a turn in the words of a jump is a turn in the air
                clauses.append(Clause(UNKNOWN, words, start, end, True, unknown="turn in the air", **extra))
        last = clauses[-1]
        if last.unknown in ("get down on all fours", "crawl"):
            fours = True
        elif last.kind in ("stand_up", "get_up") or last.unknown == "stand up from kneeling":
            fours = False
    clauses = _jump_turns(text, [_as_known_kind(c) for c in clauses])
    if not clauses and _names_someone(text):
        # no verb the reader knows ("shaved off his mustache", "wolk back and forth"): still one
        # action asked for, unknown, so that the page names it rather than showing nothing
        start, end = _trim(text, 0, len(text))
        words = text[start:end]
        clauses = [Clause(UNKNOWN, words, start, end, False, unknown=_without_subject(words))]
    return Reading(text, tuple(_after_neighbours(clauses)), subject)


def _names_someone(text: str) -> bool:
    """Whether a text that read as no clause still speaks of someone ("a man ...", "someone ..."):
    then it asks for an action the reader does not know. Gibberish ("asdf qwer") names no one and
    is left to the warning's own check."""
    words = re.findall(r"[a-z]+", text.lower())
    return any(w in _SUBJECT_WORDS for w in words)


def _as_known_kind(c: Clause) -> Clause:
    """An unknown clause whose name stands for a kind the models now know (``lx.AS_KIND``, the
    kind in ``CATALOGUE``) read as that kind, with the details it takes; others as they are."""
    from .actions import CATALOGUE

    if c.kind != UNKNOWN:
        return _as_finer_kind(c, CATALOGUE)
    if c.unknown is None:
        return c
    norm = normalise(c.words)
    for name, pattern, kind in lx.AS_KIND:
        if name == c.unknown and (pattern is None or re.search(pattern, norm)):
            if kind is None or kind not in CATALOGUE:
                return c
            fields = ("side", "direction", "count", "angle", "speed", "amplitude")
            det = {**_details(kind, norm), **{f: getattr(c, f) for f in fields if getattr(c, f) is not None}}
            fit = _fit(kind, det)
            return replace(c, kind=kind, unknown=None, **{f: fit.get(f) for f in fields})
    return c


def _as_finer_kind(c: Clause, catalogue: dict) -> Clause:
    """A known clause read as the finer kind its words name (``lx.FINER_KIND``) once the models
    know that kind; until then, as it is."""
    for kind, pattern, finer in lx.FINER_KIND:
        if c.kind == kind and finer in catalogue and re.search(pattern, normalise(c.words)):
            fields = ("side", "direction", "count", "angle", "speed", "amplitude")
            fit = _fit(finer, {f: getattr(c, f) for f in fields if getattr(c, f) is not None})
            return replace(c, kind=finer, **{f: fit.get(f) for f in fields})
    return c


def _jump_turns(text: str, clauses: list[Clause]) -> list[Clause]:
    """A jump with a spin_jump read with it ("jumps and turns 180 degrees in the air") is one
    spin_jump over both clauses' words; while spin_jump is staged the pair stays a jump with an
    unknown turn in the air beside it, as the labels have it."""
    out: list[Clause] = []
    for c in clauses:
        prev = out[-1] if out else None
        if c.kind == "spin_jump" and c.with_previous and prev is not None and prev.kind in _JUMPS:
            start, end = min(prev.start, c.start), max(prev.end, c.end)
            out[-1] = replace(c, words=text[start:end], start=start, end=end, with_previous=prev.with_previous)
        else:
            out.append(c)
    return out


_STRONG_NAMES = {name for name, _ in lx.STRONG}
_JUMPS = {"jump_up", "jump_forward", "hop"}
_POSTURE_KINDS = ("kneel", "sit_down", "lie_down", "stand_up", "get_up")


def _repeat(prev: _Draft, norm: str, verb: str, way: str | None) -> _Reading:
    """The previous clause's action again, with these words' own way, side or count."""
    kind = prev.cls.kind
    if kind == UNKNOWN:
        return _Reading(UNKNOWN, prev.cls.unknown, tuple(_details(UNKNOWN, norm, prev.cls.unknown).items()))
    if kind in _LOCOMOTION:
        # "takes one step forward, two to the right": the count left out its noun, the steps before
        if re.search(r"\bsteps?\b", prev.norm) and not re.search(r"\bsteps?\b", norm):
            norm = re.sub(r"^(\d+|a|one|another|a few|some|several)\b", r"\1 steps", norm)
        if way == "back" and kind == "sidestep":
            back = _OTHER.get(dict(prev.cls.details).get("direction") or "")
            det = {**_details("sidestep", norm), "direction": back}
            return _Reading("sidestep", None, tuple((k, v) for k, v in det.items() if v is not None))
        if kind == "sidestep" and way in ("left", "right"):
            return _Reading("sidestep", None, tuple(_details("sidestep", norm).items()))  # "..., then to the left"
        if way == "back" and kind != "walk_backward":
            kind = "walk_backward"
        else:
            again = _classify(f"{verb} {norm}".strip()).kind
            if again in _LOCOMOTION:
                kind = again
            elif kind == "walk_backward" and way == "forward":
                kind = "walk"
    return _Reading(kind, None, tuple(_details(kind, norm).items()))


def _stative(d: _Draft) -> str | None:
    """A first clause that only states a posture ("lies on his back", "is on all fours", "sitting
    on a chair"): where the motion starts when getting up follows."""
    n = d.norm
    if re.search(r"\b(?:down|get|gets|got|getting|go|goes|went|going|drops?|dropping)\b", n):
        return None
    if d.cls.kind == "lie_down" and not re.search(r"\b(?:lie|lies|lay|lays|lying|laying) back\b", n):
        return "lying"  # "lies on his back" (to lie back is to lie down)
    if (d.cls.kind == "kneel" and re.search(r"\bkneeling\b", n)) or (
        d.cls.unknown in ("crawl", "get down on all fours") and not re.search(r"\bcrawl", n)
    ):
        return "kneeling"
    if d.cls.kind == "sit_down" and re.search(r"\b(?:sitting|seated)\b", n):
        return _starting_posture(n) or "sitting"  # "sitting on his knees" is kneeling
    return None


def _getting_up(d: _Draft) -> bool:
    return d.cls.kind in ("stand_up", "get_up") or d.cls.unknown == "stand up from kneeling"


def _drop_glances(drafts: list[_Draft]) -> list[_Draft]:
    """A glance while doing something ("while looking at his feet") is the action's manner,
    not a step of its own; so is swinging the arms while walking. Two verbs joined by "and" that
    name the same unknown action ("trips and falls") are one action."""
    out: list[_Draft] = []
    for i, d in enumerate(drafts):
        incidental = d.cls.unknown in ("look around", "look down") or (
            d.cls.unknown == "hang" and re.search(r"\b(?:arms?|hands?)\b", d.norm)
        )
        glance = d.cls.unknown in ("look around", "look down")
        if d.cls.kind == UNKNOWN and incidental and d.markers & ({"while"} if glance else {"while", "with"}):
            near = [x for x in drafts[max(0, i - 1) : i + 2] if x is not d and x.sentence == d.sentence]
            if glance and any(x.cls.kind not in (None, "rest", UNKNOWN) for x in near):
                continue
            if any(x.cls.kind in _WALKING or x.cls.kind == "turn" for x in near):
                continue
        prev = out[-1] if out else None
        if (
            prev is not None
            and d.cls.kind == UNKNOWN
            and d.cls.unknown is not None
            and d.cls.unknown == prev.cls.unknown
            and d.markers == {"and"}
            and d.sentence == prev.sentence
            and not re.search(r"\b(?:again|twice|once more)\b", d.norm)
        ):
            prev.end = max(prev.end, d.end)
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
                c = replace(c, kind="sidestep", direction=direction, side=None, angle=None, speed=None)
            elif prev.kind in ("turn", "turn_around") and c.kind == "walk_backward" and not _REVERSE.search(n):
                c = replace(c, kind="walk", direction=None, side=None, angle=None)
            elif (
                prev.kind == "walk"
                and c.kind == "walk"
                and re.search(r"\b(?:go|goes|went|move|moves|moved|step|steps|stepped)\b(?: \w+)? back\b", n)
                and not re.search(r"\bback (?:to|on|onto|into|in)\b", n)
            ):
                c = replace(c, kind="walk_backward", direction="backward", side=None, angle=None)
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
    keep |= {"angle"} if kind in ("turn", "turn_around") or t["angle"] else set()
    keep |= {"amplitude"} if t["amp"] else set()
    return {k: v for k, v in det.items() if k in keep}


def _starting_posture(subject: str | None) -> str | None:
    """ "A kneeling person ...", "a person lying on the floor ...": where the motion starts."""
    n = normalise(subject or "")
    if re.search(
        r"\bkneel|\b(?:on|from) (?:his|her|its|their|the|both|2) knees\b|\bcrawl|\bon (?:all )?fours?\b|"
        r"\bhands and knees\b",
        n,
    ):
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


_STOPS_DOING = re.compile(r"\b(?:stop|stops|stopped|stopping|halts?|halted|ceases?|ceased|quits?) (\w+ing)\b")
_WALKED = re.compile(
    r"\b(?:walk\w*|steps?|stepping|go|goes|going|went|mov\w+|curves?|circles?|corners?|arcs?|path|heels?)\b"
)
_WAY_BACK = re.compile(r"\bback\b|\b(?:the )?(?:other|opposite) (?:way|direction)\b")


def _merge_corpus_phrasings(drafts: list[_Draft]) -> list[_Draft]:
    """The corpus's own phrasings of one kind that read as two clauses (``lexicon.AND_PHRASINGS``:
    "walks and turns left" is one ``turn``; with "then" or a comma it stays two), and a bare "turns" followed by "walks
    back" (a ``turn_around``)."""
    out: list[_Draft] = []
    for d in drafts:
        prev = out[-1] if out else None
        det = dict(d.cls.details)
        if (
            d.cls.kind == "turn"
            and det.get("angle") == 180
            and re.search(r"\b180\b", d.norm)
            and not _WALKED.search(d.norm)
        ):
            # "rotates once on its axis by 180 degrees": a half turn said with no walked path is
            # turning around on the spot; "walks a 180 degree curve" stays a turn
            d.cls = _Reading("turn_around", None, tuple(_fit("turn_around", det).items()))
        pair = (
            (prev.cls.unknown if prev.cls.kind == UNKNOWN else prev.cls.kind, d.cls.kind) if prev is not None else None
        )
        if (
            prev is not None
            and prev.sentence == d.sentence
            and pair in lx.AND_PHRASINGS
            and d.markers == {"and"}
            and not re.search(rf"\b{_LIMB_WORD}\b", d.norm)  # "and waves his hands": a wave of its own
        ):
            out[-1] = _remake(prev, d, lx.AND_PHRASINGS[pair])
            continue
        if (
            prev is not None
            and prev.sentence == d.sentence
            and prev.cls.kind in ("walk", "jog", "run")
            and d.cls.kind == "turn_around"
            and d.markers == {"and"}
            and re.search(r"\bu turn\b", d.norm)
            and not any(x.sentence == d.sentence and x.start > d.start for x in drafts)
        ):
            # "walks forward and makes a U-turn": a half turn at the end of a walk, with no walk back
            # after it, is the walk's curve (PROTOCOL.md); between two walks it is a turn_around
            out[-1] = _remake(prev, d, "turn")
            out[-1].cls = _Reading("turn", None, tuple({**dict(out[-1].cls.details), "angle": 180}.items()))
            continue
        if (
            prev is not None
            and prev.cls.kind == "turn"
            and d.cls.kind in ("walk", "walk_backward", "jog", "run")
            and (_WAY_BACK.search(d.norm) or _REVERSE.search(d.norm))
            and dict(prev.cls.details).get("angle") in (None, 180)
        ):
            det = {"angle": 180, **_details("turn_around", prev.norm)}  # turning to walk back is a half turn
            prev.cls = _Reading("turn_around", None, tuple(det.items()))
        out.append(d)
    return out


def _turn_between_walks(items: list[tuple[_Draft, bool]]) -> list[tuple[_Draft, bool]]:
    """ "Walking forwards, turning and walking back": a turn read as going with the walk before
    it is a half turn of its own when a walk back follows it (the walk while turning would be
    one curve, and there is no curve to walk back along)."""
    out = list(items)
    for i in range(1, len(out) - 1):
        (prev, _), (d, together), (nxt, nt) = out[i - 1], out[i], out[i + 1]
        det = dict(d.cls.details)
        if (
            together
            and not nt
            and d.cls.kind in ("turn", "turn_around")
            and det.get("angle") in (None, 180)
            and prev.cls.kind in ("walk", "jog", "run")
            and nxt.cls.kind in ("walk", "walk_backward", "jog", "run")
            and (_WAY_BACK.search(nxt.norm) or _REVERSE.search(nxt.norm))
        ):
            d.cls = _Reading("turn_around", None, tuple({"angle": 180, **_details("turn_around", d.norm)}.items()))
            out[i] = (d, False)
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
    Y", "X. Meanwhile Y": X, Y with it. "Before B, A", "A after B" and "A because of B": A / B
    first."""
    # "meanwhile", "at the same time", "during that" link to the clause before, even across a
    # sentence end; "while" at a sentence's start is "While Y, X": X runs with Y
    items = [
        [d, i > 0 and ("with" in d.markers or ("while" in d.markers and not d.first_in_sentence))]
        for i, d in enumerate(drafts)
    ]
    for i, (d, _) in enumerate(items):
        if (
            d.first_in_sentence
            and "while" in d.markers
            and "with" not in d.markers
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
        elif d.markers & {"after", "cause"} and not d.first_in_sentence and same:
            # "A after B", "A because of B": B happens first (with A's together-clauses after it)
            j = i - 1
            while j > 0 and items[j][1] and items[j - 1][0].sentence == d.sentence:
                j -= 1
            block = items[j:i]
            items[j : i + 1] = [[d, False], *block]
            block[0][1] = False
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
