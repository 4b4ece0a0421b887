"""tools/merge_results.py: a rerun's rows replace the current ones, the old rows stay under a
suffix, and the markdown beside a suite table is rewritten with a first paragraph naming the
rerun just merged (it used to keep its first paragraph, which went stale) and the prompt
count the table was made with (it used to say 200 whatever the table held)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

from tests.conftest import REPO


def test_a_merged_suite_row_replaces_the_old_one_and_the_markdown_names_the_latest_rerun(tmp_path):
    into = tmp_path / "metrics_real.json"
    table_config = json.loads((REPO / "results" / "metrics_real.json").read_text())
    table_config["config"]["n"] = 149  # the markdown's command must follow the table, not a constant
    into.write_text(json.dumps(table_config))
    (tmp_path / "metrics_real.md").write_text("a stale first paragraph\n\nan old table\n")
    new = json.loads(into.read_text())
    before = new["text_to_motion"]["rows"]["baseline"]["fid"]
    new["text_to_motion"]["rows"]["baseline"]["fid"] = 0.123456
    (tmp_path / "new.json").write_text(json.dumps(new))

    note = "2099-01-01 (a test): the baseline row rerun"
    args = ["--rows", "baseline", "--old-suffix", "was", "--note", note]
    done = subprocess.run(
        [sys.executable, "tools/merge_results.py", str(tmp_path / "new.json"), str(into), *args],
        cwd=REPO,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    merged = json.loads(into.read_text())
    rows = merged["text_to_motion"]["rows"]
    assert rows["baseline"]["fid"] == 0.123456 and rows["baseline_was"]["fid"] == before
    assert merged["note"].endswith("; 2099-01-01 (a test): the baseline row rerun")

    head, _, table = (tmp_path / "metrics_real.md").read_text().partition("\n\n")
    assert "stale" not in head and "Latest: 2099-01-01 (a test): the baseline row rerun" in head
    assert "--n 149 --source real" in head and "`metrics_real.json`'s `note`" in head
    assert "0.123" in table and "baseline_was" not in table  # the markdown shows current rows only


def test_rows_made_with_other_settings_are_refused_and_nothing_is_written(tmp_path):
    into = tmp_path / "metrics_real.json"
    shutil.copy(REPO / "results" / "metrics_real.json", into)
    before = into.read_text()
    new = json.loads(before)
    new["config"]["n"] = 50
    (tmp_path / "new.json").write_text(json.dumps(new))
    args = ["--rows", "baseline", "--old-suffix", "was", "--note", "a rerun at 50 prompts"]
    done = subprocess.run(
        [sys.executable, "tools/merge_results.py", str(tmp_path / "new.json"), str(into), *args],
        cwd=REPO,
        capture_output=True,
        text=True,
    )
    assert done.returncode != 0 and "other settings" in done.stderr and "'n': (200, 50)" in done.stderr
    assert into.read_text() == before and not (tmp_path / "metrics_real.md").exists()
