// Moves: the library, record (chosen motors), stop and save, play (speed, backwards), delete, plot.
import { api, get, post } from "./api.js";
import { button, el, say } from "./ui.js";

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
}

async function remove(name) {
  if (!confirm(`Delete the move ${name} from the library?`)) return;
  try { await api("DELETE", `/api/v1/moves/${name}`); say(`deleted ${name}`); } catch (error) { say(error.message, true); }
  refreshMoves();
}

export async function plot(name) {
  const move = await get(`/api/v1/moves/${name}?positions=true`);
  const svg = document.getElementById("plot-svg");
  const frames = move.positions || [];
  const values = frames.flat();
  const low = Math.min(...values, -1), high = Math.max(...values, 1);
  const x = (i) => 40 + (550 * i) / Math.max(frames.length - 1, 1);
  const y = (v) => 190 - (180 * (v - low)) / (high - low);
  const ns = "http://www.w3.org/2000/svg";
  svg.replaceChildren();
  const axis = document.createElementNS(ns, "text");
  Object.entries({ x: 2, y: 14, class: "axis" }).forEach(([k, v]) => axis.setAttribute(k, v));
  axis.textContent = `${high.toFixed(0)}°`;
  const bottom = axis.cloneNode();
  bottom.setAttribute("y", 195);
  bottom.textContent = `${low.toFixed(0)}°`;
  svg.append(axis, bottom);
  move.motors.forEach((motor, m) => {
    const line = document.createElementNS(ns, "polyline");
    line.setAttribute("points", frames.map((f, i) => `${x(i).toFixed(1)},${y(f[m]).toFixed(1)}`).join(" "));
    line.setAttribute("stroke", COLOURS[m % COLOURS.length]);
    line.setAttribute("fill", "none");
    const title = document.createElementNS(ns, "title");
    title.textContent = motor;
    line.append(title);
    svg.append(line);
  });
  svg.setAttribute("aria-label", `positions of ${move.motors.join(", ")} over ${move.duration_s.toFixed(1)} s`);
  const legend = move.motors.map((m, i) =>
    el("span", { className: "swatch", textContent: m, style: `border-color: ${COLOURS[i % COLOURS.length]}` }));
  document.getElementById("plot-title").replaceChildren(
    `${name} (${move.duration_s.toFixed(1)} s): `, ...legend);
  document.getElementById("plot").hidden = false;
}

function row(entry, playing) {
  const speed = el("input", { type: "number", min: "0.1", max: "10", step: "0.1", value: "1", size: 4 });
  speed.setAttribute("aria-label", `${entry.name} speed`);
  const back = el("input", { type: "checkbox" });
  back.setAttribute("aria-label", `${entry.name} backwards`);
  const tr = el("tr", { id: `move-${entry.name}` },
    el("th", { scope: "row", textContent: entry.name + (playing ? " ▶" : "") }),
    el("td", { className: "num", textContent: `${(entry.size_bytes / 1024).toFixed(1)} kB` }),
    el("td", {}, el("label", {}, "×", speed), el("label", {}, back, " backwards"),
      button("play", () => play(entry.name, Number(speed.value), back.checked), `play ${entry.name}`),
      button("stop", async () => { try { await post(`/api/v1/moves/${entry.name}/stop`); } catch (e) { say(e.message, true); } refreshMoves(); }, `stop ${entry.name}`)),
    el("td", {}, button("plot", () => plot(entry.name).catch((e) => say(e.message, true)), `plot ${entry.name}`),
      button("delete", () => remove(entry.name), `delete ${entry.name}`)));
  tr.dataset.move = entry.name;
  return tr;
}

let shown = "";
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
  const names = [...new Set(entries.map((e) => e.name))];
  const body = document.querySelector("#move-table tbody");
  body.replaceChildren(...names.map((n) => row(entries.find((e) => e.name === n), status.playing.includes(n))));
}
