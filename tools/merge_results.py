"""Merge a rerun's rows into a results table, keeping the rows they replace under a suffix.

    python tools/merge_results.py NEW.json results/verifier.json --rows motion_mamba,ftmomamba,baseline \\
        --old-suffix 2token_10_ddim_steps --note "2026-11-25: ..."

For the tables ``python -m motion_core.eval`` writes: a verifier or timeline table (rows at
the top level) or a metric suite (rows under ``text_to_motion`` and ``extended``; its
``results/metrics_*.md`` is rewritten from the merged rows). Each row named in ``--rows`` is
taken from NEW; the row it replaces stays as ``<row>_<old-suffix>``. The rerun's seconds go
into the table's ``seconds`` (a dict keyed by what was rerun) and ``--note`` is appended to
its ``note``, so the file says which rows came from which run.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from motion_core.eval.suite import markdown
from motion_core.inference.registry import REGISTRY


def merge_rows(into: dict, new: dict, rows: list[str], suffix: str) -> None:
    for row in rows:
        if row not in new:
            raise SystemExit(f"the new table has no row {row!r}")
        if row in into:
            into[f"{row}_{suffix}"] = into[row]
        into[row] = new[row]


def current_rows(part: dict | None) -> dict | None:
    """A suite table's rows the markdown shows: Real, each method's own row and its
    samplers' ("NAME:fast"), not the replaced ones kept under a suffix ("NAME:fast_guidance_4"
    shares the "NAME:" prefix; the JSON keeps the history)."""
    if not part:
        return part
    keep = {
        k: v
        for k, v in part["rows"].items()
        if k == "Real" or k in REGISTRY or (k.partition(":")[0] in REGISTRY and k.partition(":")[2] == "fast")
    }
    return {**part, "rows": keep}


def head_paragraph(path: Path, into: dict, latest: str) -> str:
    """The markdown's first paragraph: how the table is made and where its rows' history is.
    Written afresh at every merge, so it names the latest rerun rather than a stale command."""
    config = into.get("config") or {}
    source = config.get("source", "procedural")
    flags = " --source real --no-extended" if source == "real" else ""
    return (
        f"`python -m motion_core.eval --methods NAME[:fast],... --data DIR --n {config.get('n') or 200}{flags}`, "
        "rerun row by row "
        f"as the shipped checkpoints changed and merged with `tools/merge_results.py`: `{path.name}`'s "
        f"`note` says which run each row came from, and the rows replaced stay there under a suffix. "
        f"Latest: {latest}"
    )


def write_markdown(path: Path, into: dict, latest: str) -> None:
    """Rewrite the suite table's ``.md`` beside ``path`` from its current rows, under a first
    paragraph naming ``latest`` (the note of the rerun just merged)."""
    md = path.with_suffix(".md")
    table = markdown(current_rows(into["text_to_motion"]), current_rows(into.get("extended")))
    md.write_text(f"{head_paragraph(path, into, latest)}\n\n{table}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("new")
    ap.add_argument("into")
    ap.add_argument("--rows", required=True, help="comma-separated row names to take from NEW")
    ap.add_argument("--old-suffix", required=True)
    ap.add_argument("--note", required=True)
    args = ap.parse_args()
    new = json.loads(Path(args.new).read_text())
    path = Path(args.into)
    into = json.loads(path.read_text())
    rows = [r for r in args.rows.split(",") if r]
    suite = "text_to_motion" in into
    if suite:
        # rows made with another prompt count, source, seed or sample sizes are not comparable
        # with the rows they would sit beside (and the markdown names into's settings)
        mine, theirs = into.get("config") or {}, new.get("config") or {}
        differ = {k: (mine[k], theirs[k]) for k in mine.keys() & theirs.keys() if mine[k] != theirs[k]}
        if differ:
            raise SystemExit(f"the new table was made with other settings (into, new): {differ}")
        for part in ("text_to_motion", "extended"):
            if into.get(part) and new.get(part):
                merge_rows(into[part]["rows"], new[part]["rows"], rows, args.old_suffix)
    else:
        merge_rows(into, new, rows, args.old_suffix)
    seconds = into.get("seconds")
    if not isinstance(seconds, dict):
        seconds = {"earlier runs": seconds} if seconds is not None else {}
    seconds[f"{','.join(rows)} ({args.old_suffix} replaced)"] = new.get("seconds")
    into["seconds"] = seconds
    into["note"] = (into.get("note", "") + "; " if into.get("note") else "") + args.note
    path.write_text(json.dumps(into, indent=1) + "\n")
    if suite:
        write_markdown(path, into, args.note)
    print(f"merged {rows} into {path}")


if __name__ == "__main__":
    main()
