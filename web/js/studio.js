// The studio page: compose an animation spec on the floor plan with the mouse (sprites, their
// paths, location targets, a frames constraint, collisions), run it on the station's bank,
// follow the optimizer's cost and tracks, then play the render and read the judge's figures.
// docs/console.md ("Studio") is the contract; docs/animation.md the spec's fields.
//
// The page keeps the scene as plain data and writes the spec from it as JSON, which YAML reads
// as it is: "Load" is JSON.parse of a spec the page wrote (or any JSON spec; what the page does
// not draw is kept and written back unchanged).
import { Events, Limiter, basename, chrome, el, fmt, getBlob, getJson, postJson, saveBlob, sleep, token, wakeableSleep } from './api.js';
import { fitCanvas, groundGrid } from './draw.js';
import { showMessage } from './message.js';
import { $, busy } from './page.js';

const events = new Events().start();
chrome(events);

const COLOURS = ['#f5a524', '#22d3ee', '#e879f9', '#facc15', '#fb923c', '#a78bfa', '#60a5fa', '#f472b6'];
const ACTIVE = new Set(['queued', 'running', 'rendering']);
// A path's weights as docs/examples/circle.yaml has them (the reasons are written there).
const PATH_DEFAULTS = { direction_strength: 0.5, distance_strength: 200, unreached_strength: 3000 };
const HEADER = '# Written by the SpriteStation studio: JSON, which YAML reads as it is.';
const STORE_KEY = 'studio.spec';

// Frames and billboards share at most 3 connections: with the event stream and the job's
// poll that leaves one of the browser's six for the buttons.
const fetches = new Limiter(3);

let inputs = null; // GET /api/animations/inputs
let scene = newScene(); // what the plan and the forms edit
let selected = -1; // index into scene.sprites
let tool = 'select';
let job = null; // the job shown: GET /api/animations/ID (or the stream's part of it)
let jobBudget = null; // its time budget, for the cost curve's time axis
let curve = []; // [[seconds, best_cost]] of the job shown
let curveUpdates = 0; // points the event stream added to it
let step = 0; // the player's step
let playing = false;
let playerFor = null; // the job whose frames the player is set up for
const poller = { wake: null }; // the job's poll, woken by the stream
let following = 0; // bumps to stop an older job's poll

// ---- the scene ---------------------------------------------------------------

function newScene() {
  return {
    frame_rate: 30,
    camera: '',
    background: '',
    banks: [],
    min_frames: '120',
    max_frames: '600',
    time_budget_s: '10',
    collisions: { on: false, min_distance_m: '0.1', strength: '100' },
    sprites: [],
    lengthRest: {}, // keys of the spec the page does not edit, kept as loaded
    optimizerRest: { method: 'replace' },
    collisionsRest: [],
    rest: {},
  };
}

function newSprite(name, start) {
  return {
    name,
    start, // [x, y] metres
    path: [], // points after the start
    strengths: { ...PATH_DEFAULTS },
    targets: [], // [{at: [x, y], from, to, strength}] (times as typed)
    frames: { on: false, tag: inputs?.tags?.[0] || '', strength: '50', after_path: true, duration: '2', from: '0', to: 'end' },
    otherConstraints: [],
    rest: {},
  };
}

function nextName() {
  const taken = new Set(scene.sprites.map((s) => s.name));
  for (let i = 1; ; i++) {
    const name = i === 1 ? 'hamster' : `hamster${i}`;
    if (!taken.has(name)) return name;
  }
}

const mm = (v) => Math.round(v * 1000) / 1000 || 0;
const point = ([x, y]) => [mm(x), mm(y)];
const isPoint = (p) => Array.isArray(p) && p.length === 2 && p.every((v) => typeof v === 'number');

// A typed number as the spec gets it: a number when it reads as one, else the text itself (the
// API then names the field), nothing when empty.
function numberOf(text) {
  const t = String(text ?? '').trim();
  if (t === '') return null;
  const v = Number(t);
  return Number.isFinite(v) ? v : t;
}

// A typed time: seconds or "end".
const timeOf = (text) => (String(text ?? '').trim() === 'end' ? 'end' : numberOf(text));

// from/to as typed -> the spec's window keys (from blank: only at `to`).
function windowOf(from, to) {
  const f = timeOf(from);
  const t = timeOf(to);
  if (f === null && t === null) return {};
  if (f === null) return { at: t };
  if (t === null) return { from: f };
  return { from: f, to: t };
}

function windowText(w) {
  if (w.at !== undefined) return { from: '', to: String(w.at) };
  return { from: w.from === undefined ? '' : String(w.from), to: w.to === undefined ? '' : String(w.to) };
}

// ---- scene -> spec -------------------------------------------------------------

function spriteSpec(sp) {
  const constraints = [];
  if (sp.start && sp.path.length) {
    const { direction_strength, distance_strength, unreached_strength } = sp.strengths;
    constraints.push({
      path: {
        points: [sp.start, ...sp.path].map(point),
        direction_strength: numberOf(direction_strength),
        distance_strength: numberOf(distance_strength),
        unreached_strength: numberOf(unreached_strength),
      },
    });
  }
  for (const t of sp.targets) {
    constraints.push({ location: { target: point(t.at), ...windowOf(t.from, t.to), strength: numberOf(t.strength) } });
  }
  const f = sp.frames;
  if (f.on) {
    const when = f.after_path ? { after_path: sp.name, duration: numberOf(f.duration) } : windowOf(f.from, f.to);
    constraints.push({ frames: { tag: f.tag, ...when, strength: numberOf(f.strength) } });
  }
  constraints.push(...sp.otherConstraints);
  const out = { name: sp.name };
  if (sp.start) out.start = point(sp.start);
  if (constraints.length) out.constraints = constraints;
  return { ...out, ...sp.rest };
}

function specOf(s) {
  const spec = {
    version: 1,
    frame_rate: s.frame_rate,
    length: { min_frames: numberOf(s.min_frames), max_frames: numberOf(s.max_frames), ...s.lengthRest },
    camera: s.camera,
  };
  if (s.background) spec.background = s.background;
  spec.banks = s.banks;
  spec.optimizer = { ...s.optimizerRest, time_budget_s: numberOf(s.time_budget_s) };
  spec.sprites = s.sprites.map(spriteSpec);
  const collisions = [...s.collisionsRest];
  if (s.collisions.on && s.sprites.length >= 2) {
    collisions.unshift({ sprites: 'all', min_distance_m: numberOf(s.collisions.min_distance_m), strength: numberOf(s.collisions.strength) });
  }
  if (collisions.length) spec.collisions = collisions;
  return { ...spec, ...s.rest };
}

// JSON laid out for reading: a value on one line when it fits, else one member a line, and
// lists of numbers or points packed several to a line.
function inline(v) {
  if (Array.isArray(v)) return `[${v.map(inline).join(', ')}]`;
  if (v && typeof v === 'object') return `{${Object.entries(v).map(([k, x]) => `${JSON.stringify(k)}: ${inline(x)}`).join(', ')}}`;
  return JSON.stringify(v ?? null);
}

