"""Entry point for local runs and hosted spaces: `python app.py` (the demo) or
`MMS_MODE=study python app.py` / `python app.py --study` (the anonymised user study).

Binds 127.0.0.1 unless HOST (or a Gradio host's GRADIO_SERVER_NAME) says otherwise (a hosted
space binds 0.0.0.0); port from PORT (or GRADIO_SERVER_PORT), default 7860. Limits for a
hosted space: MMS_QUEUE_MAX (waiting requests, default 64), MMS_RATE_GENERATE /
MMS_RATE_STUDY_START / MMS_RATE_STUDY_VOTE ("per minute/burst" per session, per replica),
MMS_OUTPUT_TTL (seconds before a request's files are deleted, default 3600).
three.js for the viewer: node_modules/three when installed, else MMS_THREE_URL (default: the
pinned version on a public CDN, integrity-checked); see app/viewer.py and docs/hosting.md.
Study: MMS_STUDY_CONFIG (YAML/JSON, default configs/study-sample.yaml), MMS_STUDY_DB (SQLite
file, default study.sqlite) or MMS_STUDY_DB_URL (any SQLAlchemy URL), MMS_ADMIN_TOKEN (no
token, no results view; at least 16 characters, or the study does not start).
"""

from __future__ import annotations

import os

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
os.environ.setdefault("GRADIO_ANALYTICS_ENABLED", "False")

import sys
import threading

from app.cleanup import start_sweeper
from app.viewer import OUTPUT_ROOT, three_routes


def build() -> tuple[object, dict, object]:
    """(Blocks, launch kwargs, warm-up callable) for the mode asked for."""
    if os.environ.get("MMS_MODE", "demo") == "study" or "--study" in sys.argv[1:]:
        from app.runtime import configure_torch, warm_up
        from app.study import StudyService
        from app.study_config import load_config
        from app.study_store import StudyStore
        from app.study_ui import CSS, admin_token_from_env, build_study

        try:
            admin_token = admin_token_from_env()
        except ValueError as e:  # too short to be safe: say so before anything starts
            raise SystemExit(f"MMS_ADMIN_TOKEN: {e}") from None
        configure_torch()
        config = load_config()
        service = StudyService(config, StudyStore())
        demo = build_study(service, admin_token)
        return demo, {"css": CSS, "footer_links": ["api"]}, lambda: warm_up(config.methods)
    from app.runtime import warm_up
    from app.ui import build_demo, launch_kwargs

    return build_demo(), launch_kwargs(), warm_up


def bind_address() -> tuple[str, int]:
    """HOST/PORT, else what a Gradio host announces (Hugging Face's Gradio spaces set
    GRADIO_SERVER_NAME=0.0.0.0 and expect port 7860), else loopback:7860."""
    env = os.environ
    host = env.get("HOST") or env.get("GRADIO_SERVER_NAME") or "127.0.0.1"
    return host, int(env.get("PORT") or env.get("GRADIO_SERVER_PORT") or "7860")


def main() -> None:
    demo, kwargs, warm = build()
    host, port = bind_address()
    # load the text encoder and the checkpoints while the page comes up, not on the first click
    threading.Thread(target=warm, name="warm-up", daemon=True).start()
    start_sweeper(OUTPUT_ROOT, float(os.environ.get("MMS_OUTPUT_TTL", "3600")))
    demo.queue(default_concurrency_limit=2, max_size=int(os.environ.get("MMS_QUEUE_MAX", "64")))
    demo.launch(
        app_kwargs={"routes": three_routes()},  # viewer.html asks here where three.js comes from
        server_name=host,
        server_port=port,
        **kwargs,
    )


if __name__ == "__main__":
    main()
