// The station page: every camera as a live tile, the session panel, the charts.
import { Events, Limiter, chrome, el, fmt, duration, getJson, getBlob, postJson, dataUrlBlob } from './api.js';
import { VERDICT_COLOURS, VERDICT_LABELS, verdictColour, histogram, lineChart } from './draw.js';
import { showMessage } from './message.js';
import { $, busy, pollView } from './page.js';

const events = new Events().start();
chrome(events);

// Previews share at most 4 connections: with the event stream that leaves one
// of the browser's six for the session buttons, however many tiles there are.
const previews = new Limiter(4);

let status = null;
const tiles = new Map();
const tilesEl = document.querySelector('[data-testid="tiles"]');

// Previews back off while a session runs (the daemon shares one image for
// 0.5 s then; a faster loop would only fetch the same image again).
const backedOff = () => Boolean(status?.session?.active);

const VIEWS = ['raw', 'keyed', 'sprites'];

class Tile {
  constructor(name) {
    this.name = name;
    this.cam = null;
    this.alive = true;
    this.view = sessionStorage.getItem(`view.${name}`) || 'raw';
    if (!VIEWS.includes(this.view)) this.view = 'raw';
    this.wake = null;

    const q = (id) => this.root.querySelector(`[data-testid="${id}"]`);
    this.root = el('article', { class: 'tile', testid: 'tile', 'data-camera': name, 'data-view': this.view, 'data-frame': '', 'data-candidates': '0' });
    this.root.innerHTML = `
      <header>
        <span class="name" data-testid="tile-name"></span>
        <span class="badge" data-testid="tile-state"></span>
        <span class="spacer"></span>
        <span class="num fps" data-testid="tile-fps">– fps</span>
      </header>
      <div class="view">
        <canvas data-testid="tile-canvas" width="640" height="480"></canvas>
        <div class="view-msg" data-testid="tile-message"></div>
        <span class="frame num" title="frame sequence number shown">#<b data-testid="tile-frame">–</b></span>
        <span class="cands num" data-testid="tile-candidates" hidden></span>
      </div>
      <div class="controls">
        <div class="switch" role="group" aria-label="view">
          ${VIEWS.map((v) => `<button type="button" data-view="${v}" data-testid="view-${v}">${v}</button>`).join('')}
        </div>
        <span class="error-text" data-testid="tile-error"></span>
        <a class="needs" data-testid="tile-needs" href="calibrate.html" hidden></a>
      </div>
      <dl class="stats">
        <dt title="dropped because the pipeline fell behind">drops queue</dt><dd class="num" data-testid="tile-drops-queue">–</dd>
        <dt title="incomplete frames, sequence gaps, unreadable frames">drops source</dt><dd class="num" data-testid="tile-drops-source">–</dd>
        <dt>queue</dt><dd class="num"><span data-testid="tile-queue">–</span><i class="meter"><i data-testid="tile-queue-meter"></i></i></dd>
        <dt title="empty-enclosure frames the keyer learnt from">learnt</dt><dd class="num" data-testid="tile-learnt">–</dd>
        <dt title="sprites this camera stored since the station started">stored</dt><dd class="num" data-testid="tile-stored">–</dd>
        <dt title="of them, two or more subjects in one blob: tagged merged, left out of transitions">merged</dt><dd class="num" data-testid="tile-merged">–</dd>
      </dl>
      <div class="exposure">
        <canvas class="hist" data-testid="tile-histogram" title="green-screen histogram (r, g, b); shaded: green below 40"></canvas>
        <dl>
          <dt>clipped</dt><dd class="num" data-testid="tile-clipped">–</dd>
          <dt>dark</dt><dd class="num" data-testid="tile-dark">–</dd>
          <dt>uniformity</dt><dd class="num" data-testid="tile-uniformity">–</dd>
          <dt>green</dt><dd class="num" data-testid="tile-green">–</dd>
        </dl>
      </div>`;
    this.els = {
      name: q('tile-name'), state: q('tile-state'), fps: q('tile-fps'), canvas: q('tile-canvas'),
      msg: q('tile-message'), frame: q('tile-frame'), cands: q('tile-candidates'), error: q('tile-error'), needs: q('tile-needs'),
      dq: q('tile-drops-queue'), ds: q('tile-drops-source'), queue: q('tile-queue'), meter: q('tile-queue-meter'),
      learnt: q('tile-learnt'), stored: q('tile-stored'), merged: q('tile-merged'), hist: q('tile-histogram'), clipped: q('tile-clipped'), dark: q('tile-dark'),
      uniformity: q('tile-uniformity'), green: q('tile-green'),
    };
    this.els.name.textContent = name;
    this.ctx = this.els.canvas.getContext('2d');
    for (const b of this.root.querySelectorAll('.switch button')) {
      b.addEventListener('click', () => this.setView(b.dataset.view));
    }
    this.#markView();
    this.#loop();
  }

