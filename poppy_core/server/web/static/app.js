// The robot's home page: fetches who the robot is, builds each part, keeps them live.
import { api, get, onTokenAsked, openStream, post, tokenAsked } from "./api.js";
import { setupDatasets } from "./datasets.js";
import { showCameras, showChains } from "./extras.js";
import { refreshFleet } from "./fleet.js";
import { buildTable, onFrame, refresh, stats } from "./motors.js";
import { refreshMoves, setupRecorder } from "./moves.js";
import { notebookLink, notes } from "./notebook.js";
import { refreshPrimitives } from "./primitives.js";
import { setupSensors } from "./sensors.js";
import { setupSettings } from "./settings.js";
import { count, el, every, say } from "./ui.js";
import { setupView, viewFrame } from "./view-panel.js";

const STREAM_HZ = 20;
let uptimeBase = null;
let live = false; // frames are arriving: the page shows the robot as it is
let everLive = false; // the page has shown the robot: its values may be stale now

function duration(seconds) {
  const s = Math.floor(seconds);
  const h = Math.floor(s / 3600), m = Math.floor((s % 3600) / 60);
  return h ? `${h} h ${m} min` : m ? `${m} min ${s % 60} s` : `${s} s`;
}

// The links for programmers sit with the robot; the header keeps those a class uses (Snap!,
// Jupyter), short enough not to wrap it.
const DEV_LINKS = new Set(["API docs", "routes"]);

function link(name, url) {
  return el("a", { href: url, textContent: name, target: name === "routes" ? "" : "_blank", rel: "noopener" });
}

function showAbout(about) {
  document.getElementById("robot-name").textContent = about.name;
  // the creature beside the name, once (a robot served without --name is named after it)
  const creature = about.creature === about.name ? "" : about.creature;
  document.getElementById("creature").textContent = creature;
  document.title = `${about.name} · ${creature || "poppy"}`;
  document.getElementById("description").textContent = about.description;
  document.getElementById("sim-badge").hidden = !about.simulated;
  uptimeBase = { at: performance.now(), uptime: about.uptime_s };
  const buses = document.getElementById("buses");
  buses.replaceChildren(...Object.entries(about.buses).map(([name, bus]) => {
    const rate = bus.loop_hz?.present ?? 0;
    const text = bus.ok ? `ok · ${rate.toFixed(0)} Hz` : `${bus.connected ? "trouble" : "lost"}` +
      (bus.offline?.length ? ` · offline: ${bus.offline.join(", ")}` : "");
    return el("li", { className: bus.ok ? "ok" : "bad" },
      el("strong", { textContent: bus.label || name }), ` ${bus.port}: ${text}`);
  }));
  const sensors = Object.entries(about.sensors ?? {});
  document.getElementById("sensors").replaceChildren(...sensors.map(([name, sensor]) => {
    const text = sensor.ok ? (sensor.running ? `ok · ${sensor.rate_hz.toFixed(0)} Hz` : "ok · idle")
      : `lost · ${sensor.last_error}`;
    return el("li", { className: sensor.ok ? "ok" : "bad" },
      el("strong", { textContent: name }), ` ${sensor.kind}: ${text}`);
  }));
  const entries = Object.entries(about.links);
  const shown = [...entries.filter(([name]) => !DEV_LINKS.has(name)).map(([n, u]) => link(n, u)),
    notebookLink(about)].filter(Boolean);
  document.getElementById("links").replaceChildren(...shown);
  const dev = entries.filter(([name]) => DEV_LINKS.has(name)).map(([n, u]) => link(n, u));
  document.getElementById("dev-links").replaceChildren(
    ...(dev.length ? ["For programmers: ", ...dev.flatMap((a, i) => (i ? [" · ", a] : [a]))] : []),
    ...notes(about).flatMap((note) => [el("br"), note]));
}

function tickUptime() {
  if (uptimeBase && live) {
    const now = uptimeBase.uptime + (performance.now() - uptimeBase.at) / 1000;
    document.getElementById("uptime").textContent = duration(now);
  }
}

let lastLog = 0;
async function refreshLogs() {
  let lines;
  try { lines = await get(`/api/v1/web/logs?after=${lastLog}`); } catch { return; }
  const list = document.getElementById("log-lines");
  for (const line of lines) {
    lastLog = line.n;
    const time = new Date(line.time * 1000).toLocaleTimeString();
    list.append(el("li", { className: line.level.toLowerCase() },
      el("time", { textContent: time }), ` ${line.level} ${line.logger}: ${line.message}`));
  }
  while (list.children.length > 200) list.firstChild.remove();
  if (lines.length) list.scrollTop = list.scrollHeight;
}

