// The settings panel: the robot's name, Wi-Fi, services, token and version (/api/v1/settings).
// Read-only, with the reason, where the server cannot change them (no --token, no
// NetworkManager); every change goes through the API with the token, and the server logs it.
import { api, get, setToken } from "./api.js";
import { button, el, say } from "./ui.js";

let loaded = false;

function row(label, ...content) {
  return el("div", { className: "setting" }, el("strong", { textContent: `${label} ` }), ...content);
}

async function change(method, path, body, done) {
  try {
    const answer = await api(method, path, body);
    say(done(answer) + (answer.restarting ? " · poppy.service restarts: reconnecting…" : ""));
    if (answer.restarting) { await backAgain(); return; }
  } catch (error) {
    say(`Settings: ${error.message}`, true);
  }
  await showSettings();
}

// After a change that restarts the service: wait until the server answers again.
async function backAgain() {
  await new Promise((resolve) => setTimeout(resolve, 2000));
  for (let tries = 0; tries < 60; tries += 1) {
    try {
      await get("/api/v1/settings");
      await showSettings();
      say("Reconnected: the change is applied");
      return;
    } catch (error) {
      await new Promise((resolve) => setTimeout(resolve, 1000));
    }
  }
  await showSettings();
}

function nameRow(settings) {
  const input = el("input", {
    id: "settings-name", value: settings.name || settings.hostname || "", size: 16,
    pattern: "[A-Za-z0-9]([A-Za-z0-9-]{0,61}[A-Za-z0-9])?", disabled: !settings.editable,
  });
  input.setAttribute("aria-label", "robot name");
  const rename = button("Rename", () => change("PUT", "/api/v1/settings/name", { name: input.value },
    (answer) => `The robot is now ${answer.host}`));
  rename.id = "settings-rename";
  rename.disabled = !settings.editable;
  const where = settings.name ? ` (http://${settings.name}.local${settings.announced ? ", announced" : ""})` : "";
  return row("Name", input, " ", rename, el("span", { className: "muted", textContent: where }));
}

async function showNetworks(list, editable) {
  let wifi;
  try { wifi = await get("/api/v1/settings/wifi"); } catch (error) { say(`Wi-Fi: ${error.message}`, true); return; }
  const saved = new Set(wifi.saved.map((s) => s.name));
  list.replaceChildren(...wifi.networks.map((network) => {
    const password = el("input", { type: "password", size: 12, placeholder: "password", disabled: !editable });
    password.setAttribute("aria-label", `password of ${network.ssid}`);
    const join = button("Join", () => change("POST", "/api/v1/settings/wifi/join",
      { ssid: network.ssid, password: password.value || null }, () => `Joined ${network.ssid}`));
    join.disabled = !editable;
    const text = `${network.ssid} · ${network.signal}% · ${network.security}${network.in_use ? " · connected" : ""}`;
    const parts = [el("span", { textContent: text }), " ", password, " ", join];
    if (saved.has(network.ssid)) {
      const forget = button("Forget", () => change("POST", "/api/v1/settings/wifi/forget",
        { name: network.ssid }, () => `Forgot ${network.ssid}`));
      forget.disabled = !editable;
      parts.push(" ", forget);
    }
    return el("li", {}, ...parts);
  }));
}

function wifiRow(settings) {
  const list = el("ul", { id: "settings-networks", className: "buses" });
  const scan = button("Networks in range", () => showNetworks(list, settings.editable));
  scan.disabled = !settings.editable;
  const password = el("input", { type: "password", size: 12, placeholder: "8+ characters", disabled: !settings.editable });
  password.setAttribute("aria-label", "access point password");
  const on = button("Set up the access point", () => change("PUT", "/api/v1/settings/wifi/hotspot",
    { on: true, password: password.value }, (answer) => `Access point ${answer.ssid} ready when no known network answers`));
  const off = button("Remove it", () => change("PUT", "/api/v1/settings/wifi/hotspot", { on: false },
    () => "Access point removed"));
  on.disabled = off.disabled = !settings.editable;
  return el("div", {}, row("Wi-Fi", scan), list,
    row("Fallback access point", password, " ", on, " ", off));
}

