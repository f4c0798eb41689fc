// The console against a live station: two emulated GigE cameras (fakecam on
// 127.0.0.1 and 127.0.0.2) and one replayed camera, as an operator uses it.
// The tests run in order on one daemon: what a later one reads (the stored
// session) an earlier one made.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import * as h from './harness.mjs';

const CAMERAS = ['cam0', 'cam1', 'cam2'];
let s, cfg, station, cams, b, p;
const SESSION_NAME = 'web test take';

before(async () => {
  s = h.session();
  cams = {
    cam0: await h.fakecam(s, 'cam0', '127.0.0.1'),
    cam1: await h.fakecam(s, 'cam1', '127.0.0.2'),
  };
  cfg = h.config('station', s, [
    { name: 'cam0', source: 'aravis', address: '127.0.0.1', model: path.join(s.dir, 'cam0.cameramodel') },
    { name: 'cam1', source: 'aravis', address: '127.0.0.2', model: path.join(s.dir, 'cam1.cameramodel') },
    { name: 'cam2', source: 'replay', session: s.dir, session_camera: 'cam0', loop: true },
  ]);
  station = await h.daemon('station', cfg, ['--offline-after', '1.5', '--replay-dir', s.root]);
  b = await h.browser();
  p = await h.page(b);
  await p.goto(`${station.url}/`);
});

after(async () => {
  await b?.close();
  await station?.stop();
  for (const c of Object.values(cams || {})) await c.kill();
});

// Pixel statistics of a tile's canvas: the share of green-screen pixels and,
// per named colour, how many pixels are close to it.
function canvasStats(camera, colours = {}) {
  return p.$eval(`[data-testid="tile"][data-camera="${camera}"] [data-testid="tile-canvas"]`, (c, colours) => {
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    const rgb = Object.fromEntries(Object.entries(colours).map(([k, hex]) => [k, [1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16))]));
    const near = Object.fromEntries(Object.keys(rgb).map((k) => [k, 0]));
    let green = 0;
    let sum = 0;
    for (let i = 0; i < d.length; i += 4) {
      const [r, g, bl] = [d[i], d[i + 1], d[i + 2]];
      if (g > r + 40 && g > bl + 40) green++;
      sum = (sum * 31 + r + g * 7 + bl * 13) % 1000000007;
      for (const [k, [cr, cg, cb]] of Object.entries(rgb)) if (Math.abs(r - cr) + Math.abs(g - cg) + Math.abs(bl - cb) < 70) near[k]++;
    }
    return { green: green / (d.length / 4), near, hash: sum, width: c.width, height: c.height };
  }, colours);
}

// The preview requests of each camera from now on (`seen`, until stop()); each(names) waits
// until every one of them fetched one, and stops. A loaded machine (CI runs the QEMU tests
// beside this one) serves a preview in seconds rather than in milliseconds: the rate limits are
// asserted over a window, and that previews flow by waiting for them, naming what a stalled
// tile says.
function previewsFrom() {
  const seen = {};
  const on = (r) => {
    const m = /\/api\/cameras\/([^/]+)\/(preview\.jpg|sprites\.json)/.exec(r.url());
    if (m) seen[m[1]] = (seen[m[1]] || 0) + 1;
  };
  p.on('request', on);
  const stop = () => p.off('request', on);
  return {
    seen,
    stop,
    async each(names, when) {
      try {
        await h.waitFor(`a preview of each of ${names.join(', ')} ${when}`, () => names.every((n) => seen[n] > 0), { timeout: 8000, interval: 100 });
      } catch (err) {
        const said = await Promise.all(names.map(async (n) => `${n}: ${seen[n] || 0} (${await p.textContent(`[data-camera="${n}"] [data-testid="tile-message"]`).catch(() => '?')})`));
        throw new Error(`${err.message}; previews ${said.join(', ')}`);
      } finally {
        stop();
      }
    },
  };
}

// Preview requests per camera during `ms` milliseconds.
async function previewRate(ms) {
  const counter = previewsFrom();
  await h.sleep(ms);
  counter.stop();
  return counter.seen;
}

