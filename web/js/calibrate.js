// The calibration wizard page: start a wizard run on some cameras, watch each
// camera's live view with the board's corners, the coverage and the checklist,
// solve, pose on the floor, set the enclosure, save. docs/console.md
// ("Calibration wizard") is the contract; the state is status.calibration from
// the event stream, each action's answer is shown at once.
import { Events, Limiter, chrome, el, fmt, getJson, getBlob, postJson } from './api.js';
import { fitCanvas, groundGrid } from './draw.js';
import { showMessage } from './message.js';
import { $, busy, pollView } from './page.js';

const events = new Events().start();
chrome(events);

const STEPS = ['intrinsics', 'ground', 'enclosure', 'save', 'saved'];
const CAM_STEPS = ['intrinsics', 'ground', 'enclosure', 'done'];
const COLOURS = {
  corner: '#3ddc84', moving: '#f5a524', origin: '#ef4444', grid: 'rgba(34,211,238,0.75)',
  floor: '#e879f9', pick: '#facc15', fov: 'rgba(76,157,255,0.16)', fovLine: 'rgba(76,157,255,0.7)',
  board: '#f5f5f5',
};

// The view polls share at most 3 connections: with the event stream that leaves
// two of the browser's six for the buttons and the plots.
const views = new Limiter(3);

let status = null;
let calib = null;          // CALIB, from the stream or the last action's answer
let lastError = null;      // CALIB.error last shown in the message bar
let latestFloor = null;    // name of the camera whose enclosure changed last
const cards = new Map();

// ---- actions -----------------------------------------------------------------

// A request from a button (page.js); a CALIB answer is drawn at once.
function act(button, fn) {
  return busy(
    button,
    async () => {
      const r = await fn();
      if (r && typeof r === 'object' && 'cameras' in r && 'step' in r) apply(r, true);
      return r;
    },
    (b) => {
      if (b) b.disabled = false;
      render();
    },
  );
}

// ---- the start form ----------------------------------------------------------

const form = $('calib-form');
const choices = $('calib-camera-choices');
let choiceKey = '';

function syncChoices() {
  const cams = status?.cameras || [];
  const key = cams.map((c) => `${c.name}:${c.state}:${c.has_model}`).join(',');
  if (key === choiceKey) return;
  const had = choiceKey !== '';
  choiceKey = key;
  const checked = new Set([...choices.querySelectorAll('input:checked')].map((i) => i.value));
  const inRun = new Set((calib?.cameras || []).map((c) => c.name));
  choices.replaceChildren(
    ...cams.map((c) => {
      const on = had ? checked.has(c.name) : inRun.size ? inRun.has(c.name) : true;
      return el('label', { class: 'choice', 'data-camera': c.name },
        el('input', { type: 'checkbox', value: c.name, checked: on, testid: 'calib-camera-choice' }),
        el('span', { class: 'cname', text: c.name }),
        el('span', { class: 'badge', 'data-state': c.state, text: c.state }),
        el('span', { class: 'muted small', text: c.has_model ? 'has a model' : 'no model' }));
    }),
  );
  if (!cams.length) choices.append(el('span', { class: 'muted', text: 'the station has no cameras' }));
}

function num(name, fallback) {
  const v = form.elements[name].value.trim();
  if (v === '') return fallback;
  const n = Number(v);
  if (!Number.isFinite(n)) throw new Error(`${name}: not a number (${v})`);
  return n;
}

function criteriaSummary() {
  $('calib-criteria-summary').textContent =
    `views ≥ ${form.elements.min_views.value || 10}, coverage ≥ ${form.elements.min_coverage.value || 50} %, ` +
    `RMS < ${form.elements.max_rms.value || 0.5} px, floor still ${form.elements.floor_still.value || 1} s`;
}
form.addEventListener('input', criteriaSummary);
criteriaSummary();

form.addEventListener('submit', (ev) => {
  ev.preventDefault();
  act($('calib-start'), async () => {
    const cameras = [...choices.querySelectorAll('input:checked')].map((i) => i.value);
    if (!cameras.length) throw new Error('cameras: pick at least one camera');
    const board = form.elements.board.value.trim();
    if (!board) throw new Error('board: give the board spec, e.g. chessboard:10x7:0.03');
    const body = {
      cameras,
      board,
      board_pose: [num('bx', 0), num('by', 0), num('yaw', 0)],
      board_thickness_m: num('thick', 0) / 1000,
      min_views: Math.round(num('min_views', 10)),
      min_coverage: num('min_coverage', 50) / 100,
      max_rms_px: num('max_rms', 0.5),
      floor_still_s: num('floor_still', 1),
      use_current_intrinsics: form.elements.use_current.checked,
    };
    clearPicks();
    lastError = null;
    const r = await postJson('/api/calibration/start', body);
    $('calib-start-box').open = false; // the run's cards take the room
    try {
      sessionStorage.setItem('calibrate.start', JSON.stringify(body));
    } catch {
      /* storage disabled */
    }
    return r;
  });
});

$('calib-board-on-floor').addEventListener('click', (e) => {
  act(e.currentTarget, () => postJson('/api/calibration/ground'));
});

$('calib-joint-solve').addEventListener('click', (e) => {
  act(e.currentTarget, () => postJson('/api/calibration/joint'));
});

$('calib-cancel').addEventListener('click', (e) => {
  act(e.currentTarget, () => postJson('/api/calibration/cancel'));
});

$('calib-save').addEventListener('click', (e) => {
  act(e.currentTarget, async () => {
    const r = await postJson('/api/calibration/save');
    const n = (r?.saved?.files || []).filter((f) => f !== r.saved.config).length;
    showMessage(`Saved ${n} camera model${n === 1 ? '' : 's'}${r?.saved?.station_restarted ? '; the station now uses them' : ''}.`, 'info');
    return r;
  });
});

// Fills the form from a run found on load (another tab started it).
let formFilled = false;
function fillForm(c) {
  if (formFilled || !c?.active) return;
  formFilled = true;
  if (c.board) form.elements.board.value = c.board;
  const o = c.options || {};
  if (o.min_views) form.elements.min_views.value = o.min_views;
  if (o.min_coverage !== undefined) form.elements.min_coverage.value = Math.round(o.min_coverage * 100);
  if (o.max_rms_px) form.elements.max_rms.value = o.max_rms_px;
  if (o.floor_still_s) form.elements.floor_still.value = o.floor_still_s;
  if (Array.isArray(o.board_pose)) ['bx', 'by', 'yaw'].forEach((k, i) => (form.elements[k].value = o.board_pose[i]));
  if (o.board_thickness_m !== undefined) form.elements.thick.value = o.board_thickness_m * 1000;
  criteriaSummary();
}

