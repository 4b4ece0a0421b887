"""Scripts of the demo page that need no server round trip: live limits and the viewer's
idle signal. The limits come from the core's constants, written into the script here."""

from __future__ import annotations

from motion_core.generation import MAX_SECONDS, MAX_SEGMENTS, MAX_TEXT_CHARS, MIN_SECONDS

# Sent to every viewer when a Generate request has ended, however it ended: the viewer drops
# its "Generating…" note and plays on (a refused request brings no new motion to load).
IDLE_VIEWER_JS = """
() => {
  for (const frame of document.querySelectorAll('iframe.mms-viewer')) {
    if (frame.contentWindow) frame.contentWindow.postMessage({type: 'mms-idle'}, window.location.origin);
  }
}
"""

# Runs once when the page loads. A character counter under each segment's text and the
# browser's own bounds on each seconds box (min/max/step: out-of-range boxes turn red via
# :invalid), refreshed a few times a second because Gradio sets values without input events
# (row moves, examples, imports).
PAGE_JS = f"""
() => {{
  const MAX_CHARS = {MAX_TEXT_CHARS}, ROWS = {MAX_SEGMENTS};
  const refresh = () => {{
    for (let i = 0; i < ROWS; i++) {{
      const box = document.getElementById(`seg-text-${{i}}`);
      const area = box && box.querySelector('textarea');
      if (area) {{
        let count = box.querySelector('.mms-count');
        if (!count) {{
          count = document.createElement('div');
          count.className = 'mms-count';
          count.setAttribute('aria-live', 'polite');
          box.appendChild(count);
        }}
        const n = area.value.length;
        const text = n > MAX_CHARS
          ? `${{n}}/${{MAX_CHARS}} characters: ${{n - MAX_CHARS}} too many`
          : `${{n}}/${{MAX_CHARS}}`;
        if (count.textContent !== text) count.textContent = text;
        count.classList.toggle('mms-over', n > MAX_CHARS);
      }}
      const sec = document.querySelector(`#seg-sec-${{i}} input`);
      if (sec && sec.getAttribute('max') !== '{MAX_SECONDS:g}') {{
        sec.setAttribute('min', '{MIN_SECONDS:g}');
        sec.setAttribute('max', '{MAX_SECONDS:g}');
        sec.setAttribute('step', '0.5');
        sec.title = 'seconds: {MIN_SECONDS:g} to {MAX_SECONDS:g}';
      }}
    }}
  }};
  // the viewer asks for fullscreen from inside its iframe: the page puts that frame in fullscreen
  window.addEventListener('message', (e) => {{
    if (e.origin !== window.location.origin || !e.data || e.data.type !== 'mms-fullscreen') return;
    const frame = Array.from(document.querySelectorAll('iframe')).find((f) => f.contentWindow === e.source);
    if (!frame) return;
    if (document.fullscreenElement) document.exitFullscreen();
    else frame.requestFullscreen().catch(() => {{}});
  }});
  document.addEventListener('input', refresh, true);
  setInterval(refresh, 400);
  refresh();
}}
"""
