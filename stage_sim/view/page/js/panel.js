// The text around the picture: status line (sim time, real-time factor, robots) and the selected robot.

const fixed = (v, n) => (v >= 0 ? " " : "") + v.toFixed(n);
const pose = ([x, y, yaw]) => `${fixed(x, 3)} ${fixed(y, 3)}  ${fixed((yaw * 180) / Math.PI, 1)}°`;

export function showStatus(element, state, link) {
  const { scene, frame } = state;
  if (!scene || !frame) {
    element.textContent = link;
    return;
  }
  const rtf = frame.paused ? "paused" : frame.rtf === null ? "…" : `${frame.rtf.toFixed(2)}× real time`;
  const stalled = frame.stalled.filter(Boolean).length;
  element.textContent =
    `${scene.world}   t = ${frame.time.toFixed(1)} s   ${rtf}   ` +
    `${scene.robots.length} robot${scene.robots.length === 1 ? "" : "s"}` +
    (stalled ? `, ${stalled} stalled` : "") + (scene.readonly ? "   read-only" : "");
  element.classList.toggle("paused", frame.paused);
}

export function showSelection(element, state, input) {
  const { scene, frame, selected } = state;
  if (!scene || !frame || selected < 0) {
    element.hidden = true;
    return;
  }
  const stalled = frame.stalled[selected];
  const twist = ([vx, vy, va]) => `${fixed(vx, 2)} ${fixed(vy, 2)} m/s  ${fixed(va, 2)} rad/s`;
  element.hidden = false;
  element.innerHTML = "";
  const lines = [
    scene.robots[selected].name,
    `true pose  ${pose(frame.poses[selected])}`,
    `odometry   ${pose(frame.odometry[selected])}`,
    `velocity   ${twist(frame.true_velocities[selected])}`,
    `commanded  ${twist(frame.velocities[selected])}`,
    `keys drive at ${input.speed.toFixed(2)} m/s, ${input.turn.toFixed(2)} rad/s`,
  ];
  for (const line of lines) element.append(line, "\n");
  const stall = document.createElement("span");
  stall.textContent = stalled ? "STALLED" : "not stalled";
  if (stalled) stall.className = "stalled";
  element.append(stall);
}