// ---- the run panel -----------------------------------------------------------

let wasActive = null;

function renderRun() {
  const c = calib;
  const main = $('calib');
  const active = Boolean(c?.active);
  if (c && active !== wasActive) {
    // the form folds away while a run goes on (the summary opens it again)
    $('calib-start-box').open = !active;
    wasActive = active;
  }
  $('calib-start-toggle').textContent = active
    ? `New run (this one: ${(c.cameras || []).map((k) => k.name).join(', ')} · ${c.board})`
    : 'New run: cameras, board, criteria';
  main.dataset.active = String(active);
  main.dataset.step = c?.step || 'idle';
  const badge = $('calib-state');
  const stateText = !c ? 'unavailable' : active ? c.step : c.step === 'saved' ? 'saved' : 'idle';
  badge.textContent = stateText;
  badge.dataset.state = active ? 'live' : 'idle';
  $('calib-start').textContent = active ? 'Restart' : 'Start';
  $('calib-cancel').disabled = !active;
  $('calib-board-on-floor').disabled = !active || !(c?.cameras || []).some((k) => k.step === 'ground' && k.ground_word_needed);
  $('calib-run-no').textContent = c?.run ? `run ${c.run}${c.board ? ' · ' + c.board : ''}` : '';

  // the steps, as far as the least advanced camera got
  const at = STEPS.indexOf(c?.step);
  for (const li of $('calib-steps').children) {
    const i = STEPS.indexOf(li.dataset.step);
    li.dataset.state = at < 0 ? 'pending' : i < at || c.step === 'saved' ? 'done' : i === at ? 'current' : 'pending';
  }

  const warnings = c?.warnings || [];
  const wl = $('calib-warnings');
  wl.hidden = !warnings.length;
  wl.replaceChildren(...warnings.map((w) => el('li', { testid: 'calib-warning', text: w })));

  const busy = c?.busy;
  const box = $('calib-busy');
  box.hidden = !busy;
  if (busy) {
    const p = Math.max(0, Math.min(1, Number(busy.progress) || 0));
    $('calib-busy-stage').textContent = `${busy.what}${busy.camera ? ' ' + busy.camera : ''}: ${busy.stage || '…'}`;
    $('calib-busy-percent').textContent = `${Math.round(p * 100)} %`;
    $('calib-busy-bar').style.width = `${p * 100}%`;
    box.dataset.what = busy.what;
    box.dataset.progress = String(p);
  }

  const err = c?.error || '';
  const eb = $('calib-error');
  eb.hidden = !err;
  eb.textContent = err;
  if (err && err !== lastError) showMessage(err, 'error');
  if (!err && lastError) {
    // the state's error went (a camera came back, a new action): so does its message
    const box = $('message');
    if (!box.hidden && $('message-text', box)?.textContent === lastError) box.hidden = true;
  }
  lastError = err || null;

  const posed = (c?.cameras || []).some((k) => k.solve?.verdict === 'good' || k.ground || k.step !== 'intrinsics');
  $('calib-save').disabled = !active || !posed || Boolean(busy);
  const trusted = (c?.cameras || []).filter((k) => k.solve?.verdict === 'good' || (k.step !== 'intrinsics' && k.width)).length;
  $('calib-joint-solve').disabled = !active || trusted < 2 || Boolean(busy);
  renderJoint(c?.joint);
  renderSaved(c?.saved);
}

// The joint solve of the cameras (issue 41): a line per camera (its uncertainty) and per pair
// (the joint relative pose against the two cameras' own floor-board poses).
function renderJoint(joint) {
  const box = $('calib-joint');
  box.hidden = !joint;
  const key = JSON.stringify(joint || null);
  if (box.dataset.key === key) return;
  box.dataset.key = key;
  if (!joint) return box.replaceChildren();
  box.dataset.state = joint.state;
  const f = (v, d) => (v === null || v === undefined ? '–' : Number(v).toFixed(d));
  if (joint.state !== 'solved') {
    return box.replaceChildren(el('h3', { text: 'Joint solve' }),
      el('p', { testid: 'joint-status', class: joint.state === 'failed' ? 'warn' : '',
        text: joint.state === 'failed' ? joint.error : `solving: ${joint.stage || '…'}` }));
  }
  box.replaceChildren(
    el('h3', { text: `Joint solve: ${joint.shared_instants} shared instants, RMS ${f(joint.rms_px, 3)} px` +
      (joint.posed_from ? ` · posed from ${joint.posed_from}'s floor board` : '') }),
    el('ul', {}, ...(joint.cameras || []).map((k) => el('li', { testid: 'joint-camera', 'data-camera': k.name,
      text: `${k.name}: ${k.views} views, RMS ${f(k.rms_px, 3)} px, projection σ ${f(k.stdev_centre_px, 3)} px at the centre ` +
        `(${f(k.stdev_worst_px, 2)} px worst corner) at ${f(k.distance_m, 2)} m, focal ±${f(k.focal_stdev_percent, 3)} %` }))),
    el('ul', {}, ...(joint.pairs || []).map((p) => el('li', { testid: 'joint-pair', 'data-pair': `${p.a}-${p.b}`,
      text: `${p.a} ↔ ${p.b}: ${f(p.baseline_m, 3)} m apart; ` + (p.translation_mm === null
        ? 'not both posed on the floor yet'
        : `joint vs own floor boards ${f(p.translation_mm, 1)} mm, ${f(p.rotation_deg, 3)}°, a floor point both see ${f(p.floor_point_mm, 1)} mm` ) }))),
    el('p', { testid: 'joint-trust', class: joint.trusted ? 'ok' : 'warn',
      text: joint.trusted ? 'Trusted: Save writes the joint models.'
        : `Not trusted, Save keeps each camera's own model: ${(joint.doubts || []).join('; ')}` }),
  );
}

