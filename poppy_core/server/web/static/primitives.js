// Behaviours: a compact list, each primitive with its state, one start/stop toggle, and under
// its "⋯" pause / resume and its properties (editable).
import { get, post, put } from "./api.js";
import { button, el, say } from "./ui.js";

const rows = new Map(); // name -> {state, inputs, node, run, pause, resume}
// One toggle per behaviour: start when it can start, stop when it runs or is paused
// (poppy_core.motion.primitive: idle, running, paused, stopped, failed); pause and resume
// sit with its properties, under its "⋯".
const STARTS = new Set(["idle", "stopped", "failed"]);

function parse(text, old) {
  if (typeof old === "number") return Number(text);
  if (typeof old === "string") return text;
  return JSON.parse(text); // lists, objects, booleans
}

function show(value) {
  return typeof value === "string" ? value : JSON.stringify(value);
}

async function control(name, action) {
  try {
    const info = await post(`/api/v1/primitives/${name}/${action}`);
    say(`${name}: ${info.state}`);
    update(info);
  } catch (error) {
    say(`${name}: ${error.message}`, true);
  }
}

function row(info) {
  const state = el("span", { className: "state" });
  const inputs = new Map();
  const props = el("div", { className: "props" });
  for (const [prop, value] of Object.entries(info.properties)) {
    const input = el("input", { value: show(value), size: 10 });
    input.setAttribute("aria-label", `${info.name} ${prop}`);
    input.dataset.prop = prop;
    const commit = async () => {
      try {
        const answer = await put(`/api/v1/primitives/${info.name}/properties/${prop}`,
          parse(input.value, value));
        say(`${info.name}.${prop} = ${show(answer.properties[prop])}`);
        input.classList.remove("refused");
      } catch (error) {
        say(`${info.name}.${prop}: ${error.message}`, true);
        input.classList.add("refused");
      }
    };
    input.addEventListener("change", commit);
    inputs.set(prop, input);
    props.append(el("label", {}, el("span", { textContent: prop }), input));
  }
  const run = button("start", () => control(info.name, run.dataset.action));
  run.className = "run";
  const pause = button("pause", () => control(info.name, "pause"), `pause ${info.name}`);
  const resume = button("resume", () => control(info.name, "resume"), `resume ${info.name}`);
  const more = el("div", { className: "more", id: `more-${info.name}`, hidden: true },
    el("div", { className: "actions" }, pause, resume), props);
  const fold = button("⋯", () => {
    more.hidden = !more.hidden;
    fold.setAttribute("aria-expanded", String(!more.hidden));
  }, `more of ${info.name}: pause, resume, properties`);
  fold.className = "fold";
  fold.setAttribute("aria-expanded", "false");
  fold.setAttribute("aria-controls", more.id);
  const node = el("li", { id: `primitive-${info.name}`, className: "behaviour" },
    el("div", { className: "row" }, el("strong", { textContent: info.name, title: info.name }), state, run, fold),
    more);
  node.dataset.primitive = info.name;
  rows.set(info.name, { state, inputs, node, run, pause, resume });
  return node;
}

function update(info) {
  const found = rows.get(info.name);
  if (!found) return;
  found.state.textContent = info.state + (info.error ? ` (error: ${info.error.message ?? ""})` : "");
  found.state.className = `state ${info.state}`;
  found.node.dataset.state = info.state;
  const action = STARTS.has(info.state) ? "start" : "stop";
  found.run.dataset.action = action;
  found.run.textContent = action;
  found.run.setAttribute("aria-label", `${action} ${info.name}`);
  found.run.setAttribute("aria-pressed", String(action === "stop"));
  found.pause.disabled = info.state !== "running";
  found.resume.disabled = info.state !== "paused";
  for (const [prop, input] of found.inputs) {
    if (document.activeElement !== input && prop in info.properties) {
      input.value = show(info.properties[prop]);
    }
  }
}

export async function refreshPrimitives() {
  let list;
  try { list = await get("/api/v1/primitives"); } catch { return; }
  const container = document.getElementById("primitive-list");
  for (const info of list) {
    if (!rows.has(info.name)) container.append(row(info));
    update(info);
  }
}
