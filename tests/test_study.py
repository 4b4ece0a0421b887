"""User study without a server: statistics against hand computations, storage rules,
balanced anonymous trials, rate limits and the output sweeper."""

from __future__ import annotations

import itertools
import json
import math
import os
import random
import threading
import time
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize

from app.cleanup import sweep_outputs
from app.limits import RateLimited, RateLimiter
from app.study import StudyError, StudyService
from app.study_config import SAMPLE_CONFIG, StudyConfigError, load_config, parse_config
from app.study_stats import bradley_terry, bradley_terry_strengths, criteria_table, pair_table, votes_csv, wilson
from app.study_store import NewTrial, StudyStore, VoteRejected
from motion_core.body.skeleton import HUMANML3D
from motion_core.formats.gltf import glb_bytes, read_glb_joints


def vote(a: str, b: str, answer: str, criteria: dict | None = None, participant: str = "p") -> dict:
    return {"method_a": a, "method_b": b, "answer": answer, "criteria": criteria or {}, "participant": participant}


# ---------------------------------------------------------------- statistics
def test_wilson_interval_matches_the_formula_by_hand():
    # 7 of 10: p=0.7, z=1.96 -> centre (0.7 + 0.19208)/1.38416, half 1.96*sqrt(0.021 + 0.00096)/1.38416
    lo, hi = wilson(7, 10)
    z = 1.959963984540054
    centre = (0.7 + z * z / 20) / (1 + z * z / 10)
    half = z * math.sqrt(0.7 * 0.3 / 10 + z * z / 400) / (1 + z * z / 10)
    assert lo == pytest.approx(centre - half) and hi == pytest.approx(centre + half)
    assert (round(lo, 3), round(hi, 3)) == (0.397, 0.892)  # the textbook value for 7/10
    assert wilson(0, 0) == (0.0, 1.0)


def test_pair_table_counts_from_the_sorted_pairs_point_of_view():
    votes = [
        vote("x", "y", "A"),  # x wins
        vote("y", "x", "A"),  # y wins
        vote("y", "x", "B"),  # x wins
        vote("x", "y", "tie"),
        vote("y", "x", "both_bad"),
    ]
    (row,) = pair_table(votes)
    assert (row["method_1"], row["method_2"], row["n"]) == ("x", "y", 5)
    assert (row["wins_1"], row["wins_2"], row["ties"], row["both_bad"]) == (2, 1, 1, 1)
    assert row["win_rate_1"] == pytest.approx(2 / 3)
    assert row["ci95_1"] == pytest.approx(list(wilson(2, 3)))


def test_bradley_terry_two_methods_has_the_closed_form():
    # 6 wins for x, 2 for y, 2 ties: with ties as half wins, p_x/p_y = (6+1)/(2+1)
    votes = [vote("x", "y", "A")] * 6 + [vote("y", "x", "A")] * 2 + [vote("x", "y", "tie")] * 2
    index = {"x": 0, "y": 1}
    from app.study_stats import _win_matrix

    p = bradley_terry_strengths(_win_matrix(votes, index), prior=0.0)
    assert p[0] / p[1] == pytest.approx(7 / 3, rel=1e-9)
    p1 = bradley_terry_strengths(_win_matrix(votes, index), prior=1.0)  # one virtual tie
    assert p1[0] / p1[1] == pytest.approx(7.5 / 3.5, rel=1e-9)
    ranking = bradley_terry(votes, ["x", "y"], rounds=200)
    assert [r["method"] for r in ranking] == ["x", "y"]
    assert ranking[0]["score"] - ranking[1]["score"] == pytest.approx(400 * math.log10(7.5 / 3.5))
    for r in ranking:
        assert r["ci95"][0] <= r["score"] <= r["ci95"][1]