function renderSaved(saved) {
  const box = $('calib-saved');
  box.hidden = !saved;
  const key = JSON.stringify(saved || null);
  if (box.dataset.key === key) return;
  box.dataset.key = key;
  if (!saved) return box.replaceChildren();
  const list = (items, testid) => el('ul', { class: 'paths' }, ...(items || []).map((p) => el('li', { testid, title: p, 'data-path': p }, el('bdi', { text: p }))));
  box.replaceChildren(
    el('h3', { text: `Saved ${saved.at ? new Date(saved.at).toLocaleString() : ''}` }),
    list((saved.files || []).filter((f) => f !== saved.config), 'saved-file'),
    ...(saved.previous?.length ? [el('h3', { text: 'Previous files kept' }), list(saved.previous, 'saved-previous')] : []),
    ...(saved.config ? [el('h3', { text: 'Config' }), list([saved.config], 'saved-config')] : []),
    el('p', { testid: 'saved-station', class: saved.station_restarted ? 'ok' : 'warn',
      text: saved.station_restarted ? 'The station was restarted with these models and now uses them.'
        : saved.note || 'The station has not restarted with them yet.' }),
  );
}

// ---- a camera ----------------------------------------------------------------

const BARS = [['x', 'x', 'left ↔ right'], ['y', 'y', 'top ↕ bottom'], ['size', 'size', 'near ↔ far'], ['skew', 'skew', 'tilted']];

