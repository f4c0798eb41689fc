// The replay page: recorded sessions, a replay station started on one.
import { Events, chrome, el, fmt, getJson, postJson, basename } from './api.js';
import { showMessage } from './message.js';
import { $ } from './page.js';

const events = new Events().start();
chrome(events);

let status = null;
let startedHere = false;

function showMode() {
  if (!status) return;
  const replay = status.mode === 'replay';
  const badge = $('replay-mode');
  badge.textContent = replay ? 'replay' : 'live';
  badge.dataset.state = replay ? 'training' : 'live';
  $('replay-what').textContent = replay
    ? `Replaying ${status.replay?.path || '?'} (${status.replay?.paced ? 'paced' : 'fast'}), ${status.cameras?.length || 0} camera(s).`
    : `Live: the config's ${status.cameras?.length || 0} camera(s).`;
  $('replay-stop').disabled = !replay;
  $('replay-station-link').hidden = !(replay && startedHere);
  for (const tr of document.querySelectorAll('[data-testid="replay-row"]')) {
    tr.classList.toggle('current', replay && tr.dataset.path === status.replay?.path);
  }
}

async function start(path, paced, button) {
  for (const b of document.querySelectorAll('[data-testid="replay-table"] button')) b.disabled = true;
  try {
    await postJson('/api/replay/start', { path, paced });
    startedHere = true;
    showMessage(`Replay of ${basename(path)} started (${paced ? 'paced' : 'fast'}); open the Station page to watch it.`, 'info');
    $('replay-station-link').hidden = false;
  } catch (err) {
    showMessage(err.message, 'error');
  } finally {
    for (const b of document.querySelectorAll('[data-testid="replay-table"] button')) b.disabled = false;
    showMode();
  }
}

async function load() {
  const tbody = $('replay-table').querySelector('tbody');
  try {
    const r = await getJson('/api/replay/sessions');
    $('replay-roots').textContent = (r.roots || []).join(' · ');
    const rows = (r.sessions || []).map((s) =>
      el(
        'tr',
        { testid: 'replay-row', 'data-path': s.path, 'data-name': s.name },
        el('td', { text: s.name, class: 'name' }),
        el('td', { class: 'path', text: s.path, title: s.path }),
        el('td', {
          class: 'num',
          text: (s.cameras || []).map((c) => `${c.name} ${c.width}×${c.height}@${fmt(c.fps, 0)}`).join(', '),
        }),
        el('td', { class: 'num', text: fmt(s.seconds, 1) }),
        el('td', { text: s.synthetic ? 'synthetic' : 'recorded', class: s.synthetic ? 'tag-synth' : '' }),
        el('td', { class: 'num', text: (s.created || '').replace('T', ' ').replace(/\.\d+/, '') }),
        el(
          'td',
          { class: 'actions' },
          el('button', { type: 'button', class: 'primary', testid: 'replay-paced', text: 'Replay paced', onclick: (e) => start(s.path, true, e.currentTarget) }),
          el('button', { type: 'button', testid: 'replay-fast', text: 'Replay fast', onclick: (e) => start(s.path, false, e.currentTarget) }),
        ),
      ),
    );
    tbody.replaceChildren(...rows);
    if (!rows.length) tbody.append(el('tr', {}, el('td', { colspan: 7, class: 'empty', text: 'No recorded session found under these folders.' })));
    showMode();
  } catch (err) {
    showMessage(`replay sessions: ${err.message}`, 'error');
  }
}

$('replay-stop').addEventListener('click', async (e) => {
  e.currentTarget.disabled = true;
  try {
    await postJson('/api/replay/stop');
    startedHere = false;
    showMessage('Back to the live cameras.', 'info');
  } catch (err) {
    showMessage(err.message, 'error');
  } finally {
    showMode();
  }
});
$('replay-refresh').addEventListener('click', load);
events.addEventListener('status', (e) => {
  status = e.detail;
  showMode();
});
load();
