"""The prompt reader: a sentence into ordered clauses (kinds, or unknown actions by name), the
timeline plan in the user's own words, and the warning before generation. The sentences here
are written for these tests (none is from a caption data set)."""

from __future__ import annotations

import pytest

import motion_core
from motion_core.corpus import lexicon
from motion_core.corpus.actions import CATALOGUE
from motion_core.corpus.prompt_guide import MOCAP_ONLY, calibration_sets
from motion_core.corpus.reader import Clause, check_prompt, normalise, read_prompt
from motion_core.nn.text import get_text_encoder


def kinds(text: str) -> list[str]:
    return [c.kind for c in read_prompt(text).clauses]


def test_every_corpus_kind_has_one_lexicon_entry_and_every_unknown_a_name():
    names = [k.kind for k in lexicon.KINDS]
    assert sorted(names) == sorted([*CATALOGUE, *(f"mocap:{m}" for m in MOCAP_ONLY)])
    unknown = [n for n, _ in lexicon.UNKNOWN]
    assert len(unknown) == len(set(unknown)) and "unknown" not in unknown
    assert set(lexicon.NEAREST) <= set(unknown) | set(lexicon.RULE_NAMES)
    assert set(lexicon.NEAREST.values()) <= set(names)


def test_each_kind_is_read_from_its_own_corpus_caption():
    # one caption per kind as the corpus writes it (prompt_guide.action_kinds's examples)
    from motion_core.corpus.prompt_guide import action_kinds

    for k in action_kinds():
        assert kinds(k.example) == [k.kind], k.example


def test_a_sentence_of_several_actions_becomes_ordered_clauses():
    r = read_prompt("A person walks forward, then turns around and after that runs back. Finally he sits down.")
    assert [c.kind for c in r.clauses] == ["walk", "turn_around", "run", "sit_down"]
    assert not any(c.with_previous for c in r.clauses)
    # joining words and pronouns are never clauses, and never start one
    assert [c.words for c in r.clauses] == ["A person walks forward", "turns around", "runs back", "he sits down"]


def test_words_are_the_users_own_cut_from_the_text():
    text = "Someone  Walks slowly to the LEFT, and then waves twice with the right hand!"
    r = read_prompt(text)
    for c in r.clauses:
        assert text[c.start : c.end] == c.words
    assert [c.words for c in r.clauses] == ["Someone  Walks slowly to the LEFT", "waves twice with the right hand"]


def test_before_and_after_put_the_clauses_in_the_order_they_happen():
    assert kinds("Before sitting down, he waves.") == ["wave", "sit_down"]
    assert kinds("He waves before sitting down.") == ["wave", "sit_down"]
    assert kinds("She sits down after bowing.") == ["bow", "sit_down"]
    assert kinds("After bowing, she sits down.") == ["bow", "sit_down"]


def test_together_clauses_run_with_the_previous_and_share_a_segment():
    r = read_prompt("a man claps his hands while jogging, then kicks with the left leg")
    assert [(c.kind, c.with_previous) for c in r.clauses] == [("jog", False), ("clap", True), ("kick", False)]
    assert [g[0].kind for g in r.groups()] == ["jog", "kick"]
    assert r.segment_texts() == ["a man claps his hands while jogging", "a man kicks with the left leg"]
    # two ways of moving at once are one kind; the corpus's "walks and turns left" is one turn
    assert kinds("a person walks while turning to the right") == ["turn"]
    assert kinds("a person walks and turns left") == ["turn"]
    assert kinds("a person walks, then turns left") == ["walk", "turn"]


def test_side_direction_count_and_angle_come_from_the_words():
    def first(text: str) -> Clause:
        return read_prompt(text).clauses[0]

    c = first("the woman punches three times with her left fist")
    assert (c.kind, c.side, c.count) == ("punch", "left", 3)
    assert first("someone waves both hands").side == "both"
    for text in (
        "a person walks in a circle counter clockwise",
        "a person walks in a counter-clockwise circle",
        "a person walks anticlockwise in a circle",
        "a person walks a full circle to the left",
    ):
        assert (first(text).kind, first(text).direction) == ("circle", "ccw"), text
    assert first("somebody walks in a clockwise circle").direction == "cw"
    assert first("a person walks leftwards").direction == "left"
    assert first("a person jogs to the right").direction == "right"
    assert first("a man walks diagonally to the right").direction == "forward-right"
    assert first("someone jumps twice").count == 2 and first("someone jumps 2 times").count == 2
    assert first("someone takes five steps forward").count == 5
    c = first("a person turns 90 degrees to the left")
    assert (c.kind, c.direction, c.angle) == ("turn", "left", 90)
    assert first("a person turns around").angle == 180
    assert first("a person does four jumping jacks").count == 4
    # walking never takes a side: the leg it starts with is not a direction either
    c = first("a person walks forward starting with the right foot")
    assert (c.side, c.direction) == (None, "forward")


