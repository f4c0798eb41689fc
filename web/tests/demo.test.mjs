// The station demo as a user runs it (`scripts/demo.sh --station`): docs/station.replay.yaml
// byte for byte, beside the sample session scripts/sample.sh renders, in the repository's layout
// (docs/ and recordings/, the config's relative paths), on its own fixed port (the tests run in a
// private network namespace, where 8360 is free). The config the user and the tests share.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import * as h from './harness.mjs';

const root = path.join(h.WORK, 'demo');
const config = path.join(root, 'docs', 'station.replay.yaml');
const bank = path.join(root, 'recordings', 'demo-output', 'station.bank');
const CAMERAS = ['cam0', 'cam1'];
let station, b, p, started, stored;

before(async () => {
  fs.mkdirSync(path.dirname(config), { recursive: true });
  fs.copyFileSync(path.join(h.DOCS, 'station.replay.yaml'), config);
  execFileSync(path.join(h.REPO, 'scripts', 'sample.sh'), [path.join(root, 'recordings', 'sample')], {
    env: { ...process.env, SPRITESTATION: h.BIN },
    stdio: ['ignore', 'ignore', 'pipe'],
  });
  b = await h.browser();
  p = await h.page(b);
  started = Date.now();
  station = new h.Child('daemon-demo', ['daemon', '--config', config]);
  const m = await station.waitForOutput(/daemon: control API on (http:\/\/\S+) \(port (\d+)\)/, 60000);
  station.url = m[1].replace(/\/$/, '');
});

after(async () => {
  await b?.close();
  await station?.stop();
});

test('the config is the one in docs/, and the station serves on its port', () => {
  assert.deepEqual(fs.readFileSync(config), fs.readFileSync(path.join(h.DOCS, 'station.replay.yaml')));
  assert.equal(station.url, 'http://127.0.0.1:8360');
});

test('every sample camera is live in the console', async () => {
  await p.goto(`${station.url}/`);
  await h.waitFor('both sample cameras live with a frame', async () => {
    const t = await h.tiles(p);
    return CAMERAS.every((n) => t[n]?.state === 'live' && t[n]?.frame !== null);
  }, { timeout: 60000, interval: 100 });
  // The issue's goal is 15 s on a machine where the demo ran once; speed is the benchmarks' to
  // assert, this says what this run took.
  console.log(`# demo: every camera live ${((Date.now() - started) / 1000).toFixed(1)} s after the daemon started`);
  assert.equal(await p.isHidden('[data-testid="tile-needs"]'), true, 'the sample brings its models and floor');
});

test('a session started on the page stores sprites of the sample', async () => {
  await p.fill('[data-testid="session-name"]', 'demo take');
  await p.click('[data-testid="session-start"]');
  await h.waitFor('session active', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'active');
  await h.waitFor('sprites stored', async () => (await h.num(p, 'session-sprites')) > 20, { timeout: 30000, interval: 250 });
  await p.click('[data-testid="session-stop"]');
  const msg = await h.waitFor('the stop message', async () => (await h.text(p, 'message-text'))?.match(/stopped: ([\d,]+) sprites stored/), { timeout: 20000 });
  stored = Number(msg[1].replace(/,/g, ''));
  assert.ok(stored > 20, `${stored} sprites stored`);
  // the panel shows the stop's answer at once, not a status event later
  assert.equal(await p.getAttribute('[data-testid="session-state"]', 'data-state'), 'idle');
  assert.equal(await h.num(p, 'session-sprites'), stored);
  await p.screenshot({ path: path.join(h.WORK, 'demo-station.png') }); // kept with SS_WEB_KEEP=1
  assert.deepEqual(p.errors, []);
});

test('Ctrl-C stops the station cleanly and its bank verifies', async () => {
  station.proc.kill('SIGINT');
  assert.equal(await station.exited, 0, station.tail());
  h.run(['bank', 'verify', bank]);
  const info = h.bankInfo(bank);
  assert.equal(info.sessions, 1);
  assert.ok(info.sprites - info.mirrors >= stored, `${info.sprites - info.mirrors} originals in the bank, ${stored} said stored`);
});