  setView(view) {
    if (!VIEWS.includes(view) || view === this.view) return;
    this.view = view;
    sessionStorage.setItem(`view.${this.name}`, view);
    this.root.dataset.view = view;
    this.root.dataset.candidates = '0';
    this.root.dataset.verdicts = '';
    this.els.cands.hidden = view !== 'sprites';
    this.#markView();
    this.wake?.();
  }

  #markView() {
    for (const b of this.root.querySelectorAll('.switch button')) {
      b.classList.toggle('on', b.dataset.view === this.view);
      b.setAttribute('aria-pressed', String(b.dataset.view === this.view));
    }
    this.els.cands.hidden = this.view !== 'sprites';
  }

  update(cam) {
    const wasOffline = this.cam?.state === 'offline';
    this.cam = cam;
    const e = this.els;
    this.root.dataset.state = cam.state;
    e.state.textContent = cam.state;
    e.state.dataset.state = cam.state;
    e.error.textContent = cam.state === 'error' || cam.state === 'offline' ? cam.message || '' : '';
    e.error.title = cam.message || '';
    // A camera without its model or without the floor streams but stores no sprite: say which.
    const needs = !cam.has_model ? 'no camera model: calibrate' : cam.has_floor === false ? 'no floor: calibrate' : '';
    e.needs.textContent = needs;
    e.needs.title = needs ? `${cam.message || needs} (the calibration page)` : '';
    e.needs.hidden = !needs || cam.state === 'error' || cam.state === 'offline';
    e.fps.textContent = `${fmt(cam.fps, 1)} fps`;
    e.dq.textContent = fmt(cam.dropped?.queue_full);
    e.ds.textContent = fmt(cam.dropped?.at_source);
    e.dq.classList.toggle('warn', (cam.dropped?.queue_full || 0) > 0);
    e.ds.classList.toggle('warn', (cam.dropped?.at_source || 0) > 0);
    e.queue.textContent = `${fmt(cam.queue_depth)}/${fmt(cam.queue_capacity)}`;
    const fill = cam.queue_capacity ? cam.queue_depth / cam.queue_capacity : 0;
    e.meter.style.width = `${Math.round(Math.min(1, fill) * 100)}%`;
    e.meter.classList.toggle('hot', fill > 0.75);
    e.learnt.textContent = cam.learnt_from?.frames ? `${fmt(cam.learnt_from.frames)} fr` : 'not yet';
    e.stored.textContent = fmt(cam.sprites_stored);
    e.merged.textContent = fmt(cam.sprites_merged);
    const x = cam.exposure;
    e.clipped.textContent = x ? `${fmt(x.clipped_percent, 1)}%` : '–';
    e.dark.textContent = x ? `${fmt(x.dark_percent, 1)}%` : '–';
    e.uniformity.textContent = x ? fmt(x.green_uniformity, 2) : '–';
    e.green.textContent = x ? `${fmt(x.green_fraction * 100, 0)}%` : '–';
    e.clipped.classList.toggle('warn', (x?.clipped_percent || 0) > 1);
    e.dark.classList.toggle('warn', (x?.dark_percent || 0) > 5);
    e.uniformity.classList.toggle('warn', x ? x.green_uniformity < 0.8 : false);
    const histKey = x ? JSON.stringify(x.histogram) : '';
    if (histKey !== this.histKey) {
      this.histKey = histKey;
      histogram(e.hist, x?.histogram);
    }
    if (!this.sized && cam.width && cam.height) {
      this.sized = true;
      e.canvas.width = 640;
      e.canvas.height = Math.round((640 * cam.height) / cam.width);
      this.#clear();
    }
    this.root.classList.toggle('stale', cam.state === 'offline');
    if (cam.state === 'offline') this.#say(`offline${cam.message ? ': ' + cam.message : ''}`);
    else if (wasOffline) {
      this.#say('');
      this.wake?.();
    }
  }

  redrawHistogram() {
    histogram(this.els.hist, this.cam?.exposure?.histogram);
  }

  #say(text) {
    this.els.msg.textContent = text;
    this.els.msg.hidden = !text;
  }

  #clear() {
    this.ctx.fillStyle = '#06080c';
    this.ctx.fillRect(0, 0, this.els.canvas.width, this.els.canvas.height);
  }

  #width() {
    const dpr = window.devicePixelRatio || 1;
    const want = Math.ceil((this.els.canvas.clientWidth * dpr) / 160) * 160;
    const cap = this.cam?.width || 640;
    return Math.max(160, Math.min(want || 320, cap, 1280));
  }

  #showFrame(seq) {
    if (seq === null || seq === undefined || seq === '') return;
    this.root.dataset.frame = String(seq);
    this.els.frame.textContent = String(seq);
  }

  #draw(bitmap) {
    const c = this.els.canvas;
    if (c.width !== bitmap.width || c.height !== bitmap.height) {
      c.width = bitmap.width;
      c.height = bitmap.height;
    }
    this.ctx.drawImage(bitmap, 0, 0);
    bitmap.close?.();
  }

  async #preview() {
    const view = this.view;
    const { blob, headers } = await getBlob(
      `/api/cameras/${encodeURIComponent(this.name)}/preview.jpg?view=${view}&width=${this.#width()}`,
    );
    const bitmap = await createImageBitmap(blob);
    if (view !== this.view) return bitmap.close?.();
    this.#draw(bitmap);
    this.#showFrame(headers.get('X-Frame-Sequence'));
    this.#say('');
  }

  async #sprites() {
    const data = await getJson(`/api/cameras/${encodeURIComponent(this.name)}/sprites.json?width=${this.#width()}`);
    if (this.view !== 'sprites') return;
    const bitmap = await createImageBitmap(dataUrlBlob(data.image));
    if (this.view !== 'sprites') return bitmap.close?.();
    this.#draw(bitmap);
    const s = data.scale || 1;
    const ctx = this.ctx;
    const px = this.els.canvas.width / Math.max(1, this.els.canvas.clientWidth); // one CSS pixel
    const cands = data.candidates || [];
    ctx.lineJoin = 'round';
    ctx.font = `bold ${Math.round(11 * px)}px ui-monospace, monospace`;
    ctx.textBaseline = 'bottom';
    for (const c of cands) {
      const colour = verdictColour(c.verdict);
      ctx.strokeStyle = colour;
      ctx.fillStyle = colour;
      ctx.lineWidth = 2 * px;
      // Two or more subjects in one blob: stored tagged merged, drawn dashed.
      ctx.setLineDash(c.merged ? [6 * px, 4 * px] : []);
      if (c.outline && c.outline.length > 1) {
        ctx.beginPath();
        c.outline.forEach(([x, y], i) => (i ? ctx.lineTo(x * s, y * s) : ctx.moveTo(x * s, y * s)));
        ctx.closePath();
        ctx.stroke();
      } else if (c.bbox) {
        ctx.strokeRect(c.bbox[0] * s, c.bbox[1] * s, c.bbox[2] * s, c.bbox[3] * s);
      }
      // The outline is the blob's largest part; a merged blob's box holds all of its subjects.
      if (c.merged && c.bbox && c.outline?.length > 1) {
        ctx.strokeRect(c.bbox[0] * s, c.bbox[1] * s, c.bbox[2] * s, c.bbox[3] * s);
      }
      ctx.setLineDash([]);
      if (c.contact) {
        ctx.beginPath();
        ctx.arc(c.contact[0] * s, c.contact[1] * s, 3.5 * px, 0, Math.PI * 2);
        ctx.fill();
        ctx.strokeStyle = '#000';
        ctx.lineWidth = 1 * px;
        ctx.stroke();
      }
      if (c.bbox) {
        const label = (c.track >= 0 ? `#${c.track}` : '–') + (c.merged ? ' ×2' : '');
        const tx = c.bbox[0] * s;
        const ty = Math.max(12 * px, c.bbox[1] * s - 2 * px);
        const tw = ctx.measureText(label).width;
        ctx.fillStyle = 'rgba(0,0,0,0.65)';
        ctx.fillRect(tx - px, ty - 12 * px, tw + 4 * px, 12 * px);
        ctx.fillStyle = colour;
        ctx.fillText(label, tx + px, ty);
      }
    }
    this.root.dataset.candidates = String(cands.length);
    this.root.dataset.merged = String(cands.filter((c) => c.merged).length);
    this.root.dataset.verdicts = [...new Set(cands.map((c) => c.verdict))].join(',');
    this.els.cands.textContent = data.training ? 'training' : `${cands.length} candidate${cands.length === 1 ? '' : 's'}`;
    this.#showFrame(data.sequence);
    this.#say(data.training ? 'keyer learning the empty enclosure' : '');
  }

  #loop() {
    return pollView(this, {
      idle: () => !this.cam || this.cam.state === 'offline',
      pause: () => (backedOff() ? 500 : 100),
      fetch: () => previews.run(() => (this.view === 'sprites' ? this.#sprites() : this.#preview())),
      onError: (err) => {
        if (err.status === 503) this.#say(this.cam?.state === 'training' ? 'waiting for the first frame' : 'no frame yet');
        else this.#say(`preview: ${err.message}`);
      },
    });
  }

  destroy() {
    this.alive = false;
    this.wake?.();
    this.root.remove();
  }
}

