// Drawing one picture of the world: map, grid with metre labels, trails, laser data, robots and their names.

const GRID_MIN_PX = 40;     // grid lines at least this far apart on screen
const STALL = "#d00000";
const SELECT = "#1a7f37";
const NAME_FONT = "12px system-ui, sans-serif";
const NAME_OFFSET = 0.75;   // of the stall ring's radius, along each axis: just outside the ring's corner

export function decodeRanges(base64) {
  const bytes = Uint8Array.from(atob(base64), (c) => c.charCodeAt(0));
  return new Float32Array(bytes.buffer);
}

export function draw(ctx, camera, state) {
  const { scene, frame, options } = state;
  ctx.fillStyle = "#ffffff";
  ctx.fillRect(0, 0, camera.width, camera.height);
  if (!scene) return;
  drawMap(ctx, camera, scene, state.mapImage);
  if (options.grid) drawGrid(ctx, camera);
  if (!frame) return;
  if (options.trails) drawTrails(ctx, camera, scene, state.trails);
  if (options.data) drawLasers(ctx, camera, scene, frame, state.ranges);
  drawRobots(ctx, camera, scene, frame, state.selected);
}

function drawMap(ctx, camera, scene, image) {
  const [x0, y0, x1, y1] = scene.bounds;
  const [left, top] = camera.worldToCanvas(x0, y1);
  const [right, bottom] = camera.worldToCanvas(x1, y0);
  if (image && image.complete && image.naturalWidth) {
    ctx.imageSmoothingEnabled = false;
    ctx.drawImage(image, left, top, right - left, bottom - top);
  }
  ctx.strokeStyle = "#999";
  ctx.lineWidth = 1;
  ctx.strokeRect(left, top, right - left, bottom - top);
}

function gridSpacing(scale) {
  const wanted = GRID_MIN_PX / scale;
  const unit = 10 ** Math.floor(Math.log10(wanted));
  return [1, 2, 5, 10].map((m) => m * unit).find((s) => s >= wanted);
}

function drawGrid(ctx, camera) {
  const spacing = gridSpacing(camera.scale);
  const [wx0, wy1] = camera.canvasToWorld(0, 0);
  const [wx1, wy0] = camera.canvasToWorld(camera.width, camera.height);
  const digits = Math.max(0, -Math.floor(Math.log10(spacing)));
  ctx.save();
  ctx.strokeStyle = "rgba(0, 0, 0, 0.12)";
  ctx.fillStyle = "rgba(0, 0, 0, 0.55)";
  ctx.lineWidth = 1;
  ctx.font = "11px system-ui, sans-serif";
  ctx.beginPath();
  for (let x = Math.ceil(wx0 / spacing) * spacing; x <= wx1; x += spacing) {
    const [px] = camera.worldToCanvas(x, 0);
    ctx.moveTo(Math.round(px) + 0.5, 0);
    ctx.lineTo(Math.round(px) + 0.5, camera.height);
    ctx.fillText(`${x.toFixed(digits)} m`, px + 3, camera.height - 4);
  }
  for (let y = Math.ceil(wy0 / spacing) * spacing; y <= wy1; y += spacing) {
    const [, py] = camera.worldToCanvas(0, y);
    ctx.moveTo(0, Math.round(py) + 0.5);
    ctx.lineTo(camera.width, Math.round(py) + 0.5);
    ctx.fillText(`${y.toFixed(digits)} m`, 3, py - 3);
  }
  ctx.stroke();
  ctx.restore();
}

function drawTrails(ctx, camera, scene, trails) {
  ctx.save();
  ctx.lineWidth = 2;
  ctx.globalAlpha = 0.45;
  scene.robots.forEach((robot, i) => {
    const trail = trails[i];
    if (!trail || trail.length < 2) return;
    ctx.strokeStyle = robot.color;
    ctx.beginPath();
    trail.forEach(([x, y], k) => {
      const [px, py] = camera.worldToCanvas(x, y);
      if (k === 0) ctx.moveTo(px, py);
      else ctx.lineTo(px, py);
    });
    ctx.stroke();
  });
  ctx.restore();
}

