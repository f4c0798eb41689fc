// The console's access to the daemon's /api: the token, JSON requests, and the
// live state stream (GET /api/events). docs/console.md is the contract.

const TOKEN_KEY = 'spritestation.token';

export class ApiError extends Error {
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

export function token() {
  try {
    return sessionStorage.getItem(TOKEN_KEY) || '';
  } catch {
    return '';
  }
}

function setToken(value) {
  try {
    if (value) sessionStorage.setItem(TOKEN_KEY, value);
    else sessionStorage.removeItem(TOKEN_KEY);
  } catch {
    /* storage disabled: the token lives as long as the page */
  }
}

export function signOut() {
  setToken('');
  location.reload();
}

// ---- sign-in ---------------------------------------------------------------
// Every request that answers 401 waits on one shared sign-in: the form asks
// for the token once, and every waiting request retries with it.

let signInPromise = null;

function showSignIn(refused) {
  if (signInPromise) return signInPromise;
  signInPromise = new Promise((resolve) => {
    const back = document.createElement('div');
    back.className = 'signin-backdrop';
    back.innerHTML = `
      <form class="signin" data-testid="signin-form" autocomplete="off">
        <h2>Sign in to the station</h2>
        <p>This station asks for its control token (<code>control.token</code> in
        the station config). It is kept for this tab only.</p>
        <label>Token <input type="password" name="token" data-testid="signin-token" required autofocus></label>
        <p class="signin-error" data-testid="signin-error"></p>
        <button type="submit" class="primary" data-testid="signin-submit">Sign in</button>
      </form>`;
    const form = back.querySelector('form');
    const err = back.querySelector('.signin-error');
    err.textContent = refused ? 'The station refused that token.' : '';
    form.addEventListener('submit', (ev) => {
      ev.preventDefault();
      setToken(form.elements.token.value.trim());
      back.remove();
      signInPromise = null;
      resolve();
    });
    document.body.appendChild(back);
    form.elements.token.focus();
  });
  return signInPromise;
}

// ---- requests --------------------------------------------------------------

function withAuth(headers = {}) {
  const t = token();
  return t ? { ...headers, Authorization: `Bearer ${t}` } : headers;
}

// fetch() of an /api path with the token; a 401 shows the sign-in form and the
// request is sent again once the operator signed in.
export async function apiFetch(path, init = {}) {
  for (;;) {
    const sent = token();
    const res = await fetch(path, { cache: 'no-store', ...init, headers: withAuth(init.headers) });
    if (res.status !== 401) return res;
    await res.body?.cancel();
    await showSignIn(sent !== '');
  }
}

async function errorOf(res) {
  let text = `${res.status} ${res.statusText}`;
  try {
    const body = await res.json();
    if (body && body.error) text = body.error;
  } catch {
    /* not JSON */
  }
  return new ApiError(res.status, text);
}

export async function getJson(path, init) {
  const res = await apiFetch(path, init);
  if (!res.ok) throw await errorOf(res);
  return res.json();
}

// Every write: POST, a JSON body, Content-Type application/json.
export async function postJson(path, body = {}) {
  const res = await apiFetch(path, {
    method: 'POST',
    headers: { 'Content-Type': 'application/json' },
    body: JSON.stringify(body),
  });
  if (!res.ok) throw await errorOf(res);
  const text = await res.text();
  return text ? JSON.parse(text) : {};
}

export async function getBlob(path, init) {
  const res = await apiFetch(path, init);
  if (!res.ok) throw await errorOf(res);
  return { blob: await res.blob(), headers: res.headers };
}

// A limit on concurrent requests of one kind (previews, billboards), so they
// never take all of the browser's six connections to the station: the event
// stream holds one and writes must find another.
export class Limiter {
  constructor(max) {
    this.max = max;
    this.running = 0;
    this.queue = [];
  }
  async run(fn) {
    if (this.running >= this.max) await new Promise((r) => this.queue.push(r));
    this.running++;
    try {
      return await fn();
    } finally {
      this.running--;
      const next = this.queue.shift();
      if (next) next();
    }
  }
}

// Downloads a blob under a file name (export CSV fetched with the token).
export function saveBlob(blob, name) {
  const url = URL.createObjectURL(blob);
  const a = document.createElement('a');
  a.href = url;
  a.download = name;
  document.body.appendChild(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

// ---- RFC 7386 JSON Merge Patch --------------------------------------------

export function mergePatch(target, patch) {
  if (patch === null || typeof patch !== 'object' || Array.isArray(patch)) return patch;
  const out = target !== null && typeof target === 'object' && !Array.isArray(target) ? target : {};
  for (const [key, value] of Object.entries(patch)) {
    if (value === null) delete out[key];
    else out[key] = mergePatch(out[key], value);
  }
  return out;
}

// ---- the event stream ------------------------------------------------------
// Server-Sent Events read with fetch() and a ReadableStream (EventSource cannot
// send the Authorization header). Holds the status: the snapshot, then each
// merge patch applied to it. Reconnects with backoff; a stream silent for 15 s
// (the daemon sends a heartbeat every 5 s) counts as lost.

export class Events extends EventTarget {
  constructor(path = '/api/events') {
    super();
    this.path = path;
    this.status = null;
    this.history = [];
    this.connection = 'connecting';
    this.lastId = null;
    this.stopped = false;
  }

  start() {
    this.#run();
    return this;
  }

  #setConnection(state) {
    if (state === this.connection) return;
    this.connection = state;
    this.dispatchEvent(new CustomEvent('connection', { detail: state }));
  }

  #dispatch(type, id, data) {
    if (id !== null) this.lastId = id;
    let value;
    try {
      value = data === '' ? null : JSON.parse(data);
    } catch {
      return;
    }
    if (type === 'snapshot') {
      this.status = value.status;
      this.history = Array.isArray(value.history) ? value.history.slice(-300) : [];
      this.#setConnection('connected');
      this.dispatchEvent(new CustomEvent('status', { detail: this.status }));
      this.dispatchEvent(new CustomEvent('history', { detail: this.history }));
    } else if (type === 'patch') {
      if (this.status === null) return;
      this.status = mergePatch(this.status, value);
      this.dispatchEvent(new CustomEvent('status', { detail: this.status }));
    } else if (type === 'sample') {
      this.history.push(value);
      if (this.history.length > 300) this.history.splice(0, this.history.length - 300);
      this.dispatchEvent(new CustomEvent('sample', { detail: value }));
    }
    this.dispatchEvent(new CustomEvent('event', { detail: { type, id } }));
  }

  async #run() {
    let backoff = 500;
    while (!this.stopped) {
      const abort = new AbortController();
      let watchdog = null;
      const feed = () => {
        clearTimeout(watchdog);
        watchdog = setTimeout(() => abort.abort(), 15000);
      };
      try {
        feed();
        const res = await apiFetch(this.path, {
          headers: { Accept: 'text/event-stream' },
          signal: abort.signal,
        });
        if (!res.ok || !res.body) throw new Error(`events: ${res.status}`);
        const reader = res.body.pipeThrough(new TextDecoderStream()).getReader();
        let buffer = '';
        let type = 'message';
        let id = null;
        let data = [];
        for (;;) {
          const { value, done } = await reader.read();
          if (done) break;
          feed();
          buffer += value;
          let nl;
          while ((nl = buffer.search(/\r\n|\r|\n/)) >= 0) {
            const line = buffer.slice(0, nl);
            buffer = buffer.slice(nl + (buffer[nl] === '\r' && buffer[nl + 1] === '\n' ? 2 : 1));
            if (line === '') {
              if (data.length) {
                this.#dispatch(type, id, data.join('\n'));
                backoff = 500;
              }
              type = 'message';
              id = null;
              data = [];
              continue;
            }
            if (line.startsWith(':')) continue;
            const colon = line.indexOf(':');
            const field = colon < 0 ? line : line.slice(0, colon);
            let val = colon < 0 ? '' : line.slice(colon + 1);
            if (val.startsWith(' ')) val = val.slice(1);
            if (field === 'event') type = val;
            else if (field === 'data') data.push(val);
            else if (field === 'id') id = val;
          }
        }
      } catch {
        /* lost: reconnect below */
      } finally {
        clearTimeout(watchdog);
        abort.abort();
      }
      if (this.stopped) break;
      this.#setConnection('reconnecting');
      await new Promise((r) => setTimeout(r, backoff));
      backoff = Math.min(backoff * 2, 8000);
    }
  }
}

