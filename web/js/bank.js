// The bank page: sessions, clips as filmstrips of billboards, a sprite's detail,
// tagging a run of frames, export.
import { ApiError, Events, Limiter, chrome, el, fmt, getJson, getBlob, postJson, saveBlob } from './api.js';
import { showMessage } from './message.js';
import { $ } from './page.js';

const events = new Events().start();
chrome(events);

const billboards = new Limiter(4);

let sessions = [];
let sessionId = null;
let clips = new Map(); // id -> {clip, root, strip, sprites, cells: [] }
let selection = null; // {clipId, a, b} indices into the clip's sprites
let current = null; // sprite id in the detail panel
let loadToken = 0;

// ---- lazy loading ----------------------------------------------------------

const imageObserver = new IntersectionObserver(
  (entries) => {
    for (const e of entries) {
      if (!e.isIntersecting) continue;
      imageObserver.unobserve(e.target);
      loadBillboard(e.target);
    }
  },
  { rootMargin: '200px' },
);

const clipObserver = new IntersectionObserver(
  (entries) => {
    for (const e of entries) {
      if (!e.isIntersecting) continue;
      clipObserver.unobserve(e.target);
      loadClipSprites(Number(e.target.dataset.clip));
    }
  },
  { rootMargin: '300px' },
);

// A billboard whose request failed for a passing reason (a station too busy to answer, 5xx;
// a connection dropped) is asked for again after 0.5, 1, 2 and 4 s; one the bank does not have
// (4xx) shows its error at once.
const BILLBOARD_RETRIES = 4;

async function loadBillboard(cell, attempt = 0) {
  const img = cell.querySelector('img');
  cell.dataset.loaded = 'requested';
  try {
    const { blob } = await billboards.run(() => getBlob(`/api/bank/sprites/${cell.dataset.sprite}/billboard.png?height=96`));
    img.src = URL.createObjectURL(blob);
    await img.decode().catch(() => {});
    cell.dataset.loaded = '1';
    img.alt = '';
    img.title = '';
  } catch (err) {
    cell.dataset.loaded = 'error';
    img.alt = `billboard: ${err.message}`;
    img.title = img.alt;
    const passing = !(err instanceof ApiError) || err.status >= 500;
    if (passing && attempt < BILLBOARD_RETRIES && cell.isConnected) {
      setTimeout(() => loadBillboard(cell, attempt + 1), 500 * 2 ** attempt);
    }
  }
}

// ---- sessions --------------------------------------------------------------

async function loadSessions() {
  try {
    sessions = await getJson('/api/bank/sessions');
  } catch (err) {
    showMessage(`bank sessions: ${err.message}`, 'error');
    return;
  }
  const list = $('bank-sessions');
  list.replaceChildren(
    ...sessions.map((s) =>
      el(
        'li',
        { testid: 'bank-session', 'data-session': s.id, class: s.id === sessionId ? 'on' : '', onclick: () => openSession(s.id) },
        el('div', { class: 'sname', text: s.name || `session ${s.id}` }),
        el('div', { class: 'meta', text: `${(s.created || '').replace('T', ' ').replace(/\.\d+|Z$/g, '')}` }),
        el('div', {
          class: 'meta',
          text: `${(s.cameras || []).map((c) => c.name).join(' ')} · ${fmt(s.clips)} clips · ${fmt(s.sprites)} sprites`,
        }),
      ),
    ),
  );
  if (!sessions.length) list.append(el('li', { class: 'empty', text: 'The bank holds no session yet.' }));
}

async function openSession(id, thenSprite = null) {
  sessionId = id;
  const mine = ++loadToken;
  for (const li of document.querySelectorAll('[data-testid="bank-session"]')) li.classList.toggle('on', Number(li.dataset.session) === id);
  history.replaceState(null, '', `#session=${id}${thenSprite ? `&sprite=${thenSprite}` : ''}`);
  setSelection(null);
  const box = $('bank-clips');
  box.replaceChildren(el('p', { class: 'empty', text: 'Loading clips…' }));
  let list;
  try {
    list = await getJson(`/api/bank/sessions/${id}/clips`);
  } catch (err) {
    showMessage(`clips: ${err.message}`, 'error');
    return;
  }
  if (mine !== loadToken) return;
  clips = new Map();
  box.replaceChildren();
  for (const clip of list) {
    const entry = renderClip(clip);
    clips.set(clip.id, entry);
    box.append(entry.root);
    clipObserver.observe(entry.root);
  }
  if (!list.length) box.append(el('p', { class: 'empty', text: 'No complete clip in this session.' }));
  if (thenSprite) revealSprite(thenSprite);
}

