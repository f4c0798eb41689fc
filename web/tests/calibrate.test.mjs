// The calibration wizard through the console: a synthetic calibration session
// served as an emulated GigE camera (fakecam on 127.0.0.2), a daemon whose
// camera has no model, and the page driven as an operator would: a board that
// does not match, the right board held in many places, the camera vanishing
// and coming back, solve, the board lying on the floor, the enclosure, save,
// and a save over a read-only folder. The models must meet the same truth
// numbers as the command-line wizard on the same footage (issue 16).
// The tests run in order on one daemon; each goes on from the last one's state.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import * as h from './harness.mjs';
import { pose, poseError, project, readModel } from './cameramodel.mjs';

const BOARD = 'chessboard:10x7:0.03';
const POSE = ['-0.15', '0.105', '0'];
const CARD = '[data-testid="calib-camera"][data-camera="cam0"]';
const started = Date.now();
const measured = {}; // what the page and the command line reached, reported at the end

let dir, truth, floor, cfg, station, cam, b, p, cli, cliProc;

// `calibrate wizard` on the same session, in the background: {code, stdout, stderr, seconds}.
function runCli(out) {
  const args = ['--log-level', 'warn', 'calibrate', 'wizard', '--session', dir, '--board', BOARD,
    '--board-pose', ...POSE, '--board-thickness', '0.001', '--floor-still-seconds', '0.5', '--min-coverage', '0.4',
    '--out', out, '--json'];
  const t0 = Date.now();
  const proc = spawn(h.BIN, args, { stdio: ['ignore', 'pipe', 'pipe'] });
  cliProc = proc;
  let stdout = '';
  let stderr = '';
  proc.stdout.on('data', (d) => (stdout += d));
  proc.stderr.on('data', (d) => (stderr += d));
  return new Promise((resolve) => proc.on('exit', (code) => resolve({ code, stdout, stderr, seconds: (Date.now() - t0) / 1000 })));
}

// How far a model is from the truth: fx, fy in %, the centre in mm, the rotation in degrees.
function against(model) {
  const e = (i) => (Math.abs(model.intrinsics[i] - truth.intrinsics[i]) / truth.intrinsics[i]) * 100;
  const out = { fx_percent: e(0), fy_percent: e(1) };
  if (model.extrinsics.some((v) => v !== 0)) {
    Object.assign(out, poseError(model, truth));
    out.height_m = pose(model).centre[2];
  }
  return out;
}

const round = (o) => Object.fromEntries(Object.entries(o).map(([k, v]) => [k, typeof v === 'number' ? Number(v.toPrecision(3)) : v]));

// ---- the page ------------------------------------------------------------------

// The camera card as the page shows it.
function card() {
  return p.$eval(CARD, (c) => {
    const q = (id) => c.querySelector(`[data-testid="${id}"]`);
    return {
      step: c.dataset.step,
      online: c.dataset.online === 'true',
      views: Number(q('cam-views').textContent),
      checks: Object.fromEntries([...c.querySelectorAll('[data-testid="cam-check"]')].map((li) => [li.dataset.id, li.dataset.state])),
      verdict: q('cam-solve-result').dataset.verdict,
      message: q('cam-message').hidden ? '' : q('cam-message').textContent,
      guidance: [...c.querySelectorAll('[data-testid="cam-guidance-line"]')].map((l) => l.textContent),
      board: q('cam-board').textContent,
      boardState: q('cam-board').dataset.state,
      frame: Number(q('cam-view').dataset.frame || -1),
      corners: Number(q('cam-view').dataset.corners || 0),
      grid: Number(q('cam-view').dataset.grid || 0),
      floor: Number(q('cam-view').dataset.floor || 0),
      posed: q('cam-pose').dataset.posed === 'true',
      height: q('cam-height').textContent,
      tilt: q('cam-tilt').textContent,
      floorFrom: q('cam-floor-from').textContent,
      floorArea: q('cam-floor-area').textContent,
      fed: Number(q('cam-frames').textContent.replace(/\D/g, '')),
    };
  }).catch(() => null);
}

