// The calibration wizard on a studio of two cameras, through the console (issue 41): a
// synthetic two-camera calibration session replayed as the cameras of a config that names only
// them (no model, no floor), and the page driven as an operator would: start, solve each camera
// once its views meet the criteria, say "the board lies on the floor" only while it does, find
// the green floor, solve jointly, save. The saved models must agree with each other (cam1's pose
// relative to cam0's) and with the truth; then the station, started again on footage of a
// hamster seen by the same two cameras, stores sprites with them.
// The tests run in order on one daemon; each goes on from the last one's state.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import * as h from './harness.mjs';
import { angleDeg, mul, poseError, project, readModel, relative, transpose } from './cameramodel.mjs';

// In CI's run (`console_browser`) since the session holds each pose about 1 s and every pose a
// camera is held at is one its detector finds, and since the test solves as the checklist says
// (bench/RESULTS.md, "In the page": it had left CI after cam0's coverage check stayed unmet).
const BOARD = 'chessboard:10x7:0.03';
const CAMERAS = ['cam0', 'cam1'];
const SECONDS = 90;
const FPS = 8;
const FRAMES = SECONDS * FPS;
// The boards lie on the floor for the session's last 10 % (docs/synth.md): the operator says so
// in the first two thirds of that, so that they lie still long enough after the word.
const FLOOR_FROM = FRAMES - Math.round(0.1 * FRAMES) + 4;
const FLOOR_TO = FRAMES - Math.round(0.1 * FRAMES) / 3;
const cardOf = (name) => `[data-testid="calib-camera"][data-camera="${name}"]`;
const started = Date.now();
const measured = {};

let dir, animal, truth, cfg, station, b, p;

async function api(route, init) {
  const res = await fetch(`${station.url}${route}`, init);
  return res.json();
}

// A camera's card as the page shows it.
function card(name) {
  return p.$eval(cardOf(name), (c) => {
    const q = (id) => c.querySelector(`[data-testid="${id}"]`);
    return {
      step: c.dataset.step,
      views: Number(q('cam-views').textContent),
      checks: Object.fromEntries([...c.querySelectorAll('[data-testid="cam-check"]')].map((li) => [li.dataset.id, li.dataset.state])),
      verdict: q('cam-solve-result').dataset.verdict,
      frame: Number(q('cam-view').dataset.frame || -1),
      posed: q('cam-pose').dataset.posed,
      word: q('cam-ground-word').dataset.state,
      solveOff: q('cam-solve').disabled,
      wordOff: q('cam-board-on-floor').disabled,
      floorFrom: q('cam-floor-from').textContent,
      floorArea: q('cam-floor-area').textContent,
    };
  }).catch(() => null);
}

const cards = async () => Object.fromEntries(await Promise.all(CAMERAS.map(async (n) => [n, await card(n)])));

before(async () => {
  // The rig's calibration session, and 8 s of a hamster before the same two cameras (a session's
  // cameras are placed by its seed alone: the truth's models are the same files).
  const root = path.join(h.WORK, 'sessions-rig');
  dir = path.join(root, 'calibration');
  animal = path.join(root, 'hamster');
  if (!fs.existsSync(path.join(dir, 'session.json'))) {
    h.run(['--log-level', 'warn', 'synth', '--out', dir, '--kind', 'calibration', '--seconds', String(SECONDS),
      '--fps', String(FPS), '--size', '640x480', '--cameras', '2', '--seed', '5', '--threads', '2', '--no-mattes']);
  }
  if (!fs.existsSync(path.join(animal, 'session.json'))) {
    h.run(['--log-level', 'warn', 'synth', '--out', animal, '--kind', 'animal', '--seconds', '8', '--fps', '15',
      '--size', '640x480', '--cameras', '2', '--subjects', '1', '--seed', '5', '--empty-lead-in', '2', '--no-mattes']);
  }
  // As an uncalibrated station records it: no camera model beside the footage, no floor
  // polygon. (A synthetic session names its true models, and its truth's floor would give a
  // replay one: FloorForSession.)
  const info = JSON.parse(fs.readFileSync(path.join(dir, 'session.json'), 'utf8'));
  for (const c of info.cameras) {
    if (c.model) fs.rmSync(path.join(dir, c.model), { force: true });
    delete c.model;
  }
  fs.writeFileSync(path.join(dir, 'session.json'), JSON.stringify(info, null, 2));
  const floorTruth = path.join(dir, 'truth', 'floor.json');
  if (fs.existsSync(floorTruth)) fs.renameSync(floorTruth, path.join(root, 'floor-truth.json'));
  truth = Object.fromEntries(CAMERAS.map((n) => [n, readModel(path.join(dir, 'truth', `${n}.cameramodel`))]));
  for (const n of CAMERAS) {
    assert.equal(fs.readFileSync(path.join(animal, 'truth', `${n}.cameramodel`), 'utf8'), truth[n].text,
      `${n}: the hamster's footage is from the calibrated camera`);
  }
  // A first-time user's config: the two cameras alone, no model and no floor.
  cfg = h.config('rig', {}, CAMERAS.map((n) => ({ name: n, source: 'replay', session: dir, session_camera: n,
    loop: true, realtime: true })));
  station = await h.daemon('rig', cfg, ['--no-transitions']);
  b = await h.browser();
  p = await h.page(b, { width: 1400, height: 1000 });
  await p.goto(`${station.url}/calibrate.html`);
});

