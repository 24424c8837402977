// The datasets' panel: the LeRobot datasets of the robot's data folder, their episodes, and a
// player: the 3D view poses the recorded robot (observation.state solid, action as the blue
// ghost), each camera's video seeked to the episode's span of its mp4 file and kept in step, and
// a plot of state against action per joint with a cursor. Nothing is sent to the robot.
import { get, token } from "./api.js";
import { button, el, say } from "./ui.js";
import { episodeView } from "./view-panel.js";

const SPEEDS = [0.25, 0.5, 1, 2, 4];
const BAND = 46; // the plot's height per joint (px)
const LABEL = 56; // the plot's left margin for the joint names (px)
const STATE = "#2563eb", ACTION = "#f97316";
const DRIFT_S = 0.12; // a second camera this far from the first is seeked back in step
const STALL_MS = 500; // a video whose time stands still this long while playing: the page's clock

const status = { ready: false, datasets: [], episode: null, frame: 0, playing: false, plotDraws: 0, clock: "none", ticks: { video: 0, page: 0 } };
let player = null; // the episode being played (see open())

function authorizedUrl(path) {
  // a <video> cannot send a header: with a token, the file is read with fetch into a blob
  if (!token()) return Promise.resolve(path);
  return fetch(path, { headers: { Authorization: `Bearer ${token()}` } }).then(async (response) => {
    if (!response.ok) throw new Error(`${response.status}`);
    return URL.createObjectURL(await response.blob());
  });
}

// The first frame whose timestamp is at or before t (s from the episode's start).
function frameAt(times, t) {
  let low = 0, high = times.length - 1;
  if (t <= times[0]) return 0;
  while (low < high) {
    const mid = (low + high + 1) >> 1;
    if (times[mid] <= t + 1e-6) low = mid; else high = mid - 1;
  }
  return low;
}

function byName(motors, row) {
  const values = {};
  motors.forEach((name, i) => { if (row[i] !== null) values[name] = row[i]; });
  return values;
}

// The plot: one band per joint, state and action over the episode, drawn once; the cursor on top.
function makePlot(canvas, episode) {
  const joints = episode.motors.length, n = episode.frames;
  canvas.width = Math.max(320, Math.min(900, canvas.parentElement.clientWidth || 600));
  canvas.height = joints * BAND + 18;
  const width = canvas.width - LABEL - 6;
  const x = (k) => LABEL + (n > 1 ? (k / (n - 1)) * width : 0);
  const still = document.createElement("canvas");
  still.width = canvas.width; still.height = canvas.height;
  const g = still.getContext("2d");
  g.fillStyle = "#fff"; g.fillRect(0, 0, still.width, still.height);
  g.font = "11px system-ui, sans-serif";
  g.fillStyle = STATE; g.fillText("— state", LABEL, 12);
  g.fillStyle = ACTION; g.fillText("— action", LABEL + 60, 12);
  g.fillStyle = "#555"; g.fillText("(degrees)", LABEL + 125, 12);
  episode.motors.forEach((name, j) => {
    const top = 18 + j * BAND, bottom = top + BAND - 6;
    const values = [...episode.state, ...episode.action].map((row) => row[j]).filter((v) => v !== null);
    let low = Math.min(...values), high = Math.max(...values);
    if (!(high - low > 1)) { const mid = (high + low) / 2 || 0; low = mid - 1; high = mid + 1; }
    const y = (v) => bottom - ((v - low) / (high - low)) * (bottom - top);
    g.strokeStyle = "#e5e7eb"; g.strokeRect(LABEL, top, width, bottom - top);
    g.fillStyle = "#333"; g.fillText(name, 4, top + 14);
    g.fillStyle = "#777"; g.fillText(high.toFixed(0), 4, top + 26); g.fillText(low.toFixed(0), 4, bottom);
    for (const [rows, colour] of [[episode.action, ACTION], [episode.state, STATE]]) {
      g.strokeStyle = colour; g.lineWidth = 1.2; g.beginPath();
      let pen = false;
      rows.forEach((row, k) => {
        if (row[j] === null) { pen = false; return; }
        if (pen) g.lineTo(x(k), y(row[j])); else g.moveTo(x(k), y(row[j]));
        pen = true;
      });
      g.stroke();
    }
  });
  const context = canvas.getContext("2d");
  return {
    frameOf: (px) => Math.max(0, Math.min(n - 1, Math.round(((px - LABEL) / width) * (n - 1)))),
    draw(k) {
      context.drawImage(still, 0, 0);
      context.strokeStyle = "#111"; context.lineWidth = 1;
      context.beginPath(); context.moveTo(x(k) + 0.5, 16); context.lineTo(x(k) + 0.5, canvas.height); context.stroke();
      status.plotDraws += 1;
    },
  };
}

