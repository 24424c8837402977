// The live motor table: fast columns from the stream, slow ones polled; compliance, goals, LEDs.
import { api, get, post, put } from "./api.js";
import { el, say } from "./ui.js";

const FAST = ["present_position", "present_speed", "present_load", "present_temperature"];
let pending = null; // the latest frame received before the table existed
const rows = new Map(); // motor name -> {cells, slider, compliant, led, online}
export const stats = { frames: 0, firstFrameAt: null, started: performance.now() };
// A poll answered while the user changes a compliance (or asked before it) would put the old
// state back under their click: its compliance boxes are left as the user set them.
const compliance = { changing: 0, changes: 0 };

async function changeCompliance(request) {
  compliance.changing += 1;
  compliance.changes += 1;
  try {
    await request();
  } finally {
    compliance.changing -= 1;
  }
}

function fmt(value, digits = 1) {
  return typeof value === "number" ? value.toFixed(digits) : value ?? "–";
}

// Sections of the table: each motor under its smallest group, except groups that only
// re-slice a bigger group whose name they extend (l_leg_sagitall within l_leg).
export function sections(motors, groups) {
  const names = Object.keys(groups);
  const views = names.filter((g) => names.some((h) => h !== g && g.startsWith(h)
    && groups[g].every((m) => groups[h].includes(m))));
  const candidates = names.filter((g) => !views.includes(g))
    .sort((a, b) => groups[a].length - groups[b].length);
  const out = new Map();
  for (const motor of motors) {
    const group = candidates.find((g) => groups[g].includes(motor)) ?? "other motors";
    if (!out.has(group)) out.set(group, []);
    out.get(group).push(motor);
  }
  return out;
}

async function setCompliant(names, value) {
  try {
    await changeCompliance(() => api("PATCH", "/api/v1/motors",
      Object.fromEntries(names.map((n) => [n, { compliant: value }]))));
    say(`${names.length === 1 ? names[0] : `${names.length} motors`}: ${value ? "compliant" : "stiff"}`);
  } catch (error) {
    say(error.message, true);
  }
  refresh();
}

async function setGoal(name, value, slider) {
  try {
    const answer = await post("/api/v1/gotos", { positions: { [name]: value }, duration_s: 0.5 });
    const aimed = answer.positions[name]; // a goal beyond the angle limits is clamped to them
    say(aimed === value ? `${name} → ${value}°` : `${name} → ${aimed}° (clamped to the angle limits)`);
  } catch (error) {
    say(`${name}: refused: ${error.message}`, true);
    slider.closest("tr").classList.add("refused");
    setTimeout(() => slider.closest("tr").classList.remove("refused"), 2000);
  }
}

function motorRow(name, info, leds) {
  const cells = {};
  for (const key of FAST) cells[key] = el("td", { className: "num" });
  cells.present_voltage = el("td", { className: "num" });
  const [low, high] = info.angle_limit;
  const slider = el("input", {
    type: "range", min: String(low), max: String(high), step: "1",
    value: String(Math.round(info.goal_position)),
  });
  slider.setAttribute("aria-label", `${name} goal position (${low}° to ${high}°)`);
  const goalText = el("output", { className: "num" });
  // a compliant motor's goal moves nothing (the v1 API refuses it with a 409): said where it is set
  const freeNote = el("small", { className: "muted free-note", textContent: "compliant: make it stiff to move it" });
  freeNote.hidden = !info.compliant;
  // who drives its goal (a teleoperation, a move, a trajectory...): the sliders' goals are refused
  const ownerNote = el("small", { className: "muted owner-note" });
  ownerNote.hidden = true;
  slider.addEventListener("input", () => { goalText.value = slider.value; });
  slider.addEventListener("change", () => setGoal(name, Number(slider.value), slider));
  const compliant = el("input", { type: "checkbox", checked: info.compliant });
  compliant.setAttribute("aria-label", `${name} compliant`);
  compliant.addEventListener("change", () => {
    freeNote.hidden = !compliant.checked;
    setCompliant([name], compliant.checked);
  });
  const led = el("select");
  led.setAttribute("aria-label", `${name} LED`);
  // values are JSON: colour names (XL-320) or false/true (shown off/on)
  for (const value of leds) {
    const text = value === true ? "on" : value === false ? "off" : value;
    led.append(el("option", { value: JSON.stringify(value), textContent: text }));
  }
  led.addEventListener("change", async () => {
    try { await put(`/api/v1/motors/${name}/registers/led`, JSON.parse(led.value)); } catch (e) { say(e.message, true); }
  });
  const online = el("td", { className: "online" });
  const tr = el("tr", { id: `motor-${name}` },
    el("th", { scope: "row" }, name, el("small", { className: "muted", textContent: ` ${info.id} · ${info.model}` })),
    cells.present_position,
    el("td", {}, el("span", { className: "goal" }, slider, goalText), freeNote, ownerNote),
    cells.present_speed, cells.present_load, cells.present_temperature, cells.present_voltage,
    el("td", {}, compliant), el("td", {}, led), online);
  tr.dataset.motor = name;
  rows.set(name, { cells, slider, goalText, freeNote, ownerNote, compliant, led, online });
  return tr;
}

