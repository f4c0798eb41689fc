// The pages' toolkit (issue 36): what every page did with its own copy. An element by its
// test id, a wait for the tab to be shown, and a request run from a button.
import { wakeableSleep } from './api.js';
import { showMessage } from './message.js';

// The element whose data-testid is `id`, under `root` (the document by default).
export const $ = (id, root = document) => root.querySelector(`[data-testid="${id}"]`);

// Resolves when the page is visible: a hidden tab fetches no previews.
export function waitVisible() {
  if (!document.hidden) return Promise.resolve();
  return new Promise((resolve) => {
    const on = () => {
      if (document.hidden) return;
      document.removeEventListener('visibilitychange', on);
      resolve();
    };
    document.addEventListener('visibilitychange', on);
  });
}

// A camera view's poll loop (the station's tiles, the wizard's cards), for as long as owner.alive:
// fetch() at most every pause() ms, never while the tab is hidden, every second while idle() or
// after an error (onError says it). owner.wake() cuts a wait short (wakeableSleep, api.js).
export async function pollView(owner, { idle, pause, fetch, onError }) {
  while (owner.alive) {
    const started = performance.now();
    await waitVisible();
    if (!owner.alive) break;
    if (idle()) {
      await wakeableSleep(owner, 1000);
      continue;
    }
    let wait = pause();
    try {
      await fetch();
    } catch (err) {
      if (!owner.alive) break;
      onError(err);
      wait = 1000;
    }
    const left = wait - (performance.now() - started);
    if (left > 0) await wakeableSleep(owner, left);
  }
}

// Runs `fn` from `button`: the button is busy and disabled meanwhile, an error is shown in the
// API's words. Returns what `fn` returned, or null after an error. `after(button)` runs last,
// and decides whether the button is enabled again (the page knows what it allows next).
export async function busy(button, fn, after = (b) => { if (b) b.disabled = false; }) {
  if (button) {
    button.disabled = true;
    button.classList.add('busy');
  }
  try {
    return await fn();
  } catch (err) {
    showMessage(err.message, 'error');
    return null;
  } finally {
    if (button) button.classList.remove('busy');
    after(button);
  }
}
