// Moves: the library, record (chosen motors), stop and save, play (speed, backwards), delete, plot.
import { api, get, post } from "./api.js";
import { button, el, say, secondsText, sizeText } from "./ui.js";

let recording = null;
const COLOURS = ["#2b6cb0", "#c53030", "#2f855a", "#b7791f", "#6b46c1", "#319795", "#d53f8c", "#4a5568"];

export function setupRecorder(motors) {
  const box = document.getElementById("record-motors");
  for (const name of motors) {
    box.append(el("label", {}, el("input", { type: "checkbox", name: "motor", value: name, checked: true }), ` ${name}`));
  }
  const form = document.getElementById("record-form");
  const save = document.getElementById("record-save");
  form.addEventListener("submit", async (event) => {
    event.preventDefault();
    const name = document.getElementById("record-name").value;
    const chosen = [...box.querySelectorAll("input:checked")].map((i) => i.value);
    if (!chosen.length) { say("choose at least one motor to record", true); return; }
    try {
      await post(`/api/v1/moves/${name}/record`, { motors: chosen });
      recording = name;
      say(`recording ${name} (${chosen.join(", ")}): move the robot, then Stop & save`);
    } catch (error) { say(error.message, true); }
    refreshMoves();
  });
  save.addEventListener("click", async () => {
    if (!recording) return;
    try {
      const move = await post(`/api/v1/moves/${recording}/save`);
      say(`saved ${move.name}: ${move.frames} frames, ${move.duration_s.toFixed(1)} s`);
      recording = null;
    } catch (error) { say(error.message, true); }
    refreshMoves();
  });
}

async function play(name, speed, backwards) {
  try {
    await post(`/api/v1/moves/${name}/play`, { speed, backwards });
    say(`playing ${name}${backwards ? " backwards" : ""} at ×${speed}`);
  } catch (error) { say(`${name}: ${error.message}`, true); }
  refreshMoves();
}

async function remove(name) {
  if (!confirm(`Delete the move ${name} from the library?`)) return;
  try { await api("DELETE", `/api/v1/moves/${name}`); say(`deleted ${name}`); } catch (error) { say(error.message, true); }
  refreshMoves();
}

// Plot area in the SVG's viewBox (600 × 232): time along x, degrees along y.
const AREA = { left: 44, right: 590, top: 10, bottom: 190 };
const SVG_NS = "http://www.w3.org/2000/svg";

function svgNode(tag, attributes, text) {
  const node = document.createElementNS(SVG_NS, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (text !== undefined) node.textContent = text;
  return node;
}

// Ticks for 0..span: a round step (1, 2 or 5 × a power of ten), about six of them.
export function ticks(span, wanted = 6) {
  if (!(span > 0)) return { step: 1, values: [0] };
  const raw = span / wanted;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 5, 10].map((m) => m * power).find((s) => s >= raw);
  const values = [];
  for (let i = 0; i * step <= span * (1 + 1e-9); i += 1) values.push(i * step);
  return { step, values };
}

function timeAxis(svg, duration, x) {
  const { step, values } = ticks(duration);
  const digits = Math.max(0, -Math.floor(Math.log10(step) + 1e-9));
  const axis = svgNode("g", { class: "x-axis" });
  axis.append(svgNode("line", { x1: AREA.left, x2: AREA.right, y1: AREA.bottom, y2: AREA.bottom }));
  for (const t of values) {
    const at = x(t).toFixed(1);
    axis.append(svgNode("line", { x1: at, x2: at, y1: AREA.bottom, y2: AREA.bottom + 4 }),
      svgNode("text", { x: at, y: AREA.bottom + 17, class: "tick", "data-seconds": String(t) }, t.toFixed(digits)));
  }
  axis.append(svgNode("text", { x: (AREA.left + AREA.right) / 2, y: AREA.bottom + 36, class: "label" }, "time (s)"));
  svg.append(axis);
}

