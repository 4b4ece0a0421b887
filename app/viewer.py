"""Where the viewer page, three.js and each request's files live, and the HTML that embeds the viewer.

The viewer (static/viewer.html) is served by Gradio's file route from folders registered with
``gr.set_static_paths``. Every generation writes into its own fresh directory under
OUTPUT_ROOT (a random name), so concurrent users never share or overwrite a file.

three.js comes from one of two places, chosen per server (``three_source``):
* the npm package ``three`` in node_modules (``MMS_THREE_DIR`` to point elsewhere): served by
  this server, works offline; what a local install uses;
* otherwise the same pinned version from ``MMS_THREE_URL``, a base URL laid out like the npm
  package (default: jsDelivr's copy of that exact version). A hosted space installed with pip
  only has no node_modules, but its visitors' browsers can reach a CDN. Every module file the
  viewer loads from there carries a sha384 subresource-integrity hash (the import map's
  ``integrity`` table, app/three_manifest.json), so a CDN or mirror serving other bytes makes
  the viewer fail with a message instead of running them.
viewer.html asks ``/mms/three-source.js`` (``THREE_SOURCE_ROUTE``) which one to use and builds
its import map from the answer.
"""

from __future__ import annotations

import base64
import hashlib
import html
import json
import os
import re
import tempfile
import uuid
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from urllib.parse import quote

REPO = Path(__file__).resolve().parents[1]
STATIC = REPO / "static"
THREE = Path(os.environ.get("MMS_THREE_DIR", REPO / "node_modules" / "three")).resolve()
THREE_MANIFEST = Path(__file__).with_name("three_manifest.json")
THREE_SOURCE_ROUTE = "/mms/three-source.js"
CDN_TEMPLATE = "https://cdn.jsdelivr.net/npm/three@{version}/"
OUTPUT_ROOT = Path(os.environ.get("MMS_OUTPUT_DIR", Path(tempfile.gettempdir()) / "mms-outputs")).resolve()


def static_paths() -> list[Path]:
    OUTPUT_ROOT.mkdir(parents=True, exist_ok=True)
    local = [THREE] if _three_installed() else []
    return [STATIC, *local, OUTPUT_ROOT]


def new_output_dir() -> Path:
    d = OUTPUT_ROOT / uuid.uuid4().hex
    d.mkdir(parents=True)
    return d


def file_url(path: Path) -> str:
    return "/gradio_api/file=" + quote(str(Path(path).resolve()))


# ---------------------------------------------------------------- three.js source
def _three_installed() -> bool:
    return (THREE / "build" / "three.module.js").is_file()


def three_manifest() -> dict[str, Any]:
    """The pinned three version and the sha384 of every module file the viewer imports."""
    return json.loads(THREE_MANIFEST.read_text())


@dataclass(frozen=True)
class ThreeSource:
    """Where the viewer's browser loads three.js from ("local", "remote" or "none")."""

    kind: str
    version: str
    base: str = ""  # URL prefix of the package root, ends with "/"
    integrity: dict[str, str] = field(default_factory=dict)  # full URL -> "sha384-..."

    @property
    def label(self) -> str:
        if self.kind == "local":
            return f"three.js {self.version} from this server (node_modules)"
        if self.kind == "remote":
            host = re.sub(r"^[a-z]+://", "", self.base).split("/", 1)[0] or "this server"
            return f"three.js {self.version} from {host} (integrity-checked)"
        return "three.js not available"

    def importmap(self) -> dict[str, Any] | None:
        if self.kind == "none":
            return None
        out: dict[str, Any] = {
            "imports": {"three": self.base + "build/three.module.js", "three/addons/": self.base + "examples/jsm/"}
        }
        if self.integrity:
            out["integrity"] = self.integrity
        return out

    def as_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "version": self.version,
            "base": self.base,
            "label": self.label,
            "importmap": self.importmap(),
        }


def three_source() -> ThreeSource:
    """node_modules when installed, else ``$MMS_THREE_URL`` (default: the pinned version on
    jsDelivr; set it empty to allow no remote source)."""
    manifest = three_manifest()
    version = manifest["version"]
    if _three_installed():
        # same origin, offline, and whatever version npm installed: no integrity table
        return ThreeSource("local", version, file_url(THREE) + "/")
    base = os.environ.get("MMS_THREE_URL", CDN_TEMPLATE.format(version=version)).strip()
    if not base:
        return ThreeSource("none", version)
    base = base.rstrip("/") + "/"
    integrity = {base + path: digest for path, digest in manifest["files"].items()}
    return ThreeSource("remote", version, base, integrity)


