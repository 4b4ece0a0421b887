"""The HTTP API against wrong input, through gradio_client and the real `python app.py`.

Every endpoint the page's API info lists (the demo's and the study's, so a new endpoint is
covered without being named here) gets numbers, lists, objects, null, booleans and huge
values in each of its arguments: each is refused with a message naming the argument, or
accepted, and never answered with Gradio's "upstream app has raised an exception"; the
server logs no traceback and exactly one line per refused request. Besides: the timeline
formats /generate_motion takes, wrong admin tokens limited across sessions (per client
address and in all), and a study that refuses to start with a short admin token.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import pytest
from conftest import REPO, run_app, study_setup
from gradio_client import Client

# the wrong values tried in every argument
BAD_VALUES = [
    3,
    2.5,
    -1,
    True,
    None,
    [1, 2],
    {"a": 1},
    10**30,
    1e308,
    "x" * 200_000,
    list(range(5_000)),
]
# the text encoder's, drawn with carriage returns and no newline: a log line can follow it
WARM_UP_BAR = "Loading weights"
GENERIC = "upstream Gradio app has raised an exception"
ADMIN = "inputs-test-admin-token-31"
STUDY = {
    "name": "inputs-test",
    "methods": ["motion_mamba", "baseline"],
    "seeds": [0],
    "trials_per_participant": 50,
    "criteria": ["realism"],
    "allow_custom_prompts": True,
    "custom_prompt_seconds": 1,
    "prompts": [{"text": "a person walks forward", "seconds": 1}],
}
NO_LIMITS = {
    f"MMS_RATE_{n}": "0/0" for n in ("GENERATE", "STUDY_START", "STUDY_VOTE", "STUDY_RESULTS", "ADMIN_FAILURES")
}


def endpoints(client: Client) -> dict[str, list[dict]]:
    """The named endpoints of the app's API info, with their parameters."""
    info = client.view_api(print_info=False, return_format="dict")
    assert not info["unnamed_endpoints"], info["unnamed_endpoints"]  # each would need a case here
    return {name: e["parameters"] for name, e in info["named_endpoints"].items()}


def try_every_argument(url: str, base_args, log_path) -> dict[str, int]:
    """Every bad value in every argument of every endpoint; ``base_args(client, name)`` gives
    a valid call's arguments (None: the API info's example values). Returns counts."""
    client = Client(url, verbose=False)
    found = endpoints(client)
    log_before = log_path.read_text()
    refused = accepted = 0
    for name, params in found.items():
        for i, param in enumerate(params):
            for bad in BAD_VALUES:
                args = base_args(client, name)
                if args is None:
                    args = [p.get("example_input") for p in params]
                args = list(args)
                args[i] = bad
                try:
                    client.predict(*args, api_name=name)
                    accepted += 1
                except Exception as e:
                    message = str(e)
                    assert GENERIC not in message and message.strip(), (name, param["parameter_name"], repr(bad)[:40])
                    assert len(message) < 400, message  # says what to change, does not echo 200,000 x
                    refused += 1
    log = log_path.read_text()[len(log_before) :]
    assert "Traceback" not in log, log[-3000:]
    refusals = [line for line in log.splitlines() if " refused /" in line]
    assert len(refusals) == refused, (len(refusals), refused, log[-3000:])
    # nothing else: one line per refusal (besides the warm-up's progress bar, still loading)
    lines = [line for line in log.splitlines() if line.strip()]
    other = [line for line in lines if " refused /" in line or not line.startswith(WARM_UP_BAR)]
    assert len(other) == refused, other[-20:]
    return {"endpoints": len(found), "refused": refused, "accepted": accepted}


def test_a_timeline_is_a_list_of_segments_or_flowmdms_composition():
    """No server: the shapes /generate_motion's timeline takes, as JSON text or parsed."""
    from app.timeline import from_json
    from motion_core import InputError

    segments = [{"text": "a person walks", "seconds": 3}, {"text": "a person sits down", "seconds": None}]
    want = [("a person walks", 3.0), ("a person sits down", None)]
    assert from_json(json.dumps(segments)) == want == from_json(segments)
    assert from_json([{"text": "a person walks"}]) == [("a person walks", None)]  # no seconds: estimated
    assert from_json({"text": ["a person walks"], "lengths": [60]}) == [("a person walks", 3.0)]
    for bad, msg in [
        ("[]", "at least one segment"),
        ([], "at least one segment"),
        (["a person walks"], "segment 1 .* an object"),
        ([{"seconds": 3}], "segment 1 .* an object"),
        ([{"text": "a", "duration": 3}], 'unknown keys \'duration\': give "text" and "seconds"'),
        ([{"text": "a", "seconds": "3"}], "segment 1 .* a number"),
        ([{"text": 5, "seconds": 3}], "segment 1 .* a text"),
        (3, "needs a list of"),
    ]:
        with pytest.raises(InputError, match=msg):
            from_json(bad)