async function waitLive(names, timeout = 60000) {
  return h.waitFor(`tiles ${names.join(', ')} live`, async () => {
    const t = await h.tiles(p);
    return names.every((n) => t[n]?.state === 'live' && t[n]?.frame !== null) && t;
  }, { timeout });
}

async function framesAdvance(names) {
  const first = await h.tiles(p);
  return h.waitFor(`frame numbers of ${names.join(', ')} to advance`, async () => {
    const t = await h.tiles(p);
    return names.every((n) => t[n].frame !== null && first[n].frame !== null && t[n].frame > first[n].frame + 5) && t;
  }, { timeout: 6000 });
}

test('every camera is a live tile whose frame number advances', async () => {
  await waitLive(CAMERAS);
  assert.deepEqual(Object.keys(await h.tiles(p)).sort(), CAMERAS);
  await framesAdvance(CAMERAS);
  assert.equal(await p.getAttribute('[data-testid="connection"]', 'data-state'), 'connected');
  // at most 10 previews a second a tile, and each tile keeps asking (a preview can take
  // seconds on a loaded machine: the lower bound waits, the upper bound is the window's)
  const counter = previewsFrom();
  await h.sleep(2000);
  for (const n of CAMERAS) assert.ok((counter.seen[n] || 0) <= 21, `${n}: ${counter.seen[n]} previews in 2 s`);
  await counter.each(CAMERAS, 'while live');
  // the exposure aid: a histogram of the green screen with its figures
  const fig = await h.text(p, 'tile-uniformity');
  assert.match(fig, /^\d\.\d\d$/, 'green uniformity shown');
  assert.match(await h.text(p, 'tile-clipped'), /%$/);
  // the charts draw the samples the event stream sends
  await h.waitFor('chart samples', async () => Number(await p.getAttribute('[data-testid="charts"]', 'data-samples')) >= 2);
  assert.deepEqual(p.errors, []);
});

test('keyed and sprites views change the image; sprites outlines the animal', async () => {
  const tile = '[data-testid="tile"][data-camera="cam0"]';
  const VERDICTS = await p.evaluate(async () => (await import('/js/draw.js')).VERDICT_COLOURS);
  const raw = await canvasStats('cam0', VERDICTS);
  assert.ok(raw.green > 0.1, `the raw view shows the green screen (green share ${raw.green})`);

  await p.click(`${tile} [data-testid="view-keyed"]`);
  const keyed = await h.waitFor('the keyed image', async () => {
    const st = await canvasStats('cam0');
    return st.green < raw.green / 10 && st;
  });
  assert.ok(keyed.hash !== raw.hash);

  await p.click(`${tile} [data-testid="view-sprites"]`);
  // The animal walks 4 of each 6 s: wait for a frame with candidates, and for
  // pixels of their verdict's colour where the raw frame had none.
  const drawn = await h.waitFor('outlines drawn in the sprites view', async () => {
    const verdicts = (await p.getAttribute(tile, 'data-verdicts')) || '';
    const n = Number(await p.getAttribute(tile, 'data-candidates'));
    if (!n || !verdicts) return false;
    const colours = Object.fromEntries(verdicts.split(',').filter((v) => VERDICTS[v]).map((v) => [v, VERDICTS[v]]));
    const st = await canvasStats('cam0', colours);
    return Object.entries(st.near).some(([v, k]) => k > raw.near[v] + 30) && { n, verdicts, st };
  }, { timeout: 20000, interval: 200 });
  assert.ok(drawn.n > 0);
  assert.ok(drawn.st.green > 0.1, 'the sprites view draws over the raw image');

  await p.click(`[data-testid="tile"][data-camera="cam1"] [data-testid="view-keyed"]`);
  await h.waitFor('cam1 keyed', async () => (await canvasStats('cam1')).green < 0.01);
  await h.sleep(1200);
  await h.screenshot(p, 'console-station.png');
  await p.click(`${tile} [data-testid="view-raw"]`);
  await p.click(`[data-testid="tile"][data-camera="cam1"] [data-testid="view-raw"]`);
});