// Waits until pred(card) holds; a time-out shows the card as it last was.
async function cardWait(what, pred, timeout) {
  let last = null;
  try {
    return await h.waitFor(what, async () => {
      last = await card();
      return last && (await pred(last)) && last;
    }, { timeout, interval: 200 });
  } catch (err) {
    err.message += `\ncard: ${JSON.stringify(last)}`;
    throw err;
  }
}

async function openForm() {
  if (!(await p.$eval('[data-testid="calib-start-box"]', (d) => d.open))) await p.click('[data-testid="calib-start-toggle"]');
}

async function startWizard(board) {
  await openForm();
  await p.fill('[data-testid="calib-board"]', board);
  await p.fill('[data-testid="calib-pose-x"]', POSE[0]);
  await p.fill('[data-testid="calib-pose-y"]', POSE[1]);
  await p.fill('[data-testid="calib-pose-yaw"]', POSE[2]);
  await p.fill('[data-testid="calib-thickness"]', '1');
  if (!(await p.$eval('details.criteria', (d) => d.open))) await p.click('details.criteria summary');
  await p.fill('[data-testid="calib-min-coverage"]', '40');
  // still 0.5 s by the frames' timestamps, which fakecam serves as recorded (8 fps): 5 frames, as
  // the command line's; a held pose stands still 2 or 3 frames, never that long
  await p.fill('[data-testid="calib-floor-still"]', '0.5');
  const run = (await api('/api/calibration')).run || 0;
  await p.click('[data-testid="calib-start"]');
  await h.waitFor(`wizard run ${run + 1} with ${board}`, async () => {
    const c = await api('/api/calibration');
    return c.active && c.run > run && c.board === board;
  });
  await p.waitForSelector(CARD, { timeout: 10000 });
}

async function api(p2, init) {
  const res = await fetch(`${station.url}${p2}`, init);
  return res.json();
}

// The message bar's error text, once shown.
function errorShown(re) {
  return h.waitFor(`an error message matching ${re}`, async () => {
    const visible = await p.isVisible('[data-testid="message"]');
    const kind = await p.getAttribute('[data-testid="message"]', 'data-kind');
    const text = visible && kind === 'error' ? await h.text(p, 'message-text') : '';
    return re.test(text) && text;
  }, { timeout: 20000 });
}

// The session's 8 frames a second served at 2 (the same frames, 4 times as far apart): the
// board holds each pose for 2 or 3 frames, and the wizard sees it still only when it
// processes 2 of them in a row; on two cores shared with other work it processes 2 to 5
// frames a second, not 8.
const FPS = Number(process.env.SS_CALIB_FPS || 2);
async function fakecam() {
  const c = new h.Child('fakecam-calib', ['fakecam', dir, '--address', '127.0.0.2', '--serial', 'calib',
    '--loop', '0', '--pixel-format', 'rgb8', '--fps', String(FPS)]);
  await c.waitForOutput(/fakecam: serving/, 30000);
  return c;
}

// Until the station's camera delivers again (a restarted fakecam is reopened with backoff)
// at its rate, so that the wizard starts on a steady stream. (Its still times once were frame
// counts at the rate measured when it started, off for a moment after a reopen; they are now
// timed by the frames' timestamps.)
async function stationLive() {
  let steady = 0;
  await h.waitFor(`cam0 live in the station at ${FPS} fps`, async () => {
    const c = (await api('/api/status')).cameras.find((k) => k.name === 'cam0');
    steady = c?.state === 'live' && Math.abs(c.fps - FPS) < 0.2 * FPS ? steady + 1 : 0;
    return steady >= 3 && c;
  }, { timeout: 30000, interval: 250 });
}

// ---- the station -----------------------------------------------------------------