def test_unknown_actions_are_named_and_the_rest_stays_known():
    r = read_prompt("A person walks to the table, picks up a box and carries it away.")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("walk", None), ("unknown", "pick up"), ("unknown", "carry")]
    assert not r.fully_known
    for text, name in [
        ("someone does push-ups", "push-ups"),
        ("a man crawls on the floor", "crawl"),
        ("the person climbs the stairs", "climb stairs"),
        ("a person stumbles", "stumble"),
        ("a woman plays the violin", "play an instrument"),
        ("a person swims", "swim"),
    ]:
        assert [(c.kind, c.unknown) for c in read_prompt(text).clauses] == [("unknown", name)], text
    # a motion verb that matches no kind is unknown too, named by its own words
    r = read_prompt("a person wobbles then twirls a baton")
    assert [c.kind for c in r.clauses] == ["unknown", "unknown"]


def test_fillers_and_end_of_motion_are_not_clauses():
    assert kinds("A person walks forward and stops.") == ["walk"]
    assert kinds("A person stands, then jumps") == ["jump_up"]
    assert kinds("A person walks slowly, starting with the left foot") == ["walk"]
    assert kinds("A person walks forward and backward") == ["walk"]
    assert kinds("a person stands still") == ["unknown"]
    assert kinds("") == [] and kinds("   ") == []


def test_number_words_and_spellings_are_normalised():
    assert normalise("Counter-Clockwise, three times; anti clockwise") == "ccw 3 times ccw"
    assert normalise("walks leftwards") == "walks to the left"


def test_warning_names_the_unknown_part_and_the_nearest_known_action():
    c = motion_core.check_prompt("A person walks forward and then picks up a box")
    assert c.warn and len(c.unknown_parts) == 1
    assert c.messages == ("The models have not learned 'picks up a box' (nearest: reach forward with one hand)",)
    c = check_prompt("a man wipes the window with his left hand")
    assert c.messages[0].startswith("The models have not learned 'wipes the window with his left hand' (nearest: ")
    d = c.to_dict()
    assert d["warn"] and d["unknown_parts"][0]["name"] == "wipe"


def test_a_known_prompt_gets_no_warning():
    for text in (
        "a person walks forward",
        "someone jumps twice, then sits down",
        "a woman waves with her right hand while walking",
        "the man kicks high with the left leg",
    ):
        c = check_prompt(text)
        assert not c.warn and not c.messages, (text, c.messages)


def test_gibberish_and_unrelated_sentences_stay_warned():
    sets = calibration_sets()
    unfamiliar = sets["unfamiliar_cal"] + sets["unfamiliar_test"]
    get_text_encoder().encode(unfamiliar)  # one batch; check_prompt then finds them cached
    warned = [check_prompt(t).warn for t in unfamiliar]
    assert all(warned), [t for t, w in zip(unfamiliar, warned, strict=True) if not w]
    c = check_prompt("qwertyuiop asdf")
    assert c.warn and c.messages[0].startswith("The models have not learned anything like 'qwertyuiop asdf'")


@pytest.mark.parametrize(
    "text",
    ["a person stumbles forward", "someone does a cartwheel", "a man rides a bicycle", "a person carries a bag"],
)
def test_unknown_actions_are_warned(text):
    assert check_prompt(text).warn


def test_plan_is_one_segment_per_sequential_clause_with_estimated_seconds():
    r = motion_core.read_prompt(
        "A man walks forward while waving, then he jumps three times. Before sitting down, he bows."
    )
    plan = r.plan()
    assert [s.text for s in plan] == [
        "A man walks forward while waving",
        "he jumps three times",
        "he bows",
        "A man sitting down",
    ]
    assert [s.kinds for s in plan] == [("wave", "walk"), ("jump_up",), ("bow",), ("sit_down",)]
    assert all(1.0 <= s.seconds <= 10.0 for s in plan) and all(s.known for s in plan)
    d = r.to_dict(plan=True)
    assert [s["text"] for s in d["plan"]] == [s.text for s in plan]
    assert d["clauses"][0]["kind"] == "wave" and d["fully_known"]