test('a hidden tab fetches no preview, and streams again when shown', async () => {
  const setHidden = (hidden) => p.evaluate((hidden) => {
    Object.defineProperty(document, 'hidden', { configurable: true, get: () => hidden });
    Object.defineProperty(document, 'visibilityState', { configurable: true, get: () => (hidden ? 'hidden' : 'visible') });
    document.dispatchEvent(new Event('visibilitychange'));
  }, hidden);
  await setHidden(true);
  await h.sleep(400); // requests in flight finish
  const hiddenRate = await previewRate(1500);
  const shown = previewsFrom();
  await setHidden(false);
  assert.deepEqual(hiddenRate, {}, 'no preview while hidden');
  await shown.each(CAMERAS, 'once shown');
});

test('a killed camera goes offline within 5 s, and streams again when restarted', async () => {
  const previews = [];
  const onRequest = (r) => {
    if (r.url().includes('/api/cameras/cam1/')) previews.push(Date.now());
  };
  await waitLive(['cam1']);
  await cams.cam1.kill('SIGKILL');
  const killed = Date.now();
  await h.waitFor('cam1 offline', async () => (await h.tiles(p)).cam1.state === 'offline', { timeout: 5000, interval: 50 });
  const offlineAfter = Date.now() - killed;
  assert.ok(offlineAfter <= 5000, `offline after ${offlineAfter} ms`);
  assert.equal(await p.getAttribute('[data-camera="cam1"] [data-testid="tile-state"]', 'data-state'), 'offline');
  // an offline tile fetches no preview; the others stream on
  await h.sleep(300);
  p.on('request', onRequest);
  const others = await framesAdvance(['cam0', 'cam2']);
  p.off('request', onRequest);
  assert.ok(others.cam1.state === 'offline');
  assert.equal(previews.length, 0, 'no preview fetched for the offline camera');

  const lastFrame = others.cam1.frame;
  cams.cam1 = await h.fakecam(s, 'cam1', '127.0.0.2');
  // reopened with backoff (0.5 s doubling): its tile leaves offline and shows
  // new frames (the restarted camera numbers them from its own start again)
  await h.waitFor('cam1 reopened', async () => (await h.tiles(p)).cam1.state !== 'offline', { timeout: 30000, interval: 200 });
  await h.waitFor('a new frame of cam1', async () => (await h.tiles(p)).cam1.frame !== lastFrame, { timeout: 5000 });
  await framesAdvance(['cam1']);
});

// Its keyer learnt the enclosure before the kill: reopened, it is live at once.
test('the restarted camera is live again', async () => {
  await waitLive(['cam1'], 20000);
});