before(async () => {
  dir = path.join(h.WORK, 'sessions', 'calibration');
  if (!fs.existsSync(path.join(dir, 'session.json'))) {
    h.run(['--log-level', 'warn', 'synth', '--out', dir, '--kind', 'calibration', '--seconds', '20', '--fps', '8',
      '--size', '640x480', '--cameras', '1', '--seed', '5']);
  }
  truth = readModel(path.join(dir, 'truth', 'cam0.cameramodel'));
  // the true floor, where the enclosure step clicks (the config has none)
  floor = JSON.parse(fs.readFileSync(path.join(dir, 'truth', 'floor.json'), 'utf8')).polygon;
  cam = await fakecam();
  // A first-time user's config: the camera alone, no model and no floor (issue 41).
  cfg = h.config('calib', {}, [{ name: 'cam0', source: 'aravis', address: '127.0.0.2' }]);
  // As root, a read-only folder stops nobody: the daemon runs without CAP_DAC_OVERRIDE.
  const prefix = process.getuid?.() === 0 ? ['setpriv', '--bounding-set', '-dac_override,-dac_read_search'] : [];
  station = await h.daemon('calib', cfg, ['--offline-after', '1.5', '--no-transitions'], { prefix });
  b = await h.browser();
  p = await h.page(b, { width: 1280, height: 900 });
  await p.goto(`${station.url}/calibrate.html`);
});

after(async () => {
  if (cliProc && cliProc.exitCode === null) cliProc.kill('SIGKILL');
  await b?.close();
  await station?.stop();
  await cam?.kill();
  const calibDir = path.join(cfg?.dir || '', 'calibration');
  if (cfg && fs.existsSync(calibDir)) fs.chmodSync(calibDir, 0o755);
  console.log(`calibrate.test: ${JSON.stringify(measured)}; ${((Date.now() - started) / 1000).toFixed(0)} s`);
});

test('the start form lists the cameras; a board that does not match is named on the page', async () => {
  // the station runs without a floor: the camera streams, and says what it lacks
  const cam0 = (await api('/api/status')).cameras.find((c) => c.name === 'cam0');
  assert.equal(cam0.has_model, false);
  assert.equal(cam0.has_floor, false);
  await p.waitForSelector('[data-testid="calib-camera-choice"][value="cam0"]', { timeout: 20000 });
  assert.equal(await p.isChecked('[data-testid="calib-camera-choice"][value="cam0"]'), true);
  assert.equal(await p.getAttribute('[data-testid="calib"]', 'data-active'), 'false');
  await h.screenshot(p, 'console-calibrate-start.png');

  await startWizard('chessboard:12x9:0.03');
  // the camera streams (frames advance) and the page says no such board is seen
  const first = await h.waitFor('the live view', async () => {
    const c = await card();
    return c && c.frame >= 0 && c;
  }, { timeout: 20000 });
  const seen = await h.waitFor('"no board" on the page', async () => {
    const c = await card();
    return c.frame > first.frame + 8 && c.boardState === 'none' && /no board/i.test(c.board) &&
      c.guidance.some((g) => /board/.test(g)) && c;
  }, { timeout: 20000 });
  assert.equal(seen.views, 0, 'no view captured with the wrong board');
  assert.equal(seen.corners, 0);
  measured.wrong_board = seen.guidance[0];
});

