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

// "1 update", "2 updates": a count and its noun, plural right.
export function count(n, noun, plural = `${noun}s`) {
  return `${n} ${n === 1 ? noun : plural}`;
}

// A size in bytes as the CLI writes it (B, kB, MB: powers of 1000), never split over two lines.
export function sizeText(bytes) {
  const NBSP = "\u00a0";
  if (bytes < 1000) return `${bytes}${NBSP}B`;
  if (bytes < 1e6) return `${(bytes / 1000).toFixed(1)}${NBSP}kB`;
  return `${(bytes / 1e6).toFixed(1)}${NBSP}MB`;
}

// Seconds as the CLI writes a move's duration ("2.98 s"), never split over two lines.
export function secondsText(seconds) {
  return `${seconds.toFixed(2)}\u00a0s`;
}
