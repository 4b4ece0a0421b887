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
from motion_core.corpus.spelling import correct_word
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
    assert kinds("A person walks forward and to the left") == ["walk"]
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
        "he sits down",
    ]
    assert [s.kinds for s in plan] == [("wave", "walk"), ("jump_up",), ("bow",), ("sit_down",)]
    assert all(1.0 <= s.seconds <= 10.0 for s in plan) and all(s.known for s in plan)
    d = r.to_dict(plan=True)
    assert [s["text"] for s in d["plan"]] == [s.text for s in plan]
    assert d["clauses"][0]["kind"] == "wave" and d["fully_known"]


# ---------------------------------------------------------------- general phenomena of phrasing
def plan_kinds(text: str) -> list[tuple[str, ...]]:
    return [tuple(sorted(c.kind for c in g)) for g in read_prompt(text).groups()]


def test_a_list_of_verbs_with_no_joining_word_is_a_list_of_clauses():
    assert kinds("a man walks forward turns around and runs back") == ["walk", "turn_around", "run"]
    assert kinds("someone jogs to the left jumps twice then sits down") == ["jog", "jump_up", "sit_down"]
    # a verb's object that looks like a verb is not a clause of its own
    assert kinds("a person takes small steps forward") == ["walk"]
    assert kinds("the woman performs two kicks with the right leg") == ["kick"]
    assert kinds("a man does a few squats") == ["squat"]
    # a relative clause keeps its verb; the next verb starts the next clause
    assert kinds("someone who walks forward bows") == ["walk", "bow"]


def test_a_participle_in_the_subject_is_a_clause_before_the_main_verb():
    # an ongoing movement runs with the main action; an event happens before it
    r = read_prompt("the woman jogging to the right waves with her left hand")
    assert [(c.kind, c.with_previous) for c in r.clauses] == [("jog", False), ("wave", True)]
    r = read_prompt("a man getting hit from the left falls down")
    assert [(c.kind, c.unknown, c.with_previous) for c in r.clauses] == [
        ("unknown", "being pushed", False),
        ("unknown", "stumble", False),
    ]
    # a light verb split from its participle by a joining word is one clause
    assert kinds("a person walks ahead and gets then shoved from the right") == ["walk", "unknown"]


def test_a_verb_left_out_after_a_joining_word_is_the_previous_clauses_verb():
    assert kinds("a person jogs forward, then backward and forward again") == ["jog", "walk_backward", "jog"]
    assert kinds("someone goes four steps ahead, two back, then ahead again") == ["walk", "walk_backward", "walk"]
    r = read_prompt("a woman steps to the left and then back")
    assert [(c.kind, c.direction) for c in r.clauses] == [("sidestep", "left"), ("sidestep", "right")]
    # opposite ways joined by "and" are two movements; a second way that is not opposite is one
    assert kinds("a person walks forward and backward") == ["walk", "walk_backward"]
    assert kinds("a person walks forward and to the right") == ["walk"]
    # the plan restores the shared verb, in the user's own form
    r = read_prompt("The man runs forward, then backward.")
    assert r.segment_texts() == ["The man runs forward", "The man runs backward"]


def test_continuing_an_action_repeats_it():
    assert kinds("a person walks forward, turns left and keeps walking") == ["walk", "turn", "walk"]
    assert kinds("a woman jogs, jumps over a puddle and continues her jog") == ["jog", "jump_forward", "jog"]
    assert kinds("he walks to the door, turns around and continues on") == ["walk", "turn_around", "walk"]
    assert kinds("someone runs and proceeds to walk slowly") == ["run", "walk"]
    assert kinds("a man starts to walk") == ["walk"]


def test_purpose_infinitives_are_the_next_action():
    assert kinds("a person turns around to walk back") == ["turn_around", "walk"]
    assert kinds("someone kneels down to pick up a coin") == ["kneel", "unknown"]
    # not after verbs of starting, trying or wanting, nor before a noun
    assert kinds("the man tries to jump") == ["jump_up"]
    assert kinds("a person walks to the chair") == ["walk"]
    # an action for the same end is one action
    assert kinds("a woman reaches out to grab the handle") == ["reach"]


def test_causes_come_before_what_they_cause():
    r = read_prompt("a person steps to the right because of a hard push")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("unknown", "being pushed"), ("sidestep", None)]
    assert kinds("someone staggers backwards due to a shove") == ["unknown", "unknown"]
    r = read_prompt("a man takes two steps back to recover from a push")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("unknown", "being pushed"), ("walk_backward", None)]
    # "in response to", "in reaction to" say a cause as "because of" does
    r = read_prompt("a man steps to the left in reaction to a shove from the right")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("unknown", "being pushed"), ("sidestep", None)]