let stoppedCount;
test('start then stop stores sprites, and the page shows what the bank holds', async () => {
  // the API's refusal is shown in its own words
  await p.fill('[data-testid="session-name"]', 'bad/name');
  await p.click('[data-testid="session-start"]');
  const refused = await h.waitFor('the error message', async () => (await p.isVisible('[data-testid="message"]')) &&
    (await p.getAttribute('[data-testid="message"]', 'data-kind')) === 'error' && h.text(p, 'message-text'));
  assert.match(refused, /^name: /);
  assert.equal(await p.getAttribute('[data-testid="session-state"]', 'data-state'), 'idle');

  await p.fill('[data-testid="session-name"]', 'web first name');
  await p.click('[data-testid="session-start"]');
  await h.waitFor('session active', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'active');
  assert.equal(await h.text(p, 'session-current-name'), 'web first name');
  await p.fill('[data-testid="session-name"]', SESSION_NAME);
  await p.click('[data-testid="session-rename"]');
  await h.waitFor('the new name', async () => (await h.text(p, 'session-current-name')) === SESSION_NAME);
  // the elapsed time ticks on the page
  const e0 = await h.text(p, 'session-elapsed');
  await h.waitFor('elapsed time to tick', async () => (await h.text(p, 'session-elapsed')) !== e0, { timeout: 3000 });
  // while a session runs, previews back off to 2 a second a tile
  await h.sleep(600);
  const rate = await previewRate(4000);
  for (const n of CAMERAS) assert.ok((rate[n] || 0) <= 10, `${n}: ${rate[n]} previews in 4 s while a session runs`);
  const running = previewsFrom();
  await running.each(CAMERAS, 'while a session runs');
  await h.waitFor('sprites stored', async () => (await h.num(p, 'session-sprites')) > 20, { timeout: 20000, interval: 250 });
  // the station keeps the transitions current while the session runs: the session goes on
  // until one joins two of its sprites (a later test opens it); the footage loops every 6 s
  const own = `SELECT s.id FROM sprites s JOIN cameras c ON c.id = s.camera_id
    WHERE c.session_id = (SELECT max(id) FROM sessions) AND s.mirrored = 0`;
  await h.waitFor('a transition between two sprites of the session', () => Number(h.sql(cfg.bank,
    `SELECT count(*) FROM transitions WHERE from_sprite IN (${own}) AND to_sprite IN (${own})`)) > 0,
  { timeout: 40000, interval: 500 });
  await h.sleep(1000);
  await p.click('[data-testid="session-stop"]');
  await h.waitFor('session idle', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'idle', { timeout: 20000 });
  const msg = await h.waitFor('the stop message', async () => (await h.text(p, 'message-text'))?.match(/stopped: ([\d,]+) sprites stored/));
  stoppedCount = Number(msg[1].replace(/,/g, ''));

  const id = Number(h.sql(cfg.bank, `SELECT max(id) FROM sessions WHERE name = '${SESSION_NAME}'`));
  assert.ok(id > 0, 'the session is in the bank');
  const inSession = Number(h.sql(cfg.bank,
    `SELECT count(*) FROM sprites s JOIN clips k ON k.id = s.clip_id JOIN cameras c ON c.id = k.camera_id
     WHERE c.session_id = ${id} AND k.complete = 1 AND s.mirrored = 0`));
  assert.ok(inSession > 0, 'sprites stored');
  const info = h.bankInfo(cfg.bank);
  await h.waitFor(`the page's bank count (${info.sprites})`, async () => (await h.num(p, 'bank-sprites')) === info.sprites, { timeout: 3000 });
  await h.waitFor(`the page's session count (${inSession})`, async () => (await h.num(p, 'session-sprites')) === inSession, { timeout: 3000 });
  assert.equal(stoppedCount, inSession);
});

// True once every billboard cell under `scope` that is in view has loaded its image; else
// throws naming those that have not (not requested yet, or the error the page shows).
async function billboardsInView(page, scope) {
  const missing = await page.$$eval(`${scope} [data-testid="sprite-cell"]`, (cells) => cells.filter((c) => {
    // seen: inside the window and inside every box that scrolls it (the filmstrip and the
    // clips panel): a cell scrolled above the panel but still below the window's top is hidden
    const r = c.getBoundingClientRect();
    let box = { left: r.left, right: r.right, top: r.top, bottom: r.bottom };
    const clip = (o) => {
      box = { left: Math.max(box.left, o.left), right: Math.min(box.right, o.right),
        top: Math.max(box.top, o.top), bottom: Math.min(box.bottom, o.bottom) };
    };
    for (let e = c.parentElement; e && e !== document.body; e = e.parentElement) {
      if (getComputedStyle(e).overflow !== 'visible') clip(e.getBoundingClientRect());
    }
    clip({ left: 0, right: innerWidth, top: 0, bottom: innerHeight });
    const inView = box.right > box.left && box.bottom > box.top;
    return inView && c.dataset.loaded !== '1';
  }).map((c) => `sprite ${c.dataset.sprite}: ${c.dataset.loaded ?? 'not requested'} ${c.querySelector('img').alt}`));
  if (missing.length) throw new Error(`${missing.length} in view not loaded: ${missing.slice(0, 5).join('; ')}`);
  return true;
}

