"""Scripts of the demo page that need no server round trip: live limits and the viewer's
idle signal. The limits come from the core's constants, written into the script here."""

from __future__ import annotations

from motion_core.inference.base import MAX_SECONDS, MAX_SEGMENTS, MAX_TEXT_CHARS, MIN_SECONDS

# Sent to every viewer when a Generate request has ended, however it ended: the viewer drops
# its "Generating…" note and plays on (a refused request brings no new motion to load).
IDLE_VIEWER_JS = """
() => {
  for (const frame of document.querySelectorAll('iframe.mms-viewer')) {
    if (frame.contentWindow) frame.contentWindow.postMessage({type: 'mms-idle'}, window.location.origin);
  }
}
"""

# After a generation: the page's address becomes the link that reproduces it, and the tab's
# history (sessionStorage, newest first, at most 20) lists it; both drawn by drawHistory.
SHARE_JS = """
(query) => {
  if (!query) return;
  const url = window.location.pathname + '?' + query;
  if (window.location.search !== '?' + query) window.history.replaceState(null, '', url);
  const p = new URLSearchParams(query);
  // the first segment's text names the timeline; the others are counted, not hidden
  let first = '', more = 0;
  try {
    const rows = JSON.parse(p.get('timeline'));
    first = String(rows[0][0] ?? '');
    more = rows.length - 1;
  } catch (e) { first = ''; }
  const rest = more > 0 ? ` (+${more} more)` : '';
  // the sampling options too: two entries that differ only in them must not read the same
  const steps = p.get('steps');
  const how = [
    p.get('sampler'),
    steps && `${steps} step${steps === '1' ? '' : 's'}`,
    p.get('guidance') && `guidance ${p.get('guidance')}`,
  ].filter(Boolean).join(', ');
  const label = [`${first.slice(0, 60)}${rest}`, p.get('method'), how, `seed ${p.get('seed')}`]
    .filter(Boolean).join(' · ');
  let items = [];
  try { items = JSON.parse(sessionStorage.getItem('mms-history') || '[]'); } catch (e) { items = []; }
  items = [{query, label}, ...items.filter((h) => h.query !== query)].slice(0, 20);
  sessionStorage.setItem('mms-history', JSON.stringify(items));
  if (window.mmsDrawHistory) window.mmsDrawHistory();
}
"""

# Runs once when the page loads. A character counter under each segment's text and the
# browser's own bounds on each seconds box (min/max: out-of-range boxes turn red via
# :invalid; step "any", since any length is valid: a 0.5 step turned the length estimator's
# 4.8 s red although it generates as it is), refreshed a few times a second because Gradio
# sets values without input events (row moves, examples, imports).
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
        sec.setAttribute('step', 'any');
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
  // the link to the current result and this tab's earlier generations (each a link that regenerates it)
  window.mmsDrawHistory = () => {{
    const box = document.getElementById('mms-history');
    if (!box) return;
    let items = [];
    try {{ items = JSON.parse(sessionStorage.getItem('mms-history') || '[]'); }} catch (e) {{ items = []; }}
    box.replaceChildren();
    if (!items.length) return;
    const link = document.createElement('a');
    link.id = 'share-link';
    link.href = window.location.pathname + '?' + items[0].query;
    link.textContent = 'Link to this result';
    link.title = 'opening it regenerates the same motion';
    const copy = document.createElement('button');
    copy.type = 'button';
    copy.textContent = 'copy';
    copy.style.marginLeft = '8px';
    copy.onclick = () => navigator.clipboard && navigator.clipboard.writeText(link.href);
    box.append(link, copy);
    if (items.length > 1) {{
      const head = document.createElement('div');
      head.textContent = 'Earlier in this tab:';
      const list = document.createElement('ol');
      for (const h of items.slice(1)) {{
        const li = document.createElement('li');
        const a = document.createElement('a');
        a.href = window.location.pathname + '?' + h.query;
        a.textContent = h.label || h.query;
        li.appendChild(a);
        list.appendChild(li);
      }}
      box.append(head, list);
    }}
  }};
  setTimeout(window.mmsDrawHistory, 500);
  document.addEventListener('input', refresh, true);
  setInterval(refresh, 400);
  refresh();
}}
"""