@pytest.fixture(scope="module")
def demo_server(tmp_path_factory):
    out = tmp_path_factory.mktemp("api-inputs-demo")
    with run_app(out, {"MMS_MODE": "demo", **NO_LIMITS}) as srv:
        yield srv


@pytest.mark.long  # a sweep of every endpoint x every wrong value: 25-30 s each
def test_every_demo_endpoint_answers_wrong_types_and_huge_values_with_a_message(demo_server):
    timeline = json.dumps({"text": ["a person walks forward"], "seconds": [1]})

    def base(client, name):
        return [timeline, "baseline", 0, True, "humanml3d", None] if name == "/generate_motion" else None

    counts = try_every_argument(demo_server["url"], base, demo_server["log"])
    assert counts["endpoints"] >= 3  # /generate_motion, /methods and /read_prompt
    assert counts["refused"] >= 6 * len(BAD_VALUES) - 3  # the sampler's null is its default


def test_the_timeline_formats_and_a_refusal_logs_one_line(demo_server):
    client = Client(demo_server["url"], verbose=False)
    # what a new user writes first: a list of segments, as JSON text or as a list
    guess = [{"text": "a person walks", "seconds": 3}]
    for timeline in (json.dumps(guess), guess):
        got = client.predict(timeline, "kmm", 0, api_name="/generate_motion")
        assert got["frames"] == 60 and got["segments"][0]["text"] == "a person walks"
    flowmdm = {"text": ["a person walks", "a person waves"], "lengths": [40, 20]}
    got = client.predict(json.dumps(flowmdm), "kmm", 0, api_name="/generate_motion")
    assert [s["end"] - s["start"] for s in got["segments"]] == [40, 20]
    # a refusal: the client is told what to change, the server logs one line, no traceback
    before = demo_server["log"].read_text()
    with pytest.raises(Exception, match=r'"seconds"') as err:
        client.predict(json.dumps([{"text": "a person walks", "duration": 3}]), "kmm", 0, api_name="/generate_motion")
    assert "unknown keys 'duration'" in str(err.value)
    time.sleep(0.5)
    new = demo_server["log"].read_text()[len(before) :].splitlines()
    assert len(new) == 1 and "refused /generate_motion" in new[0] and "duration" in new[0], new
    before = demo_server["log"].read_text()
    with pytest.raises(Exception, match="seed must be 0 to 4,294,967,295"):
        client.predict(json.dumps(guess), "kmm", 2**40, api_name="/generate_motion")
    time.sleep(0.5)
    assert len(demo_server["log"].read_text()[len(before) :].splitlines()) == 1


def test_read_prompt_returns_the_readers_plan_and_the_warning(demo_server):
    """/read_prompt: the reading as data (Reading.to_dict(plan=True)) with check_prompt's
    warning; a text over a full timeline's worth is refused with one log line; and each of
    /generate_motion's segments carries its reading, beside the fields it had."""
    import motion_core

    client = Client(demo_server["url"], verbose=False)
    text = "a person walks forward, then sits down and picks up a box"
    got = client.predict(text, api_name="/read_prompt")
    check = motion_core.check_prompt(text)
    assert got == json.loads(json.dumps({**check.reading.to_dict(plan=True), **_warning(check)}))
    assert [(s["text"], s["seconds"], s["known"]) for s in got["plan"]] == [
        ("a person walks forward", 7.2, True),
        ("a person sits down", 3.9, True),
        ("a person picks up a box", 1.5, False),
    ]
    assert got["warn"] and got["messages"] == [
        "The models have not learned 'picks up a box' (nearest: reach forward with one hand)"
    ]
    known = client.predict("a person waves with the right hand", api_name="/read_prompt")
    assert not known["warn"] and known["fully_known"] and len(known["plan"]) == 1
    assert client.predict("", api_name="/read_prompt")["plan"] == []
    before = demo_server["log"].read_text()
    with pytest.raises(Exception, match=r"3,001 characters long \(at most 3,000"):
        client.predict("a" * 3001, api_name="/read_prompt")
    time.sleep(0.5)
    new = demo_server["log"].read_text()[len(before) :].splitlines()
    assert len(new) == 1 and "refused /read_prompt" in new[0], new
    # /generate_motion: each segment's reading, after the fields it always had
    timeline = [{"text": "a person walks forward", "seconds": 2}, {"text": "a person picks up a box", "seconds": 2}]
    res = client.predict(json.dumps(timeline), "kmm", 0, api_name="/generate_motion")
    walk, box = res["segments"]
    assert list(walk)[:3] == ["text", "start", "end"] and (walk["start"], walk["end"], box["end"]) == (0, 40, 80)
    assert not walk["reading"]["warn"] and walk["reading"]["clauses"][0]["kind"] == "walk"
    assert box["reading"]["warn"] and "picks up a box" in box["reading"]["messages"][0]
    assert set(box["reading"]) == {"warn", "messages", "unknown_parts", "unfamiliar", "no_action", "clauses"}