// ---- page chrome -----------------------------------------------------------

// Marks the current page in the top nav and shows the stream's connection.
// The console's pages, in the order the top bar lists them: adding a page is one line here.
const PAGES = [
  { href: '/', id: 'station', title: 'Station' },
  { href: 'replay.html', id: 'replay', title: 'Replay' },
  { href: 'bank.html', id: 'bank', title: 'Bank' },
  { href: 'calibrate.html', id: 'calibrate', title: 'Calibrate' },
  { href: 'label.html', id: 'label', title: 'Label' },
  { href: 'studio.html', id: 'studio', title: 'Studio' },
];

// The top bar (the pages, the mode, the connection, sign out) and the message area, the same
// on every page, put in front of the page's own content.
function addChrome() {
  const message = el('div', { class: 'message', testid: 'message', role: 'alert', hidden: true });
  document.body.prepend(
    el(
      'header',
      { class: 'topbar' },
      el('span', { class: 'brand' }, 'Sprite', el('b', { text: 'Station' })),
      el('nav', { class: 'top', testid: 'nav' }, PAGES.map((p) => el('a', { href: p.href, testid: `nav-${p.id}`, text: p.title }))),
      el('span', { class: 'spacer' }),
      el('span', { class: 'mode', testid: 'nav-mode' }),
      el('span', { class: 'connection', testid: 'connection', 'data-state': 'connecting', text: 'connecting' }),
      el('button', { class: 'link', testid: 'signout', hidden: true, text: 'Sign out' }),
    ),
    message,
  );
}