def test_bradley_terry_three_methods_equals_a_direct_likelihood_fit():
    rng = random.Random(3)
    true = {"x": 2.0, "y": 1.0, "z": 0.5}
    votes = []
    for _ in range(300):
        a, b = rng.sample(list(true), 2)
        pa = true[a] / (true[a] + true[b])
        votes.append(vote(a, b, "A" if rng.random() < pa else "B"))
    from app.study_stats import _win_matrix

    W = _win_matrix(votes, {"x": 0, "y": 1, "z": 2})
    p = bradley_terry_strengths(W, prior=0.0)

    def nll(theta):  # theta = log strengths, z fixed at 0
        s = np.append(theta, 0.0)
        return -sum(W[i, j] * (s[i] - np.logaddexp(s[i], s[j])) for i in range(3) for j in range(3) if i != j)

    theta = minimize(nll, np.zeros(2), method="BFGS", options={"gtol": 1e-10}).x
    direct = np.exp(np.append(theta, 0.0))
    assert p / p[2] == pytest.approx(direct / direct[2], rel=1e-4)
    assert list(np.argsort(-p)) == [0, 1, 2]


def test_criteria_table_and_csv():
    votes = [
        vote("x", "y", "A", {"realism": "A", "text": "B"}),
        vote("y", "x", "B", {"realism": "A"}),
        vote("y", "x", "tie", {"realism": "tie"}),
    ]
    rows = criteria_table(votes, ["realism", "text"])
    realism = next(r for r in rows if r["criterion"] == "realism")
    assert (realism["n"], realism["wins_1"], realism["wins_2"], realism["ties"]) == (3, 1, 1, 1)
    text = next(r for r in rows if r["criterion"] == "text")
    assert (text["n"], text["wins_1"], text["wins_2"]) == (1, 0, 1)
    csv_text = votes_csv([{**v, "vote_id": i} for i, v in enumerate(votes)])
    assert csv_text.splitlines()[0].startswith("vote_id,participant,trial")
    assert len(csv_text.strip().splitlines()) == 4


# ---------------------------------------------------------------- configuration
def test_sample_config_loads_and_bad_configs_say_why(tmp_path):
    cfg = load_config(SAMPLE_CONFIG)
    assert len(cfg.methods) >= 2 and cfg.prompts and cfg.trials_per_participant >= 1
    assert sorted(cfg.pairs) == sorted(itertools.combinations(sorted(cfg.methods), 2))
    with pytest.raises(StudyConfigError, match="methods"):
        parse_config({"methods": ["motion_mamba"], "prompts": ["a person walks"]})
    with pytest.raises(StudyConfigError, match="unknown method"):
        parse_config({"methods": ["motion_mamba", "nope"], "prompts": ["a person walks"]})
    with pytest.raises(StudyConfigError, match="prompts\\[0\\]"):
        parse_config({"methods": ["motion_mamba", "baseline"], "prompts": [{"text": "", "seconds": 2}]})
    with pytest.raises(StudyConfigError, match="prompts\\[0\\]"):
        parse_config({"methods": ["motion_mamba", "baseline"], "prompts": [{"text": "walk", "seconds": 99}]})
    p = tmp_path / "study.json"
    p.write_text(json.dumps({"methods": ["baseline", "motion_mamba"], "prompts": ["a person walks"], "seeds": [3]}))
    assert load_config(p).seeds == (3,)
    (tmp_path / "broken.yaml").write_text("methods: [")
    with pytest.raises(StudyConfigError, match="cannot read"):
        load_config(tmp_path / "broken.yaml")


# ---------------------------------------------------------------- storage
@pytest.fixture(params=["sqlite", "postgresql"])
def store(request, tmp_path):
    """Each storage test and each study-logic test runs twice: on SQLite in tmp_path, and on
    a fresh database of a throw-away PostgreSQL cluster (conftest.postgres)."""
    if request.param == "sqlite":
        url = f"sqlite:///{tmp_path / 'study.sqlite'}"
    else:
        url = request.getfixturevalue("postgres").new_database()
    s = StudyStore(url)
    yield s
    s.close()


def test_the_postgresql_store_is_postgresql(postgres):
    """The second run of the storage tests really talks to PostgreSQL, on its own database."""
    s = StudyStore(postgres.new_database())
    try:
        assert s.engine.dialect.name == "postgresql"
        with s.engine.connect() as c:
            assert c.exec_driver_sql("select version()").scalar().startswith("PostgreSQL")
        assert s.counts() == {"participants": 0, "trials": 0, "votes": 0}
    finally:
        s.close()