def test_recovering_after_a_push_or_stumble_is_its_end_not_an_action():
    assert kinds("a woman is shoved from behind, takes a step forward and regains her balance") == [
        "unknown",
        "walk",
    ]
    assert kinds("a person trips, recovers and walks on") == ["unknown", "walk"]
    # a recovery step with a way is a step that way
    assert kinds("a person is pushed and takes a backward recovery step") == ["unknown", "walk_backward"]
    # recovering "in one step" names the reaction's step: its own clause, as the protocol labels it
    r = read_prompt("a woman is shoved from the side and recovers with a single step")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("unknown", "being pushed"), ("unknown", "recovery step")]
    assert kinds("a man gets pushed and recovers in 2 steps to the right") == ["unknown", "sidestep"]


def test_steps_before_or_after_an_action_are_a_walk():
    assert kinds("After three steps a woman sits down") == ["walk", "sit_down"]
    assert kinds("a person turns left after a few steps") == ["walk", "turn"]
    # with a walk already under way the steps are its length, and what follows them comes next
    assert plan_kinds("someone jogs ahead and after some steps sits down and claps") == [
        ("jog",),
        ("sit_down",),
        ("clap",),
    ]
    assert plan_kinds("a man runs forward and kneels down after five steps") == [("run",), ("kneel",)]
    # an action named by its noun after "after" comes first, as a clause does
    assert plan_kinds("someone sits down after a quick jump") == [("jump_up",), ("sit_down",)]
    assert plan_kinds("a woman waves after a short bow") == [("bow",), ("wave",)]


def test_simultaneous_words_at_the_start_of_a_sentence_join_the_previous_sentence():
    r = read_prompt("A person walks forward. At the same time he waves his right hand.")
    assert [(c.kind, c.with_previous) for c in r.clauses] == [("walk", False), ("wave", True)]
    assert plan_kinds("A person jogs in place. Meanwhile, she claps.") == [("clap", "jog")]
    assert plan_kinds("He walks forward, during this he claps, then he sits down") == [("clap", "walk"), ("sit_down",)]
    # "while Y, X": the while-clause runs first, X with it
    assert plan_kinds("While walking, a man waves. Then he bows.") == [("walk", "wave"), ("bow",)]


def test_a_participle_after_a_comma_runs_with_a_movement_it_can_go_with():
    assert kinds("a person walks forward, slowly turning to the left") == ["turn"]
    assert plan_kinds("a man jogs forward, waving both hands") == [("jog", "wave")]
    # a change of posture or a turn on the spot comes after
    assert kinds("a person walks forward, turning around, and walks back") == ["walk", "turn_around", "walk"]
    # a participle that names no action is the manner of the clause before
    assert kinds("a woman walks in a circle, completing it in ten steps") == ["circle"]
    assert kinds("a man raises his right arm, bent at the elbow") == ["raise_arm"]


def test_fillers_hedges_and_typos_around_joining_words():
    assert kinds("A tired or sleepy person walks forward") == ["walk"]
    assert kinds("a person jumps, it looks like he is happy") == ["jump_up"]
    assert kinds("a person kneels down and therefore takes a step back") == ["kneel", "walk_backward"]
    # a determiner cannot stand before a verb: "a walks" is "and walks"
    assert kinds("someone turns left a walks on") == ["turn", "walk"]
    # ", than" is "then" (a comparison never follows a comma)
    assert kinds("someone jumps twice, than sits down") == ["jump_up", "sit_down"]


def test_a_starting_posture_before_getting_up_is_not_an_action():
    assert kinds("A woman lies on her back, then gets up") == ["get_up"]
    assert kinds("A woman lies down, then gets up") == ["lie_down", "get_up"]
    r = read_prompt("A man is on all fours and then stands up")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("unknown", "stand up from kneeling")]
    # moving on hands and knees is crawling
    r = read_prompt("someone gets down on hands and knees and walks across the room")
    assert [c.unknown for c in r.clauses] == ["get down on all fours", "crawl"]


def test_object_pronouns_follow_what_was_picked_up_or_lifted():
    r = read_prompt("a woman picks up a cup and puts it down again")
    assert [c.unknown for c in r.clauses] == ["pick up", "put down"]
    assert kinds("a man raises his left arm and puts it down again") == ["raise_arm"]
    assert [c.unknown for c in read_prompt("someone lifts the left leg and sets it back down").clauses] == [
        "lift a foot"
    ]


def test_arm_movements_the_corpus_lacks_are_not_read_as_raise_or_wave():
    for text in (
        "a person bounces his right hand up and down",
        "someone gesticulates with both hands",
        "a man gestures wildly with his arms",
        "a woman stretches her legs",
    ):
        assert kinds(text) == ["unknown"], text
    assert kinds("a person moves both arms upwards") == ["raise_arm"]
    assert kinds("a person moves both arms up and down") == ["raise_arm"]  # raised and lowered
    assert kinds("a person raises both arms and waves his hands") == ["raise_arm", "wave"]
    assert kinds("a person raises the right arm and waves") == ["wave"]  # the corpus's own phrasing


def test_two_verbs_for_one_action_and_incidental_arm_swings():
    r = read_prompt("someone jogs forward, then trips and falls")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("jog", None), ("unknown", "stumble")]
    assert kinds("a man walks forward while swinging his arms") == ["walk"]
    assert [c.unknown for c in read_prompt("she moves her left hand in a circular motion").clauses] == ["arm circles"]
    assert kinds("a person walks up to something picks it up and carries it away") == ["walk", "unknown", "unknown"]