export async function plot(name) {
  const move = await get(`/api/v1/moves/${name}?positions=true`);
  const svg = document.getElementById("plot-svg");
  const frames = move.positions || [];
  const values = frames.flat();
  const low = Math.min(...values, -1), high = Math.max(...values, 1);
  const duration = Math.max(move.duration_s, 0);
  const x = (t) => AREA.left + ((AREA.right - AREA.left) * t) / (duration || 1);
  const y = (v) => AREA.bottom - ((AREA.bottom - AREA.top) * (v - low)) / (high - low);
  svg.replaceChildren(
    svgNode("text", { x: 2, y: AREA.top + 4, class: "axis" }, `${high.toFixed(0)}°`),
    svgNode("text", { x: 2, y: AREA.bottom, class: "axis" }, `${low.toFixed(0)}°`));
  timeAxis(svg, duration, x);
  move.motors.forEach((motor, m) => {
    const points = frames.map((f, i) => `${x(i / move.framerate).toFixed(1)},${y(f[m]).toFixed(1)}`);
    const line = svgNode("polyline", { points: points.join(" "), stroke: COLOURS[m % COLOURS.length], fill: "none" });
    line.append(svgNode("title", {}, motor));
    svg.append(line);
  });
  svg.setAttribute("aria-label", `positions of ${move.motors.join(", ")} over ${move.duration_s.toFixed(1)} s`);
  const legend = move.motors.map((m, i) =>
    el("span", { className: "swatch", textContent: m, style: `border-color: ${COLOURS[i % COLOURS.length]}` }));
  document.getElementById("plot-title").replaceChildren(
    `${name} (${secondsText(move.duration_s)}): `, ...legend);
  document.getElementById("plot").hidden = false;
}

function row(entry, playing) {
  const speed = el("input", { type: "number", min: "0.1", max: "10", step: "0.1", value: "1", size: 4 });
  speed.setAttribute("aria-label", `${entry.name} speed`);
  const back = el("input", { type: "checkbox" });
  back.setAttribute("aria-label", `${entry.name} backwards`);
  const tr = el("tr", { id: `move-${entry.name}` },
    el("th", { scope: "row", textContent: entry.name + (playing ? " ▶" : "") }),
    el("td", { className: "num duration", textContent: entry.duration_s == null ? "unreadable" : secondsText(entry.duration_s) }),
    el("td", { className: "num size", textContent: sizeText(entry.size_bytes) }),
    el("td", {}, el("label", {}, "×", speed), el("label", {}, back, " backwards"),
      button("play", () => play(entry.name, Number(speed.value), back.checked), `play ${entry.name}`),
      button("stop", async () => { try { await post(`/api/v1/moves/${entry.name}/stop`); } catch (e) { say(e.message, true); } refreshMoves(); }, `stop ${entry.name}`)),
    el("td", {}, button("plot", () => plot(entry.name).catch((e) => say(e.message, true)), `plot ${entry.name}`),
      button("delete", () => remove(entry.name), `delete ${entry.name}`)));
  tr.dataset.move = entry.name;
  return tr;
}

let shown = "";
let shownEntries = "";
export async function refreshMoves() {
  let entries, status;
  try {
    [entries, status] = await Promise.all([get("/api/v1/moves"), get("/api/v1/moves/status")]);
  } catch { return; }
  recording = status.recording[0] ?? null;
  document.getElementById("record-save").disabled = !recording;
  document.getElementById("record-state").textContent = recording ? `● recording ${recording}` : "";
  const key = JSON.stringify([entries, status.playing]);
  if (key === shown) return; // keep focus and typed speeds while nothing changed
  shown = key;
  const body = document.querySelector("#move-table tbody");
  const entriesKey = JSON.stringify(entries);
  if (entriesKey === shownEntries) {
    // only what plays changed: mark the rows in place, keeping typed speeds, the focus and a
    // click under way (a row drawn again as a replay ended took the click meant for it)
    for (const tr of body.rows) {
      tr.querySelector("th").textContent = tr.dataset.move + (status.playing.includes(tr.dataset.move) ? " ▶" : "");
    }
    return;
  }
  shownEntries = entriesKey;
  const names = [...new Set(entries.map((e) => e.name))];
  body.replaceChildren(...names.map((n) => row(entries.find((e) => e.name === n), status.playing.includes(n))));
}