class Card {
  constructor(name) {
    this.name = name;
    this.cam = null;
    this.alive = true;
    this.view = null;       // the last view.json
    this.picks = [];        // clicked floor corners, camera pixels
    this.images = {};       // residuals / uncertainty: {url, objectUrl}
    this.wake = null;
    this.root = el('article', { class: 'calib-cam', testid: 'calib-camera', 'data-camera': name });
    this.root.innerHTML = `
      <header>
        <span class="name" data-testid="cam-name"></span>
        <ol class="track" data-testid="cam-track">${CAM_STEPS.map((s) => `<li data-step="${s}">${s}</li>`).join('')}</ol>
        <span class="spacer"></span>
        <span class="badge" data-testid="cam-online"></span>
        <span class="num muted" data-testid="cam-frames"></span>
      </header>
      <div class="cam-message" data-testid="cam-message" hidden></div>
      <div class="cam-body">
        <div class="view" data-testid="cam-view">
          <img data-testid="cam-image" alt="">
          <canvas data-testid="cam-overlay"></canvas>
          <div class="view-msg" data-testid="cam-view-message"></div>
          <span class="chip" data-testid="cam-board" data-state="none"></span>
          <span class="frame num">#<b data-testid="cam-frame">–</b></span>
        </div>
        <div class="cam-side">
          <section class="step-intrinsics" data-testid="cam-intrinsics">
            <h3>Intrinsics <span class="muted">hold the board still in new places</span></h3>
            <ul class="guidance" data-testid="cam-guidance"></ul>
            <div class="views-row">
              <span>Views <b class="num" data-testid="cam-views">0</b></span>
              <span class="spacer"></span>
              <button type="button" data-testid="cam-drop-last">Drop last</button>
              <button type="button" data-testid="cam-drop-worst">Drop worst</button>
            </div>
            <div class="coverage-row">
              <figure>
                <canvas data-testid="cam-coverage" width="130" height="98"></canvas>
                <figcaption>coverage <b class="num" data-testid="cam-coverage-percent">–</b></figcaption>
              </figure>
              <div class="bars" data-testid="cam-diversity">
                ${BARS.map(([k, label, title]) => `<div class="bar-row" title="${title}"><span>${label}</span>
                  <i class="bar"><i data-testid="cam-bar-${k}"></i></i><b class="num" data-testid="cam-bar-${k}-value">–</b></div>`).join('')}
              </div>
            </div>
            <div class="solve-row">
              <button type="button" class="primary" data-testid="cam-solve">Solve</button>
              <div class="busy" data-testid="cam-busy" hidden>
                <span data-testid="cam-busy-stage"></span>
                <div class="progress"><i data-testid="cam-busy-bar"></i></div>
              </div>
            </div>
          </section>
          <section class="step-ground" data-testid="cam-ground">
            <h3>Ground</h3>
            <p class="instructions" data-testid="cam-ground-instructions">Lay the board flat on the green floor, face up,
              where the start form says, then press <b>Board on floor</b> and leave it still: the camera is posed
              against it, if the pose is plausible (green floor all round the board, the camera above the floor looking
              down). The 10 cm floor grid is then drawn over the live image: check it sits on the floor.</p>
            <div class="buttons">
              <button type="button" class="primary" data-testid="cam-board-on-floor"
                title="the board lies flat on the floor now: pose the camera once it is still">Board on floor</button>
              <span class="muted" data-testid="cam-ground-word"></span>
            </div>
            <p class="ground-doubt" data-testid="cam-ground-doubt" role="status" hidden></p>
            <dl class="facts" data-testid="cam-pose">
              <dt>height</dt><dd class="num" data-testid="cam-height">–</dd>
              <dt>tilt (axis below horizon)</dt><dd class="num" data-testid="cam-tilt">–</dd>
              <dt>position</dt><dd class="num" data-testid="cam-centre">–</dd>
              <dt>board RMS</dt><dd class="num" data-testid="cam-ground-rms">–</dd>
            </dl>
          </section>
          <section class="step-enclosure" data-testid="cam-enclosure">
            <h3>Enclosure</h3>
            <p class="instructions">Detect the green floor in the latest frame, or click the floor's corners on the
              live image (in order around it) and use them.</p>
            <div class="buttons">
              <button type="button" class="primary" data-testid="cam-detect-floor">Detect green floor</button>
            </div>
            <div class="buttons">
              <span class="muted">corners clicked <b class="num" data-testid="cam-picks">0</b></span>
              <span class="spacer"></span>
              <button type="button" data-testid="cam-use-picks" disabled>Use these corners</button>
              <button type="button" data-testid="cam-clear-picks" disabled>Clear</button>
            </div>
            <dl class="facts">
              <dt>floor</dt><dd class="num" data-testid="cam-floor-area">–</dd>
              <dt>from</dt><dd data-testid="cam-floor-from">–</dd>
            </dl>
          </section>
          <div class="redo" data-testid="cam-redo">redo
            <button type="button" class="link" data-step="intrinsics" data-testid="cam-redo-intrinsics">intrinsics</button>
            <button type="button" class="link" data-step="ground" data-testid="cam-redo-ground">ground</button>
            <button type="button" class="link" data-step="enclosure" data-testid="cam-redo-enclosure">enclosure</button>
          </div>
        </div>
      </div>
      <div class="verdict-row">
        <section class="checklist-box">
          <h3>Checklist</h3>
          <ul class="checklist" data-testid="cam-checklist"></ul>
        </section>
        <section class="solve-box" data-testid="cam-solve-result" data-verdict="">
          <h3>Solve <span class="badge" data-testid="cam-verdict"></span></h3>
          <p class="muted" data-testid="cam-solve-none">Not solved yet: Solve uses the captured views (3 at least).</p>
          <ul class="reasons" data-testid="cam-reasons"></ul>
          <table class="intrinsics" data-testid="cam-intrinsics-table" hidden>
            <thead><tr><th></th><th>value px</th><th>± 1.96σ</th></tr></thead>
            <tbody></tbody>
          </table>
          <p class="num rms" data-testid="cam-rms"></p>
        </section>
        <figure class="plot" data-testid="cam-residuals-figure" hidden>
          <img data-testid="cam-residuals" alt="reprojection residuals of the last solve">
          <figcaption>residuals of the last solve</figcaption>
        </figure>
        <figure class="plot" data-testid="cam-uncertainty-figure" hidden>
          <img data-testid="cam-uncertainty" alt="projection uncertainty of the last solve">
          <figcaption>projection uncertainty (px)</figcaption>
        </figure>
      </div>`;
    const q = (id) => $(id, this.root);
    this.els = new Proxy({}, { get: (_, id) => q(id) });
    q('cam-name').textContent = name;
    this.img = q('cam-image');
    this.overlay = q('cam-overlay');
    q('cam-drop-last').addEventListener('click', (e) =>
      act(e.currentTarget, () => postJson('/api/calibration/drop', { camera: name, which: 'last' })));
    q('cam-drop-worst').addEventListener('click', (e) =>
      act(e.currentTarget, () => postJson('/api/calibration/drop', { camera: name, which: 'worst' })));
    q('cam-solve').addEventListener('click', (e) =>
      act(e.currentTarget, () => postJson('/api/calibration/solve', { camera: name })));
    q('cam-board-on-floor').addEventListener('click', (e) =>
      act(e.currentTarget, () => postJson('/api/calibration/ground', { camera: name })));
    q('cam-detect-floor').addEventListener('click', (e) =>
      act(e.currentTarget, () => postJson('/api/calibration/floor', { camera: name, detect: true })));
    q('cam-use-picks').addEventListener('click', (e) =>
      act(e.currentTarget, async () => {
        const pixels = this.picks.map(([x, y]) => [round1(x), round1(y)]);
        const r = await postJson('/api/calibration/floor', { camera: name, pixels });
        this.setPicks([]);
        return r;
      }));
    q('cam-clear-picks').addEventListener('click', () => this.setPicks([]));
    for (const b of q('cam-redo').querySelectorAll('button')) {
      b.addEventListener('click', (e) =>
        act(e.currentTarget, () => postJson('/api/calibration/redo', { camera: name, step: b.dataset.step })));
    }
    this.overlay.addEventListener('click', (e) => this.#pick(e));
    this.overlay.addEventListener('contextmenu', (e) => {
      if (!this.#picking()) return;
      e.preventDefault();
      this.setPicks(this.picks.slice(0, -1));
    });
    this.#loop();
  }

  // ---- state from CALIB --------------------------------------------------------

  update(cam) {
    const wasOffline = this.cam && !this.cam.online;
    this.cam = cam;
    const e = this.els;
    const r = this.root;
    r.dataset.step = cam.step;
    r.dataset.online = String(cam.online !== false);
    r.classList.toggle('stale', cam.online === false);
    const at = CAM_STEPS.indexOf(cam.step);
    for (const li of e['cam-track'].children) {
      const i = CAM_STEPS.indexOf(li.dataset.step);
      li.dataset.state = i < at || cam.step === 'done' ? 'done' : i === at ? 'current' : 'pending';
    }
    const online = e['cam-online'];
    online.textContent = cam.online === false ? 'offline' : 'online';
    online.dataset.state = cam.online === false ? 'offline' : 'live';
    e['cam-frames'].textContent = `${fmt(cam.frames)} frames`;
    const msg = cam.message || '';
    const offline = cam.online === false ? (/^offline\b/.test(msg) ? msg : `offline: ${msg || 'no frames'}`) : '';
    e['cam-message'].hidden = !msg && !offline;
    e['cam-message'].textContent = offline || msg;
    e['cam-message'].dataset.kind = offline ? 'offline' : 'problem';
    if (offline) this.#say(offline);
    else if (wasOffline) {
      this.#say('');
      this.wake?.();
    }

    // which side sections show
    e['cam-intrinsics'].hidden = cam.step !== 'intrinsics';
    e['cam-ground'].hidden = cam.step === 'intrinsics';
    e['cam-ground-instructions'].hidden = cam.step !== 'ground';
    e['cam-enclosure'].hidden = cam.step !== 'enclosure' && cam.step !== 'done';
    for (const b of e['cam-redo'].querySelectorAll('button')) b.disabled = CAM_STEPS.indexOf(b.dataset.step) > at;
    e['cam-redo'].hidden = at <= 0;

    // intrinsics
    const guidance = cam.guidance || [];
    e['cam-guidance'].replaceChildren(...guidance.map((g, i) => el('li', { testid: 'cam-guidance-line', class: i ? '' : 'first', text: g })));
    e['cam-views'].textContent = String(cam.views ?? 0);
    const busy = calib?.busy;
    const canDrop = cam.step === 'intrinsics' && (cam.views || 0) > 0 && !busy;
    e['cam-drop-last'].disabled = !canDrop;
    e['cam-drop-worst'].disabled = !canDrop;
    const ready = (cam.checklist || []).filter((c) => c.id === 'views' || c.id === 'coverage').every((c) => c.met === true);
    e['cam-solve'].disabled = cam.step !== 'intrinsics' || (cam.views || 0) < 3 || Boolean(busy);
    e['cam-solve'].classList.toggle('ready', ready);
    e['cam-solve'].title = ready ? 'the views meet the criteria: solve' : 'solve with the views so far (3 at least)';
    this.#coverage(cam.coverage);
    for (const [k] of BARS) {
      const v = cam.diversity?.[k];
      const bar = e[`cam-bar-${k}`];
      bar.style.width = `${Math.round(Math.max(0, Math.min(1, v || 0)) * 100)}%`;
      bar.dataset.value = v ?? '';
      bar.classList.toggle('good', (v || 0) >= 0.5);
      e[`cam-bar-${k}-value`].textContent = v === undefined || v === null ? '–' : fmt(v, 2);
    }
    const mine = busy && (!busy.camera || busy.camera === this.name);
    e['cam-busy'].hidden = !mine;
    if (mine) {
      const p = Math.max(0, Math.min(1, Number(busy.progress) || 0));
      e['cam-busy-stage'].textContent = `${busy.stage || busy.what} · ${Math.round(p * 100)} %`;
      e['cam-busy-bar'].style.width = `${p * 100}%`;
    }

    this.#checklist(cam.checklist || []);
    this.#solve(cam.solve);

    // ground
    const g = cam.ground;
    e['cam-height'].textContent = g ? `${fmt(g.height_m, 3)} m` : '–';
    e['cam-tilt'].textContent = g ? `${fmt(g.tilt_deg, 1)}°` : '–';
    e['cam-centre'].textContent = g?.centre_m ? g.centre_m.map((v) => fmt(v, 3)).join(', ') + ' m' : '–';
    e['cam-ground-rms'].textContent = g && g.rms_px !== undefined ? `${fmt(g.rms_px, 2)} px` : '–';
    // A camera of a rig that sees no floor board of its own is posed by the trusted joint solve,
    // from another camera's floor board: Save writes its joint model (issue 41).
    const j = calib?.joint;
    const rig = !g && j?.state === 'solved' && j.trusted && j.posed_from && j.posed_from !== this.name &&
      (j.cameras || []).some((k) => k.name === this.name) ? j.posed_from : '';
    e['cam-pose'].dataset.posed = g ? 'true' : rig ? 'rig' : 'false';
    // the operator's word, and a floor board whose pose was doubtful (not taken), with why
    const inGround = cam.step === 'ground';
    e['cam-board-on-floor'].disabled = !inGround || !cam.ground_word_needed || Boolean(busy);
    e['cam-ground-word'].textContent = !inGround ? ''
      : rig ? `posed through the joint solve from ${rig}'s floor board: Save writes it (or lay the board before this camera too)`
        : cam.ground_word_needed ? 'waiting for your word' : 'checking the board once it is still';
    e['cam-ground-word'].dataset.state = !inGround ? '' : rig ? 'rig' : cam.ground_word_needed ? 'waiting' : 'given';
    const gc = cam.ground_check;
    const doubt = inGround && gc?.doubt ? gc.doubt : '';
    e['cam-ground-doubt'].hidden = !doubt;
    e['cam-ground-doubt'].dataset.doubt = doubt;
    e['cam-ground-doubt'].textContent = doubt
      ? `Doubtful pose, not taken: ${doubt} (green round the board ${gc.ring_green === null ? '–' : fmt(gc.ring_green * 100, 0) + ' %'}, ` +
        `height ${fmt(gc.height_m, 2)} m, axis ${fmt(gc.axis_down_deg, 1)}° down)`
      : '';

    // enclosure
    const en = cam.enclosure;
    e['cam-floor-area'].textContent = en ? `${fmt(en.area_m2, 2)} m² · ${en.polygon_m?.length || 0} corners` : '–';
    e['cam-floor-from'].textContent = en?.from || '–';
    e['cam-detect-floor'].disabled = !this.#picking() || Boolean(busy);
    this.#pickControls();
    this.overlay.classList.toggle('picking', this.#picking());
    this.#drawOverlay();
  }

  #picking() {
    return this.cam?.step === 'enclosure' || this.cam?.step === 'done';
  }

  #coverage(cov) {
    const c = this.els['cam-coverage'];
    const { ctx, w, h } = fitCanvas(c);
    ctx.clearRect(0, 0, w, h);
    const grid = cov?.grid || [];
    let max = 1;
    let filled = 0;
    for (const row of grid) for (const v of row) {
      max = Math.max(max, v);
      if (v > 0) filled++;
    }
    const rows = grid.length || 10;
    const cols = grid[0]?.length || 10;
    const cw = w / cols;
    const ch = h / rows;
    for (let y = 0; y < rows; y++) {
      for (let x = 0; x < cols; x++) {
        const v = grid[y]?.[x] || 0;
        const a = v > 0 ? 0.25 + 0.75 * Math.sqrt(v / max) : 0;
        ctx.fillStyle = v > 0 ? `rgba(61,220,132,${a.toFixed(3)})` : '#0a0e14';
        ctx.fillRect(x * cw + 0.5, y * ch + 0.5, cw - 1, ch - 1);
      }
    }
    c.dataset.filled = String(filled);
    this.els['cam-coverage-percent'].textContent = cov ? `${fmt((cov.fraction || 0) * 100)} %` : '–';
  }

  #checklist(items) {
    const key = JSON.stringify(items);
    if (key === this.checkKey) return;
    this.checkKey = key;
    this.els['cam-checklist'].replaceChildren(
      ...items.map((c) => {
        const state = c.met === true ? 'met' : c.met === false ? 'unmet' : 'pending';
        return el('li', { testid: 'cam-check', 'data-id': c.id, 'data-state': state },
          el('i', { class: 'mark', 'aria-hidden': 'true', text: state === 'met' ? '✓' : state === 'unmet' ? '✗' : '·' }),
          el('span', { class: 'label', text: c.label }),
          el('span', { class: 'value num', testid: 'cam-check-value', text: c.value ?? '–' }));
      }),
    );
  }

