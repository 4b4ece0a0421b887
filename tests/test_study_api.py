"""The user study through its real HTTP API (gradio_client against `MMS_MODE=study python app.py`).

One simulated study of 50 participants with mixed votes, four at a time; the server is
killed with SIGKILL part-way through and restarted on the same database, and the interrupted
participants go on where they were. Checks: every acknowledged vote is stored, the stored
votes equal the votes cast, the results view equals a hand computation, and no payload a
participant can see names a method.
"""

from __future__ import annotations

import json
import math
import os
import random
import signal
import sqlite3
import struct
import threading
import time
import urllib.error
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest
from conftest import REPO, artifact, run_app, study_setup
from gradio_client import Client

import motion_core
from app.study_store import StudyStore

PARTICIPANTS = 50
TRIALS = 3
ADMIN = "test-admin-token-4d1f"
CONFIG = {
    "name": "api-test",
    "methods": ["motion_mamba", "baseline"],
    "seeds": [0],
    "trials_per_participant": TRIALS,
    "criteria": ["realism", "matches the text"],
    "allow_custom_prompts": True,
    "custom_prompt_seconds": 2,
    "prompts": [
        {"text": "a person walks forward", "seconds": 2},
        {"text": "a person waves with the right hand", "seconds": 2},
        {"text": "a person runs forward", "seconds": 2},
    ],
}
# every way a method could be named: internal names, display names, and their short forms
FORBIDDEN = sorted(
    {m["name"].lower() for m in motion_core.methods()}
    | {m["display_name"].lower() for m in motion_core.methods()}
    | {"motion mamba", "motion_mamba", "baseline", "transformer", "kmm", "ftmomamba"}
)


def glb_text(blob: bytes) -> bytes:
    """A GLB's JSON chunk: what it says in words (its binary chunk is vertex and key-frame
    numbers, whose bytes spell 'kmm' by chance now and then: a test run failed on that)."""
    length, kind = struct.unpack_from("<I4s", blob, 12)
    assert blob[:4] == b"glTF" and kind == b"JSON", blob[:20]
    return blob[20 : 20 + length]


def leaks(text: str | bytes) -> list[str]:
    low = (text.decode("latin-1") if isinstance(text, bytes) else text).lower()
    return [n for n in FORBIDDEN if n in low]


@pytest.fixture(scope="module")
def study_env(tmp_path_factory):
    return study_setup(tmp_path_factory.mktemp("study-run"), CONFIG, ADMIN)


