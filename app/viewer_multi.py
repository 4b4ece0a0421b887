"""Several viewers side by side (compare the methods, or variations of one timeline).

Each is the ordinary viewer page in an iframe, loading its GLB from the URL; all of one grid
share a BroadcastChannel id (viewer.js ?sync=, as the user study's A/B pair does), so play,
pause, scrubbing and speed act on all of them and the first one keeps their clocks together.
"""

from __future__ import annotations

import html
import json
import uuid
from dataclasses import dataclass
from urllib.parse import quote

from .viewer import STATIC, file_url


@dataclass(frozen=True)
class Tile:
    glb_url: str  # a file URL under this server (viewer.file_url)
    title: str  # above the viewer: the method or the seed
    caption: str  # under it: figures, time


STALE_NOTE = {
    "compare": "These motions are of an earlier timeline: the rows have changed since. Press Compare all "
    "methods again to compare the timeline shown.",
    "variations": "These variations are of an earlier timeline: the rows have changed since. Press the "
    "variations button again for the timeline shown.",
}


def grid_html(
    tiles: list[Tile], height: int = 300, kind: str = "compare", timeline: list[tuple[str, float | None]] | None = None
) -> str:
    """The grid's HTML: one labelled, synchronised viewer per tile. ``timeline``: the segments
    the grid was made from; the page marks the grid stale once its rows differ (PAGE_JS)."""
    if not tiles:
        return ""
    sync = uuid.uuid4().hex[:12]
    page = file_url(STATIC / "viewer.html")
    cells = []
    for i, t in enumerate(tiles):
        src = f"{page}?glb={quote(t.glb_url, safe='')}&sync={sync}&keyframes=0" + ("&lead=1" if i == 0 else "")
        cells.append(
            f"<figure class='mms-tile' data-index='{i}'>"
            f"<figcaption class='mms-tile-title'>{html.escape(t.title)}</figcaption>"
            f"<iframe class='mms-tile-viewer' title='{html.escape(t.title)}' src='{html.escape(src)}' "
            f"style='height:{height}px'></iframe>"
            f"<div class='mms-tile-caption'>{html.escape(t.caption)}</div></figure>"
        )
    grid = f"<div class='mms-grid mms-grid-{kind}' data-sync='{sync}'>{''.join(cells)}</div>"
    made = html.escape(json.dumps([[t, s] for t, s in (timeline or [])]), quote=True)
    note = f"<div class='mms-stale-note' hidden>{html.escape(STALE_NOTE.get(kind, STALE_NOTE['compare']))}</div>"
    return f"<div class='mms-grid-box' data-timeline='{made}'>{note}{grid}</div>"


GRID_CSS = """
.mms-grid { display: grid; grid-template-columns: repeat(auto-fit, minmax(230px, 1fr)); gap: 8px; }
.mms-tile { margin: 0; border: 1px solid #ddd; border-radius: 8px; overflow: hidden; background: #fffdf8; }
.mms-tile-title { font-weight: 600; padding: 4px 8px; }
.mms-tile-viewer { width: 100%; border: 0; display: block; }
.mms-tile-caption { font-size: 12px; color: #555; padding: 4px 8px; }
"""