function syncTiles(cameras) {
  const names = cameras.map((c) => c.name);
  for (const [name, tile] of tiles) {
    if (!names.includes(name)) {
      tile.destroy();
      tiles.delete(name);
    }
  }
  cameras.forEach((cam, i) => {
    let tile = tiles.get(cam.name);
    if (!tile) {
      tile = new Tile(cam.name);
      tiles.set(cam.name, tile);
    }
    if (tilesEl.children[i] !== tile.root) tilesEl.insertBefore(tile.root, tilesEl.children[i] || null);
    tile.update(cam);
  });
  tilesEl.dataset.count = String(cameras.length);
}

// ---- session panel ---------------------------------------------------------

const nameInput = $('session-name');
let elapsedAt = null; // {seconds, at}

function mib(v) {
  if (v === null || v === undefined) return '–';
  return v >= 10240 ? `${fmt(v / 1024, 1)} GiB` : `${fmt(v)} MiB`;
}

function updateSession(s) {
  const sess = s.session || {};
  const active = Boolean(sess.active);
  const st = $('session-state');
  st.textContent = active ? 'active' : 'idle';
  st.dataset.state = active ? 'active' : 'idle';
  document.body.classList.toggle('session-active', active);
  $('session-current-name').textContent = sess.name || '–';
  $('session-sprites').textContent = sess.name || active ? fmt(sess.sprites_stored) : '–';
  $('bank-sprites').textContent = fmt(s.bank?.sprites);
  const recEl = $('session-recording');
  recEl.replaceChildren(el('bdi', { text: sess.recording_dir || (s.storage?.recording === 'off' ? 'off' : '–') }));
  recEl.title = sess.recording_dir || '';
  elapsedAt = active ? { seconds: sess.seconds || 0, at: performance.now() } : null;
  if (!active) $('session-elapsed').textContent = sess.name ? duration(sess.seconds || 0) : '–';
  tickElapsed();
  $('session-start').disabled = active;
  $('session-stop').disabled = !active;
  $('session-rename').disabled = !active;

  const g = s.storage || {};
  const free = g.disk_free_mib;
  const rec = g.stop_recording_below_mib;
  const spr = g.stop_sprites_below_mib;
  $('disk-free').textContent = mib(free);
  $('stop-recording').textContent = mib(rec);
  $('stop-sprites').textContent = mib(spr);
  const state = $('storage-state');
  state.textContent = g.state || '–';
  state.dataset.state = g.state || '';
  const top = Math.max(free || 0, (rec || 0) * 4, (spr || 0) * 8, 1) * 1.05;
  const bar = $('disk-bar');
  const pct = (v) => `${Math.max(0, Math.min(100, ((v || 0) / top) * 100))}%`;
  bar.querySelector('.disk-fill').style.width = pct(free);
  bar.querySelector('.disk-mark.rec').style.left = pct(rec);
  bar.querySelector('.disk-mark.spr').style.left = pct(spr);
  bar.dataset.level = free === undefined ? '' : free < (spr || 0) ? 'stop' : free < (rec || 0) ? 'low' : 'ok';
}