// One click stops: every primitive and move, motors held where they are. The dialog that
// follows is not modal: it offers to make the motors compliant and blocks nothing.
async function stopAll() {
  const dialog = document.getElementById("stop-dialog");
  try {
    const done = await post("/api/v1/web/stop", { then: "hold" });
    const what = `${count(done.primitives.length, "primitive")} and ${count(done.moves.length, "move")} stopped`;
    say(`Stopped: ${what}; motors held where they are`);
    document.getElementById("stop-what").textContent = `${what}.`;
    if (!dialog.open) dialog.show();
    document.getElementById("stop-keep").focus();
  } catch (error) { say(`Stop failed: ${error.message}`, true); }
  refresh(); refreshPrimitives(); refreshMoves();
}

function setupStop() {
  const dialog = document.getElementById("stop-dialog");
  document.getElementById("stop-all").addEventListener("click", stopAll);
  document.getElementById("stop-keep").addEventListener("click", () => dialog.close());
  document.getElementById("stop-compliant").addEventListener("click", async () => {
    dialog.close();
    try {
      await api("PUT", "/api/v1/robot/compliant", { compliant: true });
      say("Stopped; motors compliant");
    } catch (error) { say(error.message, true); }
    refresh();
  });
  // Escape anywhere (but in the token dialog) stops at once, like the button
  document.addEventListener("keydown", (event) => {
    if (event.key !== "Escape" || document.getElementById("token-dialog").open) return;
    event.preventDefault();
    document.getElementById("stop-all").click();
  });
}

// The stream is up (frames arriving) or down: down, everything is greyed out and every control
// is off (the values shown are the last received, not the robot's); back, all is read again.
// Before the first frame there is nothing stale to warn about: the badge says what the page
// waits for (the token, or the robot), and no outage banner shows.
function setLive(up) {
  const conn = document.getElementById("conn");
  const waiting = !up && !everLive;
  conn.textContent = up ? "connected" : waiting ? (tokenAsked() ? "token needed" : "connecting…") : "disconnected";
  conn.className = `badge ${up ? "ok" : waiting ? "" : "bad"}`;
  const wasDown = !live;
  live = up;
  everLive = everLive || up;
  document.body.classList.toggle("offline", !up && everLive);
  document.getElementById("live").disabled = !up;
  document.getElementById("stop-all").disabled = !up;
  document.getElementById("offline").hidden = up || !everLive;
  if (!up) {
    document.getElementById("stop-dialog").close();
    document.getElementById("rate").textContent = "not live: no connection";
  } else if (wasDown) {
    document.getElementById("rate").textContent = "live";
  }
  if (up && wasDown && window.poppy.ready) {
    refresh(); refreshPrimitives(); refreshMoves();
    get("/api/v1/web/about").then(showAbout, () => { /* the badge says */ });
  }
}

function rateMeter() {
  let frames = stats.frames, at = performance.now();
  setInterval(() => {
    const now = performance.now();
    stats.rateHz = ((stats.frames - frames) * 1000) / (now - at);
    frames = stats.frames; at = now;
    if (live) document.getElementById("rate").textContent = `live · ${count(Math.round(stats.rateHz), "update")}/s`;
  }, 2000);
}

async function main() {
  window.poppy = { stats };
  setupStop();
  setupSettings();
  onTokenAsked(() => { if (!live) setLive(false); }); // the badge says what the page waits for
  // the stream opens at once and every first request goes out together: first values sooner
  openStream(STREAM_HZ, (frame) => { onFrame(frame); viewFrame(frame); }, setLive);
  const [about, details] = await Promise.all([
    get("/api/v1/web/about"), get("/api/v1/web/motors?leds=true"),
  ]);
  showAbout(about);
  setupView(about);
  setupDatasets();
  const motors = Object.keys(details.motors); // in the robot's order
  buildTable(motors, details);
  setupRecorder(motors);
  showCameras(about);
  setupSensors(about);
  showChains(about.chains);
  rateMeter();
  every(1, tickUptime);
  every(0.5, refresh);
  every(1, refreshPrimitives);
  every(1.5, refreshMoves);
  every(2, refreshLogs);
  every(5, refreshFleet);
  every(5, async () => { try { showAbout(await get("/api/v1/web/about")); } catch { /* badge */ } });
  window.poppy.ready = true;
}

main().catch((error) => say(`the page could not start: ${error.message}`, true));