def _warning(check) -> dict:
    return {
        "warn": check.warn,
        "messages": list(check.messages),
        "unfamiliar": check.unfamiliar,
        "no_action": check.no_action,
    }


@pytest.mark.long  # a sweep of every endpoint x every wrong value: 25-30 s each
def test_every_study_endpoint_answers_wrong_types_and_huge_values_with_a_message(tmp_path):
    setup = study_setup(tmp_path, STUDY, ADMIN)
    with run_app(setup["out"], {**setup["env"], **NO_LIMITS}) as srv:

        def base(client, name):
            if name == "/study_start":
                return [""]
            if name == "/study_results":
                return [ADMIN]
            view = client.predict("", api_name="/study_start")  # a fresh trial for each try
            if name == "/study_resume":
                return [view["participant"]]
            if name == "/study_vote":
                return [view["participant"], view["trial"], "A", "{}", "[true, true]", ""]
            return None

        counts = try_every_argument(srv["url"], base, srv["log"])
    assert counts["endpoints"] == 4
    assert counts["refused"] == 9 * len(BAD_VALUES)  # nothing else fits a string


def test_wrong_admin_tokens_from_many_sessions_are_refused_after_a_few(tmp_path):
    """A client opening a new session per guess used to get an answer to every one (30 in
    6.4 s). Now 5 wrong tokens per client address, then that address is refused; 8 in all
    here (MMS_RATE_ADMIN_FAILURES_TOTAL), then every address is."""
    setup = study_setup(tmp_path, STUDY, ADMIN)
    env = {**setup["env"], "MMS_RATE_ADMIN_FAILURES_TOTAL": "1/8"}
    with run_app(setup["out"], env) as srv:

        def guess(token: str, address: str) -> str:
            client = Client(srv["url"], verbose=False, headers={"X-Forwarded-For": f"203.0.113.9, {address}"})
            try:
                client.predict(token, api_name="/study_results")
                return "ok"
            except Exception as e:
                return str(e)

        answers = [guess(f"guess-{i}", "10.0.0.1") for i in range(7)]
        assert answers[:5] == ["wrong admin token"] * 5, answers
        assert all("too many wrong admin tokens from this address" in a for a in answers[5:]), answers
        # refused before the comparison: the right token from that address is refused too
        assert "too many wrong admin tokens" in guess(ADMIN, "10.0.0.1")
        assert guess(ADMIN, "10.0.0.2") == "ok"  # another address is not
        answers = [guess(f"guess-{i}", f"10.0.1.{i}") for i in range(4)]
        assert answers[:3] == ["wrong admin token"] * 3, answers  # 8 in all
        assert "too many wrong admin tokens lately" in answers[3], answers
        assert "too many wrong admin tokens lately" in guess(ADMIN, "10.0.2.1")


def test_the_study_refuses_to_start_with_a_short_admin_token(tmp_path):
    setup = study_setup(tmp_path, STUDY, "choose-a-secret")  # 15 characters
    env = {**os.environ, **setup["env"], "PORT": "7929"}
    res = subprocess.run([sys.executable, "app.py"], cwd=REPO, env=env, capture_output=True, text=True, timeout=120)
    assert res.returncode == 1
    assert "MMS_ADMIN_TOKEN: the admin token is 15 characters long; use at least 16" in res.stderr
    assert "Traceback" not in res.stderr