  #solve(s) {
    const e = this.els;
    const box = e['cam-solve-result'];
    box.dataset.verdict = s?.verdict || '';
    e['cam-solve-none'].hidden = Boolean(s);
    const v = e['cam-verdict'];
    v.textContent = s?.verdict || '';
    v.hidden = !s;
    v.dataset.state = s?.verdict === 'good' ? 'ok' : s ? 'error' : '';
    e['cam-reasons'].replaceChildren(...(s?.reasons || []).map((r) => el('li', { testid: 'cam-reason', text: r })));
    const table = e['cam-intrinsics-table'];
    table.hidden = !s?.intrinsics;
    const key = JSON.stringify([s?.intrinsics, s?.uncertainty_percent]);
    if (s?.intrinsics && key !== this.solveKey) {
      this.solveKey = key;
      table.tBodies[0].replaceChildren(
        ...['fx', 'fy', 'cx', 'cy'].map((k) => {
          const u = s.uncertainty_percent?.[k];
          return el('tr', { 'data-param': k },
            el('th', { text: k }),
            el('td', { class: 'num', testid: `cam-${k}`, 'data-value': s.intrinsics[k], text: fmt(s.intrinsics[k], 2) }),
            el('td', { class: `num${u > (calib?.options?.max_stdev_percent ?? 0.5) ? ' warn' : ''}`, text: u === undefined ? '–' : `${fmt(u, 3)} %` }));
        }),
      );
    }
    e['cam-rms'].textContent = s && s.rms_px !== undefined && s.rms_px !== null
      ? `RMS ${fmt(s.rms_px, 3)} px · worst ${fmt(s.worst_px, 2)} px` : '';
    this.#plot('residuals', s?.residuals_png);
    this.#plot('uncertainty', s?.uncertainty_png);
  }

  // A solve's PNG, fetched with the token and shown as a blob: URL.
  async #plot(kind, url) {
    const img = this.els[`cam-${kind}`];
    const fig = this.els[`cam-${kind}-figure`];
    const have = this.images[kind];
    if ((have?.url || null) === (url || null)) return;
    if (have?.objectUrl) URL.revokeObjectURL(have.objectUrl);
    this.images[kind] = { url: url || null, objectUrl: null };
    if (!url) {
      fig.hidden = true;
      img.removeAttribute('src');
      return;
    }
    try {
      const { blob } = await getBlob(url);
      if (this.images[kind].url !== url) return;
      const objectUrl = URL.createObjectURL(blob);
      this.images[kind].objectUrl = objectUrl;
      img.src = objectUrl;
      await img.decode().catch(() => {});
      fig.hidden = false;
      img.dataset.loaded = '1';
    } catch (err) {
      if (this.images[kind].url === url) this.images[kind].url = null; // retried on the next update
      showMessage(`${this.name} ${kind} plot: ${err.message}`, 'error');
    }
  }

  // ---- floor corners clicked on the image ------------------------------------

  #pick(e) {
    if (!this.#picking() || !this.view) return;
    const r = this.overlay.getBoundingClientRect();
    const scale = this.view.scale || 1;
    // CSS px -> image px (the overlay's backing store is the image's size) -> camera px
    const ix = ((e.clientX - r.left) / r.width) * this.overlay.width;
    const iy = ((e.clientY - r.top) / r.height) * this.overlay.height;
    this.setPicks([...this.picks, [ix / scale, iy / scale]]);
  }

  setPicks(points) {
    this.picks = points;
    this.#pickControls();
    this.#drawOverlay();
  }

  #pickControls() {
    const e = this.els;
    e['cam-picks'].textContent = String(this.picks.length);
    e['cam-use-picks'].disabled = this.picks.length < 3 || !this.#picking();
    e['cam-clear-picks'].disabled = this.picks.length === 0;
    this.root.dataset.picks = String(this.picks.length);
  }

  // ---- the live view -----------------------------------------------------------

  #say(text) {
    this.els['cam-view-message'].textContent = text;
  }

  #width() {
    const dpr = window.devicePixelRatio || 1;
    const want = Math.ceil((this.img.parentElement.clientWidth * dpr) / 160) * 160;
    return Math.max(160, Math.min(want || 640, this.cam?.width || 640, 1280));
  }

  async #fetchView() {
    const data = await getJson(`/api/calibration/cameras/${encodeURIComponent(this.name)}/view.json?width=${this.#width()}`);
    if (!this.alive) return;
    if (data.image) {
      this.img.src = data.image;
      await this.img.decode().catch(() => {});
    }
    this.view = data;
    const e = this.els;
    e['cam-frame'].textContent = String(data.frame ?? '–');
    const v = e['cam-view'];
    v.dataset.frame = String(data.frame ?? '');
    v.dataset.detected = String(Boolean(data.detected));
    const chip = e['cam-board'];
    const board = calib?.board || 'board';
    const wanted = this.cam?.step === 'intrinsics' || this.cam?.step === 'ground';
    chip.dataset.state = data.detected ? (data.still ? 'still' : 'moving') : wanted ? 'none' : 'idle';
    chip.textContent = data.detected
      ? `board found · ${data.corners?.length || 0} corners · ${data.still ? 'still' : 'moving'}`
      : wanted ? `no board (${board}) found` : 'no board in view';
    this.#say(this.cam?.online === false ? this.els['cam-view-message'].textContent : '');
    this.#drawOverlay();
  }

  #drawOverlay() {
    const c = this.overlay;
    const d = this.view;
    const iw = this.img.naturalWidth || (d ? Math.round((d.width || 640) * (d.scale || 1)) : 0);
    const ih = this.img.naturalHeight || (d ? Math.round((d.height || 480) * (d.scale || 1)) : 0);
    if (!iw || !ih) return;
    if (c.width !== iw || c.height !== ih) {
      c.width = iw;
      c.height = ih;
    }
    const ctx = c.getContext('2d');
    ctx.clearRect(0, 0, iw, ih);
    const s = d?.scale || 1;
    const px = Math.max(1, iw / 640); // line widths grow with the image
    ctx.lineJoin = 'round';
    ctx.lineCap = 'round';
    const path = (pts, close) => {
      ctx.beginPath();
      pts.forEach(([x, y], i) => (i ? ctx.lineTo(x * s, y * s) : ctx.moveTo(x * s, y * s)));
      if (close) ctx.closePath();
    };
    let grid = 0;
    let floor = 0;
    let corners = 0;
    // the 10 cm floor grid
    if (d?.grid?.length) {
      ctx.strokeStyle = COLOURS.grid;
      ctx.lineWidth = 1 * px;
      for (const line of d.grid) {
        if (line.length < 2) continue;
        path(line, false);
        ctx.stroke();
        grid++;
      }
    }
    // the enclosure polygon
    if (d?.floor?.length > 2) {
      path(d.floor, true);
      ctx.fillStyle = 'rgba(232,121,249,0.12)';
      ctx.fill();
      ctx.strokeStyle = COLOURS.floor;
      ctx.lineWidth = 2 * px;
      ctx.stroke();
      floor = d.floor.length;
    }
    // the board's corners, in board order: a line through them, the first one red
    if (d?.corners?.length) {
      const colour = d.still ? COLOURS.corner : COLOURS.moving;
      ctx.strokeStyle = colour;
      ctx.globalAlpha = 0.55;
      ctx.lineWidth = 1 * px;
      path(d.corners, false);
      ctx.stroke();
      ctx.globalAlpha = 1;
      d.corners.forEach(([x, y], i) => {
        ctx.beginPath();
        ctx.arc(x * s, y * s, (i ? 2.5 : 4.5) * px, 0, Math.PI * 2);
        ctx.fillStyle = i ? colour : COLOURS.origin;
        ctx.fill();
        ctx.lineWidth = 1 * px;
        ctx.strokeStyle = '#000';
        ctx.stroke();
      });
      corners = d.corners.length;
    }
    // the corners clicked so far
    if (this.picks.length) {
      ctx.setLineDash([6 * px, 4 * px]);
      ctx.strokeStyle = COLOURS.pick;
      ctx.lineWidth = 2 * px;
      path(this.picks, this.picks.length > 2);
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.font = `bold ${Math.round(12 * px)}px ui-monospace, monospace`;
      this.picks.forEach(([x, y], i) => {
        ctx.beginPath();
        ctx.arc(x * s, y * s, 5 * px, 0, Math.PI * 2);
        ctx.fillStyle = COLOURS.pick;
        ctx.fill();
        ctx.strokeStyle = '#000';
        ctx.lineWidth = 1.5 * px;
        ctx.stroke();
        ctx.fillStyle = '#000';
        ctx.fillText(String(i + 1), x * s + 7 * px, y * s - 6 * px);
        ctx.fillStyle = COLOURS.pick;
        ctx.fillText(String(i + 1), x * s + 6 * px, y * s - 7 * px);
      });
    }
    const v = this.els['cam-view'];
    v.dataset.corners = String(corners);
    v.dataset.grid = String(grid);
    v.dataset.floor = String(floor);
  }

  #loop() {
    return pollView(this, {
      idle: () => !this.cam || this.cam.online === false,
      pause: () => 250, // about 4 a second, one in flight
      fetch: () => views.run(() => this.#fetchView()),
      onError: (err) => {
        if (err.status === 503) this.#say('waiting for the first frame');
        else if (err.status === 404) this.#say('not in the wizard');
        else this.#say(`view: ${err.message}`);
      },
    });
  }

  destroy() {
    this.alive = false;
    this.wake?.();
    for (const i of Object.values(this.images)) if (i.objectUrl) URL.revokeObjectURL(i.objectUrl);
    this.root.remove();
  }
}

