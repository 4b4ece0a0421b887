"""What a hosted space reads: the bind address from HOST/PORT or the Gradio host's variables."""

from __future__ import annotations

import importlib.util

from conftest import REPO


def load_app_py():
    spec = importlib.util.spec_from_file_location("app_entry", REPO / "app.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_bind_address_from_host_port_else_the_gradio_hosts_variables(monkeypatch):
    entry = load_app_py()
    for name in ("HOST", "PORT", "GRADIO_SERVER_NAME", "GRADIO_SERVER_PORT"):
        monkeypatch.delenv(name, raising=False)
    assert entry.bind_address() == ("127.0.0.1", 7860)  # loopback unless told otherwise
    monkeypatch.setenv("GRADIO_SERVER_NAME", "0.0.0.0")
    monkeypatch.setenv("GRADIO_SERVER_PORT", "7861")
    assert entry.bind_address() == ("0.0.0.0", 7861)
    monkeypatch.setenv("HOST", "10.1.2.3")
    monkeypatch.setenv("PORT", "8080")
    assert entry.bind_address() == ("10.1.2.3", 8080)  # the project's own names win