def test_participles_with_no_comma_and_the_arms_position():
    # an -ing after a whole verb phrase happens at the same time
    assert plan_kinds("a woman jogs forward carrying a bag") == [("jog", "unknown")]
    assert kinds("a man walks ahead performing a half circle") == ["turn"]
    assert kinds("someone starts running") == ["run"]  # not after a verb of starting
    assert kinds("a man steps over a box taking a long stride") == ["step_over"]  # a light verb: the same step
    assert kinds("the man is punching, throwing jabs with his left fist") == ["punch"]  # the same action again
    # where the arms are is no raise when another action is named
    assert kinds("a woman claps her hands above her head") == ["clap"]
    assert kinds("a woman stands with her arms out") == ["raise_arm"]
    # landing is the end of a jump; turning the head is no turn of the body
    assert kinds("a man jumps forward and lands softly") == ["jump_forward"]
    assert [c.unknown for c in read_prompt("a person turns her head to the right").clauses] == ["move the head"]
    # a motion named only by what it is like
    r = read_prompt("a man makes motions as if climbing a ladder")
    assert [c.unknown for c in r.clauses] == ["climb"]
    assert kinds("someone walks forward while looking at the floor") == ["walk"]
    # a glance joined by "and" goes with the action; with "then" it comes after
    assert plan_kinds("a man kneels and looks around") == [("kneel", "unknown")]
    assert plan_kinds("a man kneels and then looks around") == [("kneel",), ("unknown",)]
    assert plan_kinds("a woman jogs, stops and looks around") == [("jog",), ("unknown",)]  # after it stopped
    assert plan_kinds("a woman hops and turns 90 degrees while in the air") == [("hop", "unknown")]


def test_jumps_and_turns_on_the_spot():
    r = read_prompt("a person jumps 180 degrees counter-clockwise")
    assert [(c.kind, c.with_previous) for c in r.clauses] == [("jump_up", False), ("unknown", True)]
    r = read_prompt("a person jumps up with a 90 degree turn to the right")
    assert [(c.kind, c.unknown, c.with_previous) for c in r.clauses] == [
        ("jump_up", None, False),
        ("unknown", "turn in the air", True),
    ]
    assert kinds("a man hops forward") == ["jump_forward"]
    assert kinds("a man jumps over a small box") == ["jump_forward"]
    assert kinds("a man turns on his left foot") == ["turn_around"]
    assert kinds("someone walks and turns on the spot") == ["walk", "turn_around"]
    assert [c.unknown for c in read_prompt("a dancer does a full spin").clauses] == ["turn 360 degrees"]


def test_more_words_for_known_kinds():
    assert kinds("someone walks around in an oval") == ["circle"]
    assert kinds("a person walks clockwise") == ["circle"]
    assert kinds("a man walks a quarter of a circle to the left") == ["turn"]
    assert kinds("someone shuffles forward") == ["walk"]
    assert kinds("a person takes a diagonal step to the front and left") == ["walk"]
    assert kinds("a person moves crabwise to the left") == ["sidestep"]
    assert kinds("the man walks away") == ["walk"]
    assert kinds("a woman jumps to the front") == ["jump_forward"]
    assert kinds("someone stands up from lying on the floor") == ["get_up"]
    assert kinds("a person performs a waltz-like dance") == ["mocap:dance-long"]
    assert kinds("the man runs to a certain point") == ["run"]
    r = read_prompt("someone sits down on the ground")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("unknown", "sit down on the floor")]
    assert kinds("a person sits down on the ground and lies back") == ["lie_down"]  # the corpus's own phrasing


def test_plan_text_is_the_users_words_with_a_subject_where_one_was_left_out():
    r = read_prompt("Before sitting down, the old man waves. After that he is bowing.")
    assert r.segment_texts() == ["the old man waves", "the old man sits down", "he is bowing"]
    r = read_prompt("A woman walks forward while waving and then turns left")
    assert r.segment_texts() == ["A woman walks forward while waving", "A woman turns left"]
    r = read_prompt("After lying down, a person gets up")
    assert r.segment_texts() == ["a person lies down", "a person gets up"]
    r = read_prompt("A man walks forward. While jogging, he claps. They sit down and then getting up")
    assert r.segment_texts() == ["A man walks forward", "While jogging, he claps", "They sit down", "They get up"]


def test_reading_one_prompt_is_fast():
    import time

    text = (
        "A person walks forward two steps, turns around to the left while waving, then backward and forward "
        "again, kneels down to pick up a box and finally walks away."
    )
    read_prompt(text)
    t0 = time.perf_counter()
    for _ in range(20):
        read_prompt(text)
    assert (time.perf_counter() - t0) / 20 < 0.05


