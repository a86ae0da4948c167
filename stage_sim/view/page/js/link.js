// The WebSocket to the simulation: scene and frames in, actions out; reconnects when the server comes back.

export class Link {
  constructor(onScene, onFrame, onStatus) {
    this.onScene = onScene;
    this.onFrame = onFrame;
    this.onStatus = onStatus;
    this.socket = null;
    this.connect();
  }

  connect() {
    const scheme = location.protocol === "https:" ? "wss" : "ws";
    const socket = new WebSocket(`${scheme}://${location.host}/ws`);
    this.socket = socket;
    socket.onmessage = (event) => {
      const message = JSON.parse(event.data);
      if (message.type === "scene") this.onScene(message);
      else if (message.type === "frame") this.onFrame(message);
    };
    socket.onopen = () => this.onStatus("connected");
    socket.onclose = () => {
      this.onStatus("disconnected: retrying…");
      setTimeout(() => this.connect(), 1000);
    };
  }

  send(message) {
    if (this.socket && this.socket.readyState === WebSocket.OPEN) this.socket.send(JSON.stringify(message));
  }
}