test("the bank page shows the session's clips as filmstrips, and a tag set there is in the bank", async () => {
  const id = Number(h.sql(cfg.bank, `SELECT max(id) FROM sessions WHERE name = '${SESSION_NAME}'`));
  const bp = await h.page(b);
  await bp.goto(`${station.url}/bank.html`);
  await bp.click(`[data-testid="bank-session"][data-session="${id}"]`);
  const clips = h.sql(cfg.bank,
    `SELECT k.id, (SELECT count(*) FROM sprites s WHERE s.clip_id = k.id AND s.mirrored = 0)
     FROM clips k JOIN cameras c ON c.id = k.camera_id WHERE c.session_id = ${id} AND k.complete = 1 ORDER BY k.id`)
    .split('\n').map((l) => l.split('|').map(Number));
  assert.ok(clips.length > 0);
  await h.waitFor('the clips', async () => (await bp.$$('[data-testid="clip"]')).length === clips.length);
  for (const [clip, n] of clips) {
    const sel = `[data-testid="clip"][data-clip="${clip}"]`;
    await bp.$eval(sel, (e) => e.scrollIntoView());
    await h.waitFor(`clip ${clip}'s ${n} sprites`, async () => (await bp.$$(`${sel} [data-testid="sprite-cell"]`)).length === n);
    // scroll the filmstrip through as a person does, half a view at a time, each view
    // looked at until its billboards are in: every billboard loads as an image
    const strip = `${sel} [data-testid="filmstrip"]`;
    for (let x = 0; ; ) {
      const view = await bp.$eval(strip, (e, left) => {
        // the strip kept in the window: clips above it that load their images push it down
        // (a cell below the window is neither requested by the page nor looked at here)
        e.scrollIntoView({ block: 'nearest' });
        e.scrollLeft = left;
        return { width: e.clientWidth, end: e.scrollWidth };
      }, x);
      // (45 s: CI's two cores also run Chromium, the daemon's capture and two cameras, and the
      // HTTP threads yield to capture)
      await h.waitFor(`clip ${clip}'s billboards in view at ${x} px`, () => billboardsInView(bp, sel), { timeout: 45000 });
      if (x + view.width >= view.end) break;
      x += Math.max(1, Math.floor(view.width / 2));
    }
    await h.waitFor(`clip ${clip}'s ${n} billboards`, async () => {
      const missing = await bp.$$eval(`${sel} [data-testid="sprite-cell"]`, (cells) => cells
        .filter((c) => !(c.querySelector('img').complete && c.querySelector('img').naturalWidth > 0))
        .map((c) => `sprite ${c.dataset.sprite}: ${c.dataset.loaded ?? 'not requested'} ${c.querySelector('img').alt}`));
      if (missing.length) throw new Error(`${missing.length} not shown: ${missing.slice(0, 5).join('; ')}`);
      return true;
    }, { timeout: 45000 });
  }

  // tag a run of frames (the 2nd to the 6th) of the longest clip as "stand"
  const [clip, n] = clips.reduce((a, c) => (c[1] > a[1] ? c : a));
  assert.ok(n >= 3, `a clip of ${n} sprites`);
  const lo = 1;
  const hi = Math.min(5, n - 1);
  const cells = `[data-testid="clip"][data-clip="${clip}"] [data-testid="sprite-cell"]`;
  await bp.$eval(`[data-testid="clip"][data-clip="${clip}"]`, (e) => e.scrollIntoView());
  await bp.$eval(`[data-testid="clip"][data-clip="${clip}"] [data-testid="filmstrip"]`, (e) => (e.scrollLeft = 0));
  await bp.locator(cells).nth(lo).click();
  await bp.locator(cells).nth(hi).click({ modifiers: ['Shift'] });
  assert.equal(await bp.getAttribute('[data-testid="bank-selection"]', 'data-count'), String(hi - lo + 1));
  const first = Number(await bp.locator(cells).nth(lo).getAttribute('data-frame'));
  const last = Number(await bp.locator(cells).nth(hi).getAttribute('data-frame'));
  await bp.fill('[data-testid="tag-input"]', 'stand');
  await bp.click('[data-testid="tag-apply"]');
  await h.waitFor('the tag on the filmstrip', async () =>
    (await bp.locator(cells).evaluateAll((e) => e.filter((c) => c.dataset.tags.split(',').includes('stand')).length)) === hi - lo + 1);
  await h.waitFor('the tag count on the clip', async () =>
    (await bp.textContent(`[data-testid="clip"][data-clip="${clip}"] [data-testid="clip-tags"]`)) === `stand ${hi - lo + 1}`);
  const tagged = h.sql(cfg.bank,
    `SELECT s.frame FROM sprite_tags t JOIN sprites s ON s.id = t.sprite_id
     WHERE t.tag = 'stand' AND s.clip_id = ${clip} AND s.mirrored = 0 ORDER BY s.frame`).split('\n').map(Number);
  const expected = h.sql(cfg.bank,
    `SELECT frame FROM sprites WHERE clip_id = ${clip} AND mirrored = 0 AND frame BETWEEN ${first} AND ${last} ORDER BY frame`)
    .split('\n').map(Number);
  assert.equal(expected.length, hi - lo + 1);
  assert.deepEqual(tagged, expected);

  // the clip's export, fetched with the page's credentials and saved
  const [download] = await Promise.all([
    bp.waitForEvent('download'),
    bp.click(`[data-testid="clip"][data-clip="${clip}"] [data-testid="clip-export"]`),
  ]);
  const csv = fs.readFileSync(await download.path(), 'utf8').trim().split('\n');
  assert.match(csv[0], /^id,clip_id,/);
  assert.equal(csv.length - 1, Number(h.sql(cfg.bank, `SELECT count(*) FROM sprites WHERE clip_id = ${clip}`)), 'a row a sprite');
  assert.ok(csv.filter((l) => l.includes('stand')).length >= hi - lo + 1, 'the tags in the export');

  // the detail of the last sprite clicked, as the bank has it
  const sprite = Number(await bp.locator(cells).nth(hi).getAttribute('data-sprite'));
  await h.waitFor('the detail panel', async () => (await bp.getAttribute('[data-testid="sprite-detail"]', 'data-sprite')) === String(sprite));
  const [frame, camera] = h.sql(cfg.bank, `SELECT s.frame, c.name FROM sprites s JOIN cameras c ON c.id = s.camera_id WHERE s.id = ${sprite}`).split('|');
  assert.equal(await h.text(bp, 'detail-frame'), frame);
  assert.equal(await h.text(bp, 'detail-camera'), camera);
  assert.match(await h.text(bp, 'detail-tags'), /stand/);
  assert.deepEqual(bp.errors, []);
  await bp.close();
});