function renderClip(clip) {
  const strip = el('div', { class: 'filmstrip', testid: 'filmstrip' });
  const chips = el('span', { class: 'chips', testid: 'clip-tags' });
  const root = el(
    'section',
    { class: 'clip', testid: 'clip', 'data-clip': clip.id, 'data-sprites': clip.sprites },
    el(
      'header',
      {},
      el('span', { class: 'cid', text: `clip ${clip.id}` }),
      el('span', { class: 'meta', text: `${clip.camera} · track ${clip.track_id} · frames ${clip.first_frame}–${clip.last_frame} · ${fmt(clip.sprites)} sprites` }),
      chips,
      el('span', { class: 'spacer' }),
      el('button', { type: 'button', class: 'link', testid: 'clip-export', text: 'Export CSV', onclick: () => exportCsv(`clip=${clip.id}`, `clip-${clip.id}.csv`) }),
    ),
    strip,
  );
  const entry = { clip, root, strip, chips, sprites: null, cells: [] };
  showClipTags(entry);
  return entry;
}

function showClipTags(entry) {
  const tags = entry.clip.tags || {};
  entry.chips.replaceChildren(...Object.entries(tags).map(([t, n]) => el('span', { class: 'chip', 'data-tag': t, text: `${t} ${n}` })));
}

async function loadClipSprites(clipId) {
  const entry = clips.get(clipId);
  if (!entry || entry.sprites) return entry;
  entry.sprites = [];
  let sprites;
  try {
    sprites = await getJson(`/api/bank/clips/${clipId}/sprites`);
  } catch (err) {
    entry.sprites = null;
    showMessage(`clip ${clipId}: ${err.message}`, 'error');
    return entry;
  }
  entry.sprites = sprites;
  entry.cells = sprites.map((s, i) => {
    const cell = el(
      'div',
      { class: 'frame-cell', testid: 'sprite-cell', 'data-sprite': s.id, 'data-frame': s.frame, title: `sprite ${s.id} · frame ${s.frame}` },
      el('img', { alt: '', testid: 'billboard', draggable: 'false' }),
      el('span', { class: 'fno', text: String(s.frame) }),
      el('span', { class: 'ftags', testid: 'sprite-tags' }),
    );
    cell.addEventListener('click', (ev) => clickCell(clipId, i, ev.shiftKey));
    showCellTags(cell, s.tags);
    imageObserver.observe(cell);
    return cell;
  });
  entry.strip.replaceChildren(...entry.cells);
  entry.root.dataset.loaded = '1';
  paintSelection();
  return entry;
}

function showCellTags(cell, tags) {
  cell.querySelector('.ftags').replaceChildren(...(tags || []).map((t) => el('span', { text: t, 'data-tag': t })));
  cell.dataset.tags = (tags || []).join(',');
}

// ---- selection and tags -----------------------------------------------------

function clickCell(clipId, index, shift) {
  const entry = clips.get(clipId);
  if (shift && selection && selection.clipId === clipId) {
    setSelection({ clipId, a: selection.a, b: index });
  } else {
    setSelection({ clipId, a: index, b: index });
  }
  showSprite(entry.sprites[index].id);
}

function selectedRange() {
  if (!selection) return null;
  const entry = clips.get(selection.clipId);
  if (!entry?.sprites) return null;
  const lo = Math.min(selection.a, selection.b);
  const hi = Math.max(selection.a, selection.b);
  return { entry, lo, hi, first: entry.sprites[lo].frame, last: entry.sprites[hi].frame };
}

function setSelection(sel) {
  selection = sel;
  paintSelection();
}