test('intrinsics: views captured while the board stands still; a vanished camera keeps them; solve is good', async () => {
  // the session from its start (the held chessboard's 18 s at 4 fps), not wherever its loop is
  await cam.kill();
  await h.waitFor('cam0 gone from the station', async () =>
    (await api('/api/status')).cameras.find((c) => c.name === 'cam0')?.state !== 'live', { timeout: 15000, interval: 100 });
  cam = await fakecam();
  await stationLive();
  await startWizard(BOARD);
  // the page draws the detected corners over the image (the JPEG has none)
  const drawn = await h.waitFor('corners drawn on the live view', async () => {
    const c = await card();
    if (!c || c.corners !== 54) return false;
    const px = await p.$eval(`${CARD} [data-testid="cam-overlay"]`, (cv) => {
      const d = cv.getContext('2d').getImageData(0, 0, cv.width, cv.height).data;
      let n = 0;
      for (let i = 3; i < d.length; i += 4) if (d[i] > 200) n++;
      return n;
    });
    return px > 500 && { ...c, px };
  }, { timeout: 40000, interval: 50 });
  assert.ok(drawn.px > 500);
  await cardWait('2 views', (c) => c.views >= 2, 40000);
  const cells = Number(await p.getAttribute(`${CARD} [data-testid="cam-coverage"]`, 'data-filled'));
  assert.ok(cells > 5, `coverage map filled (${cells} cells)`);
  const bars = await p.$$eval(`${CARD} [data-testid^="cam-bar-"]:not([data-testid$="-value"])`, (e) => e.map((x) => Number(x.dataset.value)));
  assert.equal(bars.length, 4);
  assert.ok(bars.some((v) => v > 0), `diversity bars ${bars}`);
  await h.screenshot(p, 'console-calibrate-intrinsics.png');

  // the camera vanishes: the page shows it offline with the reason; the views stay
  const before = (await card()).views;
  measured.views_before_vanishing = before;
  await cam.kill('SIGKILL');
  const off = await h.waitFor('cam0 offline on the page', async () => {
    const c = await card();
    return !c.online && /offline: \S/.test(c.message) && c;
  }, { timeout: 15000, interval: 100 });
  assert.ok(off.views >= before, `views kept (${off.views} of ${before})`);
  assert.equal(await p.getAttribute(`${CARD} [data-testid="cam-online"]`, 'data-state'), 'offline');
  measured.offline_message = off.message;
  await h.screenshot(p, 'console-calibrate-offline.png');
  await h.sleep(1000);
  assert.ok((await card()).views >= before, 'views kept while offline');

  // back: the wizard goes on from those views
  cam = await fakecam();
  await h.waitFor('cam0 online again', async () => (await card()).online, { timeout: 30000, interval: 200 });

  // the checklist's views and coverage come true as the board goes round
  await cardWait('views and coverage met', (c) => c.checks.views === 'met' && c.checks.coverage === 'met', 90000);
  // as an operator would, hold the board on in new places until the segment ends (no
  // board for 2 s): every pose caught makes the intrinsics, and so the pose, better
  let seen = Date.now();
  const met = await cardWait('the held chessboard gone', (c) => {
    if (c.boardState !== 'none') seen = Date.now();
    return Date.now() - seen > 2000;
  }, 30000);
  measured.views = met.views;
  assert.equal((await card()).checks.rms, 'pending', 'not solved yet');

  // Solve: the progress comes over the event stream
  await p.evaluate(() => {
    window.busySeen = [];
    const box = document.querySelector('[data-testid="calib-busy"]');
    new MutationObserver(() => {
      if (!box.hidden) window.busySeen.push(document.querySelector('[data-testid="calib-busy-stage"]').textContent);
    }).observe(box, { attributes: true, subtree: true, childList: true, characterData: true });
  });
  await p.click(`${CARD} [data-testid="cam-solve"]`);
  const solved = await h.waitFor('the verdict', async () => {
    const c = await card();
    return c.verdict && c;
  }, { timeout: 60000, interval: 100 });
  assert.equal(solved.verdict, 'good', `verdict ${solved.verdict}: ${await h.text(p, 'cam-reasons')}`);
  const busySeen = await p.evaluate(() => window.busySeen);
  assert.ok(busySeen.some((t) => /solve/.test(t)), `the solve's progress shown (${JSON.stringify(busySeen.slice(0, 5))})`);
  for (const id of ['views', 'coverage', 'rms', 'fx', 'fy', 'cx', 'cy']) {
    assert.equal(solved.checks[id], 'met', `checklist ${id}`);
  }
  // the residual plot and the uncertainty map, fetched with the token as blobs
  for (const id of ['cam-residuals', 'cam-uncertainty']) {
    await h.waitFor(`the ${id} image`, () => p.$eval(`${CARD} [data-testid="${id}"]`,
      (i) => i.complete && i.naturalWidth > 0 && i.src.startsWith('blob:')), { timeout: 15000 });
  }
  const shown = await p.$$eval(`${CARD} [data-testid="cam-intrinsics-table"] td[data-value]`,
    (tds) => Object.fromEntries(tds.map((td) => [td.dataset.testid.slice(4), Number(td.dataset.value)])));
  const page = { intrinsics: [shown.fx, shown.fy, shown.cx, shown.cy], extrinsics: [0, 0, 0, 0, 0, 0] };
  const err = against(page);
  measured.page_solve = round(err);
  assert.ok(err.fx_percent < 0.2 && err.fy_percent < 0.2, `fx, fy within 0.2 % of the truth: ${JSON.stringify(err)}`);
  await h.sleep(300);
  await h.screenshot(p, 'console-calibrate-solve.png');
  // The command-line wizard's run, while this one waits for the boards to lie on the floor
  // (the ChArUco segment: 36 s at 2 fps, little for the station to do).
  cli = runCli(path.join(h.WORK, 'calib-cli'));
});

