// The daemon soak (issue 20): a station on paced replay cameras and a browser-like client on
// it, for MINUTES (default 30). The first third a capture session stores sprites (the bank
// writer and the transitions worker at work: the bank, and the worker's in-memory index of
// it, grow by design); then the session stops and the station stays live (keying, tracking,
// previews, the API), which must hold its memory. Every 10 s it records the daemon's
// resident memory, the API's latency and the cameras' counters; at the end it prints the
// figures bench/RESULTS.md records and exits 1 when one is off:
//   - RSS flat: the mean of the last 5 minutes within 5 % of the mean of the 5 minutes that
//     start 2 minutes after the session stopped;
//   - latency steady: the p99 of /api/status in the last third no more than 2x the first third's;
//   - no drop: every frame the cameras delivered was processed (dropped.total 0), no batch
//     failed, sprites were stored.
// The client does what the station page does: the events stream open, /api/status every
// second, 8 preview streams (raw, keyed, sprites and a second keyed one for each of the two
// cameras) at 5 Hz each, /metrics every 5 s. And what the studio does (issue 39): from the
// second minute, an animation job on the station's own bank every minute (a 20 s budget,
// rendered), cancelled when it has not ended by the next; every job must end done or
// cancelled, none failed or left running.
//   node bench/soak/soak.mjs [MINUTES]     (scripts/soak.sh builds first)
import fs from 'node:fs';
import http from 'node:http';
import * as h from '../../web/tests/harness.mjs';

const minutes = Number(process.argv[2] || 30);
const cameras = ['cam0', 'cam1'];
const s = h.session();
const cfg = h.config('soak', s, cameras.map((c) => ({
  name: c, source: 'replay', session: s.dir, session_camera: c, loop: true, realtime: true,
})));
const station = await h.daemon('soak', cfg);
const base = station.url;
const pid = station.proc.pid;

function get(path) {
  const t0 = process.hrtime.bigint();
  return new Promise((resolve) => {
    const req = http.get(base + path, (res) => {
      let bytes = 0;
      res.on('data', (d) => { bytes += d.length; });
      res.on('end', () => resolve({ status: res.statusCode, ms: Number(process.hrtime.bigint() - t0) / 1e6, bytes }));
    });
    req.on('error', (e) => resolve({ status: 0, ms: Number(process.hrtime.bigint() - t0) / 1e6, error: e.message }));
    req.setTimeout(10000, () => req.destroy(new Error('timeout')));
  });
}
async function json(path) {
  return new Promise((resolve, reject) => {
    http.get(base + path, (res) => {
      let body = '';
      res.on('data', (d) => { body += d; });
      res.on('end', () => { try { resolve(JSON.parse(body)); } catch (e) { reject(e); } });
    }).on('error', reject);
  });
}
const post = (path, body) => new Promise((resolve, reject) => {
  const req = http.request(base + path, { method: 'POST', headers: { 'content-type': 'application/json' } }, (res) => {
    res.resume();
    res.on('end', () => resolve(res.statusCode));
  });
  req.on('error', reject);
  req.end(JSON.stringify(body));
});
const rssMiB = () => {
  const m = fs.readFileSync(`/proc/${pid}/status`, 'utf8').match(/VmRSS:\s+(\d+) kB/);
  return m ? Number(m[1]) / 1024 : NaN;
};
const pct = (xs, p) => {
  if (!xs.length) return NaN;
  const v = [...xs].sort((a, b) => a - b);
  return v[Math.min(v.length - 1, Math.floor(p * v.length))];
};

await h.waitFor('both cameras live', async () => {
  const st = await json('/api/status');
  return cameras.every((c) => st.cameras.find((x) => x.name === c)?.state === 'live');
}, { timeout: 60000 });
if ((await post('/api/session/start', { name: 'soak' })) !== 200) throw new Error('the session did not start');

// The events stream, held open as the page holds it.
let events = 0;
const sse = http.get(base + '/api/events', (res) => res.on('data', () => { events++; }));
sse.on('error', () => {});

