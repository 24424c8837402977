// The robot in 3D: its URDF and meshes (from /api/v1/model) drawn with three.js, moved by the
// state stream's present positions; the goal as a ghost while a goto runs; each chain's tip and
// its cartesian target as dots; what a marker detector sees, under it. Renders only when
// something changed (a motor moved, the mouse).
import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { STLLoader } from "three/examples/jsm/loaders/STLLoader.js";
import URDFLoader from "/web/vendor/urdf-loader/URDFLoader.js";
import { get, token } from "../api.js";

const POLL_S = 0.5; // goals and targets: how often they are read while the view shows
const GHOST_DEG = 1.5; // a goal this far from where the motor is shows the ghost
const BODY = 0xd9dde3, GHOST = 0x3b82f6, TIP = 0xf97316, TARGET = 0x16a34a;

function authorized(path) {
  const headers = token() ? { Authorization: `Bearer ${token()}` } : {};
  return fetch(path, { headers });
}

// One STL per file name, fetched once for the robot and its ghost; null when it is missing.
function meshSource(base, present, missing) {
  const geometries = new Map();
  return (name) => {
    if (!present.has(name)) { missing.add(name); return Promise.resolve(null); }
    if (!geometries.has(name)) {
      geometries.set(name, authorized(base + name).then(async (response) => {
        if (!response.ok) { missing.add(name); return null; }
        const geometry = new STLLoader().parse(await response.arrayBuffer());
        geometry.computeVertexNormals();
        return geometry;
      }).catch(() => { missing.add(name); return null; }));
    }
    return geometries.get(name);
  };
}

function parseRobot(text, mesh, material, pending) {
  const loader = new URDFLoader();
  loader.packages = () => "";
  loader.loadMeshCb = (path, manager, _urdfMaterial, done) => {
    const name = path.split("/").pop();
    pending.push(mesh(name).then((geometry) => done(geometry ? new THREE.Mesh(geometry, material) : null)));
  };
  const robot = loader.parse(text);
  robot.rotation.x = -Math.PI / 2; // URDF's z up, three's y up
  return robot;
}

// Thin sticks from each joint to the next, drawn when some meshes are missing: the robot's
// frames still show where it is.
function skeleton(robot, material, size) {
  const unit = new THREE.CylinderGeometry(size * 0.012, size * 0.012, 1, 8);
  unit.translate(0, 0.5, 0);
  unit.rotateX(Math.PI / 2); // along +z, from 0 to 1
  const ball = new THREE.SphereGeometry(size * 0.02, 12, 8);
  const along = new THREE.Vector3(0, 0, 1);
  for (const joint of Object.values(robot.joints)) {
    joint.add(new THREE.Mesh(ball, material));
    const length = joint.position.length();
    if (!joint.parent || length < 1e-4) continue;
    const stick = new THREE.Mesh(unit, material);
    stick.scale.set(1, 1, length);
    stick.quaternion.setFromUnitVectors(along, joint.position.clone().normalize());
    joint.parent.add(stick);
  }
}

function markers(robot, chains, size) {
  const dot = new THREE.SphereGeometry(size * 0.018, 16, 12);
  const tips = {}, targets = {};
  for (const [name, chain] of Object.entries(chains)) {
    const joint = robot.joints[chain.tip_joint];
    const link = joint && joint.children.find((c) => c.isURDFLink);
    if (!link) continue;
    const tip = new THREE.Mesh(dot, new THREE.MeshBasicMaterial({ color: TIP, depthTest: false }));
    tip.renderOrder = 2;
    tip.position.fromArray(chain.tip);
    link.add(tip);
    tips[name] = tip;
    const base = robot.links[chain.base];
    if (!base) continue;
    const target = new THREE.Mesh(dot, new THREE.MeshBasicMaterial({ color: TARGET, wireframe: true, depthTest: false }));
    target.renderOrder = 2;
    target.visible = false;
    base.add(target);
    targets[name] = target;
  }
  return { tips, targets };
}

// How big the robot is: the diagonal of the box around its joints (m).
function jointSpan(robot) {
  robot.updateMatrixWorld(true);
  const box = new THREE.Box3();
  robot.traverse((o) => { if (o.isURDFJoint) box.expandByPoint(o.getWorldPosition(new THREE.Vector3())); });
  return box.isEmpty() ? 0.3 : Math.max(0.1, box.getSize(new THREE.Vector3()).length());
}

