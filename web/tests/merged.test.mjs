// Two subjects in one blob, as the operator sees it: a replayed session of two
// animals whose paths cross (`synth --subjects 2 --crossing`). The sprites view
// marks a merged blob (dashed, `#id ×2`), and the tile's stored and merged
// counts are what the bank holds once a session has run.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import * as h from './harness.mjs';

let cfg, station, b, p;
const tile = '[data-testid="tile"][data-camera="cam0"]';

before(async () => {
  const dir = path.join(h.WORK, 'sessions', 'crossing');
  fs.rmSync(dir, { recursive: true, force: true });
  h.run(['synth', '--out', dir, '--kind', 'animal', '--seconds', '8', '--fps', '30', '--size', '480x360',
    '--cameras', '1', '--subjects', '2', '--seed', '3', '--crossing', '--empty-lead-in', '2', '--no-mattes']);
  const floor = JSON.parse(fs.readFileSync(path.join(dir, 'truth', 'floor.json'), 'utf8')).polygon;
  cfg = h.config('merged', { floor }, [{ name: 'cam0', source: 'replay', session: dir, loop: true }]);
  station = await h.daemon('merged', cfg, ['--no-transitions']);
  b = await h.browser();
  p = await h.page(b);
  await p.goto(`${station.url}/`);
  await h.waitFor('the tile live', async () => (await h.tiles(p)).cam0?.state === 'live', { timeout: 30000 });
});

after(async () => {
  await b?.close();
  await station?.stop();
});

test('the sprites view marks a blob of two subjects', async () => {
  await p.click(`${tile} [data-testid="view-sprites"]`);
  // The animals meet once a loop (8 s): wait for a frame whose candidates include a merged one.
  await h.waitFor('a merged candidate drawn', async () => Number(await p.getAttribute(tile, 'data-merged')) > 0,
    { timeout: 30000, interval: 50 });
  await h.screenshot(p, 'console-merged.png');
  // What the page drew is what the daemon said of that frame.
  const data = await (await fetch(`${station.url}/api/cameras/cam0/sprites.json`)).json();
  for (const c of data.candidates) assert.equal(typeof c.merged, 'boolean', 'every candidate says merged or not');
  const legend = await p.textContent('[data-testid="legend"]');
  assert.match(legend, /two subjects in one blob/);
  assert.deepEqual(p.errors, []);
});

test("the tile's stored and merged counts are the bank's", async () => {
  await p.fill('[data-testid="session-name"]', 'crossing');
  await p.click('[data-testid="session-start"]');
  await h.waitFor('session active', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'active');
  // A meeting and walking apart: merged sprites stored, and single ones.
  await h.waitFor('merged and single sprites stored', async () => {
    const merged = await h.num(p, 'tile-merged');
    return merged > 0 && (await h.num(p, 'tile-stored')) - merged >= 30;
  }, { timeout: 40000, interval: 250 });
  await p.click('[data-testid="session-stop"]');
  await h.waitFor('session idle', async () => (await p.getAttribute('[data-testid="session-state"]', 'data-state')) === 'idle', { timeout: 20000 });
  const originals = `FROM sprites s JOIN cameras c ON c.id = s.camera_id WHERE c.name = 'cam0' AND s.mirrored = 0`;
  const stored = Number(h.sql(cfg.bank, `SELECT count(*) ${originals}`));
  const merged = Number(h.sql(cfg.bank,
    `SELECT count(*) ${originals} AND s.id IN (SELECT sprite_id FROM sprite_tags WHERE tag = 'merged')`));
  assert.ok(merged > 0 && merged < stored, `${merged} of ${stored} stored sprites tagged merged`);
  await h.waitFor(`the tile's stored count (${stored})`, async () => (await h.num(p, 'tile-stored')) === stored, { timeout: 5000 });
  await h.waitFor(`the tile's merged count (${merged})`, async () => (await h.num(p, 'tile-merged')) === merged, { timeout: 5000 });
  await p.locator(tile).screenshot({ path: path.join(h.DOCS, 'console-merged-counts.png') });
  assert.deepEqual(p.errors, []);
});
