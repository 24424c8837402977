// The robots this robot's Zenoh network sees (poppy serve --zenoh), with links to their pages.
import { get } from "./api.js";
import { el } from "./ui.js";

export async function refreshFleet() {
  let robots;
  try { robots = await get("/api/v1/web/fleet"); } catch { return; }
  const section = document.getElementById("fleet");
  if (!robots.length) { section.hidden = true; return; }
  const list = document.getElementById("fleet-list");
  list.replaceChildren(...robots.map((robot) => {
    const name = robot.page && !robot.self
      ? el("a", { href: robot.page, textContent: robot.name })
      : el("span", { textContent: robot.self ? `${robot.name} (this robot)` : robot.name });
    const state = el("span", { className: robot.ok ? "muted" : "error", textContent: robot.ok ? " ok" : " trouble" });
    return el("li", {}, name, ` ${robot.creature}`, state);
  }));
  section.hidden = false;
}
