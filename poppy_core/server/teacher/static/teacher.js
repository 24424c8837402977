// The teacher's page: one card per robot of the fleet, kept live by the server's stream (fed by
// the fleet's Zenoh subscriptions); commands to the robots selected, one Stop for all. The API
// calls and the token prompt are the robot page's (/web/api.js).
import { get, post, token } from "/web/api.js";
import { el, say } from "/web/ui.js";

const selected = new Set();
const cards = new Map(); // name -> {node, parts}
let robots = [];
const stats = { frames: 0 };
window.teacher = { stats, selected };

function hex(text) {
  return [...new TextEncoder().encode(text)].map((b) => b.toString(16).padStart(2, "0")).join("");
}

function doing(robot) {
  const parts = [];
  if (robot.playing.length) parts.push(`playing ${robot.playing.join(", ")}`);
  if (robot.running.length) parts.push(`running ${robot.running.join(", ")}`);
  return parts.join("; ") || "nothing";
}

function temperature(robot) {
  if (robot.temperature === null) return "–";
  return `${robot.temperature.toFixed(0)}\u00a0°C (${robot.hottest})`;
}

function newCard(name) {
  const box = el("input", { type: "checkbox", className: "pick" });
  box.setAttribute("aria-label", `select ${name}`);
  box.addEventListener("change", () => {
    if (box.checked) selected.add(name); else selected.delete(name);
    refreshSelection();
  });
  const parts = {
    box,
    creature: el("dd", { className: "creature" }),
    health: el("dd", { className: "health" }),
    temperature: el("dd", { className: "temperature" }),
    doing: el("dd", { className: "doing" }),
    outcome: el("p", { className: "outcome", role: "status" }),
    thumb: el("div", { className: "thumb" }),
  };
  const node = el("article", { className: "robot-card", id: `robot-${name}` },
    el("h3", {}, el("label", {}, box, el("span", { className: "name", textContent: name }))),
    el("dl", {},
      el("dt", { textContent: "creature" }), parts.creature,
      el("dt", { textContent: "health" }), parts.health,
      el("dt", { textContent: "temperature" }), parts.temperature,
      el("dt", { textContent: "doing" }), parts.doing),
    parts.outcome, parts.thumb);
  node.dataset.robot = name;
  return { node, parts, cameras: "" };
}

function cameraButtons(card, robot) {
  const key = JSON.stringify([robot.cameras, robot.no_camera, robot.alive]);
  if (card.cameras === key) return;
  card.cameras = key;
  const views = robot.cameras.map((camera) => {
    const image = el("img", { alt: `${robot.name}: ${camera.label}` });
    image.hidden = true;
    const show = el("button", { type: "button", textContent: `Camera: ${camera.name}` });
    show.title = `Ask ${robot.name} for one picture of ${camera.label}`;
    show.addEventListener("click", () => thumbnail(robot.name, camera.name, image, card));
    return el("div", { className: "camera" }, show, image);
  });
  if (!views.length && robot.described) views.push(el("p", { className: "muted", textContent: robot.no_camera }));
  card.parts.thumb.replaceChildren(...views);
}

async function thumbnail(name, camera, image, card) {
  const path = `/api/v1/fleet/robots/${encodeURIComponent(name)}/cameras/${encodeURIComponent(camera)}/frame.jpg`;
  for (let attempt = 0; attempt < 2; attempt += 1) {
    const headers = token() ? { Authorization: `Bearer ${token()}` } : {};
    const response = await fetch(path, { headers });
    if (response.status === 401 && attempt === 0) {
      await get("/api/v1/fleet/robots"); // asks for the token, as every call does
      continue;
    }
    if (!response.ok) {
      let why = response.statusText;
      try { why = (await response.json()).detail || why; } catch { /* not JSON */ }
      card.parts.outcome.textContent = why;
      card.parts.outcome.className = "outcome error";
      return;
    }
    if (image.src) URL.revokeObjectURL(image.src);
    image.src = URL.createObjectURL(await response.blob());
    image.hidden = false;
    card.parts.outcome.textContent = `${camera}: the picture of ${new Date().toLocaleTimeString()}`;
    card.parts.outcome.className = "outcome muted";
    return;
  }
}

function render(list) {
  robots = list;
  const container = document.getElementById("fleet-cards");
  for (const robot of list) {
    let card = cards.get(robot.name);
    if (!card) {
      card = newCard(robot.name);
      cards.set(robot.name, card);
    }
    const { node, parts } = card;
    parts.creature.textContent = robot.creature || "…";
    parts.health.textContent = robot.health;
    parts.health.className = `health ${robot.ok ? "ok" : "bad"}`;
    parts.temperature.textContent = temperature(robot);
    parts.doing.textContent = doing(robot);
    parts.box.checked = selected.has(robot.name);
    node.classList.toggle("gone", !robot.alive);
    node.classList.toggle("selected", selected.has(robot.name));
    cameraButtons(card, robot);
  }
  container.replaceChildren(...list.map((robot) => cards.get(robot.name).node));
  const here = list.filter((robot) => robot.alive).length;
  document.getElementById("fleet-count").textContent = `${here} robot${here === 1 ? "" : "s"}`;
  document.getElementById("no-robot").hidden = list.length > 0;
  refreshSelection();
}

