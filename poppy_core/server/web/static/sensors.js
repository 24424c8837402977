// The sensors panel: every sensor that is not a camera (detectors, IMUs, sonar, Arduino, contact,
// Kinect, camera pose), its kind, its health and its registers' values, read twice a second.
// Values come from /api/v1/sensors/<name> (every register in one request), health from
// /api/v1/sensors/health; a sensor whose read fails shows the server's reason, nothing else breaks.
import { ApiError, get } from "./api.js";
import { count, el } from "./ui.js";

const POLL_S = 0.5;

const fixed = (v, digits) => (typeof v === "number" ? v.toFixed(digits) : String(v));
// "yaw 0.0° · pitch …": an axis and its value never split over two lines
const NBSP = "\u00a0";
const axes = (value, keys, digits, unit) =>
  keys.map((k) => `${k}${NBSP}${fixed(value[k], digits)}${unit.replace(" ", NBSP)}`).join(" · ");

// A point or a list of numbers as "(12, 34)"
const point = (list) => `(${list.map((v) => fixed(v, Number.isInteger(v) ? 0 : 2)).join(", ")})`;

// What one detection says in a line: a blob, a marker, a face.
function detection(item) {
  const parts = [];
  if (item.id !== undefined) parts.push(`id ${item.id}`);
  if (Array.isArray(item.center)) parts.push(`at ${point(item.center)}`);
  if (item.radius !== undefined) parts.push(`radius ${item.radius}`);
  if (item.camera) parts.push(`in ${item.camera}`);
  return parts.join(" ");
}

function listed(list, noun) {
  if (!list.length) return count(0, noun);
  return `${count(list.length, noun)} · first: ${detection(list[0])}`;
}

// Each register's value as text: the known ones in their units, others as compact JSON.
const FORMATS = {
  orientation: (v) => axes(v, ["yaw", "pitch", "roll"], 1, "°"),
  acceleration: (v) => (v === null ? "not measured" : axes(v, ["x", "y", "z"], 2, " m/s²")),
  angular_velocity: (v) => (v === null ? "not measured" : axes(v, ["x", "y", "z"], 1, " °/s")),
  quaternion: (v) => `w, x, y, z ${point(v.map((q) => Number(q.toFixed(3))))}`,
  blobs: (v) => listed(v, "blob"),
  markers: (v) => listed(v, "marker"),
  faces: (v) => listed(v, "face"),
  cards: (v) => (v.length ? v.join(", ") : "none"),
  distance: (v) => `${fixed(v, 2)} m`,
  contact: (v) => (v ? "closed" : "open"),
  tracked_skeleton: (v) => {
    const users = Object.keys(v);
    return users.length ? `${count(users.length, "user")} tracked: ${users.join(", ")}` : "no user tracked";
  },
  sensor_dict: (v) => {
    const entries = Object.entries(v);
    return entries.length ? entries.map(([k, x]) => `${k} ${JSON.stringify(x)}`).join(" · ") : "nothing yet";
  },
};

function valueText(register, value) {
  const format = FORMATS[register];
  if (format) {
    try { return format(value); } catch { /* an unexpected shape: shown as it is */ }
  }
  return typeof value === "string" ? value : JSON.stringify(value);
}

function healthText(health) {
  if (!health) return "";
  if (!health.ok) return `lost · ${health.last_error || "no answer"}`;
  return health.running ? `ok · ${health.rate_hz.toFixed(0)} Hz` : "ok · idle";
}

function card(name, kind) {
  const health = el("span", { className: "sensor-health" });
  const values = el("dl", { className: "sensor-values" });
  const error = el("p", { className: "sensor-error error", hidden: true });
  const node = el("article", { className: "card sensor", id: `sensor-${name}` },
    el("h3", {}, name, " ", el("span", { className: "muted sensor-kind", textContent: kind })),
    health, values, error);
  return { node, health, values, error };
}

function showHealth(view, health) {
  view.health.textContent = healthText(health);
  view.health.className = `sensor-health ${health && !health.ok ? "bad" : "ok"}`;
}

function showValues(view, answer) {
  if (answer.error !== undefined) { // the read failed: the reason, the last values greyed
    view.error.textContent = `cannot read: ${answer.error}`;
    view.error.hidden = false;
    view.values.classList.add("stale");
    return;
  }
  view.error.hidden = true;
  view.values.classList.remove("stale");
  view.values.replaceChildren(...Object.entries(answer.registers).flatMap(([register, value]) => {
    const dd = el("dd", { textContent: valueText(register, value) });
    dd.dataset.register = register;
    return [el("dt", { textContent: register }), dd];
  }));
}

// Builds the panel from the page's `about` (its sensors and which are cameras) and polls it;
// no sensor but cameras: the panel stays hidden.
export function setupSensors(about) {
  const cameras = new Set(about.cameras ?? []);
  const kinds = Object.entries(about.sensors ?? {}).filter(([name]) => !cameras.has(name));
  const section = document.getElementById("sensor-panel");
  if (!kinds.length) { section.hidden = true; return; }
  const views = new Map(kinds.map(([name, health]) => [name, card(name, health.kind)]));
  document.getElementById("sensor-list").replaceChildren(...[...views.values()].map((v) => v.node));
  for (const [name, health] of kinds) showHealth(views.get(name), health);
  section.hidden = false;
  const read = (name) => get(`/api/v1/sensors/${encodeURIComponent(name)}`)
    .then((answer) => showValues(views.get(name), answer),
      (error) => { // the server's reason; no connection at all is the badge's to say
        if (error instanceof ApiError) showValues(views.get(name), { error: error.message });
      });
  const poll = async () => {
    // one request for every health, one per sensor for its values; the next poll waits for
    // this one (a first read may wait for the sensor's first value)
    const health = get("/api/v1/sensors/health").then((all) => {
      for (const [name, view] of views) showHealth(view, all[name]);
    }, () => { /* no connection: the badge says */ });
    await Promise.all([health, ...[...views.keys()].map(read)]);
    setTimeout(poll, POLL_S * 1000);
  };
  poll();
}
