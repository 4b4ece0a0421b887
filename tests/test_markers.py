"""Which tests a run selects (tests/conftest.py): the long checks only where -m names them,
and ``-m browser`` every test that drives chromium."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from types import SimpleNamespace

import pytest
from conftest import REPO, pytest_collection_modifyitems


def test_a_users_own_marker_expression_still_leaves_out_the_long_checks():
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "--collect-only",
            "-p",
            "no:cacheprovider",
            "tests/test_browser.py",
            "-m",
            "browser",
        ],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stdout + out.stderr
    browser = {line.strip() for line in out.stdout.splitlines() if "::" in line}
    assert "tests/test_browser.py::test_click_to_playing_time_for_a_10s_two_segment_motion" not in browser  # long
    # a test that drives chromium is marked browser; an HTTP-only one is not
    assert "tests/test_browser.py::test_bad_inputs_get_one_titled_message_and_leave_the_form_intact" in browser
    assert "tests/test_browser.py::test_api_reports_unknown_method_and_generates" not in browser


class _Item:
    def __init__(self, name: str, long: bool, fixtures: tuple[str, ...] = ()) -> None:
        self.name, self.fixturenames = name, fixtures
        self.nodeid = f"tests/test_x.py::{name}"
        self.path = Path("/repo/tests/test_x.py")
        self.markers = {"long"} if long else set()

    def get_closest_marker(self, name: str):
        return name if name in self.markers else None

    def add_marker(self, mark) -> None:
        self.markers.add(mark.name)


ALL = {"quick", "page", "slow"}


@pytest.mark.parametrize(
    ("expr", "args", "kept"),
    [
        ("", (), {"quick", "page"}),
        ("browser", (), {"quick", "page"}),
        ("long-soak or browser", (), {"quick", "page"}),  # another marker's name holding "long"
        ("long", (), ALL),
        ("not long", (), ALL),  # pytest's own filter then leaves "slow" out
        ("long or not long", (), ALL),
        ("", ("tests/test_x.py::slow",), ALL),  # a long test named on the command line runs
        ("", ("./tests/test_x.py::slow[1]",), ALL),
        ("", ("/repo/tests/test_x.py::slow",), ALL),
        ("", ("tests/test_x.py::slo",), {"quick", "page"}),
        ("", ("tests/test_y.py::slow",), {"quick", "page"}),
    ],
)
def test_long_checks_are_deselected_unless_the_expression_or_the_command_names_them(expr, args, kept):
    """The hook alone: -m's own filtering (done by pytest afterwards) is not part of it."""
    items = [_Item("quick", False), _Item("page", False, ("page", "browser")), _Item("slow", True)]
    deselected = []
    config = SimpleNamespace(
        getoption=lambda name: expr,
        args=list(args),
        invocation_params=SimpleNamespace(dir=Path("/repo")),
        hook=SimpleNamespace(pytest_deselected=lambda items: deselected.extend(items)),
    )
    pytest_collection_modifyitems(config, items)
    assert {i.name for i in items} == kept and {i.name for i in deselected} == ALL - kept
    assert [i.name for i in items if "browser" in i.markers] == ["page"]
