// The 3D view's panel: light to load. It keeps the last state frame and, once the panel is on
// screen (after the page's first paint), imports the view itself (three.js, ./view/scene.js).
import { el } from "./ui.js";

let scene = null; // the loaded view: { frame(data), setVisible(on) }
let lastFrame = null;
let started = false;
let firstFrame = null; // resolves with the page's first state frame
const framed = new Promise((resolve) => { firstFrame = resolve; });
let sceneReady = null; // resolves with the loaded view, or null when there is none
const loaded = new Promise((resolve) => { sceneReady = resolve; });
let shownAbout = null;

export function viewFrame(data) {
  lastFrame = data;
  firstFrame(data);
  if (scene) scene.frame(data);
}

function hasWebGL() {
  try {
    const canvas = document.createElement("canvas");
    return Boolean(canvas.getContext("webgl2") || canvas.getContext("webgl"));
  } catch { return false; }
}

function line(panel, text) {
  panel.querySelector(".view-note").textContent = text;
}

async function start(panel, about) {
  if (started) return;
  started = true;
  const room = panel.querySelector(".view-canvas");
  if (!hasWebGL()) {
    room.classList.remove("loading");
    line(panel, "No 3D view: this browser has no WebGL (the table below shows every motor).");
    window.poppy.view = { ready: false, fallback: true };
    sceneReady(null);
    return;
  }
  line(panel, "Loading the 3D model…");
  // the table's first live values go first: three.js is parsed once they are shown
  await framed;
  await new Promise((resolve) => setTimeout(resolve, 50));
  try {
    const { startView } = await import("./view/scene.js");
    scene = await startView(room, about);
    room.classList.remove("loading");
    line(panel, "Drag to turn, wheel or pinch to zoom, right-drag or two fingers to pan.");
    if (lastFrame) scene.frame(lastFrame);
    sceneReady(scene);
  } catch (error) {
    room.classList.remove("loading");
    line(panel, `No 3D view: ${error.message}`);
    window.poppy.view = { ready: false, error: error.message };
    sceneReady(null);
  }
}

// Build the panel in #view3d; the view loads when the panel first shows (and stays idle while
// it is hidden or off screen).
export function setupView(about) {
  const panel = document.getElementById("view3d");
  if (!panel) return;
  shownAbout = about;
  const toggle = el("button", { type: "button", textContent: "hide" });
  toggle.setAttribute("aria-controls", "view3d-canvas");
  toggle.setAttribute("aria-expanded", "true");
  // the view's room is kept until it is drawn (style.css): nothing under it moves then
  const canvas = el("div", { className: "view-canvas loading", id: "view3d-canvas" });
  panel.querySelector("h2").append(" ", toggle);
  panel.append(el("p", { className: "view-note muted", textContent: "Loading the 3D model…" }), canvas);
  toggle.addEventListener("click", () => {
    const open = canvas.hidden;
    canvas.hidden = !open;
    toggle.textContent = open ? "hide" : "show";
    toggle.setAttribute("aria-expanded", String(open));
    if (scene) scene.setVisible(open && onScreen);
  });
  let onScreen = false;
  new IntersectionObserver((entries) => {
    onScreen = entries.some((e) => e.isIntersecting);
    if (onScreen && !canvas.hidden) requestAnimationFrame(() => start(panel, about));
    if (scene) scene.setVisible(onScreen && !canvas.hidden);
  }).observe(panel);
}

// The view for the datasets' player (datasets.js), loaded now if it was not yet: resolves with
// { showEpisode(state, action), endEpisode() } or null (no WebGL, no model).
export function episodeView() {
  const panel = document.getElementById("view3d");
  if (!panel || !shownAbout) return Promise.resolve(null);
  start(panel, shownAbout);
  return loaded;
}