test("a sprite's detail lists its transitions; clicking one shows that sprite", async () => {
  const id = Number(h.sql(cfg.bank, `SELECT max(id) FROM sessions WHERE name = '${SESSION_NAME}'`));
  const inSession = `SELECT s.id FROM sprites s JOIN cameras c ON c.id = s.camera_id WHERE c.session_id = ${id} AND s.mirrored = 0`;
  // the transition worker finds them on its own thread, after the clips are stored, below the
  // console in CPU priority (60 s: on CI it shares two cores with Chromium and capture)
  const from = Number(await h.waitFor('a stored transition', () => h.sql(cfg.bank,
    `SELECT t.from_sprite FROM transitions t WHERE t.from_sprite IN (${inSession}) AND t.to_sprite IN (${inSession})
     GROUP BY t.from_sprite ORDER BY count(*) DESC LIMIT 1`), { timeout: 60000, interval: 500 }));
  const out = h.sql(cfg.bank, `SELECT to_sprite, cost FROM transitions WHERE from_sprite = ${from} ORDER BY cost, to_sprite LIMIT 50`)
    .split('\n').map((l) => l.split('|').map(Number));
  const bp = await h.page(b);
  await bp.goto(`${station.url}/bank.html#session=${id}&sprite=${from}`);
  await h.waitFor('the detail', async () => (await bp.getAttribute('[data-testid="sprite-detail"]', 'data-sprite')) === String(from));
  const rows = await bp.$$eval('[data-testid="transitions-out"] [data-testid="transition"]', (r) => r.map((e) => Number(e.dataset.sprite)));
  assert.deepEqual(rows.slice().sort((a, c) => a - c), out.map(([to]) => to).sort((a, c) => a - c), 'the transitions out the bank holds');
  const costs = await bp.$$eval('[data-testid="transitions-out"] [data-testid="transition"] td:nth-child(2)', (r) => r.map((e) => Number(e.textContent)));
  assert.deepEqual(costs, costs.slice().sort((a, c) => a - c), 'cheapest first');
  // the sprite it leads to, in its filmstrip
  await bp.click(`[data-testid="transitions-out"] [data-testid="transition"][data-sprite="${rows[0]}"]`);
  await h.waitFor('the next sprite', async () => (await bp.getAttribute('[data-testid="sprite-detail"]', 'data-sprite')) === String(rows[0]));
  await h.waitFor('its cell marked', async () => bp.$eval(`[data-testid="sprite-cell"][data-sprite="${rows[0]}"]`, (e) => e.classList.contains('current')).catch(() => false));
  const frame = h.sql(cfg.bank, `SELECT frame FROM sprites WHERE id = ${rows[0]}`);
  assert.equal(await h.text(bp, 'detail-frame'), frame);
  await h.waitFor('the billboards in view', () => billboardsInView(bp, '[data-testid="bank-clips"]'), { timeout: 45000 });
  await h.sleep(300);
  await h.screenshot(bp, 'console-bank.png');
  assert.deepEqual(bp.errors, []);
  await bp.close();
});

