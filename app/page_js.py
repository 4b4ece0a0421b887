"""Scripts of the demo page that need no server round trip: live limits and the viewer's
idle signal. The limits come from the core's constants, written into the script here."""

from __future__ import annotations

from motion_core.inference.base import MAX_SECONDS, MAX_SEGMENTS, MAX_TEXT_CHARS, MIN_SECONDS

HISTORY_EARLIER = 5  # earlier generations the tab's history keeps (and the current one)

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
# history (sessionStorage, newest first, the current one and HISTORY_EARLIER before it) lists
# it; both drawn by drawHistory.
SHARE_JS = f"""
(query) => {{
  if (!query) return;
  const url = window.location.pathname + '?' + query;
  if (window.location.search !== '?' + query) window.history.replaceState(null, '', url);
  const p = new URLSearchParams(query);
  // the first segment's text names the timeline; the others are counted, not hidden
  let first = '', more = 0;
  try {{
    const rows = JSON.parse(p.get('timeline'));
    first = String(rows[0][0] ?? '');
    more = rows.length - 1;
  }} catch (e) {{ first = ''; }}
  const rest = more > 0 ? ` (+${{more}} more)` : '';
  // the sampling options too: two entries that differ only in them must not read the same
  const steps = p.get('steps');
  const how = [
    p.get('sampler'),
    steps && `${{steps}} step${{steps === '1' ? '' : 's'}}`,
    p.get('guidance') && `guidance ${{p.get('guidance')}}`,
  ].filter(Boolean).join(', ');
  const label = [`${{first.slice(0, 60)}}${{rest}}`, p.get('method'), how, `seed ${{p.get('seed')}}`]
    .filter(Boolean).join(' · ');
  let items = [];
  try {{ items = JSON.parse(sessionStorage.getItem('mms-history') || '[]'); }} catch (e) {{ items = []; }}
  items = [{{query, label}}, ...items.filter((h) => h.query !== query)].slice(0, {HISTORY_EARLIER + 1});
  sessionStorage.setItem('mms-history', JSON.stringify(items));
  if (window.mmsDrawHistory) window.mmsDrawHistory();
}}
"""