function pretty(v, indent = '', used = indent.length, width = 96) {
  const one = inline(v);
  if (v === null || typeof v !== 'object' || used + one.length <= width) return one;
  const inner = indent + '  ';
  if (Array.isArray(v)) {
    const flat = v.every((x) => typeof x !== 'object' || isPoint(x));
    if (flat) {
      const lines = [];
      let line = '';
      for (const item of v.map(inline)) {
        if (line && inner.length + line.length + item.length + 2 > width) {
          lines.push(line);
          line = '';
        }
        line += (line ? ', ' : '') + item;
      }
      lines.push(line);
      return `[\n${lines.map((l) => inner + l).join(',\n')}\n${indent}]`;
    }
    return `[\n${v.map((x) => inner + pretty(x, inner)).join(',\n')}\n${indent}]`;
  }
  const members = Object.entries(v).map(([k, x]) => {
    const key = `${inner}${JSON.stringify(k)}: `;
    return key + pretty(x, inner, key.length);
  });
  return `{\n${members.join(',\n')}\n${indent}}`;
}

function specText(s) {
  return `${HEADER}\n${pretty(specOf(s))}\n`;
}

// ---- spec -> scene -------------------------------------------------------------

function parseSpecText(text) {
  // The header (and any comment line) is YAML's, not JSON's.
  const body = String(text).split('\n').filter((l) => !/^\s*#/.test(l)).join('\n');
  const spec = JSON.parse(body);
  if (!spec || typeof spec !== 'object' || Array.isArray(spec)) throw new Error('expected a spec: { ... }');
  return spec;
}

function spriteOf(obj, index) {
  if (!obj || typeof obj !== 'object') throw new Error(`sprites[${index}]: expected {name, start, constraints}`);
  const { name, start, constraints = [], ...rest } = obj;
  const sp = newSprite(String(name ?? ''), isPoint(start) ? start : null);
  sp.rest = rest;
  if (start !== undefined && !isPoint(start)) sp.rest.start = start;
  for (const c of Array.isArray(constraints) ? constraints : []) {
    const [kind, body] = c && typeof c === 'object' ? Object.entries(c)[0] || [] : [];
    if (!takeConstraint(sp, kind, body)) sp.otherConstraints.push(c);
  }
  return sp;
}

// A constraint the page draws and edits, into the sprite; false: kept as it is.
function takeConstraint(sp, kind, body) {
  if (!body || typeof body !== 'object') return false;
  const keys = Object.keys(body);
  const only = (allowed) => keys.every((k) => allowed.includes(k));
  if (kind === 'path' && !sp.path.length && sp.start && only(['points', ...Object.keys(PATH_DEFAULTS)]) &&
      Array.isArray(body.points) && body.points.length >= 2 && body.points.every(isPoint)) {
    const [first, ...more] = body.points;
    sp.path = first[0] === sp.start[0] && first[1] === sp.start[1] ? more : body.points;
    for (const k of Object.keys(PATH_DEFAULTS)) sp.strengths[k] = body[k] === undefined ? '' : String(body[k]);
    return true;
  }
  if (kind === 'location' && isPoint(body.target) && only(['target', 'at', 'from', 'to', 'strength'])) {
    sp.targets.push({ at: body.target, ...windowText(body), strength: body.strength === undefined ? '' : String(body.strength) });
    return true;
  }
  if (kind === 'frames' && !sp.frames.on && typeof body.tag === 'string' &&
      only(['tag', 'at', 'from', 'to', 'after_path', 'duration', 'strength']) &&
      (body.after_path === undefined || body.after_path === sp.name)) {
    const after = body.after_path !== undefined;
    sp.frames = {
      on: true,
      tag: body.tag,
      strength: body.strength === undefined ? '' : String(body.strength),
      after_path: after,
      duration: after ? String(body.duration ?? '') : '2',
      ...(after ? { from: '0', to: 'end' } : windowText(body)),
    };
    return true;
  }
  return false;
}

function sceneOf(spec) {
  const { frame_rate, length, camera, background, banks, optimizer, sprites, collisions, ...rest } = spec;
  const s = newScene();
  delete rest.version; // always 1 here
  s.rest = rest;
  s.frame_rate = frame_rate ?? inputs?.frame_rate ?? 30;
  s.camera = camera ?? '';
  s.background = background ?? '';
  s.banks = Array.isArray(banks) ? banks : banks ? [banks] : [];
  if (typeof length === 'number') {
    s.min_frames = s.max_frames = String(length);
  } else if (length && typeof length === 'object') {
    const { min_frames, max_frames, ...more } = length;
    s.min_frames = min_frames === undefined ? '' : String(min_frames);
    s.max_frames = max_frames === undefined ? '' : String(max_frames);
    s.lengthRest = more;
  }
  if (optimizer && typeof optimizer === 'object') {
    const { time_budget_s, ...more } = optimizer;
    s.time_budget_s = time_budget_s === undefined ? '' : String(time_budget_s);
    s.optimizerRest = more;
  }
  s.sprites = (Array.isArray(sprites) ? sprites : []).map(spriteOf);
  for (const c of Array.isArray(collisions) ? collisions : []) {
    const mine = !s.collisions.on && c && c.sprites === 'all' && Object.keys(c).every((k) => ['sprites', 'min_distance_m', 'strength'].includes(k));
    if (mine) s.collisions = { on: true, min_distance_m: String(c.min_distance_m ?? ''), strength: String(c.strength ?? '') };
    else s.collisionsRest.push(c);
  }
  return s;
}

// ---- the forms ---------------------------------------------------------------

const sceneForm = $('scene-form');
const spriteForm = $('sprite-form');
const specBox = $('spec-text');

function option(value, text, chosen) {
  return el('option', { value, text, selected: value === chosen });
}

function fillSceneForm() {
  const f = sceneForm.elements;
  const cams = inputs?.cameras || [];
  const camOptions = cams.map((c) => option(c.model, c.name, scene.camera));
  if (scene.camera && !cams.some((c) => c.model === scene.camera)) camOptions.push(option(scene.camera, basename(scene.camera), scene.camera));
  f.camera.replaceChildren(...camOptions);
  const plates = [...(inputs?.backgrounds || [])];
  if (scene.background && !plates.includes(scene.background)) plates.push(scene.background);
  f.background.replaceChildren(option('', '(none)', scene.background), ...plates.map((b) => option(b, basename(b), scene.background)));
  f.camera.title = scene.camera;
  f.background.title = scene.background;
  f.min_frames.value = scene.min_frames;
  f.max_frames.value = scene.max_frames;
  f.time_budget_s.value = scene.time_budget_s;
  if (inputs?.max_time_budget_s) f.time_budget_s.max = String(inputs.max_time_budget_s);
  f.collisions.checked = scene.collisions.on;
  f.min_distance_m.value = scene.collisions.min_distance_m;
  f.collision_strength.value = scene.collisions.strength;
  $('bank-path').textContent = `bank: ${scene.banks.map(basename).join(', ') || '–'}`;
  $('bank-path').title = scene.banks.join('\n');
}

function readSceneForm() {
  const f = sceneForm.elements;
  if (f.camera.value !== scene.camera) {
    scene.camera = f.camera.value;
    const cam = (inputs?.cameras || []).find((c) => c.model === scene.camera);
    const plate = cam && (inputs.backgrounds || []).find((b) => basename(b).includes(cam.name));
    if (plate) f.background.value = plate;
  }
  scene.background = f.background.value;
  scene.min_frames = f.min_frames.value;
  scene.max_frames = f.max_frames.value;
  scene.time_budget_s = f.time_budget_s.value;
  scene.collisions = { on: f.collisions.checked, min_distance_m: f.min_distance_m.value, strength: f.collision_strength.value };
}

function fillTags(chosen) {
  const tags = [...(inputs?.tags || [])];
  if (chosen && !tags.includes(chosen)) tags.push(chosen);
  const select = spriteForm.elements.frames_tag;
  select.replaceChildren(...(tags.length ? tags.map((t) => option(t, t, chosen)) : [option('', '(no tags in the bank)', '')]));
  return tags.length > 0;
}

function fillSpriteForm() {
  const sp = scene.sprites[selected];
  spriteForm.hidden = !sp;
  $('sprite-empty').hidden = Boolean(sp);
  $('sprite-note').textContent = scene.sprites.length ? `${selected + 1} of ${scene.sprites.length}` : '';
  if (!sp) return;
  const f = spriteForm.elements;
  if (document.activeElement !== f.name) f.name.value = sp.name;
  for (const k of Object.keys(PATH_DEFAULTS)) f[k].value = sp.strengths[k];
  const hasTags = fillTags(sp.frames.tag);
  f.frames_on.checked = sp.frames.on;
  f.frames_on.disabled = !hasTags && !sp.frames.on;
  f.frames_strength.value = sp.frames.strength;
  f.after_path.checked = sp.frames.after_path;
  f.frames_duration.value = sp.frames.duration;
  f.frames_from.value = sp.frames.from;
  f.frames_to.value = sp.frames.to;
  for (const label of spriteForm.querySelectorAll('[data-after]')) label.hidden = (label.dataset.after === '1') !== sp.frames.after_path;
  fillSpriteFacts(sp);
  fillTargets(sp);
}

function fillSpriteFacts(sp) {
  $('sprite-start').textContent = sp.start ? `${fmt(sp.start[0], 3)}, ${fmt(sp.start[1], 3)} m` : '–';
  $('sprite-path').textContent = sp.path.length ? `${sp.path.length + 1} points, ${fmt(pathLength(sp), 2)} m` : 'none: pick Path';
}

function pathLength(sp) {
  const pts = [sp.start, ...sp.path];
  let sum = 0;
  for (let i = 1; i < pts.length; i++) sum += Math.hypot(pts[i][0] - pts[i - 1][0], pts[i][1] - pts[i - 1][1]);
  return sum;
}

function fillTargets(sp) {
  const list = $('targets');
  if (!sp.targets.length) {
    list.replaceChildren(el('li', { class: 'muted', text: 'none' }));
    return;
  }
  list.replaceChildren(...sp.targets.map((t, i) => {
    const field = (key, label) =>
      el('label', {}, label, el('input', { type: 'text', value: t[key], 'data-key': key, onchange: (ev) => {
        t[key] = ev.target.value;
        changed();
      } }));
    return el('li', { testid: 'target' },
      el('span', { class: 'num', text: `${fmt(t.at[0], 2)}, ${fmt(t.at[1], 2)}` }),
      field('from', 'from'), field('to', 'to'), field('strength', 'γ'),
      el('button', { type: 'button', class: 'link', title: 'remove this target', text: '×', onclick: () => {
        sp.targets.splice(i, 1);
        changed();
      } }));
  }));
}

function readSpriteForm() {
  const sp = scene.sprites[selected];
  if (!sp) return;
  const f = spriteForm.elements;
  sp.name = f.name.value.trim();
  for (const k of Object.keys(PATH_DEFAULTS)) sp.strengths[k] = f[k].value;
  sp.frames = {
    on: f.frames_on.checked,
    tag: f.frames_tag.value,
    strength: f.frames_strength.value,
    after_path: f.after_path.checked,
    duration: f.frames_duration.value,
    from: f.frames_from.value,
    to: f.frames_to.value,
  };
}

// The scene changed: the forms, the spec text and the plan follow it.
function changed({ forms = true } = {}) {
  if (forms) {
    fillSceneForm();
    fillSpriteForm();
  }
  const n = scene.sprites.length;
  $('collision-hint').textContent = scene.collisions.on && n < 2 ? 'written once there are two sprites or more' : '';
  const text = specText(scene);
  specBox.value = text;
  $('spec-note').textContent = `${text.split('\n').length - 1} lines`;
  try {
    if (inputs) sessionStorage.setItem(STORE_KEY, text); // a reload keeps the scene
  } catch {
    /* storage disabled */
  }
  queuePlan();
}

sceneForm.addEventListener('input', () => {
  readSceneForm();
  changed({ forms: false });
});
sceneForm.addEventListener('change', () => {
  readSceneForm();
  changed();
});
spriteForm.addEventListener('input', (ev) => {
  if (ev.target.closest('[data-testid="targets"]')) return;
  readSpriteForm();
  changed({ forms: false });
});
spriteForm.addEventListener('change', (ev) => {
  if (ev.target.closest('[data-testid="targets"]')) return;
  readSpriteForm();
  changed();
});
for (const form of [sceneForm, spriteForm]) form.addEventListener('submit', (ev) => ev.preventDefault());

$('undo-point').addEventListener('click', () => {
  const sp = scene.sprites[selected];
  if (sp?.path.length) sp.path.pop();
  changed();
});
$('clear-path').addEventListener('click', () => {
  const sp = scene.sprites[selected];
  if (sp) sp.path = [];
  changed();
});
$('delete-sprite').addEventListener('click', () => {
  if (selected < 0) return;
  scene.sprites.splice(selected, 1);
  selected = Math.min(selected, scene.sprites.length - 1);
  changed();
});

// The text as a spec: the JSON the page writes as it is, any other YAML (docs/examples', a spec
// written by hand) as the station reads it (POST /api/animations/spec.json).
async function specOfText(text) {
  try {
    return parseSpecText(text);
  } catch {
    const { spec } = await postJson('/api/animations/spec.json', { spec: text });
    if (!spec || typeof spec !== 'object' || Array.isArray(spec)) throw new Error('expected a spec: a mapping of keys');
    return spec;
  }
}

$('load-spec').addEventListener('click', async () => {
  try {
    loadScene(sceneOf(await specOfText(specBox.value)));
    showMessage('Spec loaded into the plan.', 'info');
  } catch (err) {
    showMessage(`load: ${err.message}`, 'error');
  }
});

function loadScene(s) {
  scene = s;
  selected = scene.sprites.length ? 0 : -1;
  changed();
}

// ---- tools -------------------------------------------------------------------

function setTool(name) {
  tool = name;
  for (const b of $('tools').querySelectorAll('button')) b.classList.toggle('on', b.dataset.tool === name);
  $('plan').dataset.tool = name;
  $('target-opts').hidden = name !== 'target';
}
$('tools').addEventListener('click', (ev) => {
  const b = ev.target.closest('button[data-tool]');
  if (b) setTool(b.dataset.tool);
});

function selectedOrSay(what) {
  const sp = scene.sprites[selected];
  if (!sp) showMessage(`${what}: add a sprite first (Add sprite, then click its start)`, 'info');
  return sp;
}

function clickPlan(gx, gy, px, py) {
  const at = [mm(gx), mm(gy)];
  if (tool === 'sprite') {
    scene.sprites.push(newSprite(nextName(), at));
    selected = scene.sprites.length - 1;
    setTool('path');
  } else if (tool === 'path') {
    const sp = selectedOrSay('path');
    if (!sp) return;
    sp.path.push(at);
  } else if (tool === 'target') {
    const sp = selectedOrSay('target');
    if (!sp) return;
    const f = $('target-opts');
    sp.targets.push({ at, from: $('target-from', f).value, to: $('target-to', f).value, strength: $('target-strength', f).value });
  } else {
    pick(px, py);
    return;
  }
  changed();
}

// Select: the nearest of the sprites' starts (selects it) and the result's track points (shows
// that step), within a few pixels.
function pick(px, py) {
  let best = { d: 10 };
  const near = (x, y) => Math.hypot(X(x) - px, Y(y) - py);
  if (playerReady()) {
    for (const tr of tracks()) {
      tr.positions.forEach(([x, y], t) => {
        const d = near(x, y);
        if (d < best.d) best = { d, step: t };
      });
    }
  }
  scene.sprites.forEach((sp, i) => {
    const d = sp.start ? near(...sp.start) : Infinity;
    if (d < best.d) best = { d, sprite: i };
  });
  if (best.sprite !== undefined) {
    selected = best.sprite;
    changed();
  } else if (best.step !== undefined) {
    pause();
    show(best.step);
  }
}

// ---- the floor plan (ground metres, top-down, y up) -------------------------

const planCanvas = $('plan');
const view = { k: 100, cx: 0, cy: 0, w: 1, h: 1 };
const X = (x) => view.w / 2 + (x - view.cx) * view.k;
const Y = (y) => view.h / 2 - (y - view.cy) * view.k;
const ground = (px, py) => [view.cx + (px - view.w / 2) / view.k, view.cy - (py - view.h / 2) / view.k];
const colourOf = (name, i) => {
  const at = scene.sprites.findIndex((s) => s.name === name);
  return COLOURS[(at >= 0 ? at : i) % COLOURS.length];
};

// The job's tracks: the sequences' positions once done, else the latest the optimizer holds.
function tracks() {
  if (job?.sequences?.sprites) return job.sequences.sprites.map((s) => ({ name: s.name, positions: s.steps.map((st) => [st[2], st[3]]) }));
  return Array.isArray(job?.tracks) ? job.tracks : [];
}

// The view holds the enclosure (a fixed frame to click in), widened to what lies outside it.
function fitView(w, h) {
  const enclosure = inputs?.enclosure?.length > 2 ? inputs.enclosure : [[-0.5, -0.4], [0.5, 0.4]];
  const pts = [...enclosure];
  for (const sp of scene.sprites) {
    if (sp.start) pts.push(sp.start);
    pts.push(...sp.path, ...sp.targets.map((t) => t.at));
  }
  for (const tr of tracks()) pts.push(...tr.positions);
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (const [x, y] of pts) {
    if (!Number.isFinite(x) || !Number.isFinite(y)) continue;
    x0 = Math.min(x0, x); x1 = Math.max(x1, x);
    y0 = Math.min(y0, y); y1 = Math.max(y1, y);
  }
  const pad = 22;
  view.w = w;
  view.h = h;
  view.k = Math.min((w - 2 * pad) / Math.max(x1 - x0, 0.2), (h - 2 * pad - 10) / Math.max(y1 - y0, 0.2));
  view.cx = (x0 + x1) / 2;
  view.cy = (y0 + y1) / 2;
}

function drawGrid(ctx, w, h) {
  const span = Math.max(w, h) / view.k;
  const stepM = span > 4 ? 0.5 : 0.1;
  const [gx0, gy1] = ground(0, 0);
  const [gx1, gy0] = ground(w, h);
  groundGrid(ctx, w, h, X, Y, [gx0, gx1, gy0, gy1], stepM);
}

function drawScale(ctx, h) {
  const want = 160 / view.k;
  const len = [0.05, 0.1, 0.2, 0.25, 0.5, 1, 2, 5, 10].reduce((a, v) => (v <= want ? v : a), 0.05);
  const sx = 10;
  const sy = h - 8;
  ctx.strokeStyle = '#d7dee9';
  ctx.fillStyle = '#d7dee9';
  ctx.lineWidth = 2;
  ctx.beginPath();
  ctx.moveTo(sx, sy - 4); ctx.lineTo(sx, sy); ctx.lineTo(sx + len * view.k, sy); ctx.lineTo(sx + len * view.k, sy - 4);
  ctx.stroke();
  ctx.font = '11px ui-monospace, monospace';
  ctx.fillText(len >= 1 ? `${len} m` : `${Math.round(len * 100)} cm`, sx + len * view.k + 6, sy);
}

function polyline(ctx, pts, close = false) {
  ctx.beginPath();
  pts.forEach(([x, y], i) => (i ? ctx.lineTo(X(x), Y(y)) : ctx.moveTo(X(x), Y(y))));
  if (close) ctx.closePath();
}

function dot(ctx, [x, y], r, fill, stroke) {
  ctx.beginPath();
  ctx.arc(X(x), Y(y), r, 0, Math.PI * 2);
  if (fill) {
    ctx.fillStyle = fill;
    ctx.fill();
  }
  if (stroke) {
    ctx.strokeStyle = stroke;
    ctx.stroke();
  }
}

function label(ctx, text, [x, y], colour) {
  ctx.font = '11px ui-monospace, monospace';
  const tw = ctx.measureText(text).width;
  const tx = Math.min(view.w - tw - 4, Math.max(4, X(x) + 9));
  const ty = Math.max(12, Math.min(view.h - 20, Y(y) - 8));
  ctx.fillStyle = 'rgba(10,14,20,0.8)';
  ctx.fillRect(tx - 2, ty - 10, tw + 4, 13);
  ctx.fillStyle = colour;
  ctx.fillText(text, tx, ty);
}

function drawSprite(ctx, sp, i) {
  const colour = COLOURS[i % COLOURS.length];
  if (sp.start && sp.path.length) {
    ctx.strokeStyle = colour;
    ctx.lineWidth = 1.5;
    ctx.setLineDash([5, 4]);
    polyline(ctx, [sp.start, ...sp.path]);
    ctx.stroke();
    ctx.setLineDash([]);
    for (const p of sp.path) dot(ctx, p, 3, colour);
  }
  ctx.lineWidth = 2;
  for (const t of sp.targets) {
    const [x, y] = [X(t.at[0]), Y(t.at[1])];
    ctx.strokeStyle = colour;
    ctx.beginPath();
    ctx.moveTo(x - 7, y); ctx.lineTo(x, y - 7); ctx.lineTo(x + 7, y); ctx.lineTo(x, y + 7); ctx.closePath();
    ctx.moveTo(x - 3, y); ctx.lineTo(x + 3, y); ctx.moveTo(x, y - 3); ctx.lineTo(x, y + 3);
    ctx.stroke();
    const w = windowOf(t.from, t.to);
    const when = w.at !== undefined ? `at ${w.at}` : w.from !== undefined ? `${w.from}–${w.to ?? 'end'}` : 'always';
    ctx.font = '10px ui-monospace, monospace';
    ctx.fillStyle = colour;
    ctx.fillText(when, x + 10, y + 4);
  }
  if (!sp.start) return;
  ctx.lineWidth = i === selected ? 2.5 : 1;
  dot(ctx, sp.start, 6, colour, i === selected ? '#ffffff' : '#0a0e14');
  label(ctx, sp.name || '(no name)', sp.start, colour);
}

function drawTracks(ctx) {
  const jumps = transitionMarks();
  tracks().forEach((tr, i) => {
    const colour = colourOf(tr.name, i);
    if (tr.positions.length < 1) return;
    ctx.strokeStyle = colour;
    ctx.globalAlpha = 0.9;
    ctx.lineWidth = 2.5;
    polyline(ctx, tr.positions);
    ctx.stroke();
    ctx.globalAlpha = 1;
    ctx.fillStyle = '#ffffff';
    for (const t of jumps.get(tr.name)?.keys() || []) {
      const p = tr.positions[t];
      if (p) ctx.fillRect(X(p[0]) - 2.5, Y(p[1]) - 2.5, 5, 5);
    }
    if (playerReady()) {
      const p = tr.positions[Math.min(step, tr.positions.length - 1)];
      ctx.lineWidth = 2;
      dot(ctx, p, 7, null, '#ffffff');
      dot(ctx, p, 3.5, colour);
    }
  });
}

function drawPlan() {
  const { ctx, w, h } = fitCanvas(planCanvas);
  fitView(w, h);
  ctx.clearRect(0, 0, w, h);
  ctx.fillStyle = '#0a0e14';
  ctx.fillRect(0, 0, w, h);
  ctx.textAlign = 'left';
  ctx.textBaseline = 'alphabetic';
  drawGrid(ctx, w, h);
  const enclosure = inputs?.enclosure || [];
  if (enclosure.length > 2) {
    polyline(ctx, enclosure, true);
    ctx.fillStyle = 'rgba(61,220,132,0.12)';
    ctx.fill();
    ctx.strokeStyle = '#3ddc84';
    ctx.lineWidth = 2;
    ctx.stroke();
  }
  drawTracks(ctx);
  scene.sprites.forEach((sp, i) => drawSprite(ctx, sp, i));
  drawScale(ctx, h);
  // Where ground (0, 0) is and how many pixels a metre: the tests click metres with these.
  Object.assign(planCanvas.dataset, {
    pxPerM: view.k.toFixed(4),
    originX: X(0).toFixed(2),
    originY: Y(0).toFixed(2),
    sprites: String(scene.sprites.length),
    pathPoints: String(scene.sprites[selected]?.path.length ?? 0),
    tracks: String(tracks().length),
  });
}

let planQueued = false;
function queuePlan() {
  if (planQueued) return;
  planQueued = true;
  requestAnimationFrame(() => {
    planQueued = false;
    drawPlan();
  });
}

planCanvas.addEventListener('click', (ev) => {
  const [gx, gy] = ground(ev.offsetX, ev.offsetY);
  clickPlan(gx, gy, ev.offsetX, ev.offsetY);
});
planCanvas.addEventListener('mousemove', (ev) => {
  const [gx, gy] = ground(ev.offsetX, ev.offsetY);
  $('plan-cursor').textContent = `x ${fmt(gx, 3)}  y ${fmt(gy, 3)} m`;
});
planCanvas.addEventListener('mouseleave', () => ($('plan-cursor').textContent = ''));
new ResizeObserver(queuePlan).observe(planCanvas);

// ---- running a job -----------------------------------------------------------

// A request from a button (page.js); the run's state decides the buttons after it.
function act(button, fn) {
  return busy(button, fn, () => renderRun());
}

$('run').addEventListener('click', async () => {
  const text = specBox.value;
  const r = await act($('run'), () => postJson('/api/animations', { spec: text }));
  if (!r) return;
  $('message').hidden = true;
  openJob(r.id, { state: r.state || 'queued', spec: text });
});

$('cancel').addEventListener('click', async () => {
  if (!job) return;
  const r = await act($('cancel'), () => postJson(`/api/animations/${job.id}/cancel`));
  if (r && r.id === job.id) applyJob(r);
  poller.wake?.();
});

// Shows a job and follows it until it ends: its JSON once a second while it runs (the tracks),
// and at once when the stream says its state changed.
async function openJob(id, first = null) {
  const mine = ++following;
  resetPlayer();
  job = { id, state: 'queued', ...first };
  jobBudget = budgetOf(job.spec);
  curve = [];
  curveUpdates = 0;
  renderRun();
  for (;;) {
    let j;
    try {
      j = await getJson(`/api/animations/${id}`);
    } catch (err) {
      if (mine === following) showMessage(`animation ${id}: ${err.message}`, 'error');
      return;
    }
    if (mine !== following) return;
    applyJob(j);
    if (!ACTIVE.has(j.state)) break;
    await wakeableSleep(poller, 1000);
    if (mine !== following) return;
  }
  loadSaved();
}

function budgetOf(text) {
  try {
    return Number(parseSpecText(text).optimizer.time_budget_s) || null;
  } catch {
    return null;
  }
}

function applyJob(j) {
  job = { ...job, ...j };
  if (job.spec && jobBudget === null) jobBudget = budgetOf(job.spec);
  const trace = j.progress?.trace;
  if (Array.isArray(trace) && trace.length) curve = mergeCurve(trace, curve);
  renderRun();
  if (job.state === 'failed' && job.error) showMessage(`animation ${job.id} failed: ${job.error}`, 'error');
  if (playerReady() && playerFor !== job.id) setUpPlayer();
  renderJudge();
  queuePlan();
}

// The job's trace and the stream's points, by time, as the best cost so far (never rising).
function mergeCurve(a, b) {
  const byTime = new Map();
  for (const [t, c] of [...a, ...b]) if (Number.isFinite(t) && Number.isFinite(c)) byTime.set(t, c);
  let best = Infinity;
  return [...byTime.entries()].sort((p, q) => p[0] - q[0]).map(([t, c]) => [t, (best = Math.min(best, c))]);
}

// The stream's `animation` (4 times a second): the state, the cost curve's next point.
events.addEventListener('status', (e) => {
  const a = e.detail.animation;
  if (a === undefined) {
    if (!inputs) $('job-state').textContent = 'unavailable';
    return;
  }
  if (!a) return;
  if (job && a.id === job.id) {
    const stateChanged = a.state !== job.state;
    job.state = a.state;
    const figures = { ...a }; // seconds, cost, best_cost, moves_kept, restarts, ...
    delete figures.id;
    delete figures.state;
    delete figures.by_kind; // the latest only: the job's poll brings the curves
    job.progress = { ...job.progress, ...figures };
    const last = curve[curve.length - 1];
    // A point while it optimizes (a best cost of 0 is none yet), later than the curve's last.
    const point = a.state === 'running' && Number.isFinite(a.seconds) && Number.isFinite(a.best_cost) && (a.best_cost > 0 || last);
    if (point && (!last || a.seconds > last[0])) {
      curve.push([a.seconds, last ? Math.min(last[1], a.best_cost) : a.best_cost]);
      curveUpdates++;
    }
    renderRun();
    if (stateChanged) poller.wake?.();
  } else if (ACTIVE.has(a.state) && (!job || !ACTIVE.has(job.state))) {
    openJob(a.id); // started elsewhere (another tab, a script): follow it
  }
});

function renderRun() {
  const state = job?.state || 'idle';
  const badge = $('job-state');
  badge.dataset.state = state;
  badge.textContent = state;
  $('job-id').textContent = job ? `#${job.id}` : '';
  const active = ACTIVE.has(state);
  $('run').disabled = active || !inputs;
  $('cancel').disabled = !active;
  const p = job?.progress || {};
  const seconds = p.seconds ?? job?.seconds; // a job of an earlier run has no progress
  $('job-seconds').textContent = seconds === undefined ? '–' : `${fmt(seconds, 1)} s${jobBudget ? ` of ${fmt(jobBudget)}` : ''}`;
  $('job-cost').textContent = p.best_cost === undefined ? '–' : fmt(p.best_cost, 2);
  $('job-moves').textContent = movesText(p);
  const rendered = $('job-rendered');
  rendered.textContent = p.steps_rendered ? `${fmt(p.steps_rendered)} of ${fmt(p.num_steps || job?.num_steps)} frames` : '–';
  const error = $('job-error');
  error.hidden = !job?.error;
  error.textContent = job?.error || '';
  drawCurve();
}

function movesText(p) {
  const restarts = `${fmt(p.restarts ?? 0)} restarts`;
  if (p.moves_kept !== undefined) return `${fmt(p.moves_kept)} kept · ${restarts}`;
  if (p.turns !== undefined) return `${fmt(p.turns)} turns · ${restarts}`;
  return '–';
}

// The best cost against the optimizer's seconds (a log axis when it spans decades).
function drawCurve() {
  const canvas = $('cost-curve');
  const { ctx, w, h } = fitCanvas(canvas);
  canvas.dataset.points = String(curve.length);
  canvas.dataset.updates = String(curveUpdates);
  ctx.clearRect(0, 0, w, h);
  ctx.fillStyle = '#0a0e14';
  ctx.fillRect(0, 0, w, h);
  ctx.font = '10px ui-monospace, monospace';
  ctx.fillStyle = '#8a94a6';
  if (!curve.length) {
    ctx.textAlign = 'center';
    ctx.fillText(job ? 'waiting for the optimizer…' : "the optimizer's best cost shows here", w / 2, h / 2);
    return;
  }
  const t1 = Math.max(jobBudget || 0, curve[curve.length - 1][0], 1);
  const kinds = kindCurves();
  const costs = [...curve.map(([, c]) => c), ...kinds.flatMap(({ points }) => points.map(([, c]) => c).filter((c) => c > 0))];
  const lo = Math.min(...costs);
  const hi = Math.max(...costs);
  const log = lo > 0 && hi / lo > 20;
  const f = (c) => (log ? Math.log10(c) : c);
  const [f0, f1] = [f(lo), f(hi) === f(lo) ? f(lo) + 1 : f(hi)];
  const [left, right, top, bottom] = [44, w - 6, 8, h - 14];
  const x = (t) => left + (t / t1) * (right - left);
  const y = (c) => bottom - ((f(c) - f0) / (f1 - f0)) * (bottom - top);
  ctx.strokeStyle = '#222b39';
  ctx.textAlign = 'right';
  ctx.textBaseline = 'middle';
  for (const c of [lo, hi]) {
    ctx.beginPath(); ctx.moveTo(left, Math.round(y(c)) + 0.5); ctx.lineTo(right, Math.round(y(c)) + 0.5); ctx.stroke();
    ctx.fillText(shortCost(c), left - 4, y(c));
  }
  ctx.textBaseline = 'alphabetic';
  ctx.textAlign = 'left';
  ctx.fillText('0', left, h - 2);
  ctx.textAlign = 'right';
  ctx.fillText(`${fmt(t1, 0)} s${log ? ' · log cost' : ''}`, right, h - 2);
  ctx.lineWidth = 1;
  for (const { colour, points } of kinds) { // the current sequences' cost of each kind of term
    ctx.strokeStyle = colour;
    ctx.beginPath();
    points.forEach(([t, c], i) => (i ? ctx.lineTo : ctx.moveTo).call(ctx, x(t), y(Math.max(c, lo))));
    ctx.stroke();
  }
  ctx.strokeStyle = '#4c9dff';
  ctx.lineWidth = 1.5;
  ctx.beginPath();
  curve.forEach(([t, c], i) => {
    if (i) ctx.lineTo(x(t), y(curve[i - 1][1]));
    (i ? ctx.lineTo : ctx.moveTo).call(ctx, x(t), y(c));
  });
  ctx.stroke();
}

// The job's cost by kind of term over time (progress.by_kind: [[seconds, {kind: cost}]...]), a
// curve and a colour each, and their latest values under the chart.
const KIND_COLOURS = ['#f5a524', '#22d3ee', '#e879f9', '#a3e635', '#fb7185', '#a78bfa', '#facc15', '#94a3b8'];
function kindCurves() {
  const samples = Array.isArray(job?.progress?.by_kind) ? job.progress.by_kind : [];
  const names = [...new Set(samples.flatMap(([, costs]) => Object.keys(costs || {})))].sort();
  const kinds = names.map((name, i) => ({
    name,
    colour: KIND_COLOURS[i % KIND_COLOURS.length],
    points: samples.filter(([t, costs]) => Number.isFinite(t) && Number.isFinite(costs?.[name])).map(([t, costs]) => [t, costs[name]]),
  }));
  const legend = $('cost-kinds');
  legend.replaceChildren(...kinds.map(({ name, colour, points }) => {
    const last = points[points.length - 1];
    const item = el('span', {}, `${name} ${last ? shortCost(last[1]) : '–'}`);
    item.style.setProperty('--c', colour);
    item.dataset.kind = name;
    return item;
  }));
  return kinds;
}

function shortCost(c) {
  if (c >= 10000) return `${fmt(c / 1000, 0)}k`;
  if (c >= 100) return fmt(c, 0);
  return fmt(c, c >= 10 ? 1 : 2);
}

// ---- the judge's figures -----------------------------------------------------

const pct = (v) => `${fmt(v * 100, 1)} %`;
const cm = (v) => `${fmt(v * 100, 1)} cm`;

function judgeRows(j) {
  const rows = [];
  for (const l of j.lengths || []) rows.push(['length', l.sprite, `${l.frames} frames${l.min_frames ? ` (min ${l.min_frames})` : ''}`]);
  for (const p of j.paths || []) {
    rows.push(['path', p.sprite, `swept ${pct(p.swept_share)}, ${p.finished_step >= 0 ? `done at step ${p.finished_step}` : 'unfinished'}`]);
    rows.push(['deviation', p.sprite, `max ${cm(p.max_deviation_m)}, median ${cm(p.median_deviation_m)}`]);
  }
  for (const l of j.locations || []) {
    rows.push(['target', `${l.sprite} ${l.target}`, `last ${cm(l.distance_m.last)}, median ${cm(l.distance_m.median)}, max ${cm(l.distance_m.max)}`]);
  }
  for (const c of j.collisions || []) {
    rows.push(['closest', c.sprites.join('–'), `${cm(c.closest_m)} at step ${c.closest_step} (min ${cm(c.min_distance_m)}), ${c.steps_closer} steps closer`]);
  }
  for (const f of j.frames || []) rows.push(['frames', `${f.sprite} ${f.set}`, `${pct(f.on_share)} of steps ${f.first_step}–${f.end_step}`]);
  if (j.stutter) rows.push(['stutter', '', `${pct(j.stutter.share)} (replayed ${pct(j.stutter.replayed_share)})`]);
  if (j.clones && (j.lengths || []).length > 1) rows.push(['clones', '', `${pct(j.clones.share)}, ${j.clones.sprites_cloned} sprites mostly copies`]);
  if (j.facing?.measured && j.facing.median_deg !== null) {
    rows.push(['facing', `${j.facing.moving_steps} moving steps`, `drawn ${fmt(j.facing.median_deg, 0)}° off the way it moves (median), p90 ${fmt(j.facing.p90_deg, 0)}°`]);
  }
  const v = j.jumps;
  if (v?.measured) {
    const x = (n) => (n === null || n === undefined ? '–' : fmt(n, 2));
    rows.push(['jumps', `${v.transitions} transitions`, v.transitions
      ? `median ${x(v.median)}, p95 ${x(v.p95)}, max ${x(v.max)} × a frame step`
      : 'none taken: every step is the next frame of its clip']);
  }
  return rows;
}

function renderJudge() {
  const table = $('judge');
  const j = job?.state === 'done' ? job.judge : null;
  table.hidden = !j;
  $('judge-empty').hidden = Boolean(j);
  if (!j) {
    table.replaceChildren();
    return;
  }
  table.replaceChildren(...judgeRows(j).map(([what, who, value]) =>
    el('tr', { 'data-row': what }, el('th', { text: what }), el('td', { class: 'who', text: who }), el('td', { class: 'num', text: value }))));
}

// ---- the player ----------------------------------------------------------------

const player = $('player');
const scrubber = $('scrubber');
const frameUrls = new Map(); // step -> Promise<blob URL> of the job shown
const sprites = new Map(); // bank sprite id -> Promise<GET /api/bank/sprites/ID>
const billboards = new Map(); // bank sprite id -> Promise<blob URL>

const playerReady = () => job?.state === 'done' && job.num_steps > 0 && Boolean(job.sequences);
const numSteps = () => job?.num_steps || 0;

function frameUrl(t) {
  if (!frameUrls.has(t)) {
    const id = job.id;
    const p = fetches.run(() => getBlob(`/api/animations/${id}/frames/${t}.jpg`)).then(({ blob }) => URL.createObjectURL(blob));
    p.catch(() => frameUrls.delete(t));
    frameUrls.set(t, p);
  }
  return frameUrls.get(t);
}

function resetPlayer() {
  pause();
  playerFor = null;
  for (const p of frameUrls.values()) p.then((u) => URL.revokeObjectURL(u), () => {});
  frameUrls.clear();
  step = 0;
  player.removeAttribute('src');
  player.hidden = true;
  $('player-empty').hidden = false;
  scrubber.disabled = true;
  scrubber.max = '0';
  scrubber.value = '0';
  $('play').disabled = true;
  $('player-step').textContent = '–';
  const info = $('step-info');
  info.replaceChildren();
  info.dataset.step = '';
}

function setUpPlayer() {
  playerFor = job.id;
  scrubber.max = String(numSteps() - 1);
  scrubber.disabled = false;
  $('play').disabled = false;
  player.hidden = false;
  $('player-empty').hidden = true;
  show(0);
}

// Shows step t: the frame, the scrubber, the step's sprites, the markers on the plan.
async function show(t, url = null) {
  step = Math.max(0, Math.min(numSteps() - 1, t));
  scrubber.value = String(step);
  const rate = job.frame_rate || scene.frame_rate || 30;
  $('player-step').textContent = `${step} / ${numSteps() - 1} · ${fmt(step / rate, 2)} s`;
  renderStepInfo(step);
  queuePlan();
  const shown = step;
  try {
    const src = url || (await frameUrl(shown));
    if (step === shown) player.src = src;
  } catch (err) {
    if (step === shown) showMessage(`frame ${shown}: ${err.message}`, 'error');
  }
}

async function play() {
  if (!playerReady() || playing) return;
  playing = true;
  $('play').textContent = 'Pause';
  const id = job.id;
  const period = 1000 / (job.frame_rate || 30);
  let due = performance.now();
  while (playing && job?.id === id) {
    const t = step + 1 >= numSteps() ? 0 : step + 1;
    for (let k = 1; k <= 10; k++) frameUrl((t + k) % numSteps());
    let url;
    try {
      url = await frameUrl(t);
    } catch (err) {
      showMessage(`frame ${t}: ${err.message}`, 'error');
      break;
    }
    due += period;
    const wait = due - performance.now();
    if (wait > 0) await sleep(wait);
    else due = performance.now(); // fell behind (a slow frame): no catching up in a burst
    if (!playing || job?.id !== id) break;
    show(t, url);
  }
  pause();
}

function pause() {
  playing = false;
  $('play').textContent = 'Play';
  if (job && playerReady()) renderStepInfo(step);
}

$('play').addEventListener('click', () => (playing ? pause() : play()));
scrubber.addEventListener('input', () => {
  pause();
  show(Number(scrubber.value));
});

// ---- the step's sprites ----------------------------------------------------------

// Per sprite name, the steps that take a transition (not the natural successor of the step
// before), with the visible jump: the judge's list when it has one, else null.
function judgedTransitions() {
  const each = job?.state === 'done' ? job.judge?.jumps?.each : null;
  if (!Array.isArray(each)) return null;
  const out = new Map();
  for (const t of each) {
    if (!out.has(t.sprite)) out.set(t.sprite, new Map());
    out.get(t.sprite).set(t.step, t);
  }
  return out;
}

// The steps to mark on the plan: the judge's, else those whose bank sprite id is not the step
// before's plus one (a bank stores a clip's frames under consecutive ids).
function transitionMarks() {
  const judged = judgedTransitions();
  if (judged) return judged;
  const out = new Map();
  for (const seq of job?.sequences?.sprites || []) {
    const steps = new Map();
    seq.steps.forEach((st, t) => {
      const prev = seq.steps[t - 1];
      if (prev && (st[0] !== prev[0] || st[1] !== prev[1] + 1)) steps.set(t, {});
    });
    out.set(seq.name, steps);
  }
  return out;
}

// The station's bank sprite (bank index 0 of a spec that names the station's bank).
function bankSprite(bank, id) {
  const banks = job?.sequences?.banks || [];
  if (banks[bank] !== inputs?.bank) return null;
  if (!sprites.has(id)) {
    const p = fetches.run(() => getJson(`/api/bank/sprites/${id}`));
    p.catch(() => sprites.delete(id));
    sprites.set(id, p);
  }
  return sprites.get(id);
}

function billboardUrl(id) {
  if (!billboards.has(id)) {
    const p = fetches.run(() => getBlob(`/api/bank/sprites/${id}/billboard.png?height=72`)).then(({ blob }) => URL.createObjectURL(blob));
    p.catch(() => billboards.delete(id));
    billboards.set(id, p);
  }
  return billboards.get(id);
}

// A step taken by a transition or not: the judge's list when it measured them, else the bank's
// clips (the natural successor is the next frame of the same clip, originals and mirrors apart).
async function isTransition(seq, t, jumps) {
  if (t === 0) return { transition: false, why: 'first step' };
  if (jumps) {
    const j = jumps.get(seq.name)?.get(t);
    return j ? { transition: true, jump: j.jump } : { transition: false };
  }
  const [a, b] = [seq.steps[t - 1], seq.steps[t]];
  if (a[0] !== b[0]) return { transition: true };
  const [pa, pb] = [bankSprite(a[0], a[1]), bankSprite(b[0], b[1])];
  if (!pa || !pb) return { transition: b[1] !== a[1] + 1, why: 'sprite ids' };
  const [sa, sb] = await Promise.all([pa, pb]);
  const natural = sa.clip_id === sb.clip_id && sa.mirrored === sb.mirrored && sb.frame === sa.frame + 1;
  return { transition: !natural, mirrorChanged: sa.mirrored !== sb.mirrored };
}

function showTransition(card, how, answer) {
  answer.then((r) => {
    card.dataset.transition = r.transition ? 'yes' : 'no';
    how.classList.toggle('jump', r.transition);
    const jump = r.jump === undefined || r.jump === null ? '' : `: jump ${fmt(r.jump, 2)} × a frame step`;
    if (r.transition) how.textContent = `transition${jump}${r.mirrorChanged ? ', mirror changed' : ''}`;
    else how.textContent = r.why === 'first step' ? 'first step' : 'natural successor';
  }, () => (how.textContent = ''));
}

function renderStepInfo(t) {
  const info = $('step-info');
  info.dataset.step = String(t);
  const seqs = job?.sequences?.sprites || [];
  const jumps = judgedTransitions();
  info.replaceChildren(...seqs.map((seq, i) => stepCard(seq, i, t, jumps)));
}

function stepCard(seq, i, t, jumps) {
  const held = t >= seq.steps.length;
  const [bank, id, x, y] = seq.steps[Math.min(t, seq.steps.length - 1)];
  const img = el('img', { alt: '', class: 'bb' });
  const how = el('span', { class: 'how', testid: 'step-transition', text: '…' });
  const detail = el('span', { class: 'muted small', testid: 'step-sprite-detail' });
  const card = el('div', { class: 'step-card', testid: 'step-sprite', 'data-sprite': seq.name, 'data-bank-sprite': String(id) },
    el('i', { class: 'swatch', style: { background: colourOf(seq.name, i) } }),
    el('div', { class: 'bb-box' }, img),
    el('div', { class: 'step-text' },
      el('b', { text: seq.name }),
      el('span', { class: 'num', text: `sprite #${id}${bank ? ` (bank ${bank})` : ''}${held ? ' · held' : ''}` }),
      el('span', { class: 'num muted', text: `at ${fmt(x, 3)}, ${fmt(y, 3)} m` }),
      detail, how));
  if (held) how.textContent = 'held: its sequence ended';
  else if (jumps || !playing) showTransition(card, how, isTransition(seq, t, jumps));
  else how.textContent = ''; // playing: the bank's clips are looked up once it stops
  if (!playing) {
    bankSprite(bank, id)?.then((s) => {
      detail.textContent = `clip ${s.clip_id} frame ${s.frame}${s.mirrored ? ' mirrored' : ''}`;
    }, () => {});
    if (bankSprite(bank, id)) billboardUrl(id).then((u) => (img.src = u), () => {});
  }
  return card;
}

// ---- saved runs ---------------------------------------------------------------------

const FILES = [['spec', 'spec'], ['sequences', 'sequences'], ['render', 'video'], ['cost_plot', 'cost plot']];

function fileLink(url, text, testid) {
  return el('a', { href: url, text, testid, target: '_blank', rel: 'noopener', onclick: async (ev) => {
    ev.stopPropagation();
    if (!token()) return; // the browser fetches it itself
    ev.preventDefault(); // with a token: fetched with it, saved from a blob
    try {
      const { blob } = await getBlob(url);
      saveBlob(blob, basename(url));
    } catch (err) {
      showMessage(err.message, 'error');
    }
  } });
}

function created(v) {
  if (typeof v === 'number') return new Date(v * 1000).toLocaleString('en-GB');
  return String(v ?? '').replace('T', ' ').replace(/\.\d+/, '').replace(/Z$/, ' UTC');
}

async function loadSaved() {
  let r;
  try {
    r = await getJson('/api/animations');
  } catch (err) {
    showMessage(`animations: ${err.message}`, 'error');
    return;
  }
  const list = $('saved');
  const jobs = r.jobs || [];
  if (!jobs.length) {
    list.replaceChildren(el('li', { class: 'muted', text: 'no runs yet' }));
    return;
  }
  list.replaceChildren(...jobs.map((j) => el('li', {
    class: job?.id === j.id ? 'on' : '', testid: 'saved-job', 'data-job': String(j.id), 'data-state': j.state,
    title: 'show this run', onclick: () => showSaved(j.id),
  },
  el('div', { class: 'saved-head' },
    el('b', { class: 'num', text: `#${j.id}` }), el('span', { class: 'sname', text: j.name || '' }),
    el('span', { class: 'badge', 'data-state': j.state, text: j.state })),
  el('div', { class: 'saved-meta' },
    el('span', { class: 'muted num', text: created(j.created) }),
    ...FILES.filter(([k]) => j.files?.[k]).map(([k, text]) => fileLink(j.files[k], text, `saved-${k}`))))));
}

// A saved run: its spec back on the plan (when the page can read it), its result shown.
async function showSaved(id) {
  let j;
  try {
    j = await getJson(`/api/animations/${id}`);
  } catch (err) {
    showMessage(`animation ${id}: ${err.message}`, 'error');
    return;
  }
  try {
    loadScene(sceneOf(parseSpecText(j.spec)));
  } catch {
    specBox.value = j.spec;
    showMessage(`animation ${id}: its spec is not the studio's JSON; it is shown as text and the plan is left as it was`, 'info');
  }
  openJob(id, j);
}

$('saved-refresh').addEventListener('click', loadSaved);

// ---- start ---------------------------------------------------------------------

function defaultScene() {
  const s = newScene();
  s.frame_rate = inputs.frame_rate || 30;
  const cam = inputs.cameras?.[0];
  s.camera = cam?.model || '';
  s.background = (cam && inputs.backgrounds?.find((b) => basename(b).includes(cam.name))) || inputs.backgrounds?.[0] || '';
  s.banks = inputs.bank ? [inputs.bank] : [];
  return s;
}

function restoredScene() {
  try {
    const text = sessionStorage.getItem(STORE_KEY);
    return text ? sceneOf(parseSpecText(text)) : null;
  } catch {
    return null;
  }
}

async function start() {
  setTool('select');
  changed();
  renderRun();
  try {
    inputs = await getJson('/api/animations/inputs');
  } catch (err) {
    showMessage(`animations: ${err.message}`, 'error');
    $('job-state').textContent = 'unavailable';
    return;
  }
  loadScene(restoredScene() || defaultScene());
  selected = scene.sprites.length ? 0 : -1;
  renderRun();
  loadSaved();
}

start();