def test_misspelt_joining_words_still_join():
    # "an" before a consonant is never the article, and "the" before a verb with its object is "then"
    assert plan_kinds("a person is sitting down an standing up") == [("sit_down",), ("stand_up",)]
    assert plan_kinds("a man walks ahead and the takes a bow") == [("walk",), ("bow",)]
    assert plan_kinds("someone jogs two steps the turn around") == [("jog",), ("turn_around",)]
    assert plan_kinds("a woman jogs forward adn sits down") == [("jog",), ("sit_down",)]
    assert plan_kinds("someone walks forward the turns right 90 degrees") == [("walk",), ("turn",)]
    # "than" with no comparative before it is "then"; after one it compares
    assert plan_kinds("a woman jogs in place than sits down") == [("jog",), ("sit_down",)]
    assert plan_kinds("a person is waving and than sitting down") == [("wave",), ("sit_down",)]
    assert plan_kinds("a person walks more than ten steps") == [("walk",)]
    assert plan_kinds("a person walks faster than before") == [("walk",)]
    # a real article stays one: "takes the turn to the left" is the corpus's walk-and-turn
    assert plan_kinds("a person walks forward and takes the turn to the left") == [("turn",)]


def test_coming_to_a_halt_slowing_down_or_closing_the_feet_ends_the_movement():
    assert kinds("a woman runs ahead and comes to a halt") == ["run"]
    assert kinds("someone jogs forward then getting slower") == ["jog"]
    assert kinds("a man takes a step to the left and closes his legs") == ["sidestep"]
    # the steps before a stop are the movement's own, not a walk
    assert kinds("a person stumbles and stops after three steps") == ["unknown"]


def test_during_and_when_say_when():
    assert plan_kinds("During jogging a man is shoved from the left") == [("jog", "unknown")]
    assert plan_kinds("When walking, he waves") == [("walk", "wave")]
    # an event after ", when" interrupts what went before: in the order of the text
    assert plan_kinds("a woman runs forward, when she kicks a ball") == [("run",), ("kick",)]


def test_one_verb_done_both_ways_is_one_clause():
    assert kinds("a man looks to the right and left") == ["unknown"]


def test_the_way_an_action_is_done_is_no_action_of_its_own():
    # a hand as support, keeping one's balance, a guard position, what does not happen
    assert kinds("someone kneels on the ground with the right hand as a support") == ["kneel"]
    assert kinds("a woman squats, using her hands as extra support") == ["squat"]
    assert kinds("a man lunges forward and keeps his balance with both arms") == ["lunge"]
    assert kinds("someone kicks with the right leg, holding the fists up in a guard position") == ["kick"]
    assert kinds("a person is shoved and steps back so he does not fall") == ["unknown", "walk_backward"]
    # "as he does so": the clause before runs with the one before it
    r = read_prompt("a woman walks forward and claps as she does so")
    assert plan_kinds(r.text) == [("clap", "walk")]


def test_keeping_on_with_a_gerund_names_the_action():
    assert plan_kinds("a man jogs, turns around and keeps on jogging") == [("jog",), ("turn_around",), ("jog",)]


def test_steps_to_a_side_stay_sidesteps_and_steps_to_the_front_are_walks():
    # a sidestep repeated with a side left out of its verb stays a sidestep
    r = read_prompt("someone sidesteps to the left, then to the right")
    assert [(c.kind, c.direction) for c in r.clauses] == [("sidestep", "left"), ("sidestep", "right")]
    # a count whose noun is left out counts the steps named before: "three to the left" are steps
    assert kinds("a man takes two steps ahead, three to the left and three back") == ["walk", "sidestep", "sidestep"]
    # a side step to the front is a step forward
    r = read_prompt("a woman makes a 30 degree side step to the front")
    assert [(c.kind, c.count) for c in r.clauses] == [("walk", 1)]
    # crossing the feet is part of the sidestep; going back to the start after it is a sidestep back
    r = read_prompt("a person steps to the right, crosses over with the left foot and returns to the start")
    assert [(c.kind, c.direction) for c in r.clauses] == [("sidestep", "right"), ("sidestep", "left")]


def test_a_posture_held_is_not_a_second_action_and_a_while_is_no_joining_word():
    assert kinds("a man kneels down, kneels there for a moment, then gets up") == ["kneel", "stand_up"]
    assert plan_kinds("someone sits down, stays for a little while and stands up") == [("sit_down",), ("stand_up",)]


def test_a_bare_verb_after_a_complete_verb_phrase_is_the_next_clause():
    # the -s left off the second verb of a list: the object's head closed the phrase before
    assert plan_kinds("a man jogs three steps turn around") == [("jog",), ("turn_around",)]
    assert plan_kinds("a person takes two steps back kick with the right leg") == [("walk_backward",), ("kick",)]
    # a noun after an adjective of way is no verb: "a wide left curve"; a number before "point" makes it a noun
    assert kinds("a man walks from 1 point to the next") == ["walk"]
    assert plan_kinds("someone walks in a wide left curve") == [("turn",)]
    # "to another" is a pronoun, so the -s word after it is the verb
    assert plan_kinds("a man walks from one spot to another turns around and sits down") == [
        ("walk",),
        ("turn_around",),
        ("sit_down",),
    ]


