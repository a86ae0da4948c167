// World <-> canvas transform: `scale` CSS pixels per metre, world point (cx, cy) at the canvas centre, +y up.

export class Camera {
  constructor() {
    this.scale = 20;
    this.cx = 0;
    this.cy = 0;
    this.width = 1;   // canvas size in CSS pixels
    this.height = 1;
  }

  resize(width, height) {
    this.width = width;
    this.height = height;
  }

  worldToCanvas(x, y) {
    return [this.width / 2 + (x - this.cx) * this.scale, this.height / 2 - (y - this.cy) * this.scale];
  }

  canvasToWorld(px, py) {
    return [this.cx + (px - this.width / 2) / this.scale, this.cy - (py - this.height / 2) / this.scale];
  }

  // Show the whole box [x0, y0, x1, y1] with a small margin.
  fit([x0, y0, x1, y1]) {
    const margin = 0.97;
    this.scale = Math.min(this.width / (x1 - x0), this.height / (y1 - y0)) * margin;
    this.cx = (x0 + x1) / 2;
    this.cy = (y0 + y1) / 2;
  }

  // Zoom by `factor`, keeping the world point under canvas pixel (px, py) where it is.
  zoomAt(px, py, factor) {
    const [wx, wy] = this.canvasToWorld(px, py);
    this.scale = Math.min(Math.max(this.scale * factor, 0.05), 5000);
    const [nx, ny] = this.canvasToWorld(px, py);
    this.cx += wx - nx;
    this.cy += wy - ny;
  }

  panBy(dx, dy) {
    this.cx -= dx / this.scale;
    this.cy += dy / this.scale;
  }

  centreOn(x, y) {
    this.cx = x;
    this.cy = y;
  }
}