function servicesRow(settings) {
  const items = Object.entries(settings.services).map(([name, service]) => {
    if (service.how === "settings") { // Snap!, ZMQ: the service's settings file, then it restarts
      const blocked = Boolean(service.reason) && !service.on; // ZMQ has no token: only turned off here
      const box = el("input", { id: `settings-${name}`, type: "checkbox", checked: Boolean(service.on), disabled: !settings.token_required || blocked });
      box.setAttribute("aria-label", `${name} on`);
      box.addEventListener("change", () => change("PUT", `/api/v1/settings/services/${name}`, { on: box.checked },
        (answer) => `${name} ${box.checked ? "on" : "off"}${answer.restarting ? "" : " at the next start"}`));
      const why = service.reason ? el("span", { className: "muted", textContent: ` (${service.reason})` }) : "";
      return el("li", {}, el("label", {}, box, ` ${name} (poppy.service)`), why);
    }
    if (service.how !== "systemctl") {
      return el("li", { textContent: `${name}: ${service.on ? "on" : "off"} (poppy serve ${service.how.replace("serve ", "")})` });
    }
    const box = el("input", { type: "checkbox", checked: Boolean(service.on), disabled: !settings.editable || service.on === null });
    box.setAttribute("aria-label", `${name} on`);
    box.addEventListener("change", () => change("PUT", `/api/v1/settings/services/${name}`, { on: box.checked },
      () => `${name} ${box.checked ? "started" : "stopped"}`));
    return el("li", {}, el("label", {}, box, ` ${name} (${service.unit})`));
  });
  return row("Services", el("ul", { className: "buses" }, ...items));
}

function tokenRow(settings) {
  if (!settings.token_changeable) {
    const shown = settings.token_required ? "required (given on the server's command line)" : "none";
    return row("Token", el("span", { id: "settings-token", textContent: shown }));
  }
  const input = el("input", { id: "settings-new-token", type: "password", size: 16, placeholder: "12+ characters" });
  input.setAttribute("aria-label", "new token");
  const apply = button("Change the token", () => {
    const chosen = input.value;
    return change("PUT", "/api/v1/settings/token", { token: chosen }, (answer) => {
      if (answer.restarting) setToken(chosen); // the server keeps the old one until it starts again
      return `Token changed${answer.restarting ? "" : " (it applies at the next start)"}`;
    });
  });
  apply.id = "settings-change-token";
  return row("Token", el("span", { textContent: "required " }), input, " ", apply);
}

export async function showSettings() {
  const body = document.getElementById("settings-body");
  let settings;
  try { settings = await get("/api/v1/settings"); } catch (error) { body.textContent = error.message; return; }
  const reason = el("p", { id: "settings-reason", className: "muted", hidden: settings.editable,
    textContent: settings.editable ? "" : `Read-only here: ${settings.reason}` });
  body.replaceChildren(reason, nameRow(settings), wifiRow(settings), servicesRow(settings),
    tokenRow(settings),
    row("Version", el("span", { id: "settings-version", textContent: `poppy ${settings.version}` })));
}

// One click on the header's Settings opens the panel at the top of the page (read when first
// opened: it asks the OS, not on every page load); again, or its close button, hides it.
export function setupSettings() {
  const panel = document.getElementById("settings");
  const open = document.getElementById("settings-open");
  const show = (on) => {
    panel.hidden = !on;
    open.setAttribute("aria-expanded", String(on));
    if (on && !loaded) { loaded = true; showSettings(); }
    if (on) window.scrollTo({ top: 0 }); // the panel heads the page, under the header
  };
  open.addEventListener("click", () => show(panel.hidden));
  document.getElementById("settings-close").addEventListener("click", () => { show(false); open.focus(); });
}
