// The browser tests' harness: a synthetic session, emulated GigE cameras, the
// daemon under test, Debian's chromium through playwright-core, and waiting.
//
// run.sh sets SPRITESTATION (the executable) and SS_WEB_WORK (a temporary
// folder shared by the test files of one run) and runs the tests inside a
// private network namespace with 127.0.0.2 on its loopback.
import { spawn, execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = path.dirname(fileURLToPath(import.meta.url));
export const WEB_DIR = path.resolve(here, '..');
export const REPO = path.resolve(WEB_DIR, '..');
export const DOCS = path.join(REPO, 'docs');
export const BIN = process.env.SPRITESTATION || path.join(REPO, 'build/apps/spritestation');
export const WORK = process.env.SS_WEB_WORK || fs.mkdtempSync(path.join(os.tmpdir(), 'ss-web-'));
export const TOKEN = '0123456789abcdef0123';

const children = new Set();
function killAll() {
  for (const c of children) {
    try {
      c.kill('SIGKILL');
    } catch {
      /* gone */
    }
  }
}
process.on('exit', killAll);
for (const sig of ['SIGINT', 'SIGTERM']) process.on(sig, () => process.exit(1));

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Polls fn() until it returns a truthy value; throws naming `what` (and the
// last value seen) after `timeout` ms.
export async function waitFor(what, fn, { timeout = 10000, interval = 100 } = {}) {
  const end = Date.now() + timeout;
  let last;
  for (;;) {
    try {
      last = await fn();
      if (last) return last;
    } catch (err) {
      last = err;
    }
    if (Date.now() > end) {
      throw new Error(`timed out after ${timeout} ms waiting for ${what} (last: ${last instanceof Error ? last.message : JSON.stringify(last)})`);
    }
    await sleep(interval);
  }
}

export function run(args, opts = {}) {
  return execFileSync(BIN, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'], ...opts });
}

// A background process whose output goes to a log file (and is kept for
// waiting on a line).
// `prefix`: a command the executable runs under (e.g. setpriv dropping a
// capability), its arguments before BIN's.
export class Child {
  constructor(name, args, { prefix = [] } = {}) {
    this.name = name;
    this.log = path.join(WORK, `${name}.log`);
    this.out = '';
    this.proc = prefix.length
      ? spawn(prefix[0], [...prefix.slice(1), BIN, ...args], { stdio: ['ignore', 'pipe', 'pipe'] })
      : spawn(BIN, args, { stdio: ['ignore', 'pipe', 'pipe'] });
    children.add(this.proc);
    const file = fs.createWriteStream(this.log, { flags: 'a' });
    file.write(`$ spritestation ${args.join(' ')}\n`);
    for (const s of [this.proc.stdout, this.proc.stderr]) {
      s.on('data', (d) => {
        this.out += d;
        file.write(d);
      });
    }
    this.exited = new Promise((resolve) =>
      this.proc.on('exit', (code, signal) => {
        children.delete(this.proc);
        this.code = code ?? signal;
        resolve(this.code);
      }),
    );
  }

  async waitForOutput(re, timeout = 30000) {
    return waitFor(`${this.name} to print ${re}`, () => {
      if (this.code !== undefined) throw new Error(`${this.name} exited (${this.code}):\n${this.tail()}`);
      return this.out.match(re);
    }, { timeout, interval: 50 });
  }

  tail(n = 30) {
    return this.out.split('\n').slice(-n).join('\n');
  }

  kill(signal = 'SIGKILL') {
    if (this.code === undefined) this.proc.kill(signal);
    return this.exited;
  }

  // SIGTERM, then SIGKILL after `grace` ms.
  async stop(grace = 8000) {
    if (this.code !== undefined) return this.code;
    this.proc.kill('SIGTERM');
    const t = setTimeout(() => this.proc.kill('SIGKILL'), grace);
    const code = await this.exited;
    clearTimeout(t);
    return code;
  }
}

// The synthetic session every test streams: made once a run. `seed` 11 is the one the tests
// share; the labelling test asks for 12, whose animal stays on the open floor long enough for
// its 6 s to hold transitions (seed 11's walks into the walls since the subjects explore).
export function session(seed = 11, { size = '640x480', fps = 30 } = {}) {
  // Another seed's (or size's) session in a folder of its own: the replay tests list the shared one's.
  const usual = seed === 11 && size === '640x480' && fps === 30;
  const root = path.join(WORK, usual ? 'sessions' : `sessions-${seed}-${size}-${fps}`);
  const dir = path.join(root, 'studio');
  const done = path.join(root, 'done');
  if (!fs.existsSync(done)) {
    fs.rmSync(dir, { recursive: true, force: true });
    fs.mkdirSync(path.dirname(dir), { recursive: true });
    run(['synth', '--out', dir, '--kind', 'animal', '--seconds', '6', '--fps', String(fps), '--size', size,
      '--cameras', '2', '--subjects', '1', '--seed', String(seed), '--empty-lead-in', '2', '--no-mattes']);
    fs.writeFileSync(done, 'ok\n');
  }
  const floor = JSON.parse(fs.readFileSync(path.join(dir, 'truth', 'floor.json'), 'utf8'));
  return { dir, root: path.dirname(dir), floor: floor.polygon };
}

export async function fakecam(s, camera, address) {
  const cam = new Child(`fakecam-${camera}`, ['fakecam', s.dir, '--camera', camera, '--address', address,
    '--serial', camera, '--loop', '1000']);
  await cam.waitForOutput(/fakecam: serving/, 30000);
  return cam;
}

// Writes a station config: `cameras` a list of {name, source, ...} objects; `control`,
// `storage` and `pipeline` add keys to those sections; `s.floor` the enclosure's (none: no
// enclosure section, as a first-time user's config).
export function config(name, s, cameras, { control = {}, storage = {}, pipeline = {} } = {}) {
  const dir = path.join(WORK, name);
  fs.mkdirSync(dir, { recursive: true });
  const y = (v) => JSON.stringify(v); // JSON is YAML
  const lines = ['version: 1', 'cameras:'];
  for (const c of cameras) {
    const [first, ...rest] = Object.entries(c);
    lines.push(`  - ${first[0]}: ${y(first[1])}`);
    for (const [k, v] of rest) lines.push(`    ${k}: ${y(v)}`);
  }
  if (s.floor) lines.push('enclosure:', `  floor: ${y(s.floor)}`); // none: the wizard finds it
  const st = { bank: path.join(dir, 'station.bank'), recording_dir: path.join(dir, 'recordings'), ...storage };
  lines.push('storage:', ...Object.entries(st).map(([k, v]) => `  ${k}: ${y(v)}`));
  if (Object.keys(pipeline).length) lines.push('pipeline:', ...Object.entries(pipeline).map(([k, v]) => `  ${k}: ${y(v)}`));
  const ctl = { port: 0, ...control };
  lines.push('control:', ...Object.entries(ctl).map(([k, v]) => `  ${k}: ${y(v)}`));
  const file = path.join(dir, 'station.yaml');
  fs.writeFileSync(file, lines.join('\n') + '\n');
  return { file, dir, bank: st.bank };
}

export async function daemon(name, cfg, args = [], opts = {}) {
  const d = new Child(`daemon-${name}`, ['daemon', '--config', cfg.file, '--web-dir', WEB_DIR, ...args], opts);
  const m = await d.waitForOutput(/daemon: control API on (http:\/\/\S+) \(port (\d+)\)/, 60000);
  d.url = m[1].replace(/\/$/, '');
  d.port = Number(m[2]);
  d.bank = cfg.bank;
  return d;
}

export function sql(bank, query) {
  return execFileSync('sqlite3', ['-readonly', bank, query], { encoding: 'utf8' }).trim();
}

export function bankInfo(bank) {
  return JSON.parse(run(['bank', 'info', '--json', bank]));
}

export async function browser() {
  return chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--headless=new', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
}

// A page whose console errors and failed page scripts are collected (a test
// may assert there were none).
export async function page(b, { width = 1600, height = 1000 } = {}) {
  const context = await b.newContext({ viewport: { width, height } });
  const p = await context.newPage();
  p.errors = [];
  p.on('pageerror', (e) => p.errors.push(e.message));
  return p;
}

// The tiles as the page shows them: name -> {state, frame, view, candidates}.
export function tiles(p) {
  return p.$$eval('[data-testid="tile"]', (els) =>
    Object.fromEntries(els.map((t) => [t.dataset.camera, {
      state: t.dataset.state,
      frame: t.dataset.frame === '' ? null : Number(t.dataset.frame),
      view: t.dataset.view,
      candidates: Number(t.dataset.candidates),
    }])),
  );
}

export const text = (p, testid) => p.textContent(`[data-testid="${testid}"]`);
export const num = async (p, testid) => Number(((await text(p, testid)) || '').replace(/[^\d.-]/g, ''));

export async function screenshot(p, name) {
  fs.mkdirSync(DOCS, { recursive: true });
  await p.screenshot({ path: path.join(DOCS, name) });
}
