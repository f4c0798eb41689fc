// The page's message area: API errors (the JSON "error" text) and notices.
let timer = null;

export function showMessage(text, kind = 'error') {
  const box = document.querySelector('[data-testid="message"]');
  if (!box) return;
  clearTimeout(timer);
  box.replaceChildren();
  const span = document.createElement('span');
  span.dataset.testid = 'message-text';
  span.textContent = text;
  const close = document.createElement('button');
  close.className = 'link';
  close.textContent = 'Dismiss';
  close.addEventListener('click', () => (box.hidden = true));
  box.append(span, close);
  box.dataset.kind = kind;
  box.hidden = false;
  if (kind === 'info') timer = setTimeout(() => (box.hidden = true), 8000);
}