def test_repeating_says_the_actions_before_again():
    assert plan_kinds("a man bows, claps and then does it again") == [("bow",), ("clap",), ("bow",), ("clap",)]
    assert plan_kinds("A woman kicks with the left leg. She repeats the movement.") == [("kick",), ("kick",)]
    # the copies are the user's own words for the actions
    assert read_prompt("someone squats and repeats it").segment_texts() == ["someone squats", "someone squats"]
    # "does it" with no "again" is no repeat
    assert kinds("a man does it") == ["unknown"]


def test_two_verbs_sharing_one_object_are_one_clause():
    assert kinds("a woman lifts and lowers both arms") == ["raise_arm"]


def test_coming_to_rest_is_no_purpose():
    assert kinds("a woman jogs ahead and comes to rest") == ["jog"]


def test_holding_a_thing_while_acting_on_it_is_one_action():
    r = read_prompt("someone holds a plate and scrubs it")
    assert [c.kind for c in r.clauses] == ["unknown"] and r.clauses[0].unknown == "wipe"
    assert len(read_prompt("a man plays the guitar, holding it against his belly").clauses) == 1
    # picking a thing up and then holding it stays two
    assert len(read_prompt("a woman picks up a bag and holds it").clauses) == 2


def test_bending_the_knees_or_leaning_before_a_jump_or_walk_is_its_way():
    assert kinds("a man bends the knees slightly and hops") == ["hop"]
    assert kinds("someone leans forward and runs") == ["run"]


def test_a_way_before_the_noun_says_what_it_says_after_the_verb():
    r = read_prompt("a woman does a left jump")
    assert [(c.unknown, c.direction) for c in r.clauses] == [("jump sideways", "left")]
    assert read_prompt("someone makes a small backward hop").clauses[0].unknown == "jump backward"
    assert kinds("a man makes a big jump") == ["jump_up"]


def test_a_misspelt_motion_word_is_read_as_the_word_and_a_real_word_is_left_alone():
    assert kinds("a woman wakls backwards") == ["walk_backward"]
    assert kinds("a woman is jumpnig in place") == ["jump_up"]
    assert correct_word("talking") == "talking"  # a word, although one letter from "walking"
    assert correct_word("hobble") == "hobble"  # the first letter is never the slip
    assert correct_word("lager") == "lager"  # no misspelling is made into a joining word
    # two lexicon words one edit away: which one is meant is not known
    assert correct_word("stoped") == "stoped"


def test_a_comparison_is_no_clause_of_its_own():
    assert plan_kinds("someone is punching the air like he is boxing") == [("punch",)]
    assert plan_kinds("a woman is kicking high like she is doing a kick in karate") == [("kick",)]
    assert plan_kinds("a man punches like he is boxing, then sits down") == [("punch",), ("sit_down",)]


def test_a_turn_joined_to_a_jump_by_and_is_made_in_the_air():
    r = read_prompt("a man jumps and turns 90 degrees to the right")
    assert [[(c.kind, c.unknown) for c in g] for g in r.groups()] == [
        [("jump_up", None), ("unknown", "turn in the air")]
    ]
    assert plan_kinds("a man jumps, then turns around") == [("jump_up",), ("turn_around",)]


def test_a_half_turn_on_the_spot_is_turning_around_and_a_walked_one_a_turn():
    assert kinds("a woman rotates on her axis by 180 degrees") == ["turn_around"]
    assert kinds("a man walks a 180 degree curve to the left") == ["turn"]
    assert plan_kinds("someone walks ahead, changes direction and walks the other way") == [
        ("walk",),
        ("turn_around",),
        ("walk",),
    ]


def test_against_the_clock_is_counterclockwise():
    r = read_prompt("a person walks in a circle against the clockwise direction")
    assert [(c.kind, c.direction) for c in r.clauses] == [("circle", "ccw")]


def test_more_phrasings_of_known_kinds_and_of_a_figure_eight():
    assert kinds("a woman does a few knee bends") == ["squat"]  # the body part is the noun's, not a clause
    assert kinds("someone stops jogging") == ["jog"]  # the jog is named, and ends
    assert kinds("a man hits the bag with his left fist") == ["punch"]
    assert plan_kinds("a woman jogs and oversteps a low bar") == [("jog",), ("step_over",)]
    r = read_prompt("a person walks a lying eight")
    assert [(c.kind, c.unknown) for c in r.clauses] == [("unknown", "walk in a figure eight")]