function tickElapsed() {
  if (!elapsedAt) return;
  $('session-elapsed').textContent = duration(elapsedAt.seconds + (performance.now() - elapsedAt.at) / 1000);
}
setInterval(tickElapsed, 250);

function defaultName() {
  const d = new Date();
  const two = (x) => String(x).padStart(2, '0');
  return `take ${d.getFullYear()}-${two(d.getMonth() + 1)}-${two(d.getDate())} ${two(d.getHours())}${two(d.getMinutes())}`;
}

// The session as a start, stop or rename answered it (the same fields as the status's), shown at
// once rather than when the next status event brings it.
// A status event taken before the change can arrive after its answer: the session with the
// higher revision (the station raises it at each start, stop and rename) is the one shown.
let answered = null; // the session of the last answer
function applySession(session) {
  if (!session || typeof session.active !== 'boolean') return;
  answered = session;
  if (status) status = { ...status, session };
}
function newerSession(s) {
  if (answered && (s.session?.revision ?? 0) < (answered.revision ?? 0)) return { ...s, session: answered };
  answered = null; // the station has caught up with the answer
  return s;
}

// A session request from its button; the session's state decides the buttons after it.
function act(button, fn) {
  return busy(button, fn, (b) => {
    if (status) updateSession(status);
    else b.disabled = false;
  });
}