class Ledger:
    """What the simulated participants did and what the server acknowledged."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.cast: dict[str, tuple[str, dict]] = {}  # trial -> (answer, criteria), sent
        self.acked: set[str] = set()  # trials whose vote the server confirmed
        self.payloads: list[dict] = []  # every response a participant got
        self.interrupted: list[tuple[str, str]] = []  # (participant, trial in flight)
        self.finished = 0


def participant(url: str, ledger: Ledger, rng: random.Random, resume: str | None = None) -> None:
    client = Client(url, verbose=False)
    view = client.predict(resume, api_name="/study_resume") if resume else client.predict("", api_name="/study_start")
    while True:
        with ledger.lock:
            ledger.payloads.append(view)
        if view["done"]:
            with ledger.lock:
                ledger.finished += 1
            return
        answer = rng.choices(["A", "B", "tie", "both_bad"], weights=[4, 3, 2, 1])[0]
        criteria = {c: rng.choice(["A", "B", "tie"]) for c in CONFIG["criteria"] if rng.random() < 0.6}
        with ledger.lock:
            ledger.cast[view["trial"]] = (answer, criteria)
        try:
            nxt = client.predict(
                view["participant"],
                view["trial"],
                answer,
                json.dumps(criteria),
                json.dumps([True, rng.random() < 0.9]),
                "",
                api_name="/study_vote",
            )
        except Exception:
            with ledger.lock:
                ledger.interrupted.append((view["participant"], view["trial"]))
            return
        with ledger.lock:
            ledger.acked.add(view["trial"])
        view = nxt


def run_participants(url: str, ledger: Ledger, jobs: list[str | None], seed: int, killer=None) -> None:
    rng = random.Random(seed)
    seeds = [rng.randrange(1 << 30) for _ in jobs]
    with ThreadPoolExecutor(max_workers=4) as pool:
        futures = [pool.submit(participant, url, ledger, random.Random(s), j) for j, s in zip(jobs, seeds, strict=True)]
        if killer:
            killer()
        for f in futures:
            try:
                f.result()
            except Exception:
                pass  # a participant whose start failed at the kill: replaced below


def stored_votes(db: Path) -> dict[str, tuple[str, dict]]:
    con = sqlite3.connect(db)
    try:
        assert con.execute("PRAGMA integrity_check").fetchone()[0] == "ok"
        rows = con.execute("SELECT t.token, v.answer, v.criteria FROM votes v JOIN trials t ON t.id = v.trial_id")
        return {tok: (ans, json.loads(crit)) for tok, ans, crit in rows}
    finally:
        con.close()


@pytest.mark.long
def test_simulated_study_of_50_participants_survives_kill_9(study_env):
    t_start = time.time()
    ledger = Ledger()
    db = study_env["db"]
    with run_app(study_env["out"], study_env["env"]) as srv:

        def kill_after_some_votes() -> None:
            deadline = time.time() + 300
            while len(ledger.acked) < 45 and time.time() < deadline:
                time.sleep(0.02)
            os.kill(srv["proc"].pid, signal.SIGKILL)  # no shutdown, no flush: a crash

        run_participants(srv["url"], ledger, [None] * 30, seed=1, killer=kill_after_some_votes)
        srv["proc"].wait()
        assert srv["proc"].returncode == -signal.SIGKILL

    # after the crash: every acknowledged vote is there, and nothing that was not cast
    stored = stored_votes(db)
    assert len(ledger.acked) >= 45
    missing = ledger.acked - set(stored)
    assert not missing, f"{len(missing)} acknowledged votes lost"
    assert set(stored) <= set(ledger.cast)
    in_flight = set(stored) - ledger.acked
    assert len(in_flight) <= 4  # at most one trial in flight per concurrent participant
    for tok, (answer, crit) in stored.items():
        assert (answer, crit) == ledger.cast[tok]
    votes_before = len(stored)
    figures = {
        "acknowledged_before_kill": len(ledger.acked),
        "stored_after_kill": votes_before,
        "in_flight_votes_stored": len(in_flight),
        "participants_interrupted": len(ledger.interrupted),
    }

    # restart on the same database: interrupted participants go on, new ones join up to 50
    with run_app(study_env["out"], study_env["env"]) as srv:
        started = len({p["participant"] for p in ledger.payloads})
        resumed = [p for p, _ in ledger.interrupted]
        run_participants(srv["url"], ledger, resumed + [None] * (PARTICIPANTS - started), seed=2)

        client = Client(srv["url"], verbose=False)
        # a replayed vote and a forged trial id are refused, and store nothing
        some_trial = next(iter(ledger.acked))
        owner = next(p["participant"] for p in ledger.payloads if p.get("trial") == some_trial)
        for trial_id in (some_trial, "f" * 32):
            with pytest.raises(Exception, match=r"already has a vote|unknown trial"):
                client.predict(owner, trial_id, "A", "{}", "[]", "", api_name="/study_vote")
        with pytest.raises(Exception, match="wrong admin token"):
            client.predict("guess", api_name="/study_results")
        results = client.predict(ADMIN, api_name="/study_results")
        anonymity_payloads = [
            urllib.request.urlopen(srv["url"] + path).read()
            for path in ("", "config", "gradio_api/info", "gradio_api/openapi.json")
        ]
        glbs = [
            urllib.request.urlopen(srv["url"].rstrip("/") + p[s]).read()
            for p in ledger.payloads[:20]
            for s in "ab"
            if not p["done"]
        ]
        for rel in ("static/viewer.html", "static/viewer.js", "static/viewer.css"):
            anonymity_payloads.append(urllib.request.urlopen(srv["url"] + "gradio_api/file=" + str(REPO / rel)).read())

    stored = stored_votes(db)
    assert ledger.finished == PARTICIPANTS
    assert len(stored) == PARTICIPANTS * TRIALS  # every participant answered every trial once
    assert len(stored) > votes_before
    assert ledger.acked <= set(stored) and set(stored) <= set(ledger.cast)
    for tok, (answer, crit) in stored.items():
        assert (answer, crit) == ledger.cast[tok]

    # the results view equals a hand computation from the votes cast and the stored pairs
    store = StudyStore(f"sqlite:///{db}")
    wins = {"baseline": 0, "motion_mamba": 0}
    ties = both_bad = 0
    crit_count = {c: 0 for c in CONFIG["criteria"]}
    for tok in stored:
        t = store.trial(tok)
        answer, crit = ledger.cast[tok]
        if answer == "A":
            wins[t.method_a] += 1
        elif answer == "B":
            wins[t.method_b] += 1
        elif answer == "tie":
            ties += 1
        else:
            both_bad += 1
        for c in crit:
            crit_count[c] += 1
    store.close()
    (pair,) = results["pairs"]
    assert (pair["method_1"], pair["method_2"]) == ("baseline", "motion_mamba")
    assert (pair["wins_1"], pair["wins_2"], pair["ties"], pair["both_bad"]) == (
        wins["baseline"],
        wins["motion_mamba"],
        ties,
        both_bad,
    )
    assert pair["win_rate_1"] == pytest.approx(wins["baseline"] / (wins["baseline"] + wins["motion_mamba"]))
    assert results["votes"] == PARTICIPANTS * TRIALS and results["participants"] == PARTICIPANTS
    # two methods: Bradley-Terry has a closed form (ties half a win, one virtual tie as prior)
    half = (ties + both_bad) / 2 + 0.5
    gap = 400 * math.log10((wins["baseline"] + half) / (wins["motion_mamba"] + half))
    scores = {r["method"]: r["score"] for r in results["ranking"]}
    assert scores["baseline"] - scores["motion_mamba"] == pytest.approx(gap)
    for c in CONFIG["criteria"]:
        row = next(r for r in results["criteria"] if r["criterion"] == c)
        assert row["n"] == crit_count[c]

    figures.update(
        participants=PARTICIPANTS,
        votes=len(stored),
        payloads_checked=len(ledger.payloads) + len(anonymity_payloads) + len(glbs),
        duration_s=round(time.time() - t_start, 1),
    )
    artifact("results/study_simulation.json").write_text(json.dumps(figures, indent=1) + "\n")

    # anonymity: nothing a participant receives names a method
    for p in ledger.payloads:
        assert not leaks(json.dumps(p)), p
    for blob in anonymity_payloads + [glb_text(g) for g in glbs]:
        assert not leaks(blob), leaks(blob)


def test_study_page_refuses_files_outside_its_folders_and_has_no_results_without_token(study_env, tmp_path):
    env = {**study_env["env"], "MMS_STUDY_DB": str(tmp_path / "other.sqlite")}
    env.pop("MMS_ADMIN_TOKEN")
    with run_app(study_env["out"], {**env, "MMS_ADMIN_TOKEN": ""}) as srv:
        base = srv["url"].rstrip("/")
        config = urllib.request.urlopen(base + "/config").read().decode()
        assert "study_results" not in config and "Admin token" not in config
        for path in (
            "/gradio_api/file=/etc/passwd",
            "/gradio_api/file=" + str(study_env["out"]) + "/../../../../etc/passwd",
            "/gradio_api/file=" + str(study_env["out"]) + "/%2e%2e/%2e%2e/%2e%2e/etc/passwd",
            "/gradio_api/file=" + str(study_env["db"]),
            "/gradio_api/file=" + str(REPO / "app.py"),
        ):
            with pytest.raises(urllib.error.HTTPError) as err:
                urllib.request.urlopen(base + path)
            assert err.value.code in (403, 404), path
