// Mouse and keyboard: pan/zoom, select and drag robots, Stage's toggles, teleop_twist_keyboard driving.

// teleop_twist_keyboard's bindings: key -> [x, y, (z), turn] directions, and speed factors.
const MOVES = {
  i: [1, 0, 0], o: [1, 0, -1], j: [0, 0, 1], l: [0, 0, -1], u: [1, 0, 1], ",": [-1, 0, 0], ".": [-1, 0, 1],
  m: [-1, 0, -1], k: [0, 0, 0],
  O: [1, -1, 0], I: [1, 0, 0], J: [0, 1, 0], L: [0, -1, 0], U: [1, 1, 0], "<": [-1, 0, 0], ">": [-1, -1, 0],
  M: [-1, 1, 0], K: [0, 0, 0],
};
const SPEEDS = { q: [1.1, 1.1], z: [0.9, 0.9], w: [1.1, 1], x: [0.9, 1], e: [1, 1.1], c: [1, 0.9] };
const DRIVE_PERIOD_MS = 100;  // resend while a key is held: the simulator's watchdog stops a silent robot
const CLICK_PX = 4;

export class Input {
  constructor(canvas, state, actions) {
    this.canvas = canvas;
    this.state = state;
    this.actions = actions;  // {send, toggle(name), togglePause(), redraw()}
    this.drag = null;
    this.held = null;
    this.speed = 0.5;
    this.turn = 1.0;
    canvas.addEventListener("mousedown", (e) => this.down(e));
    window.addEventListener("mousemove", (e) => this.move(e));
    window.addEventListener("mouseup", (e) => this.up(e));
    canvas.addEventListener("wheel", (e) => this.wheel(e), { passive: false });
    window.addEventListener("keydown", (e) => this.keyDown(e));
    window.addEventListener("keyup", (e) => this.keyUp(e));
    window.addEventListener("blur", () => this.release());
    setInterval(() => this.sendHeld(), DRIVE_PERIOD_MS);
  }

  point(e) {
    const box = this.canvas.getBoundingClientRect();
    return [e.clientX - box.left, e.clientY - box.top];
  }

  robotAt(px, py) {
    const { scene, frame, camera } = this.state;
    if (!scene || !frame) return -1;
    const [wx, wy] = camera.canvasToWorld(px, py);
    let best = -1;
    let bestDistance = Infinity;
    scene.robots.forEach((robot, i) => {
      const [x, y] = frame.poses[i];
      const distance = Math.hypot(wx - x, wy - y);
      if (distance <= Math.max(robot.radius, 6 / camera.scale) && distance < bestDistance) {
        best = i;
        bestDistance = distance;
      }
    });
    return best;
  }

  down(e) {
    if (e.button !== 0) return;
    this.canvas.focus();
    const [px, py] = this.point(e);
    const robot = this.robotAt(px, py);
    const start = { px, py, moved: false };
    if (robot >= 0 && !this.state.scene.readonly) {
      const [wx, wy] = this.state.camera.canvasToWorld(px, py);
      const [x, y] = this.state.frame.poses[robot];
      this.drag = { ...start, robot, dx: x - wx, dy: y - wy };
    } else {
      this.drag = { ...start, robot };
    }
    e.preventDefault();
  }

  move(e) {
    const drag = this.drag;
    if (!drag) return;
    const [px, py] = this.point(e);
    if (Math.hypot(px - drag.px, py - drag.py) > CLICK_PX) drag.moved = true;
    if (!drag.moved) return;
    const camera = this.state.camera;
    if (drag.robot >= 0 && drag.dx !== undefined) {
      const [wx, wy] = camera.canvasToWorld(px, py);
      const name = this.state.scene.robots[drag.robot].name;
      const [x, y] = this.state.frame.poses[drag.robot];
      if (e.shiftKey) {
        this.actions.send({ type: "pose", robot: name, x, y, yaw: Math.atan2(wy - y, wx - x) });
      } else {
        this.actions.send({ type: "pose", robot: name, x: wx + drag.dx, y: wy + drag.dy });
      }
    } else if (drag.robot < 0) {
      camera.panBy(px - (drag.lastX ?? drag.px), py - (drag.lastY ?? drag.py));
      this.state.options.follow = false;
      this.actions.redraw();
    }
    drag.lastX = px;
    drag.lastY = py;
  }

  up(e) {
    const drag = this.drag;
    this.drag = null;
    if (!drag || drag.moved) return;
    this.state.selected = drag.robot;
    this.actions.redraw();
  }

  wheel(e) {
    e.preventDefault();
    const [px, py] = this.point(e);
    this.state.camera.zoomAt(px, py, Math.pow(1.0015, -e.deltaY));
    this.actions.redraw();
  }

  keyDown(e) {
    const target = e.target;
    if (target && (target.tagName === "INPUT" || target.tagName === "SELECT") && target.type !== "checkbox") return;
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    const key = e.key;
    if (key in MOVES) {
      this.held = key;
      this.heldCode = e.code;  // the physical key: its key-up may carry another character (Shift released first)
      if (!e.repeat) this.sendHeld();
      e.preventDefault();
      return;
    }
    if (key in SPEEDS) {
      const [linear, angular] = SPEEDS[key];
      this.speed *= linear;
      this.turn *= angular;
      this.actions.redraw();
      return;
    }
    const toggles = { p: "pause", d: "data", t: "trails", g: "grid", f: "follow" };
    const name = toggles[key.toLowerCase()];
    if (name && !e.repeat) {
      this.actions.toggle(name);
      e.preventDefault();
    } else if (key === "Escape") {
      this.state.selected = -1;
      this.actions.redraw();
    }
  }

  keyUp(e) {
    if (this.held !== null && e.code === this.heldCode) this.release();
  }

  release() {
    if (this.held === null) return;
    this.held = null;
    this.sendDrive([0, 0, 0]);
  }

  sendHeld() {
    if (this.held !== null) this.sendDrive(MOVES[this.held]);
  }

  sendDrive([x, y, turn]) {
    const { scene, selected } = this.state;
    if (!scene || selected < 0 || scene.readonly) return;
    const name = scene.robots[selected].name;
    this.actions.send({ type: "drive", robot: name, vx: x * this.speed, vy: y * this.speed, va: turn * this.turn });
  }
}