test('ground: the board lying on the floor poses the camera only after the word; height, tilt, grid; the green floor detected', async () => {
  // The boards lie on the floor (the chessboard seen again after the ChArUco segment, still):
  // without the operator's word nothing is posed and the step is not ticked, however long it lies.
  const lying = await cardWait('the board lying still on the floor', (k) => k.step === 'ground' && k.boardState === 'still', 90000);
  const waiting = () => p.$eval(`${CARD} [data-testid="cam-ground-word"]`, (x) => x.dataset.state);
  assert.equal(await waiting(), 'waiting');
  assert.equal(await p.isDisabled(`${CARD} [data-testid="cam-board-on-floor"]`), false, 'the word can be given');
  assert.ok(lying.guidance.some((g) => /say so/.test(g)), `the guidance asks for the word: ${JSON.stringify(lying.guidance)}`);
  // lying still longer than floor_still_s (0.5 s of the session's time: 5 frames, 2.5 s at 2 fps),
  // then the word: the boards lie on the floor for 16 frames of the loop, the pose needs 5 more
  // after the word
  const t0 = Date.now();
  const fed0 = (await api('/api/calibration')).cameras[0].frames;
  const violations = [];
  await h.waitFor('the board lying still for 6 frames without the word', async () => {
    const k = await card();
    const tick = await p.getAttribute('[data-testid="calib-steps"] li[data-step="ground"]', 'data-state');
    if (k.posed || k.step !== 'ground' || tick !== 'current') violations.push({ ...k, tick });
    return Date.now() - t0 > 6000 / FPS && k;
  }, { timeout: 10000, interval: 100 });
  assert.deepEqual(violations, [], 'posed or ticked without the word');
  measured.frames_fed_without_word = (await api('/api/calibration')).cameras[0].frames - fed0;
  assert.ok((await api('/api/calibration')).cameras[0].ground === null, 'the API has no pose either');
  await h.screenshot(p, 'console-calibrate-ground-waiting.png');
  const [req] = await Promise.all([
    p.waitForRequest((r) => r.url().endsWith('/api/calibration/ground') && r.method() === 'POST'),
    p.click(`${CARD} [data-testid="cam-board-on-floor"]`),
  ]);
  assert.deepEqual(JSON.parse(req.postData()), { camera: 'cam0' });
  // Missed (a loaded machine sees too few frames of the boards' 8 s on the floor), the word
  // lapses after 10 s and the card asks for it again: the operator gives it again when the
  // boards lie still once more (80 s on, a loop later), as the guidance says.
  let again = 0;
  const c = await cardWait('the camera posed', async (k) => {
    if (k.posed && k.grid > 0) return true;
    if (k.step === 'ground' && k.boardState === 'still' && (await waiting()) === 'waiting' &&
        !(await p.isDisabled(`${CARD} [data-testid="cam-board-on-floor"]`))) {
      again++;
      await p.click(`${CARD} [data-testid="cam-board-on-floor"]`);
    }
    return false;
  }, 150000);
  measured.words_given_again = again;
  const check = (await api('/api/calibration')).cameras[0].ground_check;
  assert.equal(check.doubt, null);
  measured.ground_check = round(check);
  assert.ok(check.ring_green > 0.6, `green round the board: ${check.ring_green}`);
  // The floor is clear of held boards only while the boards lie on it (16 frames of the
  // loop's 160, 8 s at 2 fps): detect at once, and again until a whole floor is seen. Posed
  // late in that window, the next comes a loop later (80 s): CI once saw 0.24 m2 for 30 s.
  // A frame with a board held up over the floor may find none ("no green floor found", said
  // on the page), and the command-line wizard runs beside this one: each try waits for the
  // station's answer, as the rig's test does, and a refused one is tried again.
  let area = 0;
  let tries = 0;
  const end = Date.now() + 100000;
  while (Date.now() < end) {
    tries++;
    await Promise.all([
      p.waitForResponse((r) => r.url().endsWith('/api/calibration/floor') && r.request().method() === 'POST',
        { timeout: 30000 }),
      p.click(`${CARD} [data-testid="cam-detect-floor"]`),
    ]);
    const en = (await api('/api/calibration')).cameras[0].enclosure;
    area = en?.from === 'green floor' ? en.area_m2 : 0;
    if (area > 0.6 && area < 0.97) break;
    await h.sleep(700); // a board held up hides part of it: look again
  }
  measured.page_floor_m2 = area;
  measured.floor_detect_tries = tries;
  assert.ok(area > 0.6 && area < 0.97, `floor area ${area} m² (truth 0.96 m², the near wall hides a strip)`);
  await h.waitFor('the card shows the green floor', async () => {
    const x = await card();
    return x.floorFrom === 'green floor' && Number(x.floorArea.split(' ')[0]) === Number(area.toFixed(2));
  }, { timeout: 10000 });
  await h.waitFor('the floor drawn on the live view', async () => (await card()).floor >= 3);

  assert.match(c.height, /^\d\.\d{3} m$/);
  assert.match(c.tilt, /^\d+(\.\d)?°$/);
  const height = Number(c.height.replace(/ m$/, ''));
  assert.ok(Math.abs(height - pose(truth).centre[2]) < 0.01, `height ${height} m`);
  assert.ok(['enclosure', 'done'].includes(c.step), `step ${c.step}`);
  assert.equal(await p.getAttribute('[data-testid="calib-plan"]', 'data-cameras'), '1', 'the posed camera on the plan');
  await h.screenshot(p, 'console-calibrate-ground.png');
});