async function setRobotCompliant(value) {
  try {
    await changeCompliance(() => api("PUT", "/api/v1/robot/compliant", { compliant: value }));
    say(`robot: ${value ? "compliant" : "stiff"}`);
  } catch (error) {
    say(error.message, true);
  }
  refresh();
}

function groupButtons(container, groups) {
  container.replaceChildren();
  const add = (label, onChoice) => {
    const box = el("span", { className: "toggle" }, el("span", { textContent: label }));
    for (const [text, value] of [["stiff", false], ["compliant", true]]) {
      const button = el("button", { type: "button", textContent: text });
      button.dataset.group = label;
      button.dataset.compliant = String(value);
      button.setAttribute("aria-label", `${label}: ${text}`);
      button.addEventListener("click", () => onChoice(value));
      box.append(button);
    }
    container.append(box);
  };
  add("robot", setRobotCompliant);
  for (const [group, names] of Object.entries(groups)) add(group, (v) => setCompliant(names, v));
}

// The table of `motorNames` from `details` (/api/v1/web/motors?leds=true).
export function buildTable(motorNames, details) {
  const table = document.getElementById("motor-table");
  for (const body of table.querySelectorAll("tbody")) body.remove();
  rows.clear();
  for (const [group, names] of sections(motorNames, details.groups)) {
    const body = el("tbody", {},
      el("tr", { className: "group" }, el("th", { colSpan: 10, scope: "rowgroup", textContent: group })));
    for (const name of names) body.append(motorRow(name, details.motors[name], details.motors[name].leds));
    table.append(body);
  }
  groupButtons(document.getElementById("group-toggles"), details.groups);
  applyDetails(details.motors);
  if (pending) onFrame(pending);
  pending = null;
}

function applyDetails(motors, withCompliance = true) {
  for (const [name, info] of Object.entries(motors)) {
    const row = rows.get(name);
    if (!row) continue;
    row.cells.present_voltage.textContent = fmt(info.present_voltage);
    if (withCompliance) {
      row.compliant.checked = info.compliant;
      row.freeNote.hidden = !info.compliant;
    }
    if (document.activeElement !== row.slider) {
      row.slider.value = String(info.goal_position);
      row.goalText.value = fmt(info.goal_position);
    }
    row.ownerNote.textContent = info.owner ? `${name}: ${info.owner}` : "";
    row.ownerNote.hidden = !info.owner;
    row.online.textContent = info.online ? "●" : "offline";
    row.online.className = info.online ? "online ok" : "online bad";
  }
}

export async function refresh() {
  const changes = compliance.changes;
  try {
    const { motors } = await get("/api/v1/web/motors");
    applyDetails(motors, compliance.changing === 0 && compliance.changes === changes);
  } catch { /* the connection badge says */ }
}

function setText(cell, text) {
  if (cell.textContent !== text) cell.textContent = text;
}

export function onFrame(frame) {
  if (!rows.size) { pending = frame; return; } // shown as soon as the table is built
  stats.frames += 1;
  if (stats.firstFrameAt === null) stats.firstFrameAt = performance.now();
  for (const [name, state] of Object.entries(frame)) {
    const row = rows.get(name);
    if (!row) continue;
    // written only when it changed: a write lays the page out again, 20 times a second
    for (const key of FAST) setText(row.cells[key], fmt(state[key]));
    if (document.activeElement !== row.led && state.led !== undefined) {
      const led = JSON.stringify(state.led);
      if (row.led.value !== led) row.led.value = led;
    }
  }
}