export function chrome(events) {
  addChrome();
  const here = location.pathname.replace(/^\/$/, '/index.html');
  for (const a of document.querySelectorAll('nav.top a[href]')) {
    const target = new URL(a.href, location.href).pathname.replace(/^\/$/, '/index.html');
    if (target === here) a.classList.add('current');
  }
  const dot = document.querySelector('[data-testid="connection"]');
  const mode = document.querySelector('[data-testid="nav-mode"]');
  const show = () => {
    if (dot) {
      dot.dataset.state = events.connection;
      dot.textContent = events.connection;
    }
  };
  events.addEventListener('connection', show);
  events.addEventListener('status', (e) => {
    if (!mode) return;
    const s = e.detail;
    mode.dataset.mode = s.mode || 'live';
    mode.textContent = s.mode === 'replay' ? `replay: ${basename(s.replay?.path || '')}` : 'live cameras';
  });
  show();
  const signout = document.querySelector('[data-testid="signout"]');
  if (signout) {
    signout.hidden = !token();
    signout.addEventListener('click', signOut);
  }
}

// ---- small formatting helpers ----------------------------------------------

export function basename(p) {
  const parts = String(p).split('/').filter(Boolean);
  return parts.length ? parts[parts.length - 1] : p;
}

export function fmt(n, digits = 0) {
  if (n === null || n === undefined || Number.isNaN(n)) return '–';
  return Number(n).toLocaleString('en-US', { minimumFractionDigits: digits, maximumFractionDigits: digits });
}

export function duration(seconds) {
  const s = Math.max(0, Math.floor(seconds));
  const h = Math.floor(s / 3600);
  const m = Math.floor((s % 3600) / 60);
  const two = (x) => String(x).padStart(2, '0');
  return `${h ? h + ':' : ''}${two(m)}:${two(s % 60)}`;
}

export function el(tag, attrs = {}, ...children) {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k === 'class') e.className = v;
    else if (k === 'text') e.textContent = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else if (k === 'testid') e.dataset.testid = v;
    else if (k === 'style') Object.assign(e.style, v); // CSSOM: the daemon's CSP refuses style attributes
    else e.setAttribute(k, v === true ? '' : v);
  }
  for (const c of children.flat()) if (c !== null && c !== undefined) e.append(c);
  return e;
}

// A data: URL's bytes as a Blob (fetch() of a data: URL is outside the
// daemon's connect-src 'self').
export function dataUrlBlob(url) {
  const comma = url.indexOf(',');
  const head = url.slice(5, comma);
  const body = url.slice(comma + 1);
  const type = head.split(';')[0] || 'application/octet-stream';
  if (!/;base64$/.test(head)) return new Blob([decodeURIComponent(body)], { type });
  const bin = atob(body);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
  return new Blob([bytes], { type });
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Sleeps `ms`, or less when owner.wake() is called (a poller's view changed, its camera came back).
export function wakeableSleep(owner, ms) {
  return new Promise((resolve) => {
    const t = setTimeout(done, ms);
    function done() {
      clearTimeout(t);
      resolve();
    }
    owner.wake = () => {
      owner.wake = null;
      done();
    };
  });
}