test('enclosure: the floor corners clicked on the image are the floor on the plan', async () => {
  // click where the true floor's corners are in the image: the page posts camera pixels,
  // the wizard carries them onto the floor through the posed model
  const overlay = `${CARD} [data-testid="cam-overlay"]`;
  const box = await p.locator(overlay).boundingBox();
  const pixels = floor.map(([x, y]) => project(truth, [x, y, 0]));
  for (const [u, v] of pixels) {
    assert.ok(u > 0 && u < 640 && v > 0 && v < 480, `corner in view: ${u}, ${v}`);
    await p.mouse.click(box.x + (u / 640) * box.width, box.y + (v / 480) * box.height);
  }
  assert.equal(await p.getAttribute(CARD, 'data-picks'), String(floor.length));
  await h.sleep(200);
  await h.screenshot(p, 'console-calibrate-corners.png');
  const [req] = await Promise.all([
    p.waitForRequest((r) => r.url().endsWith('/api/calibration/floor') && r.method() === 'POST'),
    p.click(`${CARD} [data-testid="cam-use-picks"]`),
  ]);
  const body = JSON.parse(req.postData());
  assert.equal(body.camera, 'cam0');
  body.pixels.forEach(([u, v], i) => {
    assert.ok(Math.hypot(u - pixels[i][0], v - pixels[i][1]) < 1.5, `pixel ${i}: ${u}, ${v} for ${pixels[i]}`);
  });
  await h.waitFor('the clicked polygon', async () => (await card()).floorFrom === 'clicked corners', { timeout: 10000 });
  const polygon = (await api('/api/calibration')).cameras[0].enclosure.polygon_m;
  assert.equal(polygon.length, floor.length);
  const off = Math.max(...polygon.map(([x, y], i) => Math.hypot(x - floor[i][0], y - floor[i][1])));
  measured.clicked_floor_mm = Number((off * 1000).toFixed(1));
  assert.ok(off < 0.01, `clicked corners on the floor within ${(off * 1000).toFixed(1)} mm of the truth`);
  await h.waitFor('the plan with the polygon', async () =>
    (await p.getAttribute('[data-testid="calib-plan"]', 'data-polygon')) === String(floor.length));
  await h.waitFor('the floor drawn on the live view', async () => (await card()).floor === floor.length);
  await h.sleep(300);
  await h.screenshot(p, 'console-calibrate-enclosure.png');
});