function frameCamera(camera, controls, robot) {
  robot.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(robot);
  robot.traverse((o) => { if (o.isURDFJoint) box.expandByPoint(o.getWorldPosition(new THREE.Vector3())); });
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length() || 0.5;
  const distance = size / (2 * Math.tan((camera.fov * Math.PI) / 360)) * 1.25;
  camera.position.copy(centre).add(new THREE.Vector3(0.9, 0.55, 1.0).normalize().multiplyScalar(distance));
  camera.near = distance / 100; camera.far = distance * 20;
  camera.updateProjectionMatrix();
  controls.target.copy(centre);
  controls.update();
  return box;
}

export async function startView(container, about) {
  const model = await get("/api/v1/model");
  const response = await authorized(model.urdf);
  if (!response.ok) throw new Error(`the robot's URDF could not be read (${response.status})`);
  const text = await response.text();
  const missing = new Set();
  const mesh = meshSource(model.meshes, new Set(model.mesh_files), missing);
  const pending = [];
  // Lambert shading and no multisampling: cheap enough for a software renderer (bench web)
  const bodyMaterial = new THREE.MeshLambertMaterial({ color: BODY });
  const ghostMaterial = new THREE.MeshLambertMaterial({ color: GHOST, transparent: true, opacity: 0.28, depthWrite: false });
  const robot = parseRobot(text, mesh, bodyMaterial, pending);
  const ghost = parseRobot(text, mesh, ghostMaterial, pending);
  ghost.visible = false;
  await Promise.all(pending);
  const size = jointSpan(robot);
  if (missing.size) {
    console.warn(`3D view: ${missing.size} mesh file(s) missing, drawn as sticks: ${[...missing].join(", ")}`);
    skeleton(robot, bodyMaterial, size);
  }

  const renderer = new THREE.WebGLRenderer({ antialias: false, powerPreference: "low-power" });
  renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 1.5));
  const canvas = renderer.domElement;
  canvas.setAttribute("role", "img");
  canvas.setAttribute("aria-label", `3D view of ${about.name}`);
  container.append(canvas);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xf4f5f7);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x8a8f99, 2.2));
  const sun = new THREE.DirectionalLight(0xffffff, 1.6);
  sun.position.set(2, 4, 3);
  scene.add(sun);
  scene.add(robot, ghost);
  const camera = new THREE.PerspectiveCamera(40, 1, 0.01, 50);
  const controls = new OrbitControls(camera, canvas);
  controls.enableDamping = false;
  const box = frameCamera(camera, controls, robot);
  const grid = new THREE.GridHelper(Math.max(0.4, box.getSize(new THREE.Vector3()).length() * 1.5), 12, 0xc4c8d0, 0xdde0e6);
  grid.position.y = box.min.y;
  scene.add(grid);
  const { tips, targets } = markers(robot, model.chains, size);

  const stats = { ready: true, frames: 0, updates: 0, missing: [...missing], meshes: 0, continuous: false, empty: false, ghost: false, targets: 0, firstDrawAt: null };
  robot.traverse((o) => { if (o.isMesh && o.material === bodyMaterial && o.geometry.type === "BufferGeometry") stats.meshes += 1; });
  window.poppy.view = stats;
  // each chain's tip as drawn, in the chain's base frame (m): what /api/v1/chains/<chain> says
  stats.tips = () => Object.fromEntries(Object.entries(tips).map(([name, tip]) => {
    const base = robot.links[model.chains[name].base];
    robot.updateMatrixWorld(true);
    return [name, base.worldToLocal(tip.getWorldPosition(new THREE.Vector3())).toArray()];
  }));
  let dirty = true, visible = true;

  function resize() {
    const width = container.clientWidth || 480;
    const height = Math.round(Math.min(480, Math.max(240, width * 0.62)));
    renderer.setSize(width, height);
    camera.aspect = width / height;
    camera.updateProjectionMatrix();
    dirty = true;
  }
  new ResizeObserver(resize).observe(container);
  resize();
  controls.addEventListener("change", () => { dirty = true; });

  const blank = new THREE.Scene(); // bench web: `empty` draws nothing, for the cost of a frame
  function loop() {
    requestAnimationFrame(loop);
    if (!visible || !(dirty || stats.continuous)) return;
    dirty = false;
    renderer.render(stats.empty ? blank : scene, camera);
    if (stats.frames === 0) stats.firstDrawAt = performance.now();
    stats.frames += 1;
  }
  loop();

  const angle = (name, degrees) => {
    const j = model.joints[name];
    return j ? (j.scale * (degrees + j.offset_deg) * Math.PI) / 180 : null;
  };
  const present = {}, drawn = {}; // the angles the stream gives, and those last drawn
  function pose(target, values) {
    for (const [name, degrees] of Object.entries(values)) {
      const joint = target.joints[name];
      const radians = angle(name, degrees);
      if (joint && radians !== null) joint.setJointValue(radians);
    }
  }

  // an episode played by the datasets' panel poses the view instead of the live robot (the
  // robot itself is never sent anything): its state drawn solid, its action as the ghost
  let episode = null;
  stats.episode = null;
  // each joint as drawn now, in the robot's degrees (the inverse of angle())
  stats.degrees = () => Object.fromEntries(Object.entries(model.joints).filter(([name]) => robot.joints[name])
    .map(([name, j]) => [name, (robot.joints[name].angle * 180) / Math.PI / j.scale - j.offset_deg]));

  // the gotos under way (their goals as a ghost) and cartesian targets: read while it shows
  async function poll() {
    if (!visible || episode) return;
    try {
      const live = await get("/api/v1/model/goals");
      const away = Object.entries(live.goals).some(([name, goal]) => name in present && Math.abs(goal - present[name]) > GHOST_DEG);
      if (away) pose(ghost, { ...present, ...live.goals });
      if (ghost.visible !== away || away) { ghost.visible = away; dirty = true; }
      stats.ghost = away;
      for (const [name, marker] of Object.entries(targets)) {
        const aim = live.targets[name];
        const show = Array.isArray(aim);
        if (show) marker.position.fromArray(aim);
        if (show || marker.visible) dirty = true;
        marker.visible = show;
      }
      stats.targets = Object.values(targets).filter((m) => m.visible).length;
    } catch { /* the page's badge says when the robot is away */ }
  }
  setInterval(poll, POLL_S * 1000);

  // what the robot's marker detector sees, under the view; read only while the detector runs
  // (someone uses it): reading it would start it, camera and all
  const detectors = Object.entries(about.sensors ?? {}).filter(([, s]) => s.kind === "MarkerDetector").map(([name]) => name);
  const seen = document.createElement("p");
  seen.className = "view-seen muted";
  container.append(seen);
  async function look() {
    if (!visible) return;
    try {
      const health = await get("/api/v1/sensors/health");
      const lines = [];
      for (const name of detectors.filter((n) => health[n]?.running)) {
        const { registers } = await get(`/api/v1/sensors/${name}`);
        const cards = registers.cards ?? [], markers = registers.markers ?? [];
        const what = cards.length ? cards.join(", ") : markers.map((m) => `marker ${m.id}`).join(", ");
        lines.push(`${name} sees ${what || "no marker"}`);
      }
      seen.textContent = lines.join("; ");
      stats.seen = seen.textContent;
    } catch { /* the badge says */ }
  }
  if (detectors.length) setInterval(look, 1000);

  return {
    frame(data) {
      if (episode) { // the live values are kept for when the episode ends, not drawn
        for (const [name, state] of Object.entries(data)) {
          if (typeof state?.present_position === "number") present[name] = state.present_position;
        }
        return;
      }
      let moved = false; // a still robot is not drawn again (a tenth of a degree is nothing to see)
      for (const [name, state] of Object.entries(data)) {
        const degrees = state?.present_position;
        if (typeof degrees !== "number") continue;
        if (!(name in drawn) || Math.abs(degrees - drawn[name]) > 0.1) moved = true;
        present[name] = degrees;
      }
      stats.updates += 1;
      if (!moved) return;
      pose(robot, present);
      Object.assign(drawn, present);
      dirty = true;
    },
    setVisible(on) { visible = on; dirty = true; },
    // draw a recorded frame: {joint: degrees} of the state and of the action (null: no ghost)
    showEpisode(state, action) {
      episode = { state, action };
      stats.episode = episode;
      pose(robot, state);
      if (action) pose(ghost, action);
      ghost.visible = Boolean(action);
      stats.ghost = ghost.visible;
      dirty = true;
    },
    // back to the live robot
    endEpisode() {
      if (!episode) return;
      episode = null;
      stats.episode = null;
      ghost.visible = false;
      stats.ghost = false;
      pose(robot, present);
      Object.assign(drawn, present);
      dirty = true;
    },
  };
}