# Runs once when the page loads. A character counter under each segment's text and the
# browser's own bounds on each seconds box (min/max: out-of-range boxes turn red via
# :invalid; step "any", since any length is valid: a 0.5 step turned the length estimator's
# 4.8 s red although it generates as it is), refreshed a few times a second because Gradio
# sets values without input events (row moves, examples, imports).
PAGE_JS = f"""
() => {{
  const MAX_CHARS = {MAX_TEXT_CHARS}, ROWS = {MAX_SEGMENTS};
  // the timeline the rows show now: [[text, seconds or null], ...]
  const rowsNow = () => {{
    const out = [];
    for (let i = 0; i < ROWS; i++) {{
      const row = document.getElementById(`seg-row-${{i}}`);
      if (!row || row.offsetParent === null) continue;
      const area = document.querySelector(`#seg-text-${{i}} textarea`);
      const sec = document.querySelector(`#seg-sec-${{i}} input`);
      out.push([area ? area.value.trim() : '', sec && sec.value !== '' ? Number(sec.value) : null]);
    }}
    return out;
  }};
  // a compare / variations grid shows the motions of the timeline it was made for
  // (data-timeline): once the rows say otherwise it is marked stale, with a note. A blank
  // seconds box then (null) matches the duration the estimator filled in since
  const markStale = () => {{
    const box = document.querySelector('#multi-view .mms-grid-box');
    if (!box) return;
    let made = [];
    try {{ made = JSON.parse(box.dataset.timeline || '[]'); }} catch (e) {{ return; }}
    const now = rowsNow();
    const same = now.length === made.length && made.every(([t, s], i) =>
      String(t).trim() === now[i][0] && (s === null || now[i][1] === null || Math.abs(s - now[i][1]) < 1e-9));
    box.classList.toggle('mms-grid-stale', !same);
    const note = box.querySelector('.mms-stale-note');
    if (note) note.hidden = same;
    const grid = box.querySelector('.mms-grid');
    if (grid) grid.classList.toggle('mms-stale', !same);
  }};
  // a row's split offer is about the text it was read from (data-text). While the user types
  // in the row the server reads each new text and the offer stays until its answer (hiding
  // it at each key made the rows below jump); a box that holds other text a moment after the
  // last key (the rows moved or refilled, an answer that came after a split) hides it
  const typedAt = {{}};
  document.addEventListener('input', (e) => {{
    const box = e.target.closest && e.target.closest('[id^=seg-text-]');
    if (box) typedAt[box.id] = Date.now();
  }}, true);
  const hideStaleSplits = () => {{
    for (let i = 0; i < ROWS; i++) {{
      const box = document.getElementById(`seg-split-${{i}}`);
      const line = box && box.querySelector('.mms-reading');
      if (!box || !line) continue;
      const area = document.querySelector(`#seg-text-${{i}} textarea`);
      const typing = Date.now() - (typedAt[`seg-text-${{i}}`] || 0) < 1500;
      box.classList.toggle('mms-split-stale', !area || (area.value !== line.dataset.text && !typing));
    }}
  }};
  const refresh = () => {{
    markStale();
    hideStaleSplits();
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
        // the server's rule (the core's validate): Python's len of the stripped text, in
        // code points; .length counts UTF-16 units, 2 per emoji
        const n = Array.from(area.value.trim()).length;
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
      // folded by default (and kept as the user left it): the list must not push the page down
      const fold = document.createElement('details');
      fold.open = window.mmsHistoryOpen === true;
      fold.addEventListener('toggle', () => {{ window.mmsHistoryOpen = fold.open; }});
      const head = document.createElement('summary');
      head.textContent = `Earlier in this tab (${{items.length - 1}}, the last {HISTORY_EARLIER} kept)`;
      const list = document.createElement('ol');
      for (const h of items.slice(1)) {{
        const li = document.createElement('li');
        const a = document.createElement('a');
        a.href = window.location.pathname + '?' + h.query;
        a.textContent = h.label || h.query;
        li.appendChild(a);
        list.appendChild(li);
      }}
      fold.append(head, list);
      box.append(fold);
    }}
  }};
  setTimeout(window.mmsDrawHistory, 500);
  // bring a result into view when it arrives (nothing moves when it is in view already)
  // (and again over the next 2.5 s: the page's own updates, such as an earlier message going
  // away above it, can still move it; a viewer revealed as its motion came sat 55 px too high)
  window.mmsReveal = (selector, block, waits = [600, 900, 1000]) => {{
    const el = document.querySelector(selector);
    if (!el) return;
    const r = el.getBoundingClientRect();
    const h = window.innerHeight || document.documentElement.clientHeight;
    const inView = block === 'start' ? r.top >= 0 && r.top < h * 0.5 : r.top >= 0 && r.bottom <= h;
    if (!inView) el.scrollIntoView({{block: block || 'nearest', behavior: 'instant'}});
    if (waits.length) setTimeout(() => window.mmsReveal(selector, block, waits.slice(1)), waits[0]);
  }};
  document.addEventListener('input', refresh, true);
  // the text the user typed last into a row, whatever way it went in (TYPED_JS reads it)
  document.addEventListener('input', (e) => {{
    const area = e.isTrusted && e.target.closest && e.target.closest('[id^=seg-text-] textarea');
    if (area) window.mmsTyped = area.value;
  }}, true);
  // Gradio's textbox sends its "input" event from a keypress, so a row's text changed by a
  // paste, a drop, Backspace or Delete, undo or an IME reached the server as no input at all:
  // a pasted sentence got no split offer, and words deleted left a stale one. Such a change
  // (a user's own: a script's value sets fire no DOM input) is passed on as the keypress that
  // typing would have sent. Inserted text is left alone: typed, it comes with its own keypress
  // (a phone keyboard that types with none is not covered).
  document.addEventListener('input', (e) => {{
    if (!e.isTrusted || e.inputType === 'insertText' || e.inputType === 'insertLineBreak') return;
    const area = e.target.closest && e.target.closest('[id^=seg-text-] textarea');
    if (area) area.dispatchEvent(new KeyboardEvent('keypress', {{bubbles: true, key: 'Unidentified'}}));
  }}, true);
  // a seconds box typed into holds the user's number again, not the estimate its label named
  document.addEventListener('input', (e) => {{
    const box = e.target.closest && e.target.closest('[id^=seg-sec-]');
    const label = box && box.querySelector('[data-testid=block-info]');
    if (label && label.textContent.startsWith('estimated')) label.textContent = 'seconds';
  }}, true);
  setInterval(refresh, 400);
  refresh();
}}
"""


# the guide line's event: its first input is the text the user typed last (PAGE_JS keeps it),
# the rest the rows as the page holds them
TYPED_JS = "(typed, ...rows) => [window.mmsTyped || '', ...rows]"


def pending_grid_js(what: str) -> str:
    """On a click on Compare / variations: a note where the grid will be, brought into view
    (the grid itself comes after every motion is generated); ``GRID_DONE_JS`` removes it."""
    return f"""
() => {{
  const box = document.getElementById('multi-view');
  if (!box) return;
  box.querySelectorAll('.mms-pending').forEach((n) => n.remove());
  const note = document.createElement('div');
  note.className = 'mms-pending';
  note.textContent = {what!r};
  box.prepend(note);
  if (window.mmsReveal) window.mmsReveal('#multi-view', 'start');
}}
"""


# When Compare / variations has ended, however it ended: the note goes, the grid comes into view.
GRID_DONE_JS = """
() => {
  document.querySelectorAll('#multi-view .mms-pending').forEach((n) => n.remove());
  if (document.querySelector('#multi-view .mms-grid') && window.mmsReveal) window.mmsReveal('#multi-view', 'start');
}
"""