$('session-start').addEventListener('click', (e) =>
  act(e.currentTarget, async () => {
    const name = nameInput.value.trim() || defaultName();
    applySession(await postJson('/api/session/start', { name }));
    showMessage(`Session “${name}” started.`, 'info');
  }),
);
$('session-stop').addEventListener('click', (e) =>
  act(e.currentTarget, async () => {
    $('session-stop').textContent = 'Stopping…';
    try {
      const r = await postJson('/api/session/stop');
      applySession(r);
      const n = r.sprites_stored ?? r.session?.sprites_stored;
      showMessage(`Session stopped${n !== undefined ? `: ${fmt(n)} sprites stored` : ''}.`, 'info');
    } finally {
      $('session-stop').textContent = 'Stop';
    }
  }),
);
$('session-rename').addEventListener('click', (e) =>
  act(e.currentTarget, async () => {
    const name = nameInput.value.trim();
    if (!name) throw new Error('name: type the new name first');
    applySession(await postJson('/api/session/rename', { name }));
    showMessage(`Session renamed to “${name}”.`, 'info');
  }),
);
$('session-form').addEventListener('submit', (e) => {
  e.preventDefault();
  (status?.session?.active ? $('session-rename') : $('session-start')).click();
});

// ---- charts ----------------------------------------------------------------

const COLOURS = { a: '#3ddc84', p50: '#60a5fa', p99: '#f5a524', t: '#c084fc', d: '#ef4444' };
let chartsQueued = false;
function drawCharts() {
  chartsQueued = false;
  const h = events.history;
  const t1 = h.length ? h[h.length - 1].t : Date.now() / 1000;
  const t0 = t1 - 300;
  const series = (key) => h.map((s) => [s.t, s[key]]);
  const last = h[h.length - 1] || {};
  lineChart($('chart-sprites'), [{ values: series('sprites_per_s'), colour: COLOURS.a }], t0, t1);
  lineChart(
    $('chart-latency'),
    [
      { values: series('latency_p99_ms'), colour: COLOURS.p99 },
      { values: series('latency_p50_ms'), colour: COLOURS.p50 },
    ],
    t0,
    t1,
    { unit: '' },
  );
  lineChart($('chart-transitions'), [{ values: series('transitions_pending'), colour: COLOURS.t }], t0, t1);
  lineChart($('chart-drops'), [{ values: series('dropped_per_s'), colour: COLOURS.d }], t0, t1);
  $('chart-sprites-now').textContent = h.length ? fmt(last.sprites_per_s, 1) : '';
  $('chart-latency-now').textContent = h.length ? `${fmt(last.latency_p50_ms)} / ${fmt(last.latency_p99_ms)} ms` : '';
  $('chart-transitions-now').textContent = h.length ? fmt(last.transitions_pending) : '';
  $('chart-drops-now').textContent = h.length ? fmt(last.dropped_per_s, 1) : '';
  $('charts').dataset.samples = String(h.length);
}
function queueCharts() {
  if (chartsQueued || document.hidden) return;
  chartsQueued = true;
  requestAnimationFrame(drawCharts);
}

// ---- legend ----------------------------------------------------------------

$('legend').querySelector('ul').append(
  ...Object.entries(VERDICT_COLOURS).map(([v, c]) =>
    el('li', { 'data-verdict': v }, el('i', { style: { background: c } }), el('span', { text: VERDICT_LABELS[v] || v })),
  ),
  el('li', {}, el('i', { class: 'dot' }), el('span', { text: 'contact point, #track id' })),
  el('li', {}, el('i', { class: 'dashed' }), el('span', { text: 'dashed, #id ×2: two subjects in one blob (merged)' })),
);

// ---- wiring ----------------------------------------------------------------

events.addEventListener('status', (e) => {
  status = newerSession(e.detail);
  syncTiles(status.cameras || []);
  updateSession(status);
  document.body.dataset.mode = status.mode || 'live';
});
events.addEventListener('connection', (e) => {
  if (e.detail !== 'connected') answered = null; // a restarted daemon counts revisions afresh
});
events.addEventListener('history', queueCharts);
events.addEventListener('sample', queueCharts);
document.addEventListener('visibilitychange', queueCharts);
new ResizeObserver(() => {
  queueCharts();
  for (const t of tiles.values()) t.redrawHistogram();
}).observe(document.querySelector('main'));