test('a replay started on the replay page shows on the station page', async () => {
  const rp = await h.page(b, { width: 1600, height: 700 });
  await rp.goto(`${station.url}/replay.html`);
  const row = `[data-testid="replay-row"][data-path="${s.dir}"]`;
  await rp.waitForSelector(row, { timeout: 10000 });
  await rp.click(`${row} [data-testid="replay-paced"]`);
  await h.waitFor('replay mode', async () => (await rp.getAttribute('[data-testid="replay-mode"]', 'data-state')) && (await h.text(rp, 'replay-mode')) === 'replay', { timeout: 30000 });
  await rp.waitForSelector('[data-testid="replay-station-link"]:not([hidden])');
  await h.screenshot(rp, 'console-replay.png');
  await rp.click('[data-testid="replay-station-link"]');
  await rp.waitForURL(`${station.url}/`);
  // the replayed session's cameras, live, their frames advancing
  const names = ['cam0', 'cam1'];
  await h.waitFor('the replayed cameras as tiles', async () => {
    const t = await h.tiles(rp);
    return Object.keys(t).sort().join() === names.join() && names.every((n) => t[n].state === 'live' && t[n].frame !== null);
  }, { timeout: 60000 });
  assert.match(await h.text(rp, 'nav-mode'), /replay/);
  const first = await h.tiles(rp);
  await h.waitFor('replayed frames advancing', async () => {
    const t = await h.tiles(rp);
    return names.every((n) => t[n].frame > first[n].frame + 5);
  }, { timeout: 8000 });

  // and back to the config's cameras
  await rp.click('[data-testid="nav-replay"]');
  await rp.click('[data-testid="replay-stop"]');
  await h.waitFor('live mode', async () => (await h.text(rp, 'replay-mode')) === 'live', { timeout: 30000 });
  await rp.click('[data-testid="nav-station"]');
  await h.waitFor('the live cameras back', async () => Object.keys(await h.tiles(rp)).sort().join() === CAMERAS.join(), { timeout: 30000 });
  assert.match(await h.text(rp, 'nav-mode'), /live/);
  assert.deepEqual(rp.errors, []);
  await rp.close();
});