function paintSelection() {
  for (const entry of clips.values()) {
    entry.cells.forEach((cell, i) => {
      const on = selection && selection.clipId === entry.clip.id && i >= Math.min(selection.a, selection.b) && i <= Math.max(selection.a, selection.b);
      cell.classList.toggle('sel', Boolean(on));
      cell.classList.toggle('current', Number(cell.dataset.sprite) === current);
    });
  }
  const r = selectedRange();
  const label = $('bank-selection');
  if (r) {
    const n = r.hi - r.lo + 1;
    label.textContent = `clip ${r.entry.clip.id}: frames ${r.first}–${r.last} (${n} sprite${n === 1 ? '' : 's'})`;
    label.dataset.first = r.first;
    label.dataset.last = r.last;
    label.dataset.count = n;
  } else {
    label.textContent = 'Click a sprite; shift-click another of its clip to select the run between.';
    delete label.dataset.count;
  }
  $('tag-apply').disabled = !r;
  $('tag-remove').disabled = !r;
}

async function tag(untag) {
  const r = selectedRange();
  const t = $('tag-input').value.trim();
  if (!r) return;
  if (!t) return showMessage('tag: type a tag first', 'error');
  try {
    const reply = await postJson(untag ? '/api/bank/untag' : '/api/bank/tag', {
      tag: t,
      clip: r.entry.clip.id,
      first_frame: r.first,
      last_frame: r.last,
    });
    showMessage(`${untag ? 'Untagged' : 'Tagged'} ${fmt(reply.tagged)} sprite(s) ${untag ? 'from' : 'as'} “${t}”.`, 'info');
  } catch (err) {
    showMessage(err.message, 'error');
    return;
  }
  await refreshTags(r.entry);
  if (current) showSprite(current, false);
}

async function refreshTags(entry) {
  try {
    const [sprites, list] = await Promise.all([
      getJson(`/api/bank/clips/${entry.clip.id}/sprites`),
      getJson(`/api/bank/sessions/${sessionId}/clips`),
    ]);
    const byId = new Map(sprites.map((s) => [s.id, s]));
    entry.sprites.forEach((s, i) => {
      const fresh = byId.get(s.id);
      if (!fresh) return;
      s.tags = fresh.tags;
      showCellTags(entry.cells[i], fresh.tags);
    });
    const c = list.find((c) => c.id === entry.clip.id);
    if (c) {
      entry.clip = c;
      showClipTags(entry);
    }
  } catch (err) {
    showMessage(err.message, 'error');
  }
}

async function exportCsv(query, name) {
  try {
    const { blob, headers } = await getBlob(`/api/bank/export.csv?${query}`);
    const named = /filename="?([^";]+)"?/.exec(headers.get('Content-Disposition') || '');
    saveBlob(blob, named ? named[1] : name);
  } catch (err) {
    showMessage(`export: ${err.message}`, 'error');
  }
}

// ---- detail ----------------------------------------------------------------

const num = (v, d = 3) => (typeof v === 'number' ? fmt(v, d) : '–');
const vec = (v, d = 3) => (Array.isArray(v) ? `(${v.map((x) => num(x, d)).join(', ')})` : num(v, d));

async function revealSprite(id) {
  for (const entry of clips.values()) {
    const loaded = entry.sprites ? entry : null;
    if (!loaded) continue;
    const cell = entry.cells.find((c) => Number(c.dataset.sprite) === id);
    if (cell) {
      // again once the billboards around it have loaded and widened their cells
      for (const delay of [0, 400, 1200]) {
        setTimeout(() => current === id && cell.scrollIntoView({ block: 'nearest', inline: 'center' }), delay);
      }
      return;
    }
  }
}