function round1(v) {
  return Math.round(v * 10) / 10;
}

function clearPicks() {
  for (const c of cards.values()) c.setPicks([]);
}

function syncCards() {
  const cams = calib?.active ? calib.cameras || [] : calib?.step === 'saved' ? calib.cameras || [] : [];
  const host = $('calib-cameras');
  const names = cams.map((c) => c.name);
  for (const [name, card] of cards) {
    if (!names.includes(name)) {
      card.destroy();
      cards.delete(name);
    }
  }
  cams.forEach((cam, i) => {
    let card = cards.get(cam.name);
    if (!card) {
      card = new Card(cam.name);
      cards.set(cam.name, card);
    }
    const at = host.children[i + 1] || null; // after the idle note
    if (host.children[i + 1] !== card.root) host.insertBefore(card.root, at);
    card.update(cam);
  });
  $('calib-idle').hidden = cams.length > 0;
  host.dataset.count = String(cams.length);
}

// ---- the floor plan (ground metres, top-down) -------------------------------

const lastEnclosure = new Map();

function boardRect() {
  // the board lying on the floor, from the run's board spec and pose
  const m = /^(chessboard|charuco):(\d+)x(\d+):([\d.]+)/.exec(calib?.board || '');
  let pose = calib?.options?.board_pose;
  if (!Array.isArray(pose)) {
    // the contract's CALIB has no pose: the one this tab started the run with
    try {
      const started = JSON.parse(sessionStorage.getItem('calibrate.start') || 'null');
      if (started?.board === calib?.board) pose = started.board_pose;
    } catch {
      /* none */
    }
  }
  if (!m || !Array.isArray(pose)) return null;
  const w = Number(m[2]) * Number(m[4]);
  const hgt = Number(m[3]) * Number(m[4]);
  const [x0, y0, yaw] = pose;
  const a = (yaw * Math.PI) / 180;
  // board (bx, by) -> ground: flip y, turn by yaw, move to (x0, y0)
  return [[0, 0], [w, 0], [w, hgt], [0, hgt]].map(([bx, by]) => {
    const gx = bx;
    const gy = -by;
    return [x0 + gx * Math.cos(a) - gy * Math.sin(a), y0 + gx * Math.sin(a) + gy * Math.cos(a)];
  });
}