def test_an_unknown_name_becomes_its_kind_once_the_models_know_it(monkeypatch):
    """lexicon.AS_KIND: while push_up and spin_jump are staged the reader names them unknown;
    moved into CATALOGUE (what shipping retrained models does) they read as those kinds, with
    the details they take, and a name the table keeps unknown stays so."""
    from motion_core.corpus import actions, reader
    from motion_core.corpus.kinds import REGISTRY

    assert kinds("a person does five push-ups") == ["unknown"]
    catalogue = dict(actions.CATALOGUE)
    for k in ("push_up", "spin_jump", "swim"):
        catalogue[k] = REGISTRY[k].catalogue
    monkeypatch.setattr(actions, "CATALOGUE", catalogue)
    reader._takes.cache_clear()
    try:
        got = read_prompt("a person does five push-ups").clauses
        assert [c.kind for c in got] == ["push_up"] and got[0].unknown is None
        spin = read_prompt("a person jumps and turns 180 degrees to the left in the air").clauses
        assert "spin_jump" in [c.kind for c in spin]
        assert next(c for c in spin if c.kind == "spin_jump").angle == 180
        assert kinds("a person swims in breaststroke style") == ["unknown"]
    finally:
        monkeypatch.undo()
        reader._takes.cache_clear()
    assert kinds("a person does five push-ups") == ["unknown"]


def test_every_as_kind_entry_names_a_reader_name_and_a_staged_or_known_kind():
    from motion_core.corpus.kinds import all_kinds

    names = {n for n, _ in lexicon.UNKNOWN} | set(lexicon.RULE_NAMES)
    for name, _, kind in lexicon.AS_KIND:
        assert name in names, name
        assert kind is None or kind in all_kinds(), kind


def test_walking_back_with_no_turn_before_is_a_backward_walk():
    # no turn named: back the way it came, still facing forward (PROTOCOL.md, walk_backward)
    assert kinds("a woman strolls ahead, then walks back three steps") == ["walk", "walk_backward"]
    assert kinds("someone jogs forward and goes back again") == ["jog", "walk_backward"]
    # after a turn, the same words are a forward walk the other way
    assert kinds("a woman strolls ahead, turns around, then walks back") == ["walk", "turn_around", "walk"]


def test_a_guard_or_wind_up_before_a_strike_is_the_strike_s_start():
    # incidental arm posture before a kick, a punch or a throw (PROTOCOL.md): not a segment
    assert plan_kinds("a woman raises her guard and kicks with the right leg") == [("kick",)]
    assert plan_kinds("someone brings both hands up for protection and punches twice") == [("punch",)]
    assert plan_kinds("a man winds up and throws a stone far away") == [("throw",)]
    # an arm raised for its own sake, or a guard then a strike in sequence, stays two
    assert plan_kinds("a man lifts his left arm and throws a stone") == [("raise_arm",), ("throw",)]


def test_going_back_to_the_start_after_a_sidestep_is_a_sidestep_the_other_way():
    got = read_prompt("a woman steps to the right, coming back to her original spot").clauses
    assert [(c.kind, c.direction) for c in got] == [("sidestep", "right"), ("sidestep", "left")]


def test_steps_to_regain_balance_after_a_push_are_the_recovery():
    got = read_prompt("a man gets shoved and takes two quick steps to keep his balance").clauses
    assert [(c.kind, c.unknown) for c in got] == [("unknown", "being pushed"), ("unknown", "recovery step")]
    side = read_prompt("a man gets shoved, then walks a little to the right").clauses
    assert [(c.kind, c.direction) for c in side][1] == ("sidestep", "right")


def test_a_passive_with_its_and_left_out_is_a_new_clause():
    assert plan_kinds("a woman jogs ahead is bumped from behind and jogs on") == [("jog",), ("unknown",), ("jog",)]


def test_two_sizes_of_one_step_noun_are_one_walk():
    assert plan_kinds("someone takes a long and two short steps") == [("walk",)]
    assert plan_kinds("someone walks fast and two big steps back") == [("walk",), ("walk_backward",)]


def test_a_turn_between_a_walk_and_a_walk_back_is_a_half_turn():
    assert plan_kinds("a man jogging ahead, turning and jogging back") == [("jog",), ("turn_around",), ("jog",)]
    assert plan_kinds("someone strolls forward then turns and moves backwards") == [
        ("walk",),
        ("turn_around",),
        ("walk_backward",),
    ]


def test_raised_fists_or_an_arm_drawn_back_before_a_strike_are_its_start():
    assert plan_kinds("a woman lifts her fists up to her chin and punches with the left") == [("punch",)]
    assert plan_kinds("someone holds the arms up in a fighting manner and kicks high") == [("kick",)]
    assert plan_kinds("a man pulls his right hand back and throws the ball") == [("throw",)]


def test_coming_back_to_the_start_ends_an_action_done_in_place():
    assert plan_kinds("a woman lunges forward and then goes back to her starting posture") == [("lunge",)]
    assert plan_kinds("someone does a cartwheel and lands back on his feet") == [("unknown",)]
    # after a walk the way back is a walk; after sitting down it is standing up
    assert len(plan_kinds("a man walks forward and returns to the initial position")) == 2


def test_an_aim_after_a_movement_is_not_an_action():
    assert plan_kinds("a woman steps to the left to dodge a ball") == [("sidestep",)]


def test_what_is_done_to_the_thing_an_unknown_action_named_is_the_same_action():
    for text in (
        "a woman grips a cello and plays it with her right arm",
        "a man is playing a trumpet and moving it up",
    ):
        got = read_prompt(text).groups()
        assert [[c.unknown for c in g] for g in got] == [["play an instrument"]], text