@pytest.mark.parametrize("backend", ["sqlite", "postgresql"])
def test_replicas_starting_together_create_the_tables_once(backend, request, tmp_path):
    """Six stores opening one empty database at once, as replicas of a space starting together
    do: on PostgreSQL an unguarded CREATE TABLE race fails with a duplicate pg_type row."""
    if backend == "sqlite":
        url = f"sqlite:///{tmp_path / 'study.sqlite'}"
    else:
        url = request.getfixturevalue("postgres").new_database()
    barrier = threading.Barrier(6)
    errors: list[str] = []

    def open_store() -> None:
        barrier.wait()
        try:
            StudyStore(url).close()
        except Exception as e:  # every failure is collected, none hides another
            errors.append(f"{type(e).__name__}: {e}")

    threads = [threading.Thread(target=open_store) for _ in range(6)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert errors == []
    s = StudyStore(url)
    assert s.counts() == {"participants": 0, "trials": 0, "votes": 0}
    s.close()


def _trial(**kw) -> NewTrial:
    base = dict(
        prompt="a person walks",
        seconds=2.0,
        seed=0,
        method_a="x",
        method_b="y",
        swapped=False,
        gen_seconds_a=0.1,
        gen_seconds_b=0.2,
    )
    return NewTrial(**{**base, **kw})


def test_one_vote_per_trial_and_forged_or_foreign_trials_are_rejected(store):
    p1, p2 = store.new_participant("s"), store.new_participant("s")
    t1, pos = store.add_trial(p1, _trial())
    assert pos == 0 and len(t1) == 32
    assert store.record_vote(p1, t1, "A", {"realism": "B"}) == 1
    with pytest.raises(VoteRejected, match="already"):
        store.record_vote(p1, t1, "B")  # replay
    with pytest.raises(VoteRejected, match="unknown trial"):
        store.record_vote(p2, t1, "A")  # someone else's trial
    with pytest.raises(VoteRejected, match="unknown trial"):
        store.record_vote(p1, "0" * 32, "A")  # forged id
    with pytest.raises(VoteRejected, match="answer"):
        store.record_vote(p1, store.add_trial(p1, _trial())[0], "C")
    with pytest.raises(VoteRejected, match="criterion"):
        store.record_vote(
            p1, store.add_trial(p1, _trial())[0], "A", {"speed": "A"}, allowed_criteria={"realism": ("A",)}
        )
    rows = store.votes("s")
    assert len(rows) == 1 and rows[0]["winner"] == "x" and rows[0]["criteria"] == {"realism": "B"}
    assert store.counts() == {"participants": 2, "trials": 3, "votes": 1}


def test_racing_replays_store_exactly_one_vote(store):
    p = store.new_participant("s")
    t, _ = store.add_trial(p, _trial())
    outcomes: list[str] = []

    def cast() -> None:
        try:
            store.record_vote(p, t, "A")
            outcomes.append("stored")
        except VoteRejected:
            outcomes.append("rejected")

    threads = [threading.Thread(target=cast) for _ in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert sorted(outcomes) == ["rejected"] * 7 + ["stored"]
    assert store.counts()["votes"] == 1


def test_sqlite_is_durable_mode(tmp_path):
    store = StudyStore(f"sqlite:///{tmp_path / 'study.sqlite'}")
    with store.engine.connect() as c:
        assert c.exec_driver_sql("PRAGMA journal_mode").scalar() == "wal"
        assert c.exec_driver_sql("PRAGMA synchronous").scalar() == 2  # FULL


# ---------------------------------------------------------------- the service
FAKE_SAMPLERS = {"motion_mamba": "fast", "baseline": "quality"}


def fake_glb(method: str, text: str, seconds: float, seed: int, sampler: str | None = None) -> tuple[bytes, float, str]:
    """A real (tiny) anonymous GLB; the motion is a straight line, fast to make, 1 m long
    from the "quality" sampler and 2 m from the "fast" one. The default sampler is the
    method's entry in FAKE_SAMPLERS."""
    sampler = sampler or FAKE_SAMPLERS.get(method, "quality")
    T = int(seconds * 20)
    joints = np.repeat(HUMANML3D.rest_joints()[None].astype(np.float32), T, axis=0)
    joints[:, :, 2] += np.linspace(0, 1 if sampler == "quality" else 2, T, dtype=np.float32)[:, None]
    extras = {"fps": 20, "frames": T, "segments": [{"text": text, "start": 0, "end": T}]}
    return glb_bytes(joints, 20, extras=extras), 0.01, sampler


def fake_samplers(method: str) -> tuple[str, tuple[str, ...]]:
    return FAKE_SAMPLERS.get(method, "quality"), ("quality", "fast")


def make_service(store, tmp_path, samplers_of=fake_samplers, **overrides) -> StudyService:
    data = {
        "name": "s",
        "methods": ["motion_mamba", "baseline"],
        "prompts": [{"text": f"a person walks {w}", "seconds": 1} for w in ("forward", "back", "left")],
        "seeds": [0, 1],
        "trials_per_participant": 3,
        **overrides,
    }
    return StudyService(
        parse_config(data), store, tmp_path / "out", generate=fake_glb, samplers_of=samplers_of, rng=random.Random(0)
    )


def test_the_study_page_shows_its_configured_title_and_instructions_as_text(store, tmp_path):
    """A study's title is the organiser's text, never markup (the browser test's config is
    clean so that its screenshot can go in the README)."""
    from app.study_ui import build_study

    svc = make_service(store, tmp_path, title="Which is better? <b>bold?</b>", instructions="<i>watch</i>")
    intro = next(b for b in build_study(svc).blocks.values() if getattr(b, "elem_id", None) == "study-intro")
    assert "<b>" not in intro.value and "<i>" not in intro.value
    assert "&lt;b&gt;bold?&lt;/b&gt;" in intro.value and "&lt;i&gt;watch&lt;/i&gt;" in intro.value


def test_trials_are_balanced_randomised_and_anonymous(store, tmp_path):
    svc = make_service(store, tmp_path)
    views = []
    for _ in range(24):
        v = svc.start()
        while not v["done"]:
            views.append(v)
            v = svc.vote(v["participant"], v["trial"], random.choice(["A", "B", "tie", "both_bad"]))
        assert v["votes"] == 3
        assert svc.resume(v["participant"]) == {**v, "of": 3}  # a finished participant stays done
    assert store.counts() == {"participants": 24, "trials": 72, "votes": 72}
    rows = store.votes("s")
    combos = Counter((r["prompt"], r["seed"]) for r in rows)
    assert len(combos) == 6 and max(combos.values()) - min(combos.values()) <= 1  # 72 trials over 6 combos
    swapped = sum(r["swapped"] for r in rows)
    assert 20 <= swapped <= 52  # random order: about half
    per_participant = Counter()
    for r in rows:
        per_participant[(r["participant"], r["prompt"])] += 1
    assert max(per_participant.values()) == 1  # no participant sees a prompt twice (3 prompts, 3 trials)
    names = ["motion_mamba", "baseline", "Motion Mamba", "Transformer"]
    for v in views:
        text = json.dumps(v).lower()
        assert not any(n.lower() in text for n in names), v
        for side in ("a", "b"):
            path = Path(v[side].split("file=", 1)[1])
            assert path.name == f"{side}.glb" and path.is_file()
            blob = path.read_bytes().lower()
            assert not any(n.lower().encode() in blob for n in names)
            _, extras = read_glb_joints(path.read_bytes())
            # "body" says the file carries the mannequin, the same for every method
            assert set(extras) == {"fps", "frames", "segments", "body"} and extras["body"] == "mannequin"


def longest_run(pairs: list[tuple[str, str]]) -> tuple[int, str]:
    """The most trials in a row one method was in, and that method."""
    best, who = 0, ""
    for m in {m for p in pairs for m in p}:
        run = 0
        for p in pairs:
            run = run + 1 if m in p else 0
            if run > best:
                best, who = run, m
    return best, who


@pytest.mark.parametrize("seed", range(4))
def test_each_participants_first_trials_are_balanced_over_the_pairs(seed, tmp_path):
    """Four methods (six pairs), as in the sample config: every participant, the first one
    included, gets the six pairs in their first six trials and each pair twice in twelve,
    and no method is in more than two trials in a row (it was in four for one participant:
    the choice used to balance the study's counts only, which are all 0 for the first)."""
    store = StudyStore(f"sqlite:///{tmp_path / 'votes.sqlite'}")
    methods = ["kmm", "motion_mamba", "ftmomamba", "baseline"]
    svc = make_service(store, tmp_path, methods=methods, trials_per_participant=12)
    svc._rng = random.Random(seed)
    for _ in range(3):
        v, pairs = svc.start(), []
        while not v["done"]:
            t = store.trial(v["trial"])
            pairs.append(tuple(sorted((t.method_a, t.method_b))))
            v = svc.vote(v["participant"], v["trial"], "A")
        assert len(set(pairs[:6])) == 6, pairs
        assert set(Counter(pairs).values()) == {2}, Counter(pairs)
        run, method = longest_run(pairs)
        assert run <= 2, (method, pairs)
    store.close()


def test_each_motion_is_generated_once_and_shared(store, tmp_path):
    calls = Counter()

    def counting(method, text, seconds, seed, sampler=None):
        calls[(method, text, seed)] += 1
        return fake_glb(method, text, seconds, seed, sampler)

    svc = make_service(store, tmp_path)
    svc._generate = counting
    views = [svc.start() for _ in range(14)]
    trials = [store.trial(v["trial"]) for v in views]
    assert max(calls.values()) == 1 and len(calls) == 12  # 2 methods x 3 prompts x 2 seeds
    # a resumed trial names its samplers; the motions made under the default are found
    svc.resume(views[-1]["participant"])
    assert max(calls.values()) == 1 and len(calls) == 12
    first = {}
    for t in trials:  # each side is "cached" exactly when that motion was made before
        for method, cached in ((t.method_a, t.cached_a), (t.method_b, t.cached_b)):
            key = (method, t.prompt, t.seed)
            assert cached == (key in first)
            first[key] = True


def test_each_trial_records_the_sampler_that_made_each_motion(store, tmp_path):
    """A method's default sampler can change between server versions while a study runs:
    each side's sampler is stored with its trial, and exported with the votes (CSV too)."""
    from app.study_stats import votes_csv

    svc = make_service(store, tmp_path)
    v = svc.start()
    while not v["done"]:
        v = svc.vote(v["participant"], v["trial"], "A")
    rows = store.votes("s")
    assert len(rows) == 3
    for r in rows:
        assert (r["sampler_a"], r["sampler_b"]) == (FAKE_SAMPLERS[r["method_a"]], FAKE_SAMPLERS[r["method_b"]])
    header, first = votes_csv(rows).splitlines()[:2]
    assert "sampler_a" in header.split(",") and "sampler_b" in header.split(",")
    assert {"fast", "quality"} <= set(first.split(","))


def _served(view: dict, out: Path, side: str) -> bytes:
    return (out / Path(view[side]).parent.name / f"{side}.glb").read_bytes()


def test_a_resumed_trial_shows_the_motions_its_samplers_made_after_the_default_changed(store, tmp_path, monkeypatch):
    """A server restarted with another default sampler (a new student shipped) resumes an
    open trial with the samplers that trial recorded: the participant votes on the motions
    the record says, not on the new default's."""
    svc = make_service(store, tmp_path)
    v = svc.start()
    trial = store.trial(v["trial"])
    recorded = (trial.sampler_a, trial.sampler_b)
    shown = (_served(v, tmp_path / "out", "a"), _served(v, tmp_path / "out", "b"))
    monkeypatch.setitem(FAKE_SAMPLERS, "motion_mamba", "quality")  # the new default
    calls = []

    def spy(method, text, seconds, seed, sampler=None):
        calls.append((method, sampler))
        return fake_glb(method, text, seconds, seed, sampler)

    restarted = make_service(store, tmp_path)
    restarted._generate = spy
    again = restarted.resume(v["participant"])
    assert again["trial"] == v["trial"]
    assert (_served(again, tmp_path / "out", "a"), _served(again, tmp_path / "out", "b")) == shown
    assert sorted(calls) == sorted(zip((trial.method_a, trial.method_b), recorded, strict=True))
    assert "fast" in recorded  # motion_mamba's side: the old default, not today's "quality"
    assert (store.trial(v["trial"]).sampler_a, store.trial(v["trial"]).sampler_b) == recorded


def test_a_resumed_trial_whose_sampler_is_gone_shows_the_default_and_records_it(store, tmp_path):
    """A recorded sampler no longer offered (its student removed): the trial resumes with the
    method's default and its record says so, rather than the participant being stuck."""
    svc = make_service(store, tmp_path)
    v = svc.start()
    calls = []

    def spy(method, text, seconds, seed, sampler=None):
        calls.append(sampler)
        glb, _, made_by = fake_glb(method, text, seconds, seed, sampler)
        return glb, 0.5, made_by  # a generation time the first showing did not have

    before = store.trial(v["trial"])
    gone = "a" if before.sampler_a == "fast" else "b"  # motion_mamba's side recorded "fast"
    kept = "b" if gone == "a" else "a"
    restarted = make_service(store, tmp_path, samplers_of=lambda m: ("quality", ("quality",)))
    restarted._generate = spy
    again = restarted.resume(v["participant"])
    assert again["trial"] == v["trial"] and calls == ["quality", "quality"]
    t = store.trial(v["trial"])
    assert (t.sampler_a, t.sampler_b) == ("quality", "quality")
    # the side that fell back describes the motion now shown; the other keeps its first record
    assert (getattr(t, f"gen_seconds_{gone}"), getattr(t, f"cached_{gone}")) == (0.5, False)
    assert getattr(t, f"gen_seconds_{kept}") == getattr(before, f"gen_seconds_{kept}") == 0.01
    assert getattr(t, f"cached_{kept}") == getattr(before, f"cached_{kept}")
    # a second resume that read the old record at the same time (another tab) writes nothing
    old = (before.sampler_a, before.sampler_b)
    assert not store.set_samplers(v["trial"], old, "quality", "quality", (9.9, True), (9.9, True))
    assert getattr(store.trial(v["trial"]), f"gen_seconds_{gone}") == 0.5
    restarted.vote(v["participant"], v["trial"], "A")
    (row,) = store.votes("s")
    assert (row["sampler_a"], row["sampler_b"]) == ("quality", "quality")
    # a voted trial's record is never changed
    assert not store.set_samplers(v["trial"], ("quality", "quality"), "fast", "fast", (9.9, True), (9.9, True))
    t = store.trial(v["trial"])
    assert (t.sampler_a, t.sampler_b, getattr(t, f"gen_seconds_{gone}"), t.gen_seconds_a + t.gen_seconds_b) == (
        "quality",
        "quality",
        0.5,
        0.51,
    )


def test_a_fallback_motion_from_the_cache_is_recorded_as_cached(store, tmp_path):
    """The default's motion already made (for another participant): the side that falls back
    records the cached motion's time and that it came from the cache."""
    svc = make_service(store, tmp_path)
    v = svc.start()
    before = store.trial(v["trial"])
    gone = "a" if before.sampler_a == "fast" else "b"
    method = getattr(before, f"method_{gone}")
    restarted = make_service(store, tmp_path, samplers_of=lambda m: ("quality", ("quality",)))
    glb, _, _ = fake_glb(method, before.prompt, before.seconds, before.seed, "quality")
    restarted._cache[(method, before.prompt, float(before.seconds), int(before.seed), "quality")] = (
        glb,
        0.7,
        "quality",
    )
    restarted.resume(v["participant"])
    t = store.trial(v["trial"])
    assert (getattr(t, f"sampler_{gone}"), getattr(t, f"gen_seconds_{gone}"), getattr(t, f"cached_{gone}")) == (
        "quality",
        0.7,
        True,
    )


def test_a_trial_from_before_samplers_were_recorded_resumes_and_stays_unrecorded(store, tmp_path):
    """sampler_a / sampler_b None (an older server's trial): today's defaults make its
    motions, and the record stays None, unknown, rather than claiming today's default."""
    from sqlalchemy import update

    from app.study_store import Trial

    svc = make_service(store, tmp_path)
    v = svc.start()
    with store._session.begin() as s:
        s.execute(update(Trial).where(Trial.token == v["trial"]).values(sampler_a=None, sampler_b=None))
    again = make_service(store, tmp_path).resume(v["participant"])
    assert again["trial"] == v["trial"]
    t = store.trial(v["trial"])
    assert (t.sampler_a, t.sampler_b) == (None, None)


def test_a_database_from_before_samplers_were_recorded_opens_with_its_votes(tmp_path):
    """The trials table of an older version lacks the sampler columns: opening it adds them
    (NULL in its rows), keeps every vote, and new trials record their samplers."""
    import sqlite3

    path = tmp_path / "old.sqlite"
    StudyStore(f"sqlite:///{path}").close()
    fresh = StudyStore(f"sqlite:///{tmp_path / 'ref.sqlite'}")
    svc = make_service(fresh, tmp_path)
    v = svc.start()
    svc.vote(v["participant"], v["trial"], "B")
    fresh.close()
    # the older schema: the same trials table without the two columns, with one voted trial
    with sqlite3.connect(tmp_path / "ref.sqlite") as ref, sqlite3.connect(path) as old:
        old.execute("DROP TABLE votes")
        old.execute("DROP TABLE trials")
        cols = [r[1] for r in ref.execute("PRAGMA table_info(trials)") if r[1] not in ("sampler_a", "sampler_b")]
        ddl = ref.execute("SELECT sql FROM sqlite_master WHERE name='trials'").fetchone()[0]
        ddl = "\n".join(line for line in ddl.splitlines() if "sampler_" not in line)
        old.execute(ddl)
        old.execute(ref.execute("SELECT sql FROM sqlite_master WHERE name='votes'").fetchone()[0])
        old.execute("DELETE FROM participants")
        old.executemany("INSERT INTO participants VALUES (?,?,?,?)", ref.execute("SELECT * FROM participants"))
        old.executemany(
            f"INSERT INTO trials ({','.join(cols)}) VALUES ({','.join('?' * len(cols))})",
            ref.execute(f"SELECT {','.join(cols)} FROM trials"),
        )
        old.executemany("INSERT INTO votes VALUES (?,?,?,?,?,?,?,?)", ref.execute("SELECT * FROM votes"))
        assert "sampler_a" not in [r[1] for r in old.execute("PRAGMA table_info(trials)")]
    store = StudyStore(f"sqlite:///{path}")
    (row,) = store.votes("s")
    assert row["answer"] == "B" and row["sampler_a"] is None and row["sampler_b"] is None
    svc = make_service(store, tmp_path)
    v = svc.start()
    svc.vote(v["participant"], v["trial"], "tie")
    new = store.votes("s")[-1]
    assert new["sampler_a"] in ("fast", "quality") and new["sampler_b"] in ("fast", "quality")
    again = StudyStore(f"sqlite:///{path}")  # opening it again changes nothing
    assert again.votes("s") == store.votes("s") and len(again.votes("s")) == 2
    again.close()


def test_a_column_added_on_postgresql_gives_up_with_a_message_when_the_table_is_held(postgres, monkeypatch):
    """An older replica holding a transaction on the trials table: a new version's start-up
    stops with a message after its lock timeout, rather than waiting (and stalling every
    query queued behind its ALTER TABLE), and succeeds once the table is free."""
    import threading

    import psycopg

    import app.study_store as study_store

    url = postgres.new_database()
    StudyStore(url).close()
    from sqlalchemy.engine import make_url

    dsn = f"host={postgres.dir} port=5432 user=mms dbname={make_url(url).database}"
    with psycopg.connect(dsn, autocommit=True) as con:
        con.execute("ALTER TABLE trials DROP COLUMN sampler_a")  # the older schema
    monkeypatch.setattr(study_store, "ALTER_LOCK_TIMEOUT_S", 0.5)
    older = psycopg.connect(dsn)
    older.execute("SELECT count(*) FROM trials").fetchone()  # its open transaction holds the table
    outcome: list[BaseException | None] = []

    def start() -> None:
        try:
            StudyStore(url).close()
            outcome.append(None)
        except BaseException as e:  # the test reads what happened
            outcome.append(e)

    thread = threading.Thread(target=start, daemon=True)
    thread.start()
    thread.join(20)
    try:
        assert not thread.is_alive(), "the start-up waited on the held table"
        (error,) = outcome
        assert isinstance(error, RuntimeError) and "sampler_a" in str(error) and "0.5 s" in str(error), error
    finally:
        older.close()
    thread.join(20)
    store = StudyStore(url)  # the table free again: the column is added
    try:
        with store.engine.connect() as c:
            cols = {
                r[0]
                for r in c.exec_driver_sql(
                    "SELECT column_name FROM information_schema.columns WHERE table_name='trials'"
                )
            }
        assert "sampler_a" in cols
    finally:
        store.close()


def test_custom_prompts_only_when_allowed_and_checked(store, tmp_path):
    svc = make_service(store, tmp_path)
    with pytest.raises(StudyError, match="own prompts"):
        svc.start("a person dances")
    svc = make_service(store, tmp_path, allow_custom_prompts=True, custom_prompt_seconds=1)
    v = svc.start("<script>alert(1)</script> a person dances")
    assert v["prompt"] == "<script>alert(1)</script> a person dances"  # stored and shown as text
    with pytest.raises(StudyError, match="characters"):
        svc.vote(v["participant"], v["trial"], "A", next_prompt="x" * 400)
    assert store.counts()["votes"] == 0  # a rejected next prompt stores nothing
    with pytest.raises(StudyError, match="answer"):
        svc.vote(v["participant"], v["trial"], "left")


# ---------------------------------------------------------------- limits and cleanup
def test_rate_limiter_refuses_bursts_and_refills():
    now = [0.0]
    lim = RateLimiter(rate_per_minute=60, burst=3, clock=lambda: now[0])
    for _ in range(3):
        lim.check("s1")
    with pytest.raises(RateLimited, match="try again in 1 s"):
        lim.check("s1")
    lim.check("s2")  # another session has its own bucket
    now[0] += 1.0
    lim.check("s1")
    RateLimiter(0, 0).check("anyone")  # 0 turns it off


def test_rate_limiter_wait_and_take_count_failures_without_refusing():
    """The admin token's failure counts: ``wait`` says when a key may try again, taking
    nothing; ``take`` spends a token and never raises."""
    now = [0.0]
    lim = RateLimiter(rate_per_minute=6, burst=2, clock=lambda: now[0])
    assert lim.wait("10.0.0.1") == 0
    lim.take("10.0.0.1")
    lim.take("10.0.0.1")
    lim.take("10.0.0.1")  # below empty: stays empty
    assert lim.wait("10.0.0.1") == pytest.approx(10.0)  # one token per 10 s
    assert lim.wait("10.0.0.2") == 0
    now[0] += 10.0
    assert lim.wait("10.0.0.1") == 0
    off = RateLimiter(0, 0)
    off.take("x")
    assert off.wait("x") == 0


def test_the_admin_token_must_be_long_enough(monkeypatch):
    from app.study_ui import admin_token_from_env, check_admin_token

    check_admin_token(None)  # no token: no results view
    check_admin_token("x" * 16)
    with pytest.raises(ValueError, match="15 characters long; use at least 16"):
        check_admin_token("choose-a-secret")
    monkeypatch.setenv("MMS_ADMIN_TOKEN", "  ")
    assert admin_token_from_env() is None
    monkeypatch.setenv("MMS_ADMIN_TOKEN", "short")
    with pytest.raises(ValueError, match="at least 16"):
        admin_token_from_env()


def test_sweeper_removes_only_old_request_folders(tmp_path):
    root = tmp_path / "out"
    root.mkdir()
    old, new = root / ("a" * 32), root / ("b" * 32)
    for d in (old, new):
        d.mkdir()
        (d / "motion.glb").write_bytes(b"x")
    keep = root / "not-a-request-folder"
    keep.mkdir()
    outside = tmp_path / "outside"
    outside.mkdir()
    (root / ("c" * 32)).symlink_to(outside)
    past = time.time() - 7200
    for d in (old, keep):
        os.utime(d, (past, past))
    assert sweep_outputs(root, max_age_s=3600) == 1
    assert not old.exists() and new.exists() and keep.exists() and outside.exists()