function seconds(t) { return `${t.toFixed(2)} s`; }

// Play an episode: returns the player (show(k), play(), pause(), close()).
async function open(body, repoId, index) {
  if (player) player.close();
  const episode = await get(`/api/v1/datasets/${repoId}/episodes/${index}`);
  const times = episode.timestamps, n = episode.frames;
  const end = n ? times[n - 1] + 1 / episode.fps : 0;
  const view = await episodeView();
  const title = el("h3", { textContent: `${repoId} · episode ${index}${episode.tasks.length ? ` · ${episode.tasks.join(", ")}` : ""}` });
  const videos = await Promise.all(episode.videos.map(async (video) => {
    const element = el("video", { muted: true, playsInline: true, preload: "auto", width: 320 });
    element.muted = true;
    element.setAttribute("aria-label", `what ${video.camera} saw`);
    const figure = el("figure", { className: "episode-video" }, element, el("figcaption", { textContent: video.camera }));
    try { element.src = await authorizedUrl(video.url); } catch (error) { figure.append(el("p", { className: "error", textContent: `the video could not be read (${error.message})` })); }
    element.addEventListener("error", () => {
      figure.append(el("p", { className: "error", textContent: "this browser cannot play this video (its codec): the 3D view and the plot still play" }));
    });
    return { ...video, element, figure };
  }));
  const canvas = el("canvas", { className: "episode-plot" });
  canvas.setAttribute("role", "img");
  canvas.setAttribute("aria-label", "state against action per joint over the episode, the cursor at the frame shown");
  const scrub = el("input", { type: "range", min: 0, max: Math.max(0, n - 1), step: 1, value: 0 });
  scrub.setAttribute("aria-label", "frame");
  const clock = el("span", { className: "muted" });
  const speed = el("select", {}, ...SPEEDS.map((s) => el("option", { value: String(s), textContent: `${s}×`, selected: s === 1 })));
  speed.setAttribute("aria-label", "speed");
  const ghost = el("input", { type: "checkbox", checked: true });
  const playButton = button("play", () => (state.playing ? pause() : play()));
  const close = button("back to the live robot", () => closePlayer());
  const controls = el("div", { className: "toolbar" }, playButton, scrub, speed,
    el("label", {}, ghost, " action as a ghost"), clock, close);
  const note = el("p", { className: "muted", textContent: view ? "The 3D view shows the recorded state (grey) and the action (blue ghost); the robot is not moved. Left/right: one frame; space: play/pause." : "No 3D view here: the video and the plot still play." });
  const root = el("div", { className: "episode-player", tabIndex: 0 }, title, note,
    el("div", { className: "episode-videos" }, ...videos.map((v) => v.figure)), canvas, controls);
  body.replaceChildren(root);
  const plot = makePlot(canvas, episode);
  const state = { k: 0, playing: false, base: null, closed: false };
  const master = videos.find((v) => v.element.src) || null;
  status.episode = { repo_id: repoId, index, frames: n, fps: episode.fps, motors: episode.motors, videos: episode.videos };
  status.videoTimes = () => videos.map((v) => v.element.currentTime);
  status.videoErrors = () => videos.map((v) => (v.element.error ? v.element.error.code : null));

  const videoOk = (v) => v.element.src && !v.element.error;
  function seekVideos(t) {
    for (const v of videos) {
      if (!videoOk(v)) continue;
      // a quarter frame in: the picture stamped k/fps, never the one before it
      v.element.currentTime = Math.min(v.from_s + t + 0.25 / episode.fps, v.to_s - 0.25 / episode.fps);
    }
  }
  function show(k, seek) {
    state.k = k;
    status.frame = k;
    const st = byName(episode.motors, episode.state[k] || []);
    if (view) view.showEpisode(st, ghost.checked ? byName(episode.motors, episode.action[k] || []) : null);
    status.shown = st;
    scrub.value = String(k);
    plot.draw(k);
    clock.textContent = `${seconds(times[k] ?? 0)} / ${seconds(end)} · frame ${k + 1}/${n}`;
    if (seek) seekVideos(times[k] ?? 0);
  }
  // The first video is the clock while its time moves; one that stalls (decoding starved, a
  // seek that hangs) hands over to the page's clock, and is seeked back in step, for STALL_MS.
  function tick() {
    if (!state.playing || state.closed) return;
    const now = performance.now();
    let t = state.base.t + ((now - state.base.at) / 1000) * Number(speed.value);
    let clockName = "page";
    if (master && videoOk(master) && !master.element.paused) {
      const vt = master.element.currentTime - master.from_s;
      if (vt !== state.videoT) { state.videoT = vt; state.videoAt = now; }
      if (now - state.videoAt < STALL_MS) {
        t = vt;
        clockName = "video";
        state.base = { t, at: now };
      } else if (!master.element.seeking) {
        master.element.currentTime = master.from_s + t;
        state.videoAt = now;
      }
    }
    status.clock = clockName;
    status.ticks[clockName] += 1;
    for (const v of videos) {
      if (v !== master && videoOk(v) && !v.element.seeking && Math.abs(v.element.currentTime - v.from_s - t) > DRIFT_S) v.element.currentTime = v.from_s + t;
    }
    if (t >= end - 0.5 / episode.fps) { show(n - 1, false); pause(); return; }
    const k = frameAt(times, t);
    if (k !== state.k) show(k, false);
    requestAnimationFrame(tick);
  }
  function play() {
    if (!n) return;
    if (state.k >= n - 1) show(0, true);
    state.playing = true; status.playing = true;
    playButton.textContent = "pause";
    state.base = { t: times[state.k], at: performance.now() };
    state.videoT = null; state.videoAt = performance.now();
    for (const v of videos) {
      if (!videoOk(v)) continue;
      v.element.playbackRate = Number(speed.value);
      v.element.play().catch(() => { /* the page's clock plays on */ });
    }
    requestAnimationFrame(tick);
  }
  function pause() {
    state.playing = false; status.playing = false;
    playButton.textContent = "play";
    for (const v of videos) v.element.pause();
    seekVideos(times[state.k] ?? 0);
  }
  function step(by) {
    if (state.playing) pause();
    show(Math.max(0, Math.min(n - 1, state.k + by)), true);
  }
  function closePlayer() {
    state.closed = true;
    pause();
    if (view) view.endEpisode();
    for (const v of videos) { if (v.element.src.startsWith("blob:")) URL.revokeObjectURL(v.element.src); v.element.removeAttribute("src"); }
    body.replaceChildren();
    status.episode = null; player = null;
  }
  scrub.addEventListener("input", () => { if (state.playing) pause(); show(Number(scrub.value), true); });
  speed.addEventListener("change", () => {
    for (const v of videos) v.element.playbackRate = Number(speed.value);
    state.base = { t: times[state.k], at: performance.now() };
  });
  ghost.addEventListener("change", () => show(state.k, false));
  canvas.addEventListener("pointerdown", (event) => {
    const box = canvas.getBoundingClientRect();
    step(plot.frameOf(((event.clientX - box.left) / box.width) * canvas.width) - state.k);
  });
  // the keys step frames while the player has the focus (the page's other keys stay theirs)
  root.addEventListener("keydown", (event) => {
    if (event.target.tagName === "SELECT") return;
    const by = { ArrowLeft: -1, ArrowRight: 1 }[event.key];
    if (by) { event.preventDefault(); event.stopPropagation(); step(by); return; }
    if (event.key === " " && event.target === root) { event.preventDefault(); event.stopPropagation(); (state.playing ? pause : play)(); }
  });
  show(0, true);
  root.focus();
  player = { close: closePlayer, play, pause, step, show: (k) => show(k, true) };
  status.player = player;
  return player;
}