def three_missing_html() -> str | None:
    """The message a page shows instead of a viewer when no three.js source is configured."""
    if three_source().kind != "none":
        return None
    return (
        "<div class='mms-viewer-missing'>The 3D viewer needs three.js: install the npm package "
        "<code>three</code> (<code>bash scripts/setup.sh</code>) or set <code>MMS_THREE_URL</code> "
        "to a copy of it, and restart.</div>"
    )


def three_source_script() -> str:
    """The classic script viewer.html loads before its import map (served at THREE_SOURCE_ROUTE)."""
    data = json.dumps(three_source().as_dict()).replace("</", "<\\/")
    return f"window.mmsThree = {data};\n"


def three_routes() -> list[Any]:
    """Starlette routes to add to the Gradio app (``launch(app_kwargs={"routes": ...})``)."""
    from starlette.responses import Response
    from starlette.routing import Route

    async def source(_request) -> Response:
        return Response(
            three_source_script(),
            media_type="text/javascript",
            headers={"Cache-Control": "no-store"},  # the answer changes when node_modules does
        )

    return [Route(THREE_SOURCE_ROUTE, source, methods=["GET"])]


# ---------------------------------------------------------------- the manifest (maintainers)
_IMPORT = re.compile(r"^\s*(?:import|export)\s+(?:[^'\";]*?\sfrom\s*)?['\"]([^'\"]+)['\"]", re.M)


def module_files(three_dir: Path, entry: Path) -> list[str]:
    """Every file of the three package (relative to its root) that ``entry``'s static imports
    pull in, following imports inside three too; bare "three" and "three/addons/" resolve as in
    the viewer's import map."""
    root = three_dir.resolve()
    seen: set[Path] = set()
    todo = [entry.resolve()]
    while todo:
        f = todo.pop()
        for spec in _IMPORT.findall(f.read_text(encoding="utf-8")):
            if spec == "three":
                target = root / "build" / "three.module.js"
            elif spec.startswith("three/addons/"):
                target = root / "examples" / "jsm" / spec.removeprefix("three/addons/")
            elif spec.startswith("."):
                target = (f.parent / spec).resolve()
            else:
                raise ValueError(f"{f}: cannot resolve import {spec!r}")
            if not target.is_file():
                raise ValueError(f"{f}: import {spec!r} -> {target} does not exist")
            if target not in seen:
                seen.add(target)
                todo.append(target)
    return sorted(str(p.relative_to(root)) for p in seen)


def sri(path: Path) -> str:
    return "sha384-" + base64.b64encode(hashlib.sha384(path.read_bytes()).digest()).decode()


def build_three_manifest(three_dir: Path = THREE, entry: Path = STATIC / "viewer.js") -> dict[str, Any]:
    version = json.loads((three_dir / "package.json").read_text())["version"]
    return {
        "version": version,
        "files": {rel: sri(three_dir / rel) for rel in module_files(three_dir, entry)},
    }


# ---------------------------------------------------------------- the viewer in a page
def viewer_template(height: int = 460) -> str:
    """The viewer's iframe (loaded once per page; motions arrive by ``postMessage``)."""
    missing = three_missing_html()
    if missing is not None:
        return missing
    src = html.escape(file_url(STATIC / "viewer.html"))
    return (
        f"<iframe class='mms-viewer' title='motion viewer' src='{src}' "
        f"style='width:100%;height:{height}px;border:0;border-radius:8px'></iframe>"
    )


# Runs in the Gradio page when the component mounts: forwards every new value (a GLB URL)
# to the viewer in the iframe, and the current one again whenever the iframe (re)loads.
# A new value also brings the viewer into view (on a phone it sits above the controls, out of
# sight from the Generate button). This is done here, where the motion arrives, not after the
# request's end: there it had to guess how long a busy machine takes to pass the motion on, and
# a guess of 5 s left the viewer out of sight. A refused request sets no value, so nothing moves.
VIEWER_JS = """
const frame = element.querySelector('iframe.mms-viewer');
if (frame) {
  const send = () => {
    if (props.value && frame.contentWindow) {
      frame.contentWindow.postMessage({type: 'mms-load', glb: props.value}, window.location.origin);
    }
  };
  frame.addEventListener('load', send);
  watch('value', () => {
    send();
    if (props.value && window.mmsReveal) window.mmsReveal('iframe.mms-viewer', 'start');
  });
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


if __name__ == "__main__":
    # python -m app.viewer: rewrite app/three_manifest.json after changing three's version or
    # the viewer's imports (a test compares it with node_modules and static/viewer.js)
    THREE_MANIFEST.write_text(json.dumps(build_three_manifest(), indent=1) + "\n")
    print(f"wrote {THREE_MANIFEST}")
