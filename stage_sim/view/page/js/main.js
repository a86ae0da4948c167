// The page: one canvas drawn from the latest frame, at most once per animation frame.

import { Camera } from "./camera.js";
import { decodeRanges, draw } from "./draw.js";
import { Input } from "./input.js";
import { Link } from "./link.js";
import { showSelection, showStatus } from "./panel.js";

const TRAIL_POINTS = 2000;
const TRAIL_STEP_M = 0.02;

const canvas = document.getElementById("world");
const ctx = canvas.getContext("2d");
const state = {
  scene: null,
  frame: null,
  ranges: [],
  trails: [],
  mapImage: null,
  selected: -1,
  camera: new Camera(),
  options: { data: true, trails: true, grid: true, follow: false },
  framesReceived: 0,
  framesDrawn: 0,
  drawnFrame: null,
};
let linkStatus = "connecting…";
let dirty = true;
let fitted = false;

function resize() {
  const ratio = window.devicePixelRatio || 1;
  const box = canvas.getBoundingClientRect();
  canvas.width = Math.max(1, Math.round(box.width * ratio));
  canvas.height = Math.max(1, Math.round(box.height * ratio));
  ctx.setTransform(ratio, 0, 0, ratio, 0, 0);
  state.camera.resize(box.width, box.height);
  if (state.scene && !fitted) {
    state.camera.fit(state.scene.bounds);
    fitted = true;
  }
  dirty = true;
}

function onScene(scene) {
  const first = state.scene === null;
  state.scene = scene;
  state.trails = scene.robots.map(() => []);
  state.mapImage = new Image();
  state.mapImage.onload = () => { dirty = true; };
  state.mapImage.src = scene.map.url;
  if (first) {
    state.camera.fit(scene.bounds);
    fitted = true;
  }
  if (state.selected >= scene.robots.length) state.selected = -1;
  if (scene.robots.length === 1 && state.selected < 0) state.selected = 0;
  document.getElementById("pause").disabled = scene.readonly;
  document.getElementById("speed").disabled = scene.readonly;
  document.getElementById("reset").disabled = scene.readonly;
  dirty = true;
}

function onFrame(frame) {
  state.frame = frame;
  state.ranges = frame.ranges.map((scans) => scans.map(decodeRanges));
  frame.poses.forEach(([x, y], i) => {
    const trail = state.trails[i];
    if (!trail) return;
    const last = trail[trail.length - 1];
    if (!last || Math.hypot(x - last[0], y - last[1]) >= TRAIL_STEP_M) trail.push([x, y]);
    if (trail.length > TRAIL_POINTS) trail.splice(0, trail.length - TRAIL_POINTS);
  });
  state.framesReceived += 1;
  syncControls(frame);
  dirty = true;
}

function syncControls(frame) {
  document.getElementById("pause").textContent = frame.paused ? "Resume" : "Pause";
  const speed = document.getElementById("speed");
  if (document.activeElement !== speed) {
    const value = frame.speedup <= 0 ? "0" : String(frame.speedup);
    if (![...speed.options].some((o) => o.value === value)) speed.add(new Option(`${frame.speedup}×`, value));
    speed.value = value;
  }
}

const link = new Link(onScene, onFrame, (status) => { linkStatus = status; dirty = true; });

const actions = {
  send: (message) => link.send(message),
  redraw: () => { dirty = true; },
  toggle(name) {
    if (name === "pause") {
      if (state.frame && !state.scene.readonly) link.send({ type: "pause", paused: !state.frame.paused });
      return;
    }
    state.options[name] = !state.options[name];
    const box = document.getElementById(name === "follow" ? "follow" : `show-${name}`);
    box.checked = state.options[name];
    dirty = true;
  },
};
const input = new Input(canvas, state, actions);

document.getElementById("pause").addEventListener("click", () => actions.toggle("pause"));
document.getElementById("reset").addEventListener("click", () => {
  link.send({ type: "reset" });
  state.trails = state.trails.map(() => []);
});
document.getElementById("speed").addEventListener("change", (e) => {
  link.send({ type: "speed", speedup: Number(e.target.value) });
  canvas.focus();
});
document.getElementById("snapshot").addEventListener("click", () => {
  canvas.toBlob((blob) => {
    const a = document.createElement("a");
    a.href = URL.createObjectURL(blob);
    a.download = `stage_sim-${state.frame ? state.frame.time.toFixed(1) : 0}s.png`;
    a.click();
    setTimeout(() => URL.revokeObjectURL(a.href), 1000);
  });
});
for (const [name, id] of [["data", "show-data"], ["trails", "show-trails"], ["grid", "show-grid"], ["follow", "follow"]]) {
  document.getElementById(id).addEventListener("change", (e) => {
    state.options[name] = e.target.checked;
    dirty = true;
    canvas.focus();
  });
}

function animate() {
  if (dirty) {
    dirty = false;
    const { frame, selected, options, camera } = state;
    if (options.follow && frame && selected >= 0) camera.centreOn(frame.poses[selected][0], frame.poses[selected][1]);
    draw(ctx, camera, state);
    showStatus(document.getElementById("status"), state, linkStatus);
    showSelection(document.getElementById("selection"), state, input);
    state.drawnFrame = frame;
    state.framesDrawn += 1;
  }
  requestAnimationFrame(animate);
}

new ResizeObserver(resize).observe(canvas);
resize();
canvas.focus();
requestAnimationFrame(animate);

// For tests and curious users: the page's own world -> canvas transform and what it last drew.
window.stageView = {
  state,
  worldToCanvas: (x, y) => state.camera.worldToCanvas(x, y),
  canvasToWorld: (x, y) => state.camera.canvasToWorld(x, y),
};
