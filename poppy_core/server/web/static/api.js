// The robot's API as the page uses it: fetch with the token, and the WebSocket state stream.
// The token is asked once and kept in localStorage; HTTP requests carry it in the
// Authorization header. Browsers cannot give a WebSocket a header: it goes as a subprotocol
// "poppy-token.<hex>", so no URL ever holds it.

const TOKEN_KEY = "poppy-token";
let asking = null;

export function token() {
  return localStorage.getItem(TOKEN_KEY) || "";
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
        resolve();
      });
      dialog.showModal();
      input.focus();
    });
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
    if (token()) headers.Authorization = `Bearer ${token()}`;
    if (body !== undefined) headers["Content-Type"] = "application/json";
    const response = await fetch(path, {
      method, headers, body: body === undefined ? undefined : JSON.stringify(body),
    });
    if (response.status === 401) {
      await askToken(Boolean(token()));
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
export function openStream(rateHz, onFrame, onStatus) {
  let socket = null;
  let retry = 500;
  function connect() {
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    const url = `${scheme}://${location.host}/api/v1/ws?rate_hz=${rateHz}`;
    socket = token() ? new WebSocket(url, [`poppy-token.${hex(token())}`]) : new WebSocket(url);
    socket.onopen = () => { retry = 500; onStatus(true); };
    socket.onmessage = (event) => {
      const data = JSON.parse(event.data);
      if (!data.error && !data.type) onFrame(data);
    };
    socket.onclose = () => {
      onStatus(false);
      setTimeout(async () => {
        try { await get("/api/v1/web/about"); } catch { /* the next try says */ }
        connect();
      }, retry);
      retry = Math.min(retry * 2, 5000);
    };
  }
  connect();
  return { send: (data) => socket && socket.readyState === 1 && socket.send(JSON.stringify(data)) };
}
