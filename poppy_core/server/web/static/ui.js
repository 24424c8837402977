// Small helpers shared by the page's parts: building elements and the status line.

export function el(tag, props = {}, ...children) {
  const node = Object.assign(document.createElement(tag), props);
  node.append(...children);
  return node;
}

export function button(text, onClick, label) {
  const node = el("button", { type: "button", textContent: text });
  if (label) node.setAttribute("aria-label", label);
  node.addEventListener("click", onClick);
  return node;
}

// The status line: what the last action did, or why the robot refused it.
export function say(text, isError = false) {
  const line = document.getElementById("message");
  line.textContent = text;
  line.className = isError ? "error" : "";
}

export function every(seconds, run) {
  run();
  return setInterval(run, seconds * 1000);
}
