// The console on a station with a control token, and eight cameras: the
// sign-in form, the token on every request, and eight tiles live at once
// (the browser's six connections per host must not freeze any).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import path from 'node:path';
import * as h from './harness.mjs';

const N = 8;
let station, b, p;

before(async () => {
  // Eight replays of the usual 640x480 30 fps session decode 74 Mpx/s of FFV1, all of a 2-core
  // machine, and starve the browser (CI: tiles live after 54 s, a click unanswered for 30 s).
  // At 320x240 and 15 fps the eight cost what one usual camera does.
  const s = h.session(11, { size: '320x240', fps: 15 });
  const cameras = Array.from({ length: N }, (_, i) => ({
    name: `cam${i}`, source: 'replay', session: s.dir, session_camera: `cam${i % 2}`, loop: true,
  }));
  const cfg = h.config('token', s, cameras, { control: { address: '127.0.0.1', token: h.TOKEN } });
  station = await h.daemon('token', cfg, ['--no-transitions']);
  b = await h.browser();
  p = await h.page(b);
});

after(async () => {
  await b?.close();
  await station?.stop();
});

test('the station asks for the token, and refuses a wrong one', async () => {
  const bare = await fetch(`${station.url}/api/status`);
  assert.equal(bare.status, 401, 'the daemon wants the token');
  await p.goto(`${station.url}/`);
  await p.waitForSelector('[data-testid="signin-form"]', { timeout: 10000 });
  assert.equal((await p.$$('[data-testid="tile"]')).length, 0, 'no data before signing in');
  await p.fill('[data-testid="signin-token"]', 'not-the-token');
  await p.click('[data-testid="signin-submit"]');
  await h.waitFor('the form again, saying the token was refused', async () =>
    /refused/.test((await p.textContent('[data-testid="signin-error"]').catch(() => '')) || ''));
});

test('after signing in all eight tiles are visible and live', async () => {
  await p.fill('[data-testid="signin-token"]', h.TOKEN);
  await p.click('[data-testid="signin-submit"]');
  await h.waitFor('the form gone', async () => (await p.$$('[data-testid="signin-form"]')).length === 0);
  assert.equal(await p.evaluate(() => sessionStorage.getItem('spritestation.token')), h.TOKEN);
  const names = Array.from({ length: N }, (_, i) => `cam${i}`);
  await h.waitFor('eight live tiles', async () => {
    const t = await h.tiles(p);
    return names.every((n) => t[n]?.state === 'live' && t[n]?.frame !== null);
  }, { timeout: 60000, interval: 250 });
  const first = await h.tiles(p);
  await h.waitFor('every frame number advancing', async () => {
    const t = await h.tiles(p);
    return names.every((n) => t[n].frame > first[n].frame);
  }, { timeout: 8000, interval: 250 });
  // all eight at once in a 1600 x 1000 window
  const boxes = await p.$$eval('[data-testid="tile"]', (els) => els.map((e) => e.getBoundingClientRect().toJSON()));
  assert.equal(boxes.length, N);
  for (const r of boxes) assert.ok(r.top >= 0 && r.bottom <= 1000 && r.left >= 0 && r.right <= 1600, `tile at ${JSON.stringify(r)} is in view`);
  assert.equal(await p.getAttribute('[data-testid="connection"]', 'data-state'), 'connected');
  await p.screenshot({ path: path.join(h.WORK, 'station-8.png') }); // kept with SS_WEB_KEEP=1
});

test('writes carry the token: a session starts and stops from the page', async () => {
  await p.fill('[data-testid="session-name"]', 'token take');
  await p.click('[data-testid="session-start"]');
  await h.waitFor('session active', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'active');
  await p.click('[data-testid="session-stop"]');
  await h.waitFor('session idle', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'idle', { timeout: 20000 });
  assert.equal(await p.isHidden('[data-testid="signin-form"]').catch(() => true), true);
  assert.deepEqual(p.errors, []);
});
