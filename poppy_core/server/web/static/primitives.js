// Behaviours: each primitive with start / pause / resume / stop and its properties editable.
import { get, post, put } from "./api.js";
import { button, el, say } from "./ui.js";

const cards = new Map(); // name -> {state, inputs, node, actions}
const ACTIONS = ["start", "pause", "resume", "stop"];
// What each state allows (poppy_core.motion.primitive: idle, running, paused, stopped, failed)
const ALLOWED = {
  idle: ["start"], stopped: ["start"], failed: ["start"],
  running: ["pause", "stop"], paused: ["resume", "stop"],
};

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

function card(info) {
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
  const buttons = new Map(ACTIONS.map((a) => [a, button(a, () => control(info.name, a), `${a} ${info.name}`)]));
  const actions = el("div", { className: "actions" }, ...buttons.values());
  const node = el("article", { id: `primitive-${info.name}`, className: "card" },
    el("h3", {}, info.name, " ", state), actions,
    el("details", {}, el("summary", { textContent: "properties" }), props));
  node.dataset.primitive = info.name;
  cards.set(info.name, { state, inputs, node, buttons });
  return node;
}

function update(info) {
  const found = cards.get(info.name);
  if (!found) return;
  found.state.textContent = info.state + (info.error ? ` (error: ${info.error.message ?? ""})` : "");
  found.state.className = `state ${info.state}`;
  found.node.dataset.state = info.state;
  const allowed = ALLOWED[info.state] ?? ACTIONS; // a state this page does not know: all offered
  const focused = [...found.buttons.values()].includes(document.activeElement);
  for (const [action, node] of found.buttons) node.disabled = !allowed.includes(action);
  // a keyboard user keeps a focus in the card: on the action the new state allows
  if (focused && document.activeElement?.disabled !== false) {
    [...found.buttons.values()].find((node) => !node.disabled)?.focus();
  }
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
    if (!cards.has(info.name)) container.append(card(info));
    update(info);
  }
}
