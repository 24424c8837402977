// Record a dataset: a LeRobot dataset recorded on the robot (POST /api/v1/recording), its live
// line (episode i/N, time, frames, dropped frames), and lerobot-record's keys while the panel
// has focus: → ends the episode (or the reset), ← records it again, Esc stops (the episode under
// way saved). Esc outside a recording is the page's Stop, as everywhere.
import { get, post } from "./api.js";
import { button, el, say } from "./ui.js";

const POLL_MS = 400;
const KEYS = { ArrowRight: "end-episode", ArrowLeft: "rerecord", Escape: "stop" };
const SAID = { "end-episode": "episode ended", rerecord: "episode dropped: recording it again", stop: "stopping" };
let active = false;
let timer = null;
let panel = null;

function field(label, input) {
  return el("label", {}, `${label} `, input);
}

function number(name, value, min, max, step) {
  return el("input", { name, type: "number", value, min, max, step, required: true, size: 5 });
}

function liveText(state) {
  if (state.phase === "idle") return "No recording yet.";
  const saved = state.saved ? state.saved.length : 0;
  const where = `${state.repo_id} → ${state.folder}`;
  if (state.phase === "done") {
    const failed = state.error ? ` ${state.error}` : "";
    return `done: ${saved} episode(s) saved, the dataset holds ${state.total_episodes} (${where}).${failed}`;
  }
  if (state.phase === "finishing") return `finishing: ${saved} episode(s) saved, writing the dataset… (${where})`;
  const what = state.phase === "resetting" ? "reset before episode" : "episode";
  return `${what} ${state.episode}/${state.episodes}  ${state.elapsed_s.toFixed(1)}/${state.duration_s} s  `
    + `${state.frames} frames  ${state.dropped} dropped  (${saved} saved; ${where})`;
}

function show(state) {
  active = state.active;
  panel.querySelector("#dataset-live").textContent = liveText(state);
  panel.querySelector("#dataset-start").disabled = active;
  for (const node of panel.querySelectorAll(".dataset-key")) node.disabled = !active;
  panel.dataset.phase = state.phase;
  if (active && timer === null) timer = setInterval(poll, POLL_MS);
  if (!active && timer !== null) { clearInterval(timer); timer = null; }
}

async function poll() {
  try { show(await get("/api/v1/recording")); } catch { /* the next poll says */ }
}

async function control(action) {
  try {
    show(await post(`/api/v1/recording/${action}`));
    say(`recording: ${SAID[action]}`);
  } catch (error) { say(error.message, true); }
}

function sourceFields(form) {
  const source = form.elements.source.value;
  form.querySelector("#dataset-move-field").hidden = source !== "move";
  form.querySelector("#dataset-primitive-field").hidden = source !== "primitive";
}

async function fillChoices(form, cameras = true) {
  try {
    const [moves, robot, sensors] = await Promise.all([
      get("/api/v1/moves"), get("/api/v1/robot"), get("/api/v1/sensors")]);
    form.elements.move.replaceChildren(...moves.map((m) => el("option", { value: m.name, textContent: m.name })));
    form.elements.primitive.replaceChildren(
      ...robot.primitives.map((p) => el("option", { value: p, textContent: p })));
    if (!cameras) return;
    const box = form.querySelector("#dataset-cameras");
    const names = sensors.filter((s) => String(s.type).endsWith("Camera")).map((s) => s.name);
    box.replaceChildren(el("legend", { textContent: "Cameras" }), ...names.map((name) => el("label", {},
      el("input", { type: "checkbox", name: "camera", value: name, checked: true }), ` ${name}`)));
    if (!names.length) box.append(el("span", { className: "muted", textContent: "none" }));
  } catch (error) { say(error.message, true); }
}

async function start(form) {
  const data = form.elements;
  const source = data.source.value;
  const body = {
    repo_id: data.repo_id.value.trim(),
    task: data.task.value,
    source,
    episodes: Number(data.episodes.value),
    episode_s: Number(data.episode_s.value),
    reset_s: Number(data.reset_s.value),
    fps: Number(data.fps.value),
    cameras: [...form.querySelectorAll("input[name=camera]:checked")].map((i) => i.value),
    resume: data.resume.checked,
  };
  if (source === "move") body.move = data.move.value;
  if (source === "primitive") body.primitive = data.primitive.value;
  try {
    show(await post("/api/v1/recording", body));
    say(`recording ${body.repo_id}: → ends an episode, ← records it again, Esc stops`);
    panel.focus();
  } catch (error) { say(error.message, true); }
}

function build(section) {
  const source = el("select", { name: "source" },
    el("option", { value: "by_hand", textContent: "by hand (compliant)" }),
    el("option", { value: "move", textContent: "a move" }),
    el("option", { value: "primitive", textContent: "a behaviour" }));
  const form = el("form", { id: "dataset-form", className: "toolbar" },
    field("Dataset", el("input", { name: "repo_id", required: true, value: "poppy/demo", size: 14, pattern: "[^/\\s]+/[^/\\s]+" })),
    field("Task", el("input", { name: "task", required: true, value: "", size: 24, placeholder: "what is done, one line" })),
    field("Actions", source),
    el("span", { id: "dataset-move-field", hidden: true }, field("Move", el("select", { name: "move" }))),
    el("span", { id: "dataset-primitive-field", hidden: true }, field("Behaviour", el("select", { name: "primitive" }))),
    field("Episodes", number("episodes", 2, 1, 10000, 1)),
    field("Episode s", number("episode_s", 20, 0.1, 3600, "any")),
    field("Reset s", number("reset_s", 5, 0, 3600, "any")),
    field("fps", number("fps", 30, 1, 240, 1)),
    el("fieldset", { id: "dataset-cameras" }, el("legend", { textContent: "Cameras" })),
    field("Add to it", el("input", { name: "resume", type: "checkbox" })),
    el("button", { id: "dataset-start", type: "submit", textContent: "Record" }));
  const keys = el("div", { className: "toolbar", role: "group", ariaLabel: "Recording keys" },
    button("→ end episode", () => control("end-episode"), "end the episode (right arrow)"),
    button("← record again", () => control("rerecord"), "record the episode again (left arrow)"),
    button("Esc stop", () => control("stop"), "stop the recording (Escape)"));
  for (const node of keys.querySelectorAll("button")) { node.classList.add("dataset-key"); node.disabled = true; }
  keys.querySelectorAll("button").forEach((node, i) => { node.id = ["dataset-end", "dataset-again", "dataset-stop"][i]; });
  const live = el("p", { id: "dataset-live", className: "muted", role: "status", textContent: "…" });
  section.append(form, keys, live);
  source.addEventListener("change", () => { sourceFields(form); fillChoices(form, false); });
  form.addEventListener("submit", (event) => { event.preventDefault(); start(form); });
  section.addEventListener("keydown", (event) => {
    const action = KEYS[event.key];
    if (!active || !action) return;
    const typing = event.target.matches("input:not([type=checkbox]), select");
    if (typing && event.key !== "Escape") return; // arrows move the caret or the choice
    event.preventDefault();
    event.stopPropagation(); // Esc here stops the recording, not every motion (app.js)
    control(action);
  });
  fillChoices(form);
}

panel = document.getElementById("dataset-record");
if (panel) {
  build(panel);
  poll();
}
