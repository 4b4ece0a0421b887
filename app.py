"""Entry point for local runs and hosted spaces: `python app.py`.

Binds 127.0.0.1 unless HOST says otherwise (a hosted space sets HOST=0.0.0.0);
port from PORT, default 7860.
"""

from __future__ import annotations

import os

os.environ.setdefault("HF_HUB_OFFLINE", "1")
os.environ.setdefault("TRANSFORMERS_OFFLINE", "1")
os.environ.setdefault("GRADIO_ANALYTICS_ENABLED", "False")

import threading

from app.ui import build_demo, launch_kwargs, warm_up


def main() -> None:
    demo = build_demo()
    # load the text encoder and the checkpoints while the page comes up, not on the first click
    threading.Thread(target=warm_up, name="warm-up", daemon=True).start()
    demo.queue(default_concurrency_limit=2)
    demo.launch(
        server_name=os.environ.get("HOST", "127.0.0.1"),
        server_port=int(os.environ.get("PORT", "7860")),
        **launch_kwargs(),
    )


if __name__ == "__main__":
    main()
