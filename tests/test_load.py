"""Load and limits against `python app.py` on loopback: 20 concurrent generate requests from
20 sessions, and the per-session rate limit."""

from __future__ import annotations

import json

import pytest
from conftest import artifact, run_app
from gradio_client import Client

from app.load_test import run


@pytest.fixture(scope="module")
def limited_server(tmp_path_factory):
    # burst 3 per session: each of the load test's 20 sessions sends one request
    with run_app(tmp_path_factory.mktemp("load"), {"MMS_RATE_GENERATE": "30/3"}) as srv:
        yield srv


@pytest.mark.long
def test_20_concurrent_generate_requests_complete_without_error_or_mix_up(limited_server):
    report = run(limited_server["url"], n=20)
    artifact("results/load_test.json").write_text(json.dumps(report, indent=1) + "\n")
    assert report["errors"] == [], report["errors"]
    assert report["mixups"] == [], report["mixups"]
    assert report["completed"] == 20
    assert "Traceback" not in limited_server["log"].read_text()


def test_a_session_over_its_rate_limit_is_told_to_wait(limited_server):
    client = Client(limited_server["url"], verbose=False)
    bad = json.dumps({"text": [""], "seconds": [2]})  # refused fast, after the rate check
    for _ in range(3):
        with pytest.raises(Exception, match="empty"):
            client.predict(bad, "baseline", 0, api_name="/generate_motion")
    with pytest.raises(Exception, match="too many generate requests from this session"):
        client.predict(bad, "baseline", 0, api_name="/generate_motion")
    other = Client(limited_server["url"], verbose=False)  # another session is not affected
    with pytest.raises(Exception, match="empty"):
        other.predict(bad, "baseline", 0, api_name="/generate_motion")


@pytest.mark.long
def test_a_full_queue_refuses_with_a_message_and_serves_the_rest(tmp_path):
    import threading

    with run_app(tmp_path, {"MMS_QUEUE_MAX": "2", "MMS_RATE_GENERATE": "0/0"}) as srv:
        clients = [Client(srv["url"], verbose=False) for _ in range(8)]
        timeline = json.dumps({"text": ["a person walks forward"], "seconds": [10]})
        barrier = threading.Barrier(len(clients))
        outcomes: list[str] = []

        def one(c: Client) -> None:
            barrier.wait()
            try:
                res = c.predict(timeline, "motion_mamba", 0, api_name="/generate_motion")
                outcomes.append("ok" if res["frames"] == 200 else "wrong")
            except Exception as e:
                outcomes.append(f"refused: {e}")

        threads = [threading.Thread(target=one, args=(c,)) for c in clients]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
    refused = [o for o in outcomes if o.startswith("refused")]
    # MMS_QUEUE_MAX waiting requests are always served; whether one more was already
    # running when the rest arrived is a race (8 arrive at once), so 2 is the sure bound
    # (a clean-clone CI run saw exactly 2 once, in four runs)
    assert outcomes.count("ok") >= 2
    assert refused and all("queue is full" in o.lower() for o in refused), outcomes
    assert outcomes.count("ok") + len(refused) == 8