async function showSprite(id, navigate = true) {
  current = id;
  paintSelection();
  const box = $('sprite-detail');
  let s;
  try {
    s = await getJson(`/api/bank/sprites/${id}`);
  } catch (err) {
    showMessage(`sprite ${id}: ${err.message}`, 'error');
    return;
  }
  if (current !== id) return;
  const sid = s.session_id ?? (typeof s.session === 'number' ? s.session : sessionId);
  if (navigate) {
    history.replaceState(null, '', `#session=${sid}&sprite=${id}`);
    if (sid !== sessionId) {
      await openSession(sid, id);
    } else {
      const entry = clips.get(s.clip_id);
      if (entry) {
        entry.root.scrollIntoView({ block: 'nearest' });
        await loadClipSprites(s.clip_id);
        paintSelection();
        revealSprite(id);
      }
    }
  }
  const f = s.features || {};
  const colour = Array.isArray(f.mean_colour) ? f.mean_colour : null;
  const bbImg = el('img', { alt: `billboard of sprite ${id}` });
  getBlob(`/api/bank/sprites/${id}/billboard.png?height=160`)
    .then(({ blob }) => (bbImg.src = URL.createObjectURL(blob)))
    .catch(() => {});
  const trTable = (list, testid) =>
    el(
      'table',
      { class: 'transitions', testid },
      el('tr', {}, el('td', { class: 'muted', text: 'sprite' }), el('td', { class: 'muted', text: 'cost' }), el('td', { class: 'muted', text: 'D' })),
      ...(list || []).map((t) =>
        el(
          'tr',
          { testid: 'transition', 'data-sprite': t.sprite, onclick: () => showSprite(t.sprite) },
          el('td', {}, el('a', { href: `#sprite=${t.sprite}`, text: `#${t.sprite}`, onclick: (e) => e.preventDefault() })),
          el('td', { text: num(t.cost, 4) }),
          el('td', { text: num(t.d, 4) }),
        ),
      ),
    );
  const dl = (pairs) => el('dl', {}, ...pairs.flatMap(([k, v, tid]) => [el('dt', { text: k }), el('dd', { text: v, testid: tid })]));
  const t = typeof s.timestamp_ns === 'number' ? s.timestamp_ns / 1e9 : null;
  box.replaceChildren(
    el('h2', {}, `Sprite #${s.id ?? id}`, s.mirror_of ? el('span', { class: 'badge', text: `mirror of #${s.mirror_of}` }) : null),
    el('div', { class: 'bb' }, bbImg),
    dl([
      ['session', typeof s.session === 'string' ? s.session : (sid ?? '–'), 'detail-session'],
      ['camera', s.camera ?? '–', 'detail-camera'],
      ['clip', s.clip_id ?? '–', 'detail-clip'],
      ['frame', s.frame ?? '–', 'detail-frame'],
      ['time', t === null ? '–' : `${fmt(t, 3)} s`, 'detail-time'],
      ['ground (m)', vec(s.ground), 'detail-ground'],
      ['velocity (m/s)', vec(s.velocity), 'detail-velocity'],
      ['tags', (s.tags || []).join(', ') || '–', 'detail-tags'],
    ]),
    el('h3', { text: 'Features' }),
    el(
      'dl',
      { testid: 'detail-features' },
      el('dt', { text: 'velocity (m/s)' }), el('dd', { text: vec(f.velocity_m_s) }),
      el('dt', { text: 'mean colour' }),
      el('dd', {}, colour ? el('i', { class: 'swatch', style: { background: `rgb(${colour.map((c) => Math.round(c)).join(',')})` } }) : null, colour ? vec(colour, 0) : '–'),
      el('dt', { text: 'area (m²)' }), el('dd', { text: num(f.area_m2, 4) }),
      el('dt', { text: 'eccentricity' }), el('dd', { text: num(f.eccentricity, 3) }),
      el('dt', { text: 'billboard' }),
      el('dd', { text: s.billboard ? `${s.billboard.width}×${s.billboard.height} px, ${num(s.billboard.px_per_m, 0)} px/m` : '–' }),
      el('dt', { text: 'box in image' }), el('dd', { text: Array.isArray(s.bbox_in_image) ? s.bbox_in_image.join(' ') : '–' }),
    ),
    el('h3', { text: `Transitions out (${(s.transitions_out || []).length})` }),
    trTable(s.transitions_out, 'transitions-out'),
    el('h3', { text: `Transitions in (${(s.transitions_in || []).length})` }),
    trTable(s.transitions_in, 'transitions-in'),
  );
  box.dataset.sprite = String(s.id ?? id);
}

// ---- wiring ----------------------------------------------------------------

$('tag-apply').addEventListener('click', () => tag(false));
$('tag-remove').addEventListener('click', () => tag(true));
$('bank-refresh').addEventListener('click', async () => {
  await loadSessions();
  if (sessionId !== null) openSession(sessionId);
});

function fromHash() {
  const h = new URLSearchParams(location.hash.slice(1));
  return { session: h.has('session') ? Number(h.get('session')) : null, sprite: h.has('sprite') ? Number(h.get('sprite')) : null };
}

(async () => {
  await loadSessions();
  const h = fromHash();
  if (h.session !== null) {
    await openSession(h.session, h.sprite);
    if (h.sprite !== null) showSprite(h.sprite, false);
  }
})();
