// Behaviours: each primitive with start / pause / resume / stop and its properties editable.
import { get, post, put } from "./api.js";
import { button, el, say } from "./ui.js";

const cards = new Map(); // name -> {state, inputs}

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
  const actions = el("div", { className: "actions" },
    ...["start", "pause", "resume", "stop"].map((a) =>
      button(a, () => control(info.name, a), `${a} ${info.name}`)));
  const node = el("article", { id: `primitive-${info.name}`, className: "card" },
    el("h3", {}, info.name, " ", state), actions,
    el("details", {}, el("summary", { textContent: "properties" }), props));
  node.dataset.primitive = info.name;
  cards.set(info.name, { state, inputs, node });
  return node;
}

function update(info) {
  const found = cards.get(info.name);
  if (!found) return;
  found.state.textContent = info.state + (info.error ? ` (error: ${info.error.message ?? ""})` : "");
  found.state.className = `state ${info.state}`;
  found.node.dataset.state = info.state;
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
