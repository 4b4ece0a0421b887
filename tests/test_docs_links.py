"""Every relative link in the README and docs/ leads somewhere: a file of the checkout and,
where the link names one, a heading of that file (GitHub's anchors). Text moved from one
page to another (the README's notebook parts into docs/) must take its links with it."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

from conftest import REPO

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$", re.MULTILINE)
FENCE = re.compile(r"^(```|~~~).*?^\1", re.MULTILINE | re.DOTALL)


def anchor(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation but ``-`` and ``_`` dropped
    (backticks and apostrophes with it), spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(page: Path) -> set[str]:
    """A page's heading anchors; a repeated heading's are numbered as GitHub does (-1, -2)."""
    seen: dict[str, int] = {}
    out = set()
    for h in HEADING.findall(FENCE.sub("", page.read_text(encoding="utf-8"))):
        a = anchor(h)
        out.add(a if a not in seen else f"{a}-{seen[a]}")
        seen[a] = seen.get(a, 0) + 1
    return out


def pages() -> list[Path]:
    """The checkout's tracked Markdown pages (caches' READMEs left out)."""
    listed = subprocess.run(["git", "ls-files", "*.md"], cwd=REPO, capture_output=True, text=True, check=True)
    return [REPO / line for line in listed.stdout.split()]


def test_every_relative_link_in_the_docs_resolves():
    broken = []
    for page in pages():
        text = FENCE.sub("", page.read_text(encoding="utf-8"))
        for target in LINK.findall(text):
            if re.match(r"[a-z]+:", target):  # http:, https:, mailto:
                continue
            path, _, frag = target.partition("#")
            dest = (page.parent / path).resolve() if path else page
            if not dest.exists():
                broken.append(f"{page.relative_to(REPO)}: {target} (no such file)")
            elif frag and dest.suffix == ".md":
                if frag not in anchors(dest):
                    broken.append(f"{page.relative_to(REPO)}: {target} (no such heading)")
    assert not broken, "\n".join(broken)


RESULT_PATH = re.compile(r"results/[A-Za-z0-9_.*/-]+")
MAP_ROW = re.compile(r"^\|([^|]*)\|", re.MULTILINE)


def results_map() -> list[str]:
    """The paths (relative to results/, globs allowed) that results/README.md's table maps:
    every backticked name in a row's first cell."""
    text = (REPO / "results" / "README.md").read_text(encoding="utf-8")
    names = []
    for cell in MAP_ROW.findall(text):
        names += re.findall(r"`([^`]+)`", cell)
    return names


def test_results_readme_maps_existing_files_and_every_file_maps():
    from fnmatch import fnmatch

    names = results_map()
    assert names, "results/README.md has no table of files"
    missing = [n for n in names if not list((REPO / "results").glob(n.rstrip("/")))]
    assert not missing, f"results/README.md maps files that do not exist: {missing}"
    listed = subprocess.run(["git", "ls-files", "results"], cwd=REPO, capture_output=True, text=True, check=True)
    unmapped = []
    for line in listed.stdout.split():
        rel = line.removeprefix("results/")
        if rel == "README.md":
            continue
        if not any(fnmatch(rel, n) or (n.endswith("/") and rel.startswith(n)) for n in names):
            unmapped.append(rel)
    assert not unmapped, f"results/ files missing from results/README.md: {unmapped}"


def matches(rel: str, name: str) -> bool:
    """A cited path (a file, a glob or a folder) is covered by a map entry."""
    from fnmatch import fnmatch

    return fnmatch(rel, name) or fnmatch(name, rel) or (rel.endswith("/") and name.startswith(rel))


def test_every_results_file_the_docs_cite_exists_and_is_in_the_map():
    names = results_map()
    bad = []
    for page in pages():
        if page.parts[-2:] == ("results", "README.md"):
            continue
        for cited in RESULT_PATH.findall(page.read_text(encoding="utf-8")):
            rel = cited.rstrip(".,;:").removeprefix("results/")
            if not rel or rel == "README.md":
                continue
            if not list((REPO / "results").glob(rel.rstrip("/"))):
                bad.append(f"{page.relative_to(REPO)}: {cited} (no such file)")
            elif not any(matches(rel, n) for n in names):
                bad.append(f"{page.relative_to(REPO)}: {cited} (not in results/README.md)")
    assert not bad, "\n".join(bad)
