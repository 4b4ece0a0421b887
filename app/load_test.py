"""Load test of a running demo: N concurrent /generate_motion requests, each checked for mix-ups.

    python -m app.load_test --url http://127.0.0.1:7860/ -n 20

Every request has its own timeline (text naming the request), method and seed, from its own
``gradio_client.Client`` (its own session). A response passes when its method, seed, frame
count and segment texts are those asked for, and its GLB, fetched over HTTP, carries the same
timeline, method and seed in its extras. Prints latency p50/p90 and throughput as JSON.
"""

from __future__ import annotations

import argparse
import json
import threading
import time
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numpy as np


def request_for(i: int, methods: list[str]) -> dict[str, Any]:
    words = ["forward", "backward", "to the left", "to the right", "in a circle"]
    return {
        "text": [f"a person walks {words[i % len(words)]} ({i})", f"a person waves with the right hand ({i})"],
        "seconds": [2.0, 2.0],
        "method": methods[i % len(methods)],
        "seed": 1000 + i,
    }


def _check(url: str, req: dict[str, Any], res: dict[str, Any]) -> list[str]:
    from motion_core.formats.gltf import read_glb_joints

    problems = []
    frames = round(sum(req["seconds"]) * 20)
    if res["method"] != req["method"] or res["seed"] != req["seed"] or res["frames"] != frames:
        problems.append(
            f"asked {req['method']}/{req['seed']}/{frames}, got {res['method']}/{res['seed']}/{res['frames']}"
        )
    if [s["text"] for s in res["segments"]] != req["text"]:
        problems.append(f"segments {res['segments']} for {req['text']}")
    with urllib.request.urlopen(url.rstrip("/") + res["files"]["glb"], timeout=60) as r:
        joints, extras = read_glb_joints(r.read())
    if joints.shape != (frames, 22, 3):
        problems.append(f"GLB has {joints.shape}")
    if [s["text"] for s in extras["segments"]] != req["text"] or extras["method"] != req["method"]:
        problems.append("GLB extras belong to another request")
    if extras["seed"] != req["seed"]:
        problems.append("GLB seed belongs to another request")
    return problems


def run(url: str, n: int = 20, methods: list[str] | None = None) -> dict[str, Any]:
    """Fire n requests at once; returns latencies, throughput, errors and mix-ups."""
    from gradio_client import Client

    methods = methods or ["motion_mamba", "baseline"]
    reqs = [request_for(i, methods) for i in range(n)]
    clients = [Client(url, verbose=False) for _ in range(n)]  # n sessions, created before the clock starts
    barrier = threading.Barrier(n)
    latency: list[float | None] = [None] * n
    server_s: list[float] = []
    errors: list[str] = []
    mixups: list[str] = []

    def one(i: int) -> None:
        req = reqs[i]
        barrier.wait()
        t0 = time.perf_counter()
        try:
            res = clients[i].predict(
                json.dumps({"text": req["text"], "seconds": req["seconds"]}),
                req["method"],
                req["seed"],
                api_name="/generate_motion",
            )
            latency[i] = time.perf_counter() - t0
            server_s.append(res["seconds_to_generate"])
            mixups.extend(f"request {i}: {p}" for p in _check(url, req, res))
        except Exception as e:  # every failure is reported, none stops the others
            errors.append(f"request {i}: {type(e).__name__}: {e}")

    t0 = time.perf_counter()
    with ThreadPoolExecutor(max_workers=n) as pool:
        list(pool.map(one, range(n)))
    wall = time.perf_counter() - t0
    done = np.array([x for x in latency if x is not None])
    return {
        "requests": n,
        "completed": len(done),
        "errors": errors,
        "mixups": mixups,
        "wall_s": round(wall, 2),
        "throughput_per_s": round(len(done) / wall, 3),
        "latency_p50_s": round(float(np.percentile(done, 50)), 2) if len(done) else None,
        "latency_p90_s": round(float(np.percentile(done, 90)), 2) if len(done) else None,
        "latency_max_s": round(float(done.max()), 2) if len(done) else None,
        "server_generate_export_p50_s": round(float(np.median(server_s)), 2) if server_s else None,
        "server_generate_export_sum_s": round(float(np.sum(server_s)), 2),
        "timeline": "2 segments x 2 s (80 frames) per request",
        "methods": methods,
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", default="http://127.0.0.1:7860/")
    ap.add_argument("-n", type=int, default=20)
    ap.add_argument("--methods", default="motion_mamba,baseline")
    args = ap.parse_args()
    print(json.dumps(run(args.url, args.n, args.methods.split(",")), indent=1))


if __name__ == "__main__":
    main()
