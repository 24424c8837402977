// The links the page adds by itself: the Jupyter notebook of `poppy notebook`, only while a
// Jupyter answers (the server says where: /api/v1/web/about's `notebook`), and the server's
// notes (how to get Snap! offline...).
import { el } from "./ui.js";

export const NOTEBOOK_TEXT = "Jupyter: discover your robot";

// The link to the notebook on the page's own host name, or null when no Jupyter runs there.
export function notebookLink(about) {
  if (!about.notebook) return null;
  const host = location.hostname.includes(":") ? `[${location.hostname}]` : location.hostname;
  const url = `${location.protocol}//${host}:${about.notebook.port}${about.notebook.path}`;
  return el("a", { href: url, textContent: NOTEBOOK_TEXT, target: "_blank", rel: "noopener",
    id: "link-jupyter", title: `the notebook of \`poppy notebook\` (port ${about.notebook.port})` });
}

export function notes(about) {
  return Object.entries(about.notes ?? {}).map(([name, text]) =>
    el("span", { className: "muted note", textContent: text, id: `note-${name}` }));
}