// A robot-frame point (x, y) placed at `pose` and mapped to the canvas.
function place(camera, [px, py, yaw], x, y) {
  const c = Math.cos(yaw);
  const s = Math.sin(yaw);
  return camera.worldToCanvas(px + c * x - s * y, py + s * x + c * y);
}

function drawLasers(ctx, camera, scene, frame, ranges) {
  ctx.save();
  ctx.lineWidth = 1;
  scene.robots.forEach((robot, i) => {
    const pose = frame.poses[i];
    robot.rangers.forEach((ranger, k) => {
      const distances = ranges[i] && ranges[i][k];
      if (!distances) return;
      const [ox, oy] = [ranger.offset[0], ranger.offset[1]];
      const [sx, sy] = place(camera, pose, ox, oy);
      ctx.strokeStyle = ranger.color;
      ctx.fillStyle = ranger.color;
      ctx.globalAlpha = 0.25;
      ctx.beginPath();
      const hits = [];
      for (let b = 0; b < distances.length; b++) {
        const angle = ranger.yaw + ranger.angle_min + b * ranger.increment;
        const r = distances[b];
        const [ex, ey] = place(camera, pose, ox + r * Math.cos(angle), oy + r * Math.sin(angle));
        ctx.moveTo(sx, sy);
        ctx.lineTo(ex, ey);
        if (r < ranger.range_max) hits.push([ex, ey]);
      }
      ctx.stroke();
      ctx.globalAlpha = 0.9;
      for (const [hx, hy] of hits) ctx.fillRect(hx - 1.5, hy - 1.5, 3, 3);
    });
  });
  ctx.restore();
}

function drawRobots(ctx, camera, scene, frame, selected) {
  ctx.save();
  scene.robots.forEach((robot, i) => {
    const pose = frame.poses[i];
    for (const part of robot.parts) {
      ctx.beginPath();
      part.points.forEach(([x, y], k) => {
        const [px, py] = place(camera, pose, x, y);
        if (k === 0) ctx.moveTo(px, py);
        else ctx.lineTo(px, py);
      });
      ctx.closePath();
      ctx.fillStyle = part.color;
      ctx.fill();
      ctx.strokeStyle = "rgba(0, 0, 0, 0.5)";
      ctx.lineWidth = 1;
      ctx.stroke();
    }
    const [cx, cy] = place(camera, pose, 0, 0);
    const [nx, ny] = place(camera, pose, robot.nose, 0);
    ctx.strokeStyle = "#000";
    ctx.lineWidth = Math.max(1, 0.02 * camera.scale);
    ctx.beginPath();
    ctx.moveTo(cx, cy);
    ctx.lineTo(nx, ny);
    ctx.stroke();
    const ring = (robot.radius + 0.06) * camera.scale + 2;
    if (frame.stalled[i]) circle(ctx, cx, cy, ring, STALL, 3, []);
    if (i === selected) circle(ctx, cx, cy, ring + 4, SELECT, 2, [6, 4]);
    label(ctx, robot.name, cx + ring * NAME_OFFSET, cy - ring * NAME_OFFSET);
  });
  ctx.restore();
}

// A robot's name (its ROS prefix or model name, as the panel and the messages call it), up and to the right
// of the body, clear of its rings, with a white halo so it reads on walls and floor alike.
function label(ctx, text, x, y) {
  ctx.font = NAME_FONT;
  ctx.textBaseline = "bottom";
  ctx.lineJoin = "round";
  ctx.lineWidth = 3;
  ctx.strokeStyle = "rgba(255, 255, 255, 0.85)";
  ctx.strokeText(text, x, y);
  ctx.fillStyle = "#111";
  ctx.fillText(text, x, y);
}

function circle(ctx, x, y, radius, color, width, dash) {
  ctx.beginPath();
  ctx.setLineDash(dash);
  ctx.strokeStyle = color;
  ctx.lineWidth = width;
  ctx.arc(x, y, radius, 0, 2 * Math.PI);
  ctx.stroke();
  ctx.setLineDash([]);
}