def test_holding_a_part_of_the_body_goes_on_through_the_action_said_with_it():
    got = read_prompt("a woman jogs forward and holds her left knee with both hands").groups()
    assert [[c.kind for c in g] for g in got] == [["jog", "unknown"]]


def test_a_sentence_with_no_verb_the_reader_knows_is_one_unknown_action():
    got = read_prompt("a woman knitted a scarf by the window").clauses
    assert [(c.kind, c.words) for c in got] == [("unknown", "a woman knitted a scarf by the window")]
    assert read_prompt("asdf qwer").clauses == ()


def test_steps_after_a_preposition_or_a_noun_are_not_a_verb():
    assert plan_kinds("a man walks down steps") == [("unknown",)]  # the stairs the corpus lacks
    assert plan_kinds("a man takes some careful balance steps to the right") == [("sidestep",)]


def test_a_square_or_rectangle_walked_is_a_closed_path():
    assert plan_kinds("someone walks in a big square") == [("circle",)]


def test_a_u_turn_at_the_end_of_a_walk_is_its_curve_and_between_walks_a_half_turn():
    assert plan_kinds("a woman jogs ahead and does a u-turn") == [("turn",)]
    assert plan_kinds("a woman jogs ahead, does a u-turn and jogs back") == [("jog",), ("turn_around",), ("jog",)]


def test_together_words_at_a_clause_s_end_put_it_with_the_clause_before():
    assert plan_kinds("a man jogs on the spot and claps during that") == [("clap", "jog")]
    assert plan_kinds("someone strolls ahead and nods at the same time.") == [("unknown", "walk")]


def test_a_starting_stance_said_as_a_clause_is_no_segment():
    assert plan_kinds("someone is in a defensive pose and ducks to the left") == [("unknown",)]


def test_bearing_the_body_s_weight_on_a_hand_is_how_an_action_is_done():
    assert plan_kinds("a woman sits down, supporting her weight with both arms") == [("sit_down",)]


def test_every_staged_kind_has_words_the_reader_reads_it_by():
    """Each staged kind is named by AS_KIND (an unknown name) or FINER_KIND (a finer way of a known
    kind), so that shipping it changes what the reader says."""
    from motion_core.corpus.actions import CATALOGUE
    from motion_core.corpus.kinds import all_kinds

    staged = set(all_kinds()) - set(CATALOGUE)
    named = {k for _, _, k in lexicon.AS_KIND} | {k for _, _, k in lexicon.FINER_KIND}
    assert staged <= named, sorted(staged - named)
    for kind, _, finer in lexicon.FINER_KIND:
        assert kind in CATALOGUE and finer in staged, (kind, finer)


def test_gestures_to_the_body_and_finer_kinds_read_as_staged_kinds_once_shipped(monkeypatch):
    from motion_core.corpus import actions, reader
    from motion_core.corpus.kinds import REGISTRY

    said = {
        "a man shrugs his shoulders": "shrug",
        "a woman does bicep curls with both arms": "bicep_curls",
        "someone scratches the back of his head": "scratch_head",
        "a person rubs her chin": "touch_face",
        "a man bends over and touches his toes": "touch_toes",
        "someone folds the hands together to pray": "clasp_hands",
        "a woman crosses her arms": "cross_arms",
        "a man places both hands on his hips": "hands_on_hips",
        "a woman kneels down on both knees": "kneel_down",
        "someone marches on the spot": "march_in_place",
        "a man walks slowly along a line, heel to toe": "walk_a_line",
    }
    before = {t: [c.kind for c in read_prompt(t).clauses] for t in said}
    assert before["a woman kneels down on both knees"] == ["kneel"]
    assert before["someone marches on the spot"] == ["walk"]
    catalogue = dict(actions.CATALOGUE)
    for k in set(said.values()):
        catalogue[k] = REGISTRY[k].catalogue
    monkeypatch.setattr(actions, "CATALOGUE", catalogue)
    reader._takes.cache_clear()
    try:
        for text, kind in said.items():
            assert kind in [c.kind for c in read_prompt(text).clauses], (text, before[text])
    finally:
        monkeypatch.undo()
        reader._takes.cache_clear()
    assert kinds("a person puts the hands on the hips") == ["unknown"]
    assert kinds("a person walks with the hands on the hips") == ["walk"]  # incidental posture


def test_the_for_then_before_a_turn_to_a_side():
    assert plan_kinds("a woman jogs a few steps ahead and the turns to the left") == [("jog",), ("turn",)]
    assert plan_kinds("a woman walks and takes the turns to the left") == [("turn",)]  # the noun


def test_words_run_together_are_read_apart_and_kept_as_written():
    got = read_prompt("SlowWalk").clauses
    assert [(c.kind, c.words) for c in got] == [("walk", "SlowWalk")]
    assert kinds("Left_Side_Kicking002") == ["kick"]


