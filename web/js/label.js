// The labelling page: pairs of sprites the transition classifier is least sure of,
// each played as the transition would look (A−1, A, then B, B+1, looping); keys
// y / n / s (and u to undo); labels go to the bank; retrain from them.
import { Events, chrome, el, fmt, getBlob, getJson, postJson, saveBlob, basename } from './api.js';
import { showMessage } from './message.js';
import { $ } from './page.js';

const events = new Events().start();
chrome(events);

const BATCH = 10;
const FRAME_MS = 160; // a frame of the loop; the recorded 30 fps is too fast to judge
const HOLD_MS = 600; // pause after B+1 before the loop starts again
const GOAL = 1000; // seed 000 §3 labelled about 1000 pairs

let queue = []; // pairs still to ask in this batch, already shuffled
let batchSize = 0;
let current = null; // {pair, from, to, frames: [ids], a, b}
let busy = false;
let answered = 0;
let given = []; // [{from, to, item}] labelled on this visit, for undo
let lastRetrainState = null;
// label.html#pair=FROM,TO asks about that pair first (a link to one transition).
let linked = (() => {
  const m = /(?:^#|&)pair=(\d+),(\d+)/.exec(location.hash);
  return m ? { from: Number(m[1]), to: Number(m[2]) } : null;
})();

// ---- billboards ------------------------------------------------------------

const bitmaps = new Map(); // sprite id -> Promise<ImageBitmap>

function billboard(id) {
  if (!bitmaps.has(id)) {
    const p = getBlob(`/api/bank/sprites/${id}/billboard.png`).then(({ blob }) => createImageBitmap(blob));
    p.catch(() => bitmaps.delete(id));
    bitmaps.set(id, p);
    if (bitmaps.size > 300) bitmaps.delete(bitmaps.keys().next().value);
  }
  return bitmaps.get(id);
}

// Draws billboards standing on one ground point, all at one scale (fitting the largest of
// `all` into the canvas), so a jump in size or pose shows as it would in an animation.
function layout(canvas, metas) {
  const w = canvas.width;
  const h = canvas.height;
  let up = 1;
  let side = 1;
  for (const m of metas) {
    up = Math.max(up, m.anchor[1] + 0.5);
    side = Math.max(side, m.anchor[0] + 0.5, m.width - m.anchor[0] - 0.5);
  }
  const scale = Math.min((h * 0.86) / up, (w * 0.92) / (2 * side));
  return { scale, groundX: w / 2, groundY: h * 0.93 };
}

function draw(canvas, bitmap, meta, box) {
  const ctx = canvas.getContext('2d');
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  ctx.strokeStyle = 'rgba(255,255,255,0.18)';
  ctx.lineWidth = 1;
  ctx.beginPath();
  ctx.moveTo(0, box.groundY + 0.5);
  ctx.lineTo(canvas.width, box.groundY + 0.5);
  ctx.stroke();
  if (!bitmap) return;
  ctx.imageSmoothingEnabled = box.scale < 2;
  const x = box.groundX - (meta.anchor[0] + 0.5) * box.scale;
  const y = box.groundY - (meta.anchor[1] + 0.5) * box.scale;
  ctx.drawImage(bitmap, x, y, meta.width * box.scale, meta.height * box.scale);
}

// ---- the loop ----------------------------------------------------------------

let loopTimer = null;

function stopLoop() {
  clearTimeout(loopTimer);
  loopTimer = null;
}

function startLoop(shown, images) {
  stopLoop();
  const canvas = $('playback');
  const metas = shown.frames.map((id) => shown.pair.billboards[String(id)]);
  const box = layout(canvas, metas);
  const slots = [...document.querySelectorAll('[data-testid="strip"] span')];
  let k = 0;
  const step = () => {
    if (current !== shown) return;
    draw(canvas, images[k], metas[k], box);
    canvas.dataset.slot = String(k);
    slots.forEach((s, i) => s.classList.toggle('on', i === k));
    const wait = k === 3 ? FRAME_MS + HOLD_MS : FRAME_MS;
    k = (k + 1) % 4;
    loopTimer = setTimeout(step, wait);
  };
  step();
}

// A small picture of a labelled pair (A and B side by side) for the visit's list.
function recentItem(shown, label) {
  const c = el('canvas', { width: 72, height: 36 });
  const metas = [shown.frames[1], shown.frames[2]].map((id) => shown.pair.billboards[String(id)]);
  const half = el('canvas', { width: 36, height: 36 });
  const box = layout(half, metas);
  Promise.all([billboard(shown.from), billboard(shown.to)]).then(([a, b]) => {
    const ctx = c.getContext('2d');
    draw(half, a, metas[0], box);
    ctx.drawImage(half, 0, 0);
    draw(half, b, metas[1], box);
    ctx.drawImage(half, 36, 0);
  }, () => {});
  const item = el('li', { testid: 'recent-item', 'data-from': shown.from, 'data-to': shown.to, 'data-label': label },
    c, el('span', { text: `${shown.from}→${shown.to}` }), el('span', { class: `l ${label}`, text: label }));
  const list = $('recent');
  list.prepend(item);
  $('recent-count').textContent = `(${answered})`;
  return item;
}

// ---- pairs -------------------------------------------------------------------

function shuffle(list) {
  for (let i = list.length - 1; i > 0; i--) {
    const j = Math.floor(Math.random() * (i + 1));
    [list[i], list[j]] = [list[j], list[i]];
  }
  return list;
}

async function fetchBatch() {
  const r = await getJson(`/api/labels/pairs?count=${BATCH}`);
  queue = shuffle(r.pairs || []);
  batchSize = queue.length;
  $('judge').dataset.candidates = String(r.candidates ?? 0);
  $('judge').dataset.weights = r.weights || '';
}

function setAnswerButtons(enabled) {
  for (const b of document.querySelectorAll('.answers .answer')) b.disabled = !enabled;
  $('answer-undo').disabled = busy || given.length === 0;
}

function caption(side, name) {
  return `${name} · sprite ${side.id} · clip ${side.clip}, frame ${side.frame}`;
}

async function next() {
  stopLoop();
  current = null;
  const box = $('pair');
  box.dataset.state = 'loading';
  setAnswerButtons(false);
  let pair = null;
  let flip = Math.random() < 0.5;
  if (linked) {
    const link = linked;
    linked = null;
    window.history.replaceState(null, '', location.pathname);
    try {
      pair = await getJson(`/api/labels/pair?from=${link.from}&to=${link.to}`);
      flip = false; // as linked
    } catch (err) {
      showMessage(err.message, 'error'); // the API's words: "sprite: no sprite with id … in the bank"
    }
  }
  try {
    if (!pair && !queue.length) await fetchBatch();
  } catch (err) {
    showMessage(`pairs: ${err.message}`, 'error');
    box.dataset.state = 'error';
    return;
  }
  if (!pair && !queue.length) {
    box.dataset.state = 'empty';
    $('pair-empty').hidden = false;
    $('pair-empty').textContent = 'No unlabelled pair is left among the classifier\'s candidates of the sprites searched. ' +
      'Retrain, or come back when the bank holds more sprites.';
    $('batch-progress').textContent = 'no pairs left';
    return;
  }
  $('pair-empty').hidden = true;
  const fromLink = pair !== null;
  if (!pair) pair = queue.shift();
  // Sides at random: B → A is the same classifier pair played the other way.
  const a = flip ? pair.b : pair.a;
  const b = flip ? pair.a : pair.b;
  const shown = { pair, a, b, from: a.id, to: b.id, frames: [a.prev, a.id, b.id, b.next] };
  current = shown;
  const index = batchSize - queue.length;
  $('batch-progress').textContent = fromLink ? 'the linked pair' : `pair ${index} of ${batchSize} in this batch`;
  Object.assign(box.dataset, {
    from: String(shown.from),
    to: String(shown.to),
    frames: shown.frames.join(','),
    flipped: flip ? '1' : '0',
    decision: pair.decision,
    pAccept: String(pair.p_accept),
    index: String(answered),
  });
  $('caption-a').textContent = caption(a, 'A');
  $('caption-b').textContent = caption(b, 'B');
  let images;
  try {
    images = await Promise.all(shown.frames.map(billboard));
    // the next pairs' billboards load meanwhile
    for (const p of queue.slice(0, 2)) for (const id of Object.keys(p.billboards)) billboard(Number(id));
  } catch (err) {
    if (current === shown) showMessage(`billboards: ${err.message}`, 'error');
    return;
  }
  if (current !== shown) return;
  const metas = shown.frames.map((id) => pair.billboards[String(id)]);
  const stillBox = layout($('still-a'), metas);
  draw($('still-a'), images[1], metas[1], stillBox);
  draw($('still-b'), images[2], metas[2], stillBox);
  startLoop(shown, images);
  box.dataset.state = 'ready';
  setAnswerButtons(true);
}

async function answer(label) {
  if (busy || !current || $('pair').dataset.state !== 'ready') return;
  busy = true;
  const shown = current;
  setAnswerButtons(false);
  for (const b of document.querySelectorAll('.answers .answer')) b.classList.toggle('pressed', b.dataset.label === label);
  try {
    const r = await postJson('/api/labels', { from: shown.from, to: shown.to, label });
    answered++;
    given.push({ from: shown.from, to: shown.to, item: recentItem(shown, label) });
    $('session-count').textContent = String(answered);
    showCounts(r.labels);
  } catch (err) {
    showMessage(err.message, 'error');
    busy = false;
    setAnswerButtons(true);
    return;
  } finally {
    for (const b of document.querySelectorAll('.answers .answer')) b.classList.remove('pressed');
  }
  busy = false;
  await next();
}

async function undo() {
  if (busy || !given.length) return;
  busy = true;
  const last = given.pop();
  try {
    const r = await postJson('/api/labels/undo', { from: last.from, to: last.to });
    last.item.classList.add('undone');
    answered = Math.max(0, answered - 1);
    $('session-count').textContent = String(answered);
    $('recent-count').textContent = `(${answered})`;
    showCounts(r.labels);
    showMessage(`The label of ${last.from} → ${last.to} is removed; that pair comes back in a later batch.`, 'info');
  } catch (err) {
    showMessage(err.message, 'error');
  }
  busy = false;
  setAnswerButtons(current !== null && $('pair').dataset.state === 'ready');
}

document.addEventListener('keydown', (ev) => {
  if (ev.ctrlKey || ev.metaKey || ev.altKey) return;
  if (ev.target instanceof HTMLInputElement || ev.target instanceof HTMLTextAreaElement) return;
  const key = ev.key.toLowerCase();
  const label = { y: 'yes', n: 'no', s: 'skip' }[key];
  if (label) {
    ev.preventDefault();
    answer(label);
  } else if (key === 'u' || key === 'backspace') {
    ev.preventDefault();
    undo();
  }
});
for (const b of document.querySelectorAll('.answers .answer')) b.addEventListener('click', () => answer(b.dataset.label));
$('answer-undo').addEventListener('click', undo);

// ---- counts, weights, retrain (from the event stream) ----------------------------

function showCounts(c) {
  if (!c || c.error) return;
  $('count-yes').textContent = fmt(c.yes);
  $('count-no').textContent = fmt(c.no);
  $('count-skip').textContent = fmt(c.skip);
  $('label-counts').dataset.total = String(c.total);
  $('label-counts').dataset.exportable = String(c.exportable);
  const bar = $('label-bar').querySelector('i');
  bar.style.width = `${Math.min(100, (100 * c.exportable) / GOAL)}%`;
  $('label-goal').textContent = `${fmt(c.exportable)} of the ~${fmt(GOAL)} yes / no labels the paper trained on`;
}

const pct = (x) => (typeof x === 'number' ? x.toFixed(3) : '–');

function showClassifier(status) {
  const t = status.transitions || {};
  const w = t.weights || {};
  $('weights-name').textContent = w.name || '–';
  $('weights-name').title = w.path || 'the weights shipped with the build';
  $('weights-fingerprint').textContent = (w.fingerprint || '–').replace(/^fnv1a64:/, '');
  const table = $('weights-table');
  table.textContent = !w.table ? 'no table yet' : w.table === w.fingerprint ? 'made by these weights' : 'made by other weights';
  table.dataset.match = w.table && w.table === w.fingerprint ? '1' : '0';
  $('weights-cv').textContent = w.cross_validated ? `${pct(w.cross_validated.precision)} / ${pct(w.cross_validated.recall)}` : '–';

  const r = t.retrain || { state: 'idle' };
  const box = $('retrain-state');
  box.dataset.state = r.state;
  const badge = $('retrain-badge');
  badge.textContent = r.state;
  badge.dataset.state = { done: 'ok', failed: 'error', training: 'training', rebuilding: 'training' }[r.state] || '';
  $('retrain-stage').textContent = r.stage || '';
  const running = r.state === 'training' || r.state === 'rebuilding';
  $('retrain-bar').querySelector('i').style.width = `${Math.round(100 * (r.progress || 0))}%`;
  $('retrain-bar').dataset.progress = String(r.progress || 0);
  $('retrain-button').disabled = running;
  // A cancel is taken until the station gets the new weights: the job says so (docs/console.md).
  $('retrain-cancel').hidden = !r.cancellable;
  const figures = r.precision !== undefined;
  $('retrain-figures').hidden = !figures;
  if (figures) {
    $('retrain-precision').textContent = pct(r.precision);
    $('retrain-recall').textContent = pct(r.recall);
    $('retrain-stage1').textContent = r.stage1 ? `${pct(r.stage1.precision)} / ${pct(r.stage1.recall)}` : '–';
    $('retrain-labels').textContent = `${fmt(r.labels)} labels (${fmt(r.accepts)} yes)`;
    $('retrain-weights').textContent = r.weights ? basename(r.weights) : '–';
    $('retrain-weights').title = r.weights || '';
    $('retrain-transitions').textContent =
      r.transitions !== undefined ? `${fmt(r.transitions)} in ${fmt(r.seconds_rebuild, 1)} s` : '…';
  }
  const err = $('retrain-error');
  err.hidden = r.state !== 'failed';
  err.textContent = r.state === 'failed' ? r.error || 'failed' : '';
  if (lastRetrainState !== null && r.state !== lastRetrainState) {
    if (r.state === 'failed') showMessage(`retrain: ${r.error}`, 'error');
    if (r.state === 'cancelled') showMessage('Retrain cancelled: the weights in use and the transitions are as they were.', 'info');
    if (r.state === 'done') {
      showMessage(`Retrained: the station uses ${basename(r.weights)}; the bank's transitions are rebuilt. ` +
        'The next pairs are the new classifier\'s least sure.', 'info');
      queue = []; // ask what the new classifier is unsure of
      if ($('pair').dataset.state === 'empty') next();
    }
  }
  lastRetrainState = r.state;
}

events.addEventListener('status', (e) => {
  showCounts(e.detail.labels);
  showClassifier(e.detail);
});

$('retrain-cancel').addEventListener('click', async () => {
  $('retrain-cancel').disabled = true;
  try {
    await postJson('/api/labels/retrain/cancel', {});
  } catch (err) {
    showMessage(err.message, 'error');
  } finally {
    $('retrain-cancel').disabled = false;
  }
});

$('retrain-button').addEventListener('click', async () => {
  $('retrain-button').disabled = true;
  try {
    await postJson('/api/labels/retrain', {});
  } catch (err) {
    showMessage(err.message, 'error');
    $('retrain-button').disabled = false;
  }
});

$('export-csv').addEventListener('click', async () => {
  try {
    const { blob } = await getBlob('/api/labels/export.csv');
    saveBlob(blob, 'labels.csv');
  } catch (err) {
    showMessage(`export: ${err.message}`, 'error');
  }
});

getJson('/api/labels').then(showCounts, (err) => showMessage(`labels: ${err.message}`, 'error'));
next();
