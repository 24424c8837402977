// What only some robots have: cameras (MJPEG) and kinematic chains (tip and a cartesian jog).
import { get, post, token } from "./api.js";
import { button, el, say } from "./ui.js";

// The camera panel: each camera with a picture (a real one, MuJoCo's simulated one) under its
// label, shown on demand; without one, the panel says why ("no camera").
export function showCameras(about) {
  const views = document.getElementById("camera-views");
  if (!about.camera_views.length) {
    views.replaceChildren(el("p", { className: "muted", id: "no-camera", textContent: about.no_camera }));
    return;
  }
  views.replaceChildren(...about.camera_views.map(({ name, label }) => {
    const img = el("img", { alt: `what ${name} sees`, width: 320, height: 240 });
    const start = button(`show ${name}`, async () => {
      if (img.src) { img.removeAttribute("src"); start.textContent = `show ${name}`; return; }
      // an <img> cannot send a header: with a token, the stream is read with fetch instead
      if (token()) { await streamWithFetch(name, img); } else { img.src = `/api/v1/sensors/${name}/stream.mjpg?fps=10`; }
      start.textContent = `hide ${name}`;
    });
    return el("figure", { className: "camera-view", id: `camera-${name}` }, img,
      el("figcaption", {}, el("span", { className: "camera-label", textContent: label }), start));
  }));
}

// Polls single frames with the Authorization header (about 5 per second).
async function streamWithFetch(name, img) {
  img.src = "data:,";
  const tick = async () => {
    if (!img.src) return;
    try {
      const response = await fetch(`/api/v1/sensors/${name}/frame.jpg`, { headers: { Authorization: `Bearer ${token()}` } });
      if (response.ok) {
        const old = img.src;
        img.src = URL.createObjectURL(await response.blob());
        if (old.startsWith("blob:")) URL.revokeObjectURL(old);
      }
    } catch { /* try again */ }
    setTimeout(tick, 200);
  };
  tick();
}

const STEP_M = 0.01;
// The tip is shown in millimetres, as in the CLI and the TUI (the API speaks metres).
const inMm = (position) => position.map((v) => (v * 1000).toFixed(0)).join(", ");

async function jog(chain, axis, sign, tipText) {
  try {
    const now = await get(`/api/v1/chains/${chain}`);
    const target = [...now.position];
    target[axis] += sign * STEP_M;
    const answer = await post(`/api/v1/chains/${chain}/goto`, { position: target, duration: 0.5, wait: true });
    tipText.textContent = inMm(answer.position);
  } catch (error) {
    say(`${chain}: ${error.message}`, true);
  }
}

export async function showChains(names) {
  if (!names.length) return;
  const list = document.getElementById("chain-list");
  for (const name of names) {
    const tip = el("output");
    const pad = el("div", { className: "jog", role: "group" });
    pad.setAttribute("aria-label", `jog ${name} by 10 mm`);
    ["x", "y", "z"].forEach((axis, i) => {
      pad.append(button(`${axis}−`, () => jog(name, i, -1, tip), `${name} ${axis} minus 10 mm`),
        button(`${axis}+`, () => jog(name, i, 1, tip), `${name} ${axis} plus 10 mm`));
    });
    const heading = el("h3", { textContent: name });
    list.append(el("article", { className: "card", id: `chain-${name}` },
      heading, el("p", {}, "tip (mm): ", tip), pad));
    const refresh = async () => {
      try {
        const state = await get(`/api/v1/chains/${name}`);
        heading.textContent = state.label || name;  // the Ergo Jr's `chain` is shown as its arm
        tip.textContent = inMm(state.position);
      } catch { /* shown elsewhere */ }
    };
    refresh();
    setInterval(refresh, 2000);
  }
  document.getElementById("chains").hidden = false;
}
