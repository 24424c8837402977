// The robot's API as the page uses it: fetch with the token, and the WebSocket state stream.
// The token is asked once and kept in localStorage; HTTP requests carry it in the
// Authorization header. Browsers cannot give a WebSocket a header: it goes as a subprotocol
// "poppy-token.<hex>", so no URL ever holds it.

const TOKEN_KEY = "poppy-token";
let asking = null;
const askedListeners = [];

// True while the page waits for the token to be entered.
export function tokenAsked() {
  return asking !== null;
}

// Call `listener` when the token dialog opens and once a token is entered.
export function onTokenAsked(listener) {
  askedListeners.push(listener);
}

export function token() {
  return localStorage.getItem(TOKEN_KEY) || "";
}

// The token the page sends from now on (the settings changed it).
export function setToken(value) {
  localStorage.setItem(TOKEN_KEY, value);
}

function hex(text) {
  return [...new TextEncoder().encode(text)].map((b) => b.toString(16).padStart(2, "0")).join("");
}

export class ApiError extends Error {
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

// Ask for the token with the page's dialog; resolves once a token is entered.
function askToken(wrong) {
  if (!asking) {
    asking = new Promise((resolve) => {
      const dialog = document.getElementById("token-dialog");
      const input = document.getElementById("token-input");
      document.getElementById("token-error").textContent = wrong
        ? "The server refused that token: check it and try again." : "";
      dialog.addEventListener("close", function done() {
        dialog.removeEventListener("close", done);
        localStorage.setItem(TOKEN_KEY, input.value.trim());
        input.value = "";
        asking = null;
        for (const listener of askedListeners) listener();
        resolve();
      });
      dialog.showModal();
      input.focus();
    });
    for (const listener of askedListeners) listener();
  }
  return asking;
}

async function problem(response) {
  try {
    const body = await response.json();
    return body.error || body.detail || response.statusText;
  } catch {
    return response.statusText;
  }
}

// One API call; a 401 asks for the token and tries again.
export async function api(method, path, body) {
  for (;;) {
    const headers = {};
    const sent = token();
    if (sent) headers.Authorization = `Bearer ${sent}`;
    if (body !== undefined) headers["Content-Type"] = "application/json";
    const response = await fetch(path, {
      method, headers, body: body === undefined ? undefined : JSON.stringify(body),
    });
    if (response.status === 401) {
      // A token entered while this call was out (its 401 came late) is tried first: asking
      // again would open the dialog over a page that works.
      if (token() !== sent) continue;
      await askToken(Boolean(sent));
      continue;
    }
    if (!response.ok) throw new ApiError(response.status, await problem(response));
    if (response.status === 204) return null;
    return response.json();
  }
}

export const get = (path) => api("GET", path);
export const post = (path, body) => api("POST", path, body ?? {});
export const put = (path, value) => api("PUT", path, { value });

// The state stream: calls onFrame with {motor: {present_position, ...}} at rateHz; reconnects.
// onStatus(true) when frames arrive, onStatus(false) when the socket closes or goes silent
// (no frame for STALE_MS: a server gone without closing, a network down); each change once.
const STALE_MS = 3000;

export function openStream(rateHz, onFrame, onStatus) {
  let socket = null;
  let retry = 500;
  let up = null; // unknown until the first frame or the first failure
  let lastFrame = 0;
  const status = (now) => { if (now !== up) { up = now; onStatus(now); } };
  function lost(which) {
    if (which !== socket) return; // an older socket, already handled
    socket = null;
    which.onopen = which.onmessage = which.onclose = null;
    try { which.close(); } catch { /* already closed */ }
    status(false);
    setTimeout(async () => {
      try { await get("/api/v1/web/about"); } catch { /* the next try says */ }
      connect();
    }, retry);
    retry = Math.min(retry * 2, 5000);
  }
  function connect() {
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    const url = `${scheme}://${location.host}/api/v1/ws?rate_hz=${rateHz}`;
    const opened = token() ? new WebSocket(url, [`poppy-token.${hex(token())}`]) : new WebSocket(url);
    socket = opened;
    opened.onopen = () => { lastFrame = performance.now(); };
    opened.onmessage = (event) => {
      const data = JSON.parse(event.data);
      if (data.error || data.type) return;
      lastFrame = performance.now();
      retry = 500;
      status(true);
      onFrame(data);
    };
    opened.onclose = () => lost(opened);
  }
  setInterval(() => {
    if (socket && socket.readyState === 1 && performance.now() - lastFrame > STALE_MS) lost(socket);
  }, 1000);
  connect();
  return { send: (data) => socket && socket.readyState === 1 && socket.send(JSON.stringify(data)) };
}