const latencies = []; // {t, ms} of /api/status
let failures = 0;
let running = true;
const loop = async (period, fn) => { while (running) { await fn(); await h.sleep(period); } };
const t0 = Date.now();
const clients = [
  loop(1000, async () => {
    const r = await get('/api/status');
    if (r.status !== 200) failures++;
    latencies.push({ t: (Date.now() - t0) / 1000, ms: r.ms });
  }),
  ...cameras.flatMap((c) => ['preview.jpg?view=raw', 'preview.jpg?view=keyed', 'sprites.json?x=1', 'preview.jpg?view=keyed']
    .map((view) => loop(200, async () => {
      const r = await get(`/api/cameras/${c}/${view}&width=640`);
      if (r.status !== 200) failures++;
    }))),
  loop(5000, async () => {
    const r = await get('/metrics');
    if (r.status !== 200) failures++;
  }),
];

// The studio's jobs: a circle on the station's bank (relative names resolve beside it; the
// camera is the replayed session's, a folder the station knows).
const spec = JSON.stringify({
  version: 1, frame_rate: 30, length: { min_frames: 60, max_frames: 300 },
  camera: `${s.dir}/cam0.cameramodel`, banks: [cfg.bank],
  optimizer: { method: 'replace', time_budget_s: 20 },
  sprites: [{ name: 'hamster', start: [0.2, 0], constraints: [{ path: {
    points: [[0.2, 0], [0, 0.2], [-0.2, 0], [0, -0.2], [0.2, 0]], distance_strength: 200, unreached_strength: 3000 } }] }],
});
const postJson = (path, body) => new Promise((resolve, reject) => {
  const req = http.request(base + path, { method: 'POST', headers: { 'content-type': 'application/json' } }, (res) => {
    let text = '';
    res.on('data', (d) => { text += d; });
    res.on('end', () => resolve({ status: res.statusCode, body: text ? JSON.parse(text) : {} }));
  });
  req.on('error', reject);
  req.end(JSON.stringify(body));
});
const jobs = []; // {id, state}
async function nextJob() {
  const prev = jobs[jobs.length - 1];
  if (prev) {
    prev.state = (await json(`/api/animations/${prev.id}`)).state;
    if (['queued', 'running', 'rendering'].includes(prev.state)) {
      await postJson(`/api/animations/${prev.id}/cancel`, {});
      await h.waitFor(`job ${prev.id} cancelled`, async () => !['queued', 'running', 'rendering']
        .includes(prev.state = (await json(`/api/animations/${prev.id}`)).state), { timeout: 5000 });
    }
  }
  const r = await postJson('/api/animations', { spec });
  if (r.status !== 202) throw new Error(`job refused: ${r.status} ${JSON.stringify(r.body)}`);
  jobs.push({ id: r.body.id, state: 'queued' });
}
let nextJobAt = 1;