let savedFile;
test('save: the model is written, the station uses it, and its pose meets the truth', async () => {
  await p.click('[data-testid="calib-save"]');
  await p.waitForSelector('[data-testid="calib-saved"]:not([hidden])', { timeout: 60000 });
  const files = await p.$$eval('[data-testid="saved-file"]', (l) => l.map((e) => e.dataset.path));
  savedFile = path.join(cfg.dir, 'calibration', 'cam0.cameramodel');
  assert.deepEqual(files, [savedFile]);
  assert.ok(fs.existsSync(savedFile));
  await h.waitFor('the page saying the station uses them', async () => /now uses them/.test(await h.text(p, 'saved-station')),
    { timeout: 30000 });
  // the config names it (the previous config kept); the station's camera has a model
  const yaml = fs.readFileSync(cfg.file, 'utf8');
  assert.ok(yaml.includes(savedFile), `the config names ${savedFile}:\n${yaml}`);
  assert.ok(fs.readdirSync(cfg.dir).some((f) => /^station\.previous-.*\.yaml$/.test(f)), 'the previous config kept');
  await h.waitFor('cam0 has a model', async () => (await api('/api/status')).cameras.find((c) => c.name === 'cam0')?.has_model === true,
    { timeout: 30000, interval: 250 });
  // the floor the wizard found is the config's now (it had none), and the station's
  assert.match(yaml, /^enclosure:\n\s+floor:/m, `the config's enclosure:\n${yaml}`);
  assert.equal((await api('/api/status')).cameras.find((c) => c.name === 'cam0')?.has_floor, true);

  const model = readModel(savedFile);
  const err = against(model);
  measured.page = round(err);
  assert.ok(err.fx_percent < 0.2 && err.fy_percent < 0.2, `intrinsics ${JSON.stringify(err)}`);
  assert.ok(err.centre_mm < 2, `camera centre ${err.centre_mm} mm from the truth`);
  assert.ok(err.rotation_deg < 0.1, `rotation ${err.rotation_deg}° from the truth`);
  // the model saved is the one the page showed
  const shown = await p.$$eval(`${CARD} [data-testid="cam-intrinsics-table"] td[data-value]`, (tds) => tds.map((td) => Number(td.dataset.value)));
  shown.forEach((v, i) => assert.ok(Math.abs(v - model.intrinsics[i]) <= 1e-9 * Math.abs(v), `intrinsics[${i}] ${v} vs ${model.intrinsics[i]}`));
  await h.sleep(300);
  await h.screenshot(p, 'console-calibrate-saved.png');
});

test('saving over a read-only folder names the folder, and the saved model is kept', async () => {
  const folder = path.dirname(savedFile);
  const bytes = fs.readFileSync(savedFile);
  const listing = fs.readdirSync(folder).sort();
  fs.chmodSync(folder, 0o555);
  try {
    await h.waitFor('Save enabled', async () => !(await p.isDisabled('[data-testid="calib-save"]')), { timeout: 10000 });
    await p.click('[data-testid="calib-save"]');
    const text = await errorShown(new RegExp(folder.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')));
    measured.read_only_message = text;
    assert.ok(fs.readFileSync(savedFile).equals(bytes), 'the saved model is unchanged');
    assert.deepEqual(fs.readdirSync(folder).sort(), listing, 'nothing added or removed');
    await h.waitFor('the error in the run panel', async () => (await p.isVisible('[data-testid="calib-error"]')) &&
      (await h.text(p, 'calib-error')).includes(folder));
    await h.screenshot(p, 'console-calibrate-error.png');
  } finally {
    fs.chmodSync(folder, 0o755);
  }
  assert.deepEqual(p.errors, []);
});

test('the command-line wizard on the same footage meets the same numbers', async () => {
  assert.ok(cli, 'the command line ran');
  const r = await cli;
  assert.equal(r.code, 0, r.stderr);
  const j = JSON.parse(r.stdout);
  assert.equal(j.verdict, 'good');
  const err = against(readModel(path.join(h.WORK, 'calib-cli', 'cam0.cameramodel')));
  measured.cli = round(err);
  measured.cli_seconds = Math.round(r.seconds);
  for (const m of [measured.cli, measured.page]) {
    assert.ok(m.fx_percent < 0.2 && m.fy_percent < 0.2 && m.centre_mm < 2 && m.rotation_deg < 0.1, JSON.stringify(m));
  }
});