def test_commands_with_no_joining_word_split_at_each_new_verb():
    assert plan_kinds("jog ahead turn right jog ahead") == [("jog",), ("turn",), ("jog",)]
    assert plan_kinds("Squat Jump Clap") == [("squat",), ("jump_up",), ("clap",)]
    # one action named two ways, a jump's own turn, a step noun and a noun before the verb stay one
    assert len(plan_kinds("kick/punch")) == 1
    assert len(plan_kinds("HopTurn")) == 1
    assert plan_kinds("practise dance steps") == [("mocap:dance-long",)]
    assert plan_kinds("take a slow walk") == [("walk",)]


def test_arms_spread_opened_or_stretched_out_are_raised_and_a_bare_stretch_is_the_stretch():
    for text in (
        "a woman spreads her arms",
        "someone opens his arms wide",
        "a man is stretching out both arms",
        "a girl extends her arms outwards",
        "a woman stretches her right arm forward",
    ):
        assert kinds(text) == ["raise_arm"], text
    assert kinds("a man stretches his arms") == ["stretch"]
    assert kinds("someone opens a window") == ["unknown"]


def test_bending_or_leaning_forward_is_a_bow_but_during_a_walk_its_posture():
    assert kinds("a woman leans forward a little") == ["bow"]
    assert kinds("a man is bending slightly forward") == ["bow"]
    assert plan_kinds("a woman leans forward and then jogs away") == [("bow",), ("jog",)]
    assert plan_kinds("a man runs, leaning forward") == [("run",)]
    assert plan_kinds("someone walks ahead while bending forward") == [("walk",)]


def test_a_count_of_steps_with_no_way_is_the_count_of_the_walk_before():
    assert plan_kinds("a man jogs ahead and takes six steps") == [("jog",)]
    assert plan_kinds("a woman walks a half circle to the left, taking five steps") == [("turn",)]
    # a way of their own, or after a turn, they are a walk of their own
    assert plan_kinds("a man jogs ahead and takes two steps back") == [("jog",), ("walk_backward",)]
    assert plan_kinds("a woman turns around and takes three steps") == [("turn_around",), ("walk",)]


def test_a_way_after_a_comma_is_the_way_of_the_curve_before():
    got = read_prompt("someone strolls in a wide circle, to the left").clauses
    assert [(c.kind, c.direction) for c in got] == [("circle", "ccw")]
    assert len(plan_kinds("someone jogs ahead, then to the left")) == 2


def test_looking_down_said_after_a_walk_is_its_head_posture():
    assert plan_kinds("a woman strolls ahead, looking down") == [("walk",)]


def test_than_after_and_is_then_and_again_before_a_way_is_still_a_way():
    assert plan_kinds("a man jogs ahead and than turns around") == [("jog",), ("turn_around",)]
    assert plan_kinds("a woman walks two steps back and then again forward") == [("walk_backward",), ("walk",)]


def test_a_sport_named_before_its_exercises_is_no_verb():
    assert len(plan_kinds("a man is doing some gym exercises")) == 1
    assert len(plan_kinds("she does yoga exercises with both arms")) == 1


def test_a_hop_back_after_a_half_turn_is_a_hop_forward_again():
    got = plan_kinds("a girl hops ahead, turns around and hops back")
    assert got == [("jump_forward",), ("turn_around",), ("jump_forward",)]
    assert kinds("a girl hops back") == ["unknown"]  # with no turn, backwards


def test_steps_after_an_action_done_in_place_are_a_walk_not_that_action_again():
    assert plan_kinds("a man claps, then three steps forward") == [("clap",), ("walk",)]
    assert plan_kinds("a man kicks, then the left one") == [("kick",), ("kick",)]


def test_hands_held_before_the_chest_are_raised_and_a_thing_held_is_not():
    assert kinds("a woman holds her hands in front of her chest") == ["raise_arm"]
    assert kinds("a woman holds a cup in front of her with both hands") == ["unknown"]


def test_an_s_shaped_walk_is_a_slalom():
    got = read_prompt("a man walks ahead in an S-shape").clauses
    assert [(c.kind, c.unknown) for c in got] == [("unknown", "walk in a slalom")]


def test_a_change_of_direction_is_a_turn_and_a_blow_received_is_a_push():
    assert plan_kinds("a woman changes abruptly the direction and then jogs to the right") == [("turn",), ("jog",)]
    assert kinds("a man makes a quick change in walking direction") == ["turn"]
    got = read_prompt("a man takes a hard kick in the side").clauses
    assert [c.unknown for c in got] == ["being pushed"]
    assert kinds("a man throws a punch") == ["punch"]


def test_words_in_brackets_with_no_verb_say_how_the_clause_before_is_done():
    got = read_prompt("a woman strolls in a circle (left turn)").groups()
    assert [[(c.kind, c.direction, c.words) for c in g] for g in got] == [
        [("circle", "ccw", "a woman strolls in a circle (left turn)")]
    ]
    assert len(plan_kinds("a man jogs ahead (slowly) and turns right")) == 2
    assert plan_kinds("a man jogs ahead (then he sits down)") == [("jog",), ("sit_down",)]