after(async () => {
  await b?.close();
  await station?.stop();
  console.log(`calibrate-rig.test: ${JSON.stringify(measured)}; ${((Date.now() - started) / 1000).toFixed(0)} s`);
});

test('both cameras run without a floor; the wizard starts on both', async () => {
  const status = await h.waitFor('both cameras live', async () => {
    const s = await api('/api/status');
    return s.cameras.length === 2 && s.cameras.every((c) => c.state === 'live') && s;
  }, { timeout: 30000, interval: 250 });
  for (const c of status.cameras) {
    assert.equal(c.has_floor, false, `${c.name} has no floor`);
    assert.equal(c.has_model, false, `${c.name} has no model`);
  }
  if (!(await p.$eval('[data-testid="calib-start-box"]', (d) => d.open))) await p.click('[data-testid="calib-start-toggle"]');
  // every camera is offered, and ticked
  const offered = await h.waitFor('both cameras offered', async () => {
    const l = await p.$$eval('[data-testid="calib-camera-choices"] input[type="checkbox"]', (x) => x.map((i) => i.checked && i.value));
    return l.length === 2 && l;
  });
  assert.deepEqual([...offered].sort(), CAMERAS);
  await p.fill('[data-testid="calib-board"]', BOARD);
  await p.fill('[data-testid="calib-pose-x"]', '-0.15');
  await p.fill('[data-testid="calib-pose-y"]', '0.105');
  await p.fill('[data-testid="calib-pose-yaw"]', '0');
  await p.fill('[data-testid="calib-thickness"]', '1');
  if (!(await p.$eval('details.criteria', (d) => d.open))) await p.click('details.criteria summary');
  await p.fill('[data-testid="calib-min-coverage"]', '15');
  await p.fill('[data-testid="calib-floor-still"]', '0.5');
  await p.click('[data-testid="calib-start"]');
  await h.waitFor('the wizard on both cameras', async () => {
    const c = await api('/api/calibration');
    return c.active && c.cameras?.length === 2;
  });
  await p.waitForSelector(cardOf('cam1'), { timeout: 10000 });
});