function fill(select, names) {
  const kept = select.value;
  select.replaceChildren(...names.map((name) => el("option", { value: name, textContent: name })));
  if (names.includes(kept)) select.value = kept;
}

// The moves and behaviours the selected robots have (any of them: each robot answers).
function refreshSelection() {
  for (const [name, card] of cards) card.node.classList.toggle("selected", selected.has(name));
  const chosen = robots.filter((robot) => selected.has(robot.name));
  const union = (key) => [...new Set(chosen.flatMap((robot) => robot[key]))].sort();
  fill(document.getElementById("move-choice"), union("moves"));
  fill(document.getElementById("primitive-choice"), union("primitives"));
  document.getElementById("selected-count").textContent = chosen.length
    ? chosen.map((robot) => robot.name).join(", ") : "none: tick the robots' cards";
  document.getElementById("play").disabled = !chosen.length || !union("moves").length;
  document.getElementById("run").disabled = !chosen.length || !union("primitives").length;
}

function report(answer, what) {
  const failed = answer.outcomes.filter((outcome) => !outcome.ok);
  for (const outcome of answer.outcomes) {
    const card = cards.get(outcome.name);
    if (!card) continue;
    card.parts.outcome.textContent = outcome.ok ? `${what}: done` : outcome.message;
    card.parts.outcome.className = `outcome ${outcome.ok ? "muted" : "error"}`;
  }
  const done = answer.outcomes.filter((outcome) => outcome.ok).map((outcome) => outcome.name);
  const lines = [];
  const together = answer.start_at !== null && done.length > 1 ? ", started together" : "";
  if (done.length) lines.push(`${what}: ${done.join(", ")}${together}`);
  for (const outcome of failed) lines.push(`${outcome.name}: ${outcome.message}`);
  say(lines.join(" · "), failed.length > 0);
}

async function command(path, body, what) {
  try {
    report(await post(path, body), what);
  } catch (error) {
    say(`${what} failed: ${error.message}`, true);
  }
}

document.getElementById("play-form").addEventListener("submit", (event) => {
  event.preventDefault();
  const move = document.getElementById("move-choice").value;
  const ramp = document.getElementById("ramp").value;
  const body = { move, robots: [...selected] };
  if (ramp !== "") body.ramp_s = Number(ramp);
  command("/api/v1/fleet/play", body, `play ${move}`);
});

document.getElementById("run-form").addEventListener("submit", (event) => {
  event.preventDefault();
  const primitive = document.getElementById("primitive-choice").value;
  command("/api/v1/fleet/run", { primitive, robots: [...selected] }, `start ${primitive}`);
});

function stopAll() {
  command("/api/v1/fleet/stop", {}, "stop (motors held)");
}

document.getElementById("stop-all").addEventListener("click", stopAll);
document.addEventListener("keydown", (event) => {
  if (event.key === "Escape" && !document.getElementById("stop-all").disabled) stopAll();
});
document.getElementById("select-all").addEventListener("click", () => {
  for (const robot of robots) if (robot.alive) selected.add(robot.name);
  render(robots);
});
document.getElementById("select-none").addEventListener("click", () => {
  selected.clear();
  render(robots);
});

function connected(up) {
  document.body.classList.toggle("offline", !up);
  document.getElementById("offline").hidden = up;
  document.getElementById("live").disabled = !up;
  document.getElementById("stop-all").disabled = !up;
  const badge = document.getElementById("conn");
  badge.textContent = up ? "live" : "reconnecting…";
  badge.className = `badge ${up ? "ok" : "bad"}`;
}

// The stream of cards: the token as a subprotocol (no URL holds it); on a close, one API call
// (which asks for the token on a 401) before connecting again.
function openStream() {
  let retry = 500;
  function connect() {
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    const url = `${scheme}://${location.host}/api/v1/fleet/ws`;
    const socket = token() ? new WebSocket(url, [`poppy-token.${hex(token())}`]) : new WebSocket(url);
    socket.onmessage = (event) => {
      retry = 500;
      stats.frames += 1;
      connected(true);
      render(JSON.parse(event.data).robots);
    };
    socket.onclose = () => {
      connected(false);
      setTimeout(async () => {
        try { await get("/api/v1/fleet/robots"); } catch { /* the next try says */ }
        connect();
      }, retry);
      retry = Math.min(retry * 2, 5000);
    };
  }
  connect();
}

async function start() {
  try {
    render(await get("/api/v1/fleet/robots"));
  } catch (error) {
    say(`The fleet did not answer: ${error.message}`, true);
  }
  openStream();
}

start();
