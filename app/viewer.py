"""Where the viewer page and each request's files live, and the HTML that embeds the viewer.

The viewer (static/viewer.html) and three.js (node_modules/three) are served by Gradio's
file route from folders registered with ``gr.set_static_paths``; viewer.html finds three
through a relative importmap, so static/ and node_modules/ must stay siblings. Every
generation writes into its own fresh directory under OUTPUT_ROOT (a random name), so
concurrent users never share or overwrite a file.
"""

from __future__ import annotations

import html
import os
import tempfile
import uuid
from pathlib import Path
from urllib.parse import quote

REPO = Path(__file__).resolve().parents[1]
STATIC = REPO / "static"
THREE = REPO / "node_modules" / "three"
OUTPUT_ROOT = Path(os.environ.get("MMS_OUTPUT_DIR", Path(tempfile.gettempdir()) / "mms-outputs")).resolve()


def static_paths() -> list[Path]:
    OUTPUT_ROOT.mkdir(parents=True, exist_ok=True)
    return [STATIC, THREE, OUTPUT_ROOT]


def new_output_dir() -> Path:
    d = OUTPUT_ROOT / uuid.uuid4().hex
    d.mkdir(parents=True)
    return d


def file_url(path: Path) -> str:
    return "/gradio_api/file=" + quote(str(Path(path).resolve()))


def viewer_template(height: int = 460) -> str:
    """The viewer's iframe (loaded once per page; motions arrive by ``postMessage``)."""
    if not (THREE / "build" / "three.module.js").is_file():
        return (
            "<div class='mms-viewer-missing'>The 3D viewer needs the npm package <code>three</code>: "
            "run <code>bash scripts/setup.sh</code> (or <code>npm ci</code>) and restart.</div>"
        )
    src = html.escape(file_url(STATIC / "viewer.html"))
    return (
        f"<iframe class='mms-viewer' title='motion viewer' src='{src}' "
        f"style='width:100%;height:{height}px;border:0;border-radius:8px'></iframe>"
    )


# Runs in the Gradio page when the component mounts: forwards every new value (a GLB URL)
# to the viewer in the iframe, and the current one again whenever the iframe (re)loads.
VIEWER_JS = """
const frame = element.querySelector('iframe.mms-viewer');
if (frame) {
  const send = () => {
    if (props.value && frame.contentWindow) {
      frame.contentWindow.postMessage({type: 'mms-load', glb: props.value}, window.location.origin);
    }
  };
  frame.addEventListener('load', send);
  watch('value', send);
  send();
}
"""


PAUSE_VIEWER_JS = """
() => {
  const frame = document.querySelector('iframe.mms-viewer');
  if (frame && frame.contentWindow) frame.contentWindow.postMessage({type: 'mms-busy'}, window.location.origin);
}
"""


def viewer_page_url(glb: Path | None = None) -> str:
    """A standalone viewer URL (for links and tests): viewer.html?glb=..."""
    src = file_url(STATIC / "viewer.html")
    return src + ("?glb=" + quote(file_url(glb), safe="") if glb is not None else "")