test('each camera solved; one posed on the operator\'s word, the other through the joint solve', async () => {
  // As an operator reads the card: solve a camera once its checklist's views, coverage and tilt
  // are met, and again after three more views while a solve is rejected (a solve ran on the
  // camera's thread once, which captured nothing meanwhile: solving at every new view, as this
  // test first did, kept a loaded machine's cam0 solving through its own poses, and in CI it
  // caught only the views both cameras share, 19 covering under 15 % of its image in 7 minutes;
  // a solve now runs on a thread of its own and the camera captures on); give
  // the word only while the boards lie on the floor (the operator sees them there: here, by the
  // session's frame number).
  // The floor board lies where cam0 sees it and cam1 does not: cam1 is posed through the rig.
  const solvedAt = {};
  let words = 0;
  let last = null;
  let joint = null;
  let jointAsked = Date.now();
  let joints = 0;
  const posed = await h.waitFor('cam0 posed on the floor board, cam1 through the joint solve', async () => {
    last = await cards();
    const busy = !(await p.isHidden('[data-testid="calib-busy"]'));
    for (const [n, k] of Object.entries(last)) {
      if (!k) continue;
      const ready = ['views', 'coverage', 'tilt'].every((id) => k.checks[id] === 'met');
      if (k.step === 'intrinsics' && !busy && !k.solveOff && ready && k.views >= (solvedAt[n] ?? -3) + 3) {
        solvedAt[n] = k.views;
        await p.click(`${cardOf(n)} [data-testid="cam-solve"]`);
      }
      if (k.step === 'ground' && k.word === 'waiting' && !k.wordOff) {
        const f = k.frame % FRAMES;
        if (f >= FLOOR_FROM && f < FLOOR_TO) {
          words++;
          await p.click(`${cardOf(n)} [data-testid="cam-board-on-floor"]`);
        }
      }
    }
    // A joint solve that found too few places both cameras saw is asked for again (the page's
    // button) once a loop of the session has held the board before both once more: the
    // cameras, the posed one too, go on collecting them.
    joint = (await api('/api/calibration')).joint;
    if (joint?.state === 'failed' && Date.now() - jointAsked > (SECONDS * 1000) / 2 &&
        !(await p.isDisabled('[data-testid="calib-joint-solve"]'))) {
      jointAsked = Date.now();
      joints++;
      await p.click('[data-testid="calib-joint-solve"]');
    }
    return last.cam0?.posed === 'true' && last.cam1?.posed === 'rig' && last;
  }, { timeout: 540000, interval: 500 }).catch((err) => {
    err.message += `\ncards: ${JSON.stringify(last)}\njoint: ${JSON.stringify(joint)}`;
    throw err;
  });
  measured.views = Object.fromEntries(Object.entries(posed).map(([n, k]) => [n, k.views]));
  measured.words = words;
  measured.joint_asked_again = joints;
  assert.ok(['enclosure', 'done'].includes(posed.cam0.step), `cam0: step ${posed.cam0.step}`);
  // The operator's word before cam1 did not pose it: no floor board of its own was taken.
  assert.equal(posed.cam1.step, 'ground');
  assert.equal((await api('/api/calibration')).cameras.find((k) => k.name === 'cam1').ground, null);
  assert.match(await p.textContent(`${cardOf('cam1')} [data-testid="cam-ground-word"]`), /joint solve from cam0's floor board/);
  assert.ok(joint.trusted, `the joint solve trusted: ${JSON.stringify(joint.doubts)}`);
  assert.equal(joint.posed_from, 'cam0');
  measured.joint = { shared_instants: joint.shared_instants, rms_px: joint.rms_px,
    focal_stdev_percent: joint.cameras.map((k) => k.focal_stdev_percent) };
  await h.waitFor('the joint figures on the page', async () =>
    (await p.$$('[data-testid="joint-pair"]')).length === 1 && (await p.$$('[data-testid="joint-camera"]')).length === 2 &&
    /Trusted/.test(await h.text(p, 'joint-trust')), { timeout: 10000 });
  await h.screenshot(p, 'console-calibrate-rig-joint.png');
  await p.locator(cardOf('cam1')).screenshot({ path: path.join(h.DOCS, 'console-calibrate-rig-cam1.png') });
});

test('the green floor found from the posed camera, with no floor in the config', async () => {
  // Detected while the boards lie on the floor, as an operator would once the board is down: a
  // board held up before the camera hides part of the floor (detected then, the floor was a
  // sliver of 0.15 m²). Each try's result is read from the API after its answer: the card
  // still shows the last one until the event comes.
  let area = 0;
  let tries = 0;
  const end = Date.now() + 240000;
  while (Date.now() < end) {
    const f = (await card('cam0')).frame % FRAMES;
    if (f < FLOOR_FROM || f >= FRAMES - 4) {
      await h.sleep(250);
      continue;
    }
    tries++;
    await Promise.all([
      p.waitForResponse((r) => r.url().endsWith('/api/calibration/floor') && r.request().method() === 'POST',
        { timeout: 30000 }),
      p.click(`${cardOf('cam0')} [data-testid="cam-detect-floor"]`),
    ]);
    const en = (await api('/api/calibration')).cameras.find((c) => c.name === 'cam0').enclosure;
    area = en?.from === 'green floor' ? en.area_m2 : 0;
    if (area > 0.6 && area < 0.97) break;
    await h.sleep(700);
  }
  measured.floor_m2 = Number(area.toFixed(3));
  measured.floor_tries = tries;
  assert.ok(area > 0.6 && area < 0.97, `floor area ${area} m² (truth 0.96 m², the near wall hides a strip)`);
  await h.waitFor('the card shows it', async () => Number((await card('cam0')).floorArea.split(' ')[0]) === Number(area.toFixed(2)));
});

test('save: both joint models written; cam1 from cam0 and each pose against the truth', async () => {
  await h.waitFor('save offered', async () => !(await p.isDisabled('[data-testid="calib-save"]')), { timeout: 30000 });
  await p.click('[data-testid="calib-save"]');
  await p.waitForSelector('[data-testid="calib-saved"]:not([hidden])', { timeout: 60000 });
  const files = await p.$$eval('[data-testid="saved-file"]', (l) => l.map((e) => e.dataset.path));
  const want = CAMERAS.map((n) => path.join(cfg.dir, 'calibration', `${n}.cameramodel`));
  assert.deepEqual([...files].sort(), want);
  await h.waitFor('the page saying the station uses them', async () => /now uses them/.test(await h.text(p, 'saved-station')),
    { timeout: 30000 });
  const yaml = fs.readFileSync(cfg.file, 'utf8');
  for (const f of want) assert.ok(yaml.includes(f), `the config names ${f}`);
  assert.match(yaml, /^enclosure:\n\s+floor:/m, `the config's enclosure:\n${yaml}`);

  const got = Object.fromEntries(CAMERAS.map((n, i) => [n, readModel(want[i])]));
  const err = Object.fromEntries(CAMERAS.map((n) => [n, poseError(got[n], truth[n])]));
  const rs = relative(got.cam0, got.cam1);
  const rt = relative(truth.cam0, truth.cam1);
  err.relative = { mm: Math.hypot(...[0, 1, 2].map((i) => rs.t[i] - rt.t[i])) * 1000, deg: angleDeg(mul(rs.R, transpose(rt.R))) };
  measured.against_truth = JSON.parse(JSON.stringify(err, (k, v) => (typeof v === 'number' ? Number(v.toPrecision(3)) : v)));
  // Issue 41's goal is 2 mm / 0.05° (met by calib_tests' SolveJointRig from 20 shared instants).
  // This session's 90 s give the console 3 to 10 places both cameras saw: measured 1.3-3.8 mm,
  // 0.03-0.14° (bench/calib_rig/console_rig.py on 120 s: 1.2 mm, 0.07°). The bars catch a rig
  // composed wrongly (degrees, centimetres), not the few places' noise.
  assert.ok(err.relative.mm < 8 && err.relative.deg < 0.3, `cam1 from cam0: ${JSON.stringify(err.relative)}`);
  for (const n of CAMERAS) {
    assert.ok(err[n].centre_mm < 10 && err[n].rotation_deg < 0.4, `${n} against the truth: ${JSON.stringify(err[n])}`);
  }
  // Where each saved model sees the floor against where the true camera does (what a sprite's
  // place rests on; a pose alone is no measure, its error trades off against the intrinsics'):
  // RMS pixels over a 10 cm grid of the floor's middle, 1 m x 0.6 m, the points in the image.
  measured.floor_px = {};
  for (const n of CAMERAS) {
    let sum = 0;
    let count = 0;
    for (let x = -0.5; x <= 0.5001; x += 0.1) {
      for (let y = -0.3; y <= 0.3001; y += 0.1) {
        const [u, v] = project(truth[n], [x, y, 0]);
        if (!(u >= 0 && v >= 0 && u < 640 && v < 480)) continue;
        const [a, b] = project(got[n], [x, y, 0]);
        sum += (a - u) ** 2 + (b - v) ** 2;
        count++;
      }
    }
    measured.floor_px[n] = Number(Math.sqrt(sum / count).toPrecision(3));
    assert.ok(count > 20 && measured.floor_px[n] < 2, `${n}: the floor ${measured.floor_px[n]} px off (${count} points)`);
  }
  await h.sleep(300);
  await h.screenshot(p, 'console-calibrate-rig-saved.png');
});

test('started again on a hamster before the same cameras, the station stores sprites', async () => {
  await station.stop();
  const yaml = fs.readFileSync(cfg.file, 'utf8');
  assert.ok(yaml.split(dir).length === 3, `the config's two sessions:\n${yaml}`);
  fs.writeFileSync(cfg.file, yaml.split(dir).join(animal));
  station = await h.daemon('rig-hamster', cfg, ['--no-transitions']);
  const status = await h.waitFor('both cameras live, with model and floor', async () => {
    const s = await api('/api/status');
    return s.cameras.every((c) => c.state === 'live' && c.has_model && c.has_floor) && s;
  }, { timeout: 30000, interval: 250 });
  assert.equal(status.cameras.length, 2);
  await p.goto(`${station.url}/`);
  await p.fill('[data-testid="session-name"]', 'after calibration');
  await p.click('[data-testid="session-start"]');
  await h.waitFor('session active', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'active');
  const own = `SELECT DISTINCT c.name FROM sprites s JOIN cameras c ON c.id = s.camera_id
    WHERE c.session_id = (SELECT max(id) FROM sessions) AND s.mirrored = 0 ORDER BY c.name`;
  await h.waitFor('sprites stored from both cameras', async () =>
    (await h.num(p, 'session-sprites')) > 0 && h.sql(cfg.bank, own) === CAMERAS.join('\n'), { timeout: 60000, interval: 500 });
  await p.click('[data-testid="session-stop"]');
  await h.waitFor('session idle', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'idle', { timeout: 20000 });
  measured.sprites = Number(h.sql(cfg.bank, 'SELECT count(*) FROM sprites WHERE mirrored = 0'));
  assert.deepEqual(p.errors, []);
});