function episodeRows(dataset, body) {
  if (dataset.error) return [el("p", { className: "error", textContent: `${dataset.repo_id}: ${dataset.error}` })];
  if (!dataset.episodes.length) return [el("p", { className: "muted", textContent: `${dataset.repo_id} has no episode yet.` })];
  const rows = dataset.episodes.map((episode) => el("tr", {},
    el("td", { textContent: String(episode.index) }),
    el("td", { textContent: episode.tasks.join(", ") }),
    el("td", { textContent: seconds(episode.duration_s) }),
    el("td", { textContent: String(episode.frames) }),
    el("td", {}, button("play", () => openAndSay(body, dataset.repo_id, episode.index)))));
  const head = el("thead", {}, el("tr", {}, ...["episode", "task", "length", "frames", ""].map((t) => el("th", { scope: "col", textContent: t }))));
  const about = `${dataset.fps} fps · ${dataset.cameras.length ? `cameras: ${dataset.cameras.join(", ")}` : "no camera"} · ${dataset.robot_type || "robot unknown"}`;
  return [el("p", { className: "muted", textContent: about }),
    el("div", { className: "scroll" }, el("table", { className: "episodes" }, head, el("tbody", {}, ...rows)))];
}

async function openAndSay(body, repoId, index) {
  try { await open(body, repoId, index); } catch (error) { say(`episode ${index} of ${repoId}: ${error.message}`, true); }
}

