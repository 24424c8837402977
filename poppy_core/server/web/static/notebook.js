// The links the page adds by itself: the Jupyter notebook of `poppy notebook` (port 8888), and
// the server's notes (how to get Snap! offline...).
import { el } from "./ui.js";

export const NOTEBOOK_PORT = 8888;
export const NOTEBOOK_FILE = "discover-your-robot.ipynb";

export function notebookLink() {
  const host = location.hostname.includes(":") ? `[${location.hostname}]` : location.hostname;
  const url = `${location.protocol}//${host}:${NOTEBOOK_PORT}/notebooks/${NOTEBOOK_FILE}`;
  return el("a", { href: url, textContent: "Jupyter: discover your robot", target: "_blank",
    rel: "noopener", title: "needs `poppy notebook` running on the robot (port 8888)" });
}

export function notes(about) {
  return Object.entries(about.notes ?? {}).map(([name, text]) =>
    el("span", { className: "muted note", textContent: text, id: `note-${name}` }));
}
