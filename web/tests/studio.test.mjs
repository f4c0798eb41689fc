// The studio page (studio.html): a person composes the seed paper's circle scene with the mouse
// on the floor plan, runs it on the station's bank, watches the cost fall, reads the judge and
// plays the render; the spec the page wrote is one `spritestation animate` runs as it is. A spec
// the station refuses is named in the message bar by its line and field; a long run is
// cancelled. The harness's 6 s session ingested into the daemon's bank first (as the labelling
// test does), with 20 frames tagged `standing` for the frames constraint.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import * as h from './harness.mjs';

const R = 0.2; // the circle's radius, metres
let s, cfg, station, b, p, inputs, centre;
const t0 = Date.now();

before(async () => {
  s = h.session(12);
  cfg = h.config('studio', s, [{ name: 'cam0', source: 'replay', session: s.dir, session_camera: 'cam0', loop: true }],
    { pipeline: { px_per_m: 240 } });
  const ingest = JSON.parse(h.run(['ingest', s.dir, '--bank', cfg.bank, '--config', cfg.file, '--json']));
  assert.ok(ingest.transitions_stored > 0, `ingest stored transitions: ${JSON.stringify(ingest)}`);
  // The last 20 frames of the longest clip (and their mirrored copies) stand.
  const ids = h.sql(cfg.bank, 'SELECT id FROM sprites WHERE clip_id = (SELECT clip_id FROM sprites GROUP BY clip_id ' +
    'ORDER BY count(*) DESC LIMIT 1) ORDER BY frame DESC LIMIT 40').split('\n');
  h.run(['bank', 'tag', cfg.bank, '--tag', 'standing', '--sprites', ids.join(',')]);
  // The empty enclosure beside the bank: the station offers it as a background.
  h.run(['plate', s.dir, '--camera', 'cam0', '--out', path.join(cfg.dir, 'plate-cam0.png')]);
  station = await h.daemon('studio', cfg);
  inputs = await (await fetch(`${station.url}/api/animations/inputs`)).json();
  assert.ok(inputs.enclosure.length > 2, `the enclosure: ${JSON.stringify(inputs)}`);
  assert.ok(inputs.tags.includes('standing'), `the bank's tags: ${JSON.stringify(inputs.tags)}`);
  const n = inputs.enclosure.length;
  centre = inputs.enclosure.reduce(([x, y], [a, c]) => [x + a / n, y + c / n], [0, 0]);
  console.log(`# studio: session, bank and daemon ready in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  b = await h.browser();
  p = await h.page(b);
  await p.goto(`${station.url}/studio.html`);
  await p.waitForSelector('[data-testid="camera"] option', { state: 'attached', timeout: 10000 });
});

after(async () => {
  console.log(`# studio: ${((Date.now() - t0) / 1000).toFixed(1)} s in all`);
  await b?.close();
  await station?.stop();
});

const messageText = () => p.textContent('[data-testid="message-text"]').catch(() => '');
const jobState = () => p.getAttribute('[data-testid="job-state"]', 'data-state');
const specText = () => p.inputValue('[data-testid="spec-text"]');
const parseSpec = (text) => JSON.parse(text.split('\n').filter((l) => !l.startsWith('#')).join('\n'));
const jobId = async () => Number((await h.text(p, 'job-id')).replace('#', ''));
const api = async (url) => (await fetch(`${station.url}${url}`)).json();

// The page position of ground point (x, y): the plan canvas says where ground (0, 0) is and
// how many pixels a metre is.
async function planPoint(x, y) {
  const d = await p.$eval('[data-testid="plan"]', (c) => ({ ...c.dataset, box: c.getBoundingClientRect().toJSON() }));
  return [d.box.x + Number(d.originX) + x * Number(d.pxPerM), d.box.y + Number(d.originY) - y * Number(d.pxPerM)];
}

async function clickGround(x, y) {
  const [px, py] = await planPoint(x, y);
  await p.mouse.click(px, py);
}

// A real mouse click in the middle of an element (a selector, or a data-testid).
async function clickAt(what) {
  const sel = /^[\w-]+$/.test(what) ? `[data-testid="${what}"]` : what;
  const box = await p.$eval(sel, (e) => e.getBoundingClientRect().toJSON());
  await p.mouse.click(box.x + box.width / 2, box.y + box.height / 2);
}

async function type(testid, value) {
  await p.fill(`[data-testid="${testid}"]`, value);
  await p.press(`[data-testid="${testid}"]`, 'Tab');
}

test('a spec the station refuses is named by its line and field', async () => {
  await clickAt('tool-sprite');
  await clickGround(centre[0] + R, centre[1]);
  await clickAt('tool-path');
  for (let i = 1; i <= 8; i++) {
    const a = (i * 2 * Math.PI) / 8;
    await clickGround(centre[0] + R * Math.cos(a), centre[1] + R * Math.sin(a));
  }
  await type('time-budget', '0');
  await clickAt('run');
  const text = await h.waitFor("the API's words in the message bar", async () => {
    const t = await messageText();
    return /^spec:\d+: optimizer\.time_budget_s: /.test(t) && t;
  });
  // The line is the page's own text's.
  const line = Number(/^spec:(\d+):/.exec(text)[1]);
  assert.match((await specText()).split('\n')[line - 1], /"time_budget_s": 0/);
  assert.equal(await jobState(), 'idle');
  await clickAt('[data-testid="message"] button');
});

test('the circle composed with the mouse runs: cost curve, tracks, judge, player, saved', async () => {
  await type('time-budget', '5');
  await type('min-frames', '60');
  await type('max-frames', '150');
  // The sprite stands up at the end of its path.
  await p.check('[data-testid="frames-on"]');
  await p.selectOption('[data-testid="frames-tag"]', 'standing');
  await type('frames-duration', '1');

  const written = await specText();
  const spec = parseSpec(written);
  assert.equal(spec.banks[0], inputs.bank);
  assert.equal(spec.camera, inputs.cameras[0].model);
  assert.equal(spec.background, path.join(cfg.dir, 'plate-cam0.png'));
  const sprite = spec.sprites[0];
  assert.equal(sprite.name, 'hamster');
  const [path_, frames] = sprite.constraints.map((c) => c.path || c.frames);
  assert.equal(path_.points.length, 9, JSON.stringify(path_));
  for (const [x, y] of path_.points) {
    assert.ok(Math.abs(Math.hypot(x - centre[0], y - centre[1]) - R) < 0.006, `[${x}, ${y}] on the circle`);
  }
  assert.deepEqual(path_.points[0], sprite.start);
  assert.deepEqual([path_.distance_strength, path_.unreached_strength, path_.direction_strength], [200, 3000, 0.5]);
  assert.deepEqual(frames, { tag: 'standing', after_path: 'hamster', duration: 1, strength: 50 });
  assert.equal(spec.optimizer.time_budget_s, 5);

  const started = Date.now();
  await clickAt('run');
  await h.waitFor('the job to start', async () => ['queued', 'running'].includes(await jobState()), { timeout: 5000 });
  const id = await jobId();
  const states = new Set();
  await h.waitFor('two cost curve updates from the event stream while it runs', async () => {
    states.add(await jobState());
    return Number(await p.getAttribute('[data-testid="cost-curve"]', 'data-updates')) >= 2;
  }, { timeout: 15000 });
  assert.ok(states.has('running'), `the updates came while it ran (${[...states]})`);
  await h.waitFor('tracks on the plan', async () => Number(await p.getAttribute('[data-testid="plan"]', 'data-tracks')) >= 1,
    { timeout: 15000 });
  // the cost of each kind of term beside the total: the path's and the length's
  await p.waitForSelector('[data-testid="cost-kinds"] span[data-kind="path"]', { timeout: 15000 });
  await h.waitFor('the job done', async () => {
    const st = await jobState();
    if (st === 'failed' || st === 'cancelled') throw new Error(`job ${st}: ${await h.text(p, 'job-error')}`);
    return st === 'done';
  }, { timeout: 60000 });
  const seconds = (Date.now() - started) / 1000;
  const job = await api(`/api/animations/${id}`);

  // The judge's figures.
  await p.waitForSelector('[data-testid="judge"] tr[data-row="path"]', { timeout: 5000 });
  const rows = await p.$$eval('[data-testid="judge"] tr', (trs) => trs.map((r) => r.dataset.row));
  for (const r of ['length', 'path', 'deviation', 'frames', 'stutter']) assert.ok(rows.includes(r), `judge row ${r} in ${rows}`);
  const swept = (job.judge.paths[0].swept_share * 100).toFixed(1);
  assert.match(await p.textContent('[data-testid="judge"] tr[data-row="path"]'), new RegExp(`swept ${swept} %`));

  // The player: the rendered frames, the scrubber, the step's sprite.
  const natural = () => p.$eval('[data-testid="player"]', (i) => (i.complete ? i.naturalWidth : 0));
  await h.waitFor('the first frame shown', async () => (await natural()) > 0, { timeout: 10000 });
  const steps = job.sequences.sprites[0].steps;
  assert.equal(Number(await p.getAttribute('[data-testid="scrubber"]', 'max')), job.num_steps - 1);
  const firstSrc = await p.getAttribute('[data-testid="player"]', 'src');
  const bar = await p.$eval('[data-testid="scrubber"]', (e) => e.getBoundingClientRect().toJSON());
  await p.mouse.click(bar.x + bar.width * 0.7, bar.y + bar.height / 2);
  const t = await h.waitFor('the step info to follow the scrubber', async () => {
    const v = Number(await p.getAttribute('[data-testid="step-info"]', 'data-step'));
    return v > 0 && v;
  });
  assert.ok(Math.abs(t - 0.7 * (job.num_steps - 1)) <= 0.05 * job.num_steps + 1, `step ${t} of ${job.num_steps}`);
  const card = '[data-testid="step-sprite"][data-sprite="hamster"]';
  assert.equal(Number(await p.getAttribute(card, 'data-bank-sprite')), steps[Math.min(t, steps.length - 1)][1]);
  // A transition: not the next frame of the same clip (originals and mirrored copies apart).
  const row = (i) => h.sql(cfg.bank, `SELECT clip_id, frame, mirrored FROM sprites WHERE id = ${steps[i][1]}`).split('|').map(Number);
  const [a, c] = [row(t - 1), row(t)];
  const taken = !(a[0] === c[0] && a[2] === c[2] && c[1] === a[1] + 1);
  await h.waitFor('the step\'s transition said', async () => (await p.getAttribute(card, 'data-transition')) === (taken ? 'yes' : 'no'));
  await h.waitFor('the scrubbed frame shown', async () =>
    (await p.getAttribute('[data-testid="player"]', 'src')) !== firstSrc && (await natural()) > 0, { timeout: 10000 });
  // A click on the result's track with the select tool shows that step: the point furthest
  // from the step shown (a sprite that stays put has no other point to click).
  await clickAt('tool-select');
  const [tx, ty] = await planPoint(steps[Math.min(t, steps.length - 1)][2], steps[Math.min(t, steps.length - 1)][3]);
  const far = await Promise.all(steps.map(async ([, , x, y]) => {
    const [qx, qy] = await planPoint(x, y);
    return [Math.hypot(qx - tx, qy - ty), qx, qy];
  }));
  const [away, px, py] = far.reduce((a, v) => (v[0] > a[0] ? v : a));
  if (away > 12) {
    await p.mouse.click(px, py);
    await h.waitFor('the clicked track point\'s step', async () => {
      const v = Number(await p.getAttribute('[data-testid="step-info"]', 'data-step'));
      const [qx, qy] = await planPoint(steps[Math.min(v, steps.length - 1)][2], steps[Math.min(v, steps.length - 1)][3]);
      return Math.hypot(qx - px, qy - py) <= 8;
    });
  } else {
    console.log(`# studio: the track stays within ${away.toFixed(1)} px of step ${t}: no track point to click`);
  }
  // Play runs the frames on.
  await clickAt('play');
  const from = Number(await p.getAttribute('[data-testid="step-info"]', 'data-step'));
  await h.waitFor('the player to play', async () => Number(await p.getAttribute('[data-testid="step-info"]', 'data-step')) !== from,
    { timeout: 5000 });
  await clickAt('play');
  await h.waitFor('the paused step\'s sprite looked up in the bank', () => p.$eval(card, (c) =>
    c.dataset.transition !== undefined && c.querySelector('img').complete && c.querySelector('img').naturalWidth > 0));
  await h.screenshot(p, 'console-studio.png');

  // The saved runs list the job; its spec is what the page wrote, and `animate` runs it.
  const saved = `[data-testid="saved-job"][data-job="${id}"]`;
  await p.waitForSelector(`${saved}[data-state="done"]`, { timeout: 5000 });
  const href = await p.getAttribute(`${saved} [data-testid="saved-spec"]`, 'href');
  const savedText = await (await fetch(`${station.url}${href}`)).text();
  assert.equal(savedText, written);
  const dir = path.join(h.WORK, 'studio');
  fs.writeFileSync(path.join(dir, 'saved-spec.yaml'), savedText);
  const out = path.join(dir, 'from-saved.json');
  h.run(['animate', path.join(dir, 'saved-spec.yaml'), '--out', out, '--max-turns', '20', '--no-judge']);
  assert.deepEqual(JSON.parse(fs.readFileSync(out, 'utf8')).sprites.map((x) => x.name), ['hamster']);
  // A click on the saved run loads its spec back onto the plan, unchanged.
  await type('time-budget', '7');
  assert.notEqual(await specText(), written);
  await clickAt(`${saved} .saved-head b`);
  await h.waitFor('the saved spec loaded', async () => (await specText()) === written);
  assert.equal(await p.getAttribute('[data-testid="plan"]', 'data-path-points'), '8');
  console.log(`# studio: job ${id} ${seconds.toFixed(1)} s from Run to done (budget 5 s, ${job.num_steps} steps), ` +
    `swept ${swept} %, ${job.judge.jumps.transitions} transitions`);
  assert.deepEqual(p.errors, []);
});

test('a long run is cancelled within 2 s', async () => {
  await type('time-budget', '60');
  await clickAt('run');
  await h.waitFor('the long job running', async () => (await jobState()) === 'running', { timeout: 10000 });
  const id = await jobId();
  const clicked = Date.now();
  await clickAt('cancel');
  await h.waitFor('the state to read cancelled', async () => (await jobState()) === 'cancelled', { timeout: 2000, interval: 50 });
  const ms = Date.now() - clicked;
  await p.waitForSelector(`[data-testid="saved-job"][data-job="${id}"][data-state="cancelled"]`, { timeout: 5000 });
  assert.equal((await api(`/api/animations/${id}`)).state, 'cancelled');
  console.log(`# studio: cancelled in ${ms} ms`);
  assert.deepEqual(p.errors, []);
});

test('a YAML spec from docs/examples loads onto the plan', async () => {
  const yaml = fs.readFileSync(path.join(h.REPO, 'docs/examples/standup.yaml'), 'utf8');
  await p.fill('[data-testid="spec-text"]', yaml);
  await clickAt('load-spec');
  await h.waitFor('the example on the plan', async () => {
    try {
      return parseSpec(await specText()).sprites.length === 2;
    } catch {
      return false;
    }
  });
  const spec = parseSpec(await specText());
  assert.deepEqual(spec.sprites.map((x) => x.name), ['leader', 'follower']);
  const leader = spec.sprites[0].constraints.find((c) => c.path).path;
  assert.deepEqual(leader.points, [[-0.4, -0.25], [-0.15, -0.05], [0.05, 0.0], [0.25, 0.12]]);
  // what the page does not draw (the follower's `follow`) is kept as it was
  assert.deepEqual(spec.sprites[1].constraints.find((c) => c.location).location,
    { follow: 'leader', offset: [-0.15, 0.12], offset_axes: 'heading', strength: 20 });
  assert.equal(spec.optimizer.time_budget_s, 60);
  // YAML that is not a spec is named by its line
  await p.fill('[data-testid="spec-text"]', 'version: 1\nsprites: [1, 2\n');
  await clickAt('load-spec');
  await h.waitFor('the YAML error in the message bar', async () => /^load: spec:\d+: not valid YAML/.test(await messageText()));
  await clickAt('[data-testid="message"] button');
  assert.deepEqual(p.errors, []);
});