// Build the panel in #datasets; the list is read now and on "refresh"; #dataset=ID&episode=K in
// the page's address opens that episode (what `poppy dataset view` prints).
export function setupDatasets() {
  const panel = document.getElementById("datasets");
  if (!panel) return;
  window.poppy.datasets = status;
  const choose = el("select", { id: "dataset-choice" });
  choose.setAttribute("aria-label", "dataset");
  const list = el("div", { className: "episode-list" });
  const body = el("div", { className: "episode-body" });
  const where = el("p", { className: "muted" });
  const show = () => {
    const dataset = status.datasets.find((d) => d.repo_id === choose.value);
    list.replaceChildren(...(dataset ? episodeRows(dataset, body) : []));
  };
  async function refresh() {
    try {
      const answer = await get("/api/v1/datasets");
      status.datasets = answer.datasets;
      const kept = choose.value;
      choose.replaceChildren(...answer.datasets.map((d) => el("option", { value: d.repo_id, textContent: d.repo_id })));
      if (answer.datasets.some((d) => d.repo_id === kept)) choose.value = kept;
      where.textContent = answer.datasets.length ? `From ${answer.home} and the datasets given to poppy dataset view.`
        : `No dataset in ${answer.home}: record one with poppy dataset record.`;
      show();
      status.ready = true;
    } catch (error) { where.textContent = `The datasets cannot be listed: ${error.message}`; status.error = error.message; }
  }
  choose.addEventListener("change", show);
  panel.append(el("div", { className: "toolbar" }, choose, button("refresh", refresh)), where, list, body);
  refresh().then(() => {
    const asked = new URLSearchParams(location.hash.slice(1));
    const repoId = asked.get("dataset");
    if (!repoId || !status.datasets.some((d) => d.repo_id === repoId)) return;
    choose.value = repoId; show();
    openAndSay(body, repoId, Number(asked.get("episode") || 0));
  });
}