function drawPlan() {
  const canvas = $('calib-plan');
  const { ctx, w, h } = fitCanvas(canvas);
  ctx.clearRect(0, 0, w, h);
  ctx.fillStyle = '#0a0e14';
  ctx.fillRect(0, 0, w, h);
  ctx.textAlign = 'left';
  ctx.textBaseline = 'alphabetic';
  const cams = calib?.cameras || [];
  // the enclosure all cameras share: the one set last
  for (const c of cams) {
    const key = JSON.stringify(c.enclosure?.polygon_m || null);
    if (lastEnclosure.has(c.name) && lastEnclosure.get(c.name) !== key && c.enclosure) latestFloor = c.name;
    lastEnclosure.set(c.name, key);
  }
  const withFloor = cams.filter((c) => c.enclosure?.polygon_m?.length > 2);
  const floorCam = withFloor.find((c) => c.name === latestFloor) || withFloor[withFloor.length - 1];
  const polygon = floorCam?.enclosure.polygon_m || null;
  const posed = cams.filter((c) => c.plan?.position_m);
  const board = boardRect();

  const pts = [];
  if (polygon) pts.push(...polygon);
  for (const c of posed) pts.push(c.plan.position_m.slice(0, 2), ...(c.plan.fov_m || []));
  if (board) pts.push(...board);
  canvas.dataset.cameras = String(posed.length);
  canvas.dataset.polygon = String(polygon ? polygon.length : 0);
  $('calib-plan-note').textContent = polygon ? `${fmt(floorCam.enclosure.area_m2 ?? polygonArea(polygon), 2)} m² from ${floorCam.name}` : '';
  if (!pts.length) {
    ctx.fillStyle = '#8a94a6';
    ctx.font = '12px system-ui, sans-serif';
    ctx.textAlign = 'center';
    ctx.fillText('posed cameras and the enclosure show here', w / 2, h / 2);
    return;
  }
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  for (const [x, y] of pts) {
    x0 = Math.min(x0, x); x1 = Math.max(x1, x);
    y0 = Math.min(y0, y); y1 = Math.max(y1, y);
  }
  const pad = 18;
  const span = Math.max(x1 - x0, y1 - y0, 0.5);
  const k = Math.min((w - 2 * pad) / Math.max(x1 - x0, span * 0.2), (h - 2 * pad - 14) / Math.max(y1 - y0, span * 0.2));
  const cx = (x0 + x1) / 2;
  const cy = (y0 + y1) / 2;
  const X = (x) => w / 2 + (x - cx) * k;
  const Y = (y) => (h - 14) / 2 - (y - cy) * k; // ground y up
  const poly = (p, close = true) => {
    ctx.beginPath();
    p.forEach(([x, y], i) => (i ? ctx.lineTo(X(x), Y(y)) : ctx.moveTo(X(x), Y(y))));
    if (close) ctx.closePath();
  };
  // a light grid every 0.5 m (0.1 m when small)
  const step = span > 2 ? 0.5 : 0.1;
  groundGrid(ctx, w, h, X, Y, [cx - w / 2 / k, cx + w / 2 / k, cy - h / 2 / k, cy + (h - 14) / 2 / k], step);

  for (const c of posed) {
    if (c.plan.fov_m?.length > 2) {
      poly(c.plan.fov_m);
      ctx.fillStyle = COLOURS.fov;
      ctx.fill();
      ctx.strokeStyle = COLOURS.fovLine;
      ctx.lineWidth = 1;
      ctx.stroke();
    }
  }
  if (polygon) {
    poly(polygon);
    ctx.fillStyle = 'rgba(61,220,132,0.18)';
    ctx.fill();
    ctx.strokeStyle = '#3ddc84';
    ctx.lineWidth = 2;
    ctx.stroke();
  }
  if (board) {
    poly(board);
    ctx.setLineDash([3, 3]);
    ctx.strokeStyle = COLOURS.board;
    ctx.lineWidth = 1;
    ctx.stroke();
    ctx.setLineDash([]);
  }
  ctx.font = '11px ui-monospace, monospace';
  for (const c of posed) {
    const [px, py, pz] = c.plan.position_m;
    const fov = c.plan.fov_m || [];
    if (fov.length) {
      // a line towards the middle of what it sees
      const mx = fov.reduce((a, p) => a + p[0], 0) / fov.length;
      const my = fov.reduce((a, p) => a + p[1], 0) / fov.length;
      ctx.strokeStyle = '#4c9dff';
      ctx.beginPath(); ctx.moveTo(X(px), Y(py)); ctx.lineTo(X(mx), Y(my)); ctx.stroke();
    }
    ctx.beginPath();
    ctx.arc(X(px), Y(py), 5, 0, Math.PI * 2);
    ctx.fillStyle = '#4c9dff';
    ctx.fill();
    ctx.strokeStyle = '#fff';
    ctx.stroke();
    // its name and height beside it, on a dark patch
    const label = `${c.name} ${fmt(pz, 2)} m`;
    const tw = ctx.measureText(label).width;
    const tx = Math.min(w - tw - 4, Math.max(4, X(px) + 9));
    const ty = Math.max(12, Math.min(h - 20, Y(py) + 4));
    ctx.fillStyle = 'rgba(10,14,20,0.8)';
    ctx.fillRect(tx - 2, ty - 10, tw + 4, 13);
    ctx.fillStyle = '#d7dee9';
    ctx.fillText(label, tx, ty);
  }
  // the metre scale: a nice length about a quarter of the width
  const want = (w * 0.28) / k;
  const len = [0.05, 0.1, 0.2, 0.25, 0.5, 1, 2, 5, 10].reduce((a, v) => (v <= want ? v : a), 0.05);
  const sx = 8;
  const sy = h - 8;
  ctx.strokeStyle = '#d7dee9';
  ctx.lineWidth = 2;
  ctx.beginPath();
  ctx.moveTo(sx, sy - 4); ctx.lineTo(sx, sy); ctx.lineTo(sx + len * k, sy); ctx.lineTo(sx + len * k, sy - 4);
  ctx.stroke();
  ctx.fillStyle = '#d7dee9';
  ctx.fillText(len >= 1 ? `${len} m` : `${Math.round(len * 100)} cm`, sx + len * k + 6, sy);
  canvas.dataset.scaleM = String(len);
}