const samples = []; // every 10 s
const sessionMinutes = minutes / 3;
let sessionOpen = true;
while ((Date.now() - t0) / 60000 < minutes) {
  await h.sleep(10000);
  if (sessionOpen && (Date.now() - t0) / 60000 >= sessionMinutes) {
    if ((await post('/api/session/stop', {})) !== 200) throw new Error('the session did not stop');
    sessionOpen = false;
  }
  if ((Date.now() - t0) / 60000 >= nextJobAt && (Date.now() - t0) / 60000 < minutes - 0.5) {
    await nextJob();
    nextJobAt += 1;
  }
  const st = await json('/api/status');
  const cams = st.cameras.filter((c) => cameras.includes(c.name));
  const sample = {
    t: Math.round((Date.now() - t0) / 1000),
    rss_mib: rssMiB(),
    frames_processed: cams.reduce((a, c) => a + c.frames_processed, 0),
    dropped: cams.reduce((a, c) => a + c.dropped.total, 0),
    sprites: st.bank.sprites,
    batches_failed: st.bank.batches_failed ?? 0,
    latency_p99_ms: pct(latencies.filter((l) => l.t > (Date.now() - t0) / 1000 - 10).map((l) => l.ms), 0.99),
    animation: st.animation ? `${st.animation.id} ${st.animation.state}` : null,
  };
  samples.push(sample);
  console.log(JSON.stringify(sample));
}
running = false;
await Promise.all(clients);
// The last job: waited for while it may still end on its own, then cancelled.
const lastJob = jobs[jobs.length - 1];
if (lastJob) {
  await h.waitFor(`job ${lastJob.id} to end`, async () => !['queued', 'running', 'rendering']
    .includes(lastJob.state = (await json(`/api/animations/${lastJob.id}`)).state), { timeout: 60000 })
    .catch(async () => { await postJson(`/api/animations/${lastJob.id}/cancel`, {}); await h.sleep(2000); });
  lastJob.state = (await json(`/api/animations/${lastJob.id}`)).state;
}
const jobStates = {};
for (const j of jobs) jobStates[j.state] = (jobStates[j.state] || 0) + 1;
sse.destroy();
if (sessionOpen) await post('/api/session/stop', {});
const code = await station.stop();

const span = (a, b) => samples.filter((x) => x.t > a * 60 && x.t <= b * 60);
const mean = (xs) => xs.reduce((a, b) => a + b, 0) / xs.length;
const early = mean(span(sessionMinutes + 2, sessionMinutes + 7).map((x) => x.rss_mib));
const late = mean(span(minutes - 5, minutes).map((x) => x.rss_mib));
const third = minutes * 60 / 3;
const p99first = pct(latencies.filter((l) => l.t <= third).map((l) => l.ms), 0.99);
const p99last = pct(latencies.filter((l) => l.t > 2 * third).map((l) => l.ms), 0.99);
const last = samples[samples.length - 1];
const first = samples[0];
const result = {
  minutes,
  rss_mib: { after_session: +early.toFixed(1), last_5: +late.toFixed(1), change_percent: +((late / early - 1) * 100).toFixed(2) },
  status_latency_ms: {
    p50: +pct(latencies.map((l) => l.ms), 0.5).toFixed(2),
    p99_first_third: +p99first.toFixed(2),
    p99_last_third: +p99last.toFixed(2),
  },
  requests_failed: failures,
  events_received: events,
  frames_processed: last.frames_processed,
  dropped: last.dropped,
  sprites_stored: last.sprites - first.sprites,
  batches_failed: last.batches_failed,
  animation_jobs: jobStates,
  daemon_exit: code,
};
console.log('soak: ' + JSON.stringify(result));
const problems = [];
if (minutes < 15) console.log('soak: shorter than 15 minutes: RSS flatness not judged');
else if (!(Math.abs(result.rss_mib.change_percent) <= 5)) problems.push(`RSS changed ${result.rss_mib.change_percent} %`);
if (p99last > 2 * p99first) problems.push(`status p99 grew from ${p99first} to ${p99last} ms`);
if (result.dropped > 0) problems.push(`${result.dropped} frames dropped`);
if (result.batches_failed > 0) problems.push(`${result.batches_failed} batches failed`);
if (failures > 0) problems.push(`${failures} requests failed`);
if (!(result.sprites_stored > 0)) problems.push('no sprite stored');
if (code !== 0) problems.push(`the daemon exited ${code}`);
const unclean = jobs.filter((j) => j.state !== 'done' && j.state !== 'cancelled');
if (unclean.length) problems.push(`animation jobs not done or cancelled: ${unclean.map((j) => `${j.id} ${j.state}`).join(', ')}`);
if (minutes >= 2 && !jobs.length) problems.push('no animation job ran');
fs.writeFileSync(`${h.WORK}/soak.json`, JSON.stringify({ result, samples }, null, 1));
console.log(problems.length ? `soak: FAILED: ${problems.join('; ')}` : 'soak: passed');
process.exit(problems.length ? 1 : 0);