function polygonArea(p) {
  let a = 0;
  for (let i = 0; i < p.length; i++) {
    const [x0, y0] = p[i];
    const [x1, y1] = p[(i + 1) % p.length];
    a += x0 * y1 - x1 * y0;
  }
  return Math.abs(a) / 2;
}

// ---- wiring ------------------------------------------------------------------

let planQueued = false;
function render() {
  renderRun();
  syncChoices();
  syncCards();
  if (!planQueued) {
    planQueued = true;
    requestAnimationFrame(() => {
      planQueued = false;
      drawPlan();
    });
  }
}

// `answer`: an action's answer or GET /api/calibration, which know nothing of
// whether a camera delivers (the event stream's status adds "online"): that
// is kept from the last status until the stream says otherwise.
function apply(c, answer = false) {
  if (answer && c?.cameras && calib?.cameras) {
    for (const k of c.cameras) {
      const old = calib.cameras.find((o) => o.name === k.name);
      if (k.online === undefined && old?.online !== undefined) {
        k.online = old.online;
        if (!k.message && old.message) k.message = old.message;
      }
    }
  }
  calib = c;
  fillForm(c);
}

events.addEventListener('status', (e) => {
  status = e.detail;
  if (status.calibration !== undefined) apply(status.calibration);
  else if (calib === null) $('calib-idle').textContent = 'This station has no calibration wizard (status.calibration is missing).';
  render();
});

// The state once at load, in case the stream is slow to connect.
getJson('/api/calibration')
  .then((c) => {
    if (calib === null) {
      apply(c, true);
      render();
    }
  })
  .catch((err) => showMessage(`calibration: ${err.message}`, 'error'));

new ResizeObserver(() => {
  if (calib) drawPlan();
}).observe($('calib-plan'));

